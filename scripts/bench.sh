#!/usr/bin/env bash
# Benchmark: per-stage seconds, voxels per second and peak RSS on the liver
# and vb-seg.mha, beside the baselines they are held to. Prints figures only.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh dev
build/dev/tests/labelmesh_bench "$@"
bash scripts/bench-service.sh
