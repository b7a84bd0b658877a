#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Builds the labelmesh container image without a registry. It installs podman
# and debootstrap from Debian when missing, makes a minimal Debian 12 base
# with debootstrap from the mirror this machine's apt uses, loads it with
# `podman import` as labelmesh-base:bookworm (once; reused after), then builds
# the Dockerfile on it with podman and prints the image's size.
# Idempotent: the base is kept and podman caches the layers.
# Usage: sudo bash scripts/build-image.sh [--rebuild-base]
# Result: labelmesh:VERSION and labelmesh:latest, and the build stage as
# labelmesh-build:latest (to compare sizes). Check it with scripts/check-image.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

base=labelmesh-base:bookworm
rebuild_base=false
case "${1:-}" in
  "") ;;
  --rebuild-base) rebuild_base=true ;;
  *) echo "usage: $0 [--rebuild-base]" >&2; exit 2 ;;
esac

# debootstrap needs root, and rootful podman needs no subuid ranges.
if [ "$(id -u)" -ne 0 ]; then
  echo "build-image: run as root (debootstrap, podman import)" >&2
  exit 2
fi

# The compile takes long on few cores; let other work on the machine go first.
slow=(nice -n 19 ionice -c3)

need=()
command -v podman >/dev/null || need+=(podman)
command -v debootstrap >/dev/null || need+=(debootstrap)
if [ ${#need[@]} -gt 0 ]; then
  echo "build-image: installing ${need[*]}"
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${need[@]}"
fi

# The URI of the first apt source (deb822 or one-line) that serves the given
# Debian 12 suite, or the default.
apt_uri() {
  local suite=$1 default=$2 uri=""
  if compgen -G '/etc/apt/sources.list.d/*.sources' >/dev/null; then
    uri=$(awk -v RS= -v suite="$suite" '
      $0 ~ "Suites:[^\n]*[ \t]" suite "([ \t\n]|$)" && match($0, /URIs:[ \t]*[^ \t\n]+/) {
        u = substr($0, RSTART, RLENGTH); sub(/URIs:[ \t]*/, "", u); print u; exit
      }' /etc/apt/sources.list.d/*.sources)
  fi
  if [ -z "$uri" ] && [ -f /etc/apt/sources.list ]; then
    uri=$(awk -v suite="$suite" '$1 == "deb" {
        for (i = 2; i < NF; i++) if ($i ~ /^https?:/ && $(i + 1) == suite) { print $i; exit }
      }' /etc/apt/sources.list)
  fi
  echo "${uri:-$default}"
}

# Unmounts whatever is mounted below a directory, deepest first.
unmount_under() {
  findmnt -rno TARGET | { grep "^$1/" || true; } | sort -r | xargs -r umount -l
}

make_base() {
  local mirror security rootfs
  mirror=$(apt_uri bookworm http://deb.debian.org/debian)
  security=$(apt_uri bookworm-security http://deb.debian.org/debian-security)
  rootfs=$(mktemp -d /var/tmp/labelmesh-base.XXXXXX)
  # debootstrap mounts /proc and /sys in the target; unmount before removing.
  trap "unmount_under '$rootfs'; rm -rf --one-file-system '$rootfs'" EXIT
  echo "build-image: debootstrap bookworm from $mirror"
  "${slow[@]}" debootstrap --variant=minbase bookworm "$rootfs" "$mirror"
  # The base's apt sees the same suites as this machine: release, updates and
  # security fixes.
  rm -f "$rootfs/etc/apt/sources.list"
  cat >"$rootfs/etc/apt/sources.list.d/debian.sources" <<EOF
Types: deb
URIs: $mirror
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: $security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  rm -rf "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/cache/apt/*.bin \
    "$rootfs"/var/cache/apt/archives/*.deb
  podman image rm --force "$base" >/dev/null 2>&1 || true
  tar --numeric-owner -C "$rootfs" -c . |
    podman import \
      --change 'ENV PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
      --change 'CMD ["/bin/bash"]' - "$base"
  unmount_under "$rootfs"
  rm -rf --one-file-system "$rootfs"
  trap - EXIT
}

if $rebuild_base || ! podman image exists "$base"; then
  start=$(date +%s)
  make_base
  echo "build-image: base made in $(($(date +%s) - start)) s"
else
  echo "build-image: reusing $base"
fi

version=$(sed -n 's/^project(labelmesh VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
revision=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
# --isolation=chroot: RUN steps need no runtime, namespaces or cgroups of their
# own. --format docker: the OCI format has no HEALTHCHECK. --pull=never: the
# base is local, and nothing may come from a registry.
build=("${slow[@]}" podman build --isolation=chroot --format docker --pull=never
  --build-arg BASE="$base" --build-arg VERSION="$version" --build-arg REVISION="$revision")
start=$(date +%s)
# The build stage first, tagged to compare its size: the full build then
# reuses its layers (the other order compiles it a second time).
"${build[@]}" --target build -t labelmesh-build:latest .
# --label again: podman reuses a cached LABEL step even when the build
# argument in it changed, so the Dockerfile's revision label would go stale.
"${build[@]}" -t "labelmesh:$version" -t labelmesh:latest \
  --label org.opencontainers.image.version="$version" \
  --label org.opencontainers.image.revision="$revision" .
echo "build-image: built in $(($(date +%s) - start)) s"

for image in labelmesh:latest labelmesh-build:latest; do
  bytes=$(podman image inspect --format '{{.Size}}' "$image")
  echo "build-image: $image $((bytes / 1000000)) MB ($bytes bytes)"
done
podman images --filter reference=labelmesh --filter reference=labelmesh-build
