#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Configures and builds one CMake preset (default: dev) with Ninja and ccache.
# Usage: scripts/build.sh [preset [target...]]   (the benchmarks are built
#        only when named: scripts/build.sh dev labelmesh_surface_bench)
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-dev}
shift $(($# > 0 ? 1 : 0))
targets=()
[ $# -gt 0 ] && targets=(--target "$@")
export CCACHE_DIR=${CCACHE_DIR:-$HOME/.cache/labelmesh-ccache}
# CMake's code model (its file API), which the layering test reads: asked for
# before configuring, so the first configure writes it.
mkdir -p "build/$preset/.cmake/api/v1/query"
touch "build/$preset/.cmake/api/v1/query/codemodel-v2"
cmake --preset "$preset" >/dev/null
# Two jobs: VTK and CGAL translation units need about 1.5 GiB each.
cmake --build --preset "$preset" -j "${LABELMESH_JOBS:-2}" "${targets[@]}"
