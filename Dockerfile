# labelmesh in a container: Debian 12 with the packages from the same
# scripts/install-deps.sh that README.md and CI use.
FROM debian:12

WORKDIR /opt/labelmesh
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN bash scripts/install-deps.sh && rm -rf /var/lib/apt/lists/*

COPY . .
RUN bash scripts/build.sh release \
 && install -m 0755 build/release/client/labelmesh /usr/local/bin/labelmesh

# Run as an unprivileged user; mount volumes under /data.
RUN useradd --system --create-home labelmesh && mkdir -p /data && chown labelmesh /data
USER labelmesh
WORKDIR /data
ENTRYPOINT ["labelmesh"]
CMD ["--help"]
