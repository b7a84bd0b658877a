# SPDX-License-Identifier: AGPL-3.0-or-later
# labelmesh in a container, in two stages on Debian 12:
#   build    the compilers and -dev packages of scripts/install-deps.sh (the
#            same script README.md and CI use), the `release` preset, and
#            `cmake --install` of the three programs into /staging.
#   runtime  the shared-library packages of scripts/runtime-packages.txt and
#            the three programs: labelmeshd, labelmesh-worker (which runs each
#            job, beside labelmeshd) and the labelmesh client.
# The runtime runs as uid/gid 10001 and needs only /data and /tmp writable,
# so it works with a read-only root file system.
#   docker build -t labelmesh:latest .
# Without a registry, scripts/build-image.sh builds it with podman on a
# debootstrapped base (BASE=labelmesh-base:bookworm); scripts/check-image.sh
# checks the result.
ARG BASE=debian:12

FROM ${BASE} AS build
WORKDIR /src
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN bash scripts/install-deps.sh && apt-get clean && rm -rf /var/lib/apt/lists/*
COPY . .
# ccache survives in a cache mount, so a rebuild after a source change
# recompiles only what changed (build.sh puts CCACHE_DIR under $HOME/.cache).
RUN --mount=type=cache,target=/root/.cache/labelmesh-ccache \
    bash scripts/build.sh release \
 && DESTDIR=/staging cmake --install build/release --prefix /usr/local --strip

FROM ${BASE} AS runtime
COPY scripts/runtime-packages.txt /tmp/runtime-packages.txt
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
      $(sed 's/#.*//' /tmp/runtime-packages.txt) \
 && apt-get clean \
 && rm -rf /var/lib/apt/lists/* /tmp/runtime-packages.txt

# A fixed uid/gid, so volumes and Kubernetes' runAsUser/fsGroup can name it.
RUN groupadd --gid 10001 labelmesh \
 && useradd --uid 10001 --gid 10001 --home-dir /data --no-create-home \
      --shell /usr/sbin/nologin labelmesh \
 && mkdir -p /data/spool /data/artifacts \
 && chown -R 10001:10001 /data

COPY --from=build /staging/usr/local/bin/ /usr/local/bin/
# A library that runtime-packages.txt does not bring fails the build here.
RUN missing=$(ldd /usr/local/bin/labelmeshd /usr/local/bin/labelmesh-worker \
      /usr/local/bin/labelmesh | grep 'not found' || true); \
    if [ -n "$missing" ]; then \
      echo "scripts/runtime-packages.txt lacks:$missing" >&2; exit 1; \
    fi \
 && labelmeshd --version && labelmesh-worker --version && labelmesh --version

# Labels last: the build arguments change with every commit, and a RUN step
# after an ARG would be rebuilt with them.
ARG VERSION=0.1.0
ARG REVISION=unknown
LABEL org.opencontainers.image.title="labelmesh" \
      org.opencontainers.image.description="Meshing service for segmented medical label volumes: labelmeshd, labelmesh-worker and the labelmesh client" \
      org.opencontainers.image.version="${VERSION}" \
      org.opencontainers.image.revision="${REVISION}" \
      org.opencontainers.image.licenses="AGPL-3.0-or-later"

USER 10001:10001
WORKDIR /data
ENV LABELMESHD_SPOOL_DIR=/data/spool
EXPOSE 50051 9464
# Plain gRPC on loopback: with TLS on, override it (labelmesh health --tls ...).
HEALTHCHECK --interval=30s --timeout=5s CMD ["labelmesh", "health", "--server", "127.0.0.1:50051"]
# The service by default; `docker run IMAGE labelmesh mesh ...` runs the CLI.
CMD ["labelmeshd"]
