#!/usr/bin/env bash
# The main job, end to end: installs, builds, writes a phantom volume and
# meshes it, then shows where the meshes and the report are. Idempotent.
# Usage: scripts/demo.sh [output-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/demo}
bash scripts/install-deps.sh
bash scripts/build.sh release
labelmesh=build/release/client/labelmesh
mkdir -p "$out"
"$labelmesh" phantom oblique-ellipsoid --out "$out/ellipsoid.nii.gz"
"$labelmesh" info "$out/ellipsoid.nii.gz"
"$labelmesh" mesh "$out/ellipsoid.nii.gz" --out "$out/meshes" --formats stl,vtp,ply
echo
echo "meshes: $(ls "$out"/meshes/surface-label*.* | tr '\n' ' ')"
echo "report: $out/meshes/report.json"
