# SPDX-License-Identifier: AGPL-3.0-or-later
# labelmesh in a container: Debian 12 with the packages from the same
# scripts/install-deps.sh that README.md and CI use. The image holds the
# labelmesh client, the labelmeshd service and labelmesh-worker, which runs its
# jobs, installed by the build's install() rules.
FROM debian:12

WORKDIR /opt/labelmesh
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN bash scripts/install-deps.sh && rm -rf /var/lib/apt/lists/*

COPY . .
RUN bash scripts/build.sh release \
 && cmake --install build/release --prefix /usr/local --strip

# Run as an unprivileged user; volumes and the spool live under /data.
RUN useradd --system --create-home labelmesh && mkdir -p /data/spool && chown -R labelmesh /data
USER labelmesh
WORKDIR /data
ENV LABELMESHD_SPOOL_DIR=/data/spool
EXPOSE 50051 9464
# The service by default; `docker run IMAGE labelmesh mesh ...` runs the CLI.
CMD ["labelmeshd"]
