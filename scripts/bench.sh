#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Benchmark: per-stage seconds, voxels per second and peak RSS on the liver
# and vb-seg.mha, beside the baselines they are held to. Prints figures only.
set -euo pipefail
cd "$(dirname "$0")/.."
# Timed as shipped: -O3 with assertions off, as the release build the demo and
# the Dockerfile use (the test build keeps CGAL's assertions on).
# The default targets (labelmeshd, the CLI) and the benchmark, which is built only when named.
bash scripts/build.sh bench all labelmesh_bench
build/bench/tests/labelmesh_bench "$@"
LABELMESH_BIN=build/bench bash scripts/bench-service.sh
