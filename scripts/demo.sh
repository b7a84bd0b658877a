#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# The main job, end to end: installs, builds, starts labelmeshd on loopback,
# submits a phantom volume with the client (Poisson surface and TetGen volume
# mesh), fetches the meshes and the report, and stops the server. Idempotent.
# Usage: scripts/demo.sh [output-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
bash scripts/install-deps.sh
bash scripts/build.sh release
bin=build/release
labelmesh=$bin/client/labelmesh
mkdir -p "$out"
rm -rf "$out/meshes"

port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export LABELMESH_SERVER=127.0.0.1:$port
"$bin/server/labelmeshd" --listen "$LABELMESH_SERVER" --spool-dir "$out/spool" --workers 2 \
  2>"$out/labelmeshd.log" &
server=$!
trap 'kill -TERM $server 2>/dev/null; wait $server 2>/dev/null || true' EXIT
for _ in $(seq 100); do "$labelmesh" health >/dev/null 2>&1 && break; sleep 0.1; done
"$labelmesh" health

"$labelmesh" phantom oblique-ellipsoid --out "$out/ellipsoid.nii.gz"
"$labelmesh" submit "$out/ellipsoid.nii.gz" --out "$out/meshes" --volume tet \
  --formats stl,vtp,vtu,msh
echo
echo "meshes: $(ls "$out"/meshes/surface-label*.* "$out"/meshes/volume.* | tr '\n' ' ')"
echo "report: $out/meshes/report.json"
echo "server log: $out/labelmeshd.log"
