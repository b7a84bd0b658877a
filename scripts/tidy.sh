#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Runs clang-tidy (checks in .clang-tidy) over every project .cc file of a build's
# compile_commands.json (core/ server/ client/ tests/, not generated proto code);
# exits non-zero on any finding. Usage: [LABELMESH_TIDY_JOBS=N] scripts/tidy.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/dev}
[ -f "$build/compile_commands.json" ] || {
  echo "tidy: no $build/compile_commands.json; run scripts/build.sh first" >&2
  exit 2
}
/usr/bin/python3 - "$build/compile_commands.json" <<'PY' |
import json, os, sys
entries = json.load(open(sys.argv[1]))
files = {os.path.relpath(os.path.join(e["directory"], e["file"])) for e in entries}
for f in sorted(files):
    if f.split(os.sep)[0] in ("core", "server", "client", "tests") and f.endswith(".cc"):
        sys.stdout.write(f + "\0")
PY
  xargs -0 -r -n 1 -P "${LABELMESH_TIDY_JOBS:-1}" clang-tidy -p "$build" --quiet 2>&1 |
  { grep -Ev '^[0-9]+ (warning|error)s? (and [0-9]+ errors? )?generated\.$' || true; }
echo "tidy: clean"
