#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Checks the image that scripts/build-image.sh built, without running a
# container: it mounts the image's file system with `podman image mount` and,
# in a private mount namespace, makes that root read-only with tmpfs on /tmp
# and /data, the image's spool and the writable places a container gets.
# Then, chrooted as uid/gid 10001 with the image's environment, it runs each
# program's --version, starts labelmeshd on loopback, submits a phantom with
# the client (TetGen volume mesh), checks the report and the volume mesh,
# and stops the server. The job's meshes are copied to OUT-DIR.
# Usage: sudo bash scripts/check-image.sh [image] [out-dir]
#        (default labelmesh:latest, out/image-check)
set -euo pipefail
cd "$(dirname "$0")/.."
image=${1:-labelmesh:latest}
out=${2:-out/image-check}

if [ "$(id -u)" -ne 0 ]; then
  echo "check-image: run as root (podman image mount, chroot)" >&2
  exit 2
fi

echo "check-image: $image config:" \
  "$(podman image inspect --format 'user={{.Config.User}} cmd={{.Config.Cmd}} ports={{.Config.ExposedPorts}}' "$image")"
echo "check-image: healthcheck: $(podman image inspect --format '{{.HealthCheck.Test}}' "$image")"
mapfile -t environment < <(podman image inspect --format '{{range .Config.Env}}{{println .}}{{end}}' "$image" | grep .)

# A free loopback port; the chroot shares this machine's network.
for _ in $(seq 50); do
  port=$((20000 + RANDOM % 30000))
  (: </dev/tcp/127.0.0.1/$port) 2>/dev/null || break
done

root=$(podman image mount "$image")
trap 'podman image unmount "$image" >/dev/null' EXIT
rm -rf "$out"
mkdir -p "$out"

# Run in a private mount namespace: every mount it makes ends with it.
inside=$(cat <<'EOF'
set -euo pipefail
root=$1 port=$2 out=$3
shift 3
mount --bind "$root" "$root"
mount -o remount,bind,ro "$root"
mount -t tmpfs -o mode=1777 tmpfs "$root/tmp"
mount -t tmpfs -o mode=0755,uid=10001,gid=10001 tmpfs "$root/data"
mkdir "$root/data/spool" && chown 10001:10001 "$root/data/spool"
mount -t proc proc "$root/proc"   # labelmeshd finds labelmesh-worker via /proc/self/exe
mount --bind /dev "$root/dev"
environment=("$@")
# As uid/gid 10001, with the image's environment (PATH, LABELMESHD_SPOOL_DIR)
# and nothing of ours.
as_image_user=(chroot --userspec=10001:10001 "$root" env -i "${environment[@]}")
run() { "${as_image_user[@]}" "$@"; }

if touch "$root/usr/local/bin/.write-test" 2>/dev/null; then
  echo "check-image: the root file system is writable" >&2; exit 1
fi
echo "check-image: running as $(run id)"
run labelmeshd --version
run labelmesh-worker --version
run labelmesh --version

# The image's own spool (/data/spool from LABELMESHD_SPOOL_DIR) on the tmpfs.
"${as_image_user[@]}" labelmeshd --listen "127.0.0.1:$port" --workers 2 \
  </dev/null 2>"$root/tmp/labelmeshd.log" &
server=$!
trap 'kill -TERM $server 2>/dev/null; wait $server 2>/dev/null || true' EXIT
for _ in $(seq 100); do run labelmesh health --server "127.0.0.1:$port" >/dev/null 2>&1 && break; sleep 0.1; done
run labelmesh health --server "127.0.0.1:$port"

run labelmesh phantom oblique-ellipsoid --out /tmp/e.nii.gz
run labelmesh submit /tmp/e.nii.gz --server "127.0.0.1:$port" --out /tmp/meshes --volume tet \
  --formats stl,vtu,msh
test -s "$root/tmp/meshes/report.json"
ls "$root"/tmp/meshes/volume.* >/dev/null
kill -TERM $server
if wait $server; then
  echo "check-image: labelmeshd stopped cleanly"
else
  echo "check-image: labelmeshd exited with status $?" >&2; exit 1
fi
trap - EXIT
cp -r "$root/tmp/meshes" "$root/tmp/labelmeshd.log" "$out/"
echo "check-image: spool $(du -sh "$root/data/spool" | cut -f1) in /data/spool;" \
  "files: $(cd "$root/tmp/meshes" && echo *)"
EOF
)
unshare --mount --propagation private -- \
  bash -c "$inside" check-image "$root" "$port" "$out" "${environment[@]}"
echo "check-image: OK ($image; meshes and server log in $out)"
