#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# The test command: installs dependencies, builds (Release with assertions
# on), and runs the whole suite with ctest. Idempotent.
# Usage: scripts/test.sh            the suite
#        scripts/test.sh --sanitize the tests labelled "sanitize" (input readers and
#                                   header checks, job options, the service, the
#                                   cluster, worker lifetimes, fuzz corpora,
#                                   threaded helpers) under AddressSanitizer + UBSan
set -euo pipefail
cd "$(dirname "$0")/.."
preset=dev
[ "${1:-}" = "--sanitize" ] && preset=asan-ubsan
bash scripts/install-deps.sh
bash scripts/build.sh "$preset"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
ctest --preset "$preset" -j 2
