#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Runs clang-tidy (checks in .clang-tidy) over the project's .cc files in a
# build's compile_commands.json (core/ server/ client/ tests/, not generated
# proto code); exits non-zero on any finding. Files compiled in unity batches
# are checked one by one with their batch's command.
# Usage: [LABELMESH_TIDY_JOBS=N] scripts/tidy.sh [build-dir] [--recent N | --thread-safety]
#   --recent N       only the N .cc files changed most recently in git history
#                    (what CI runs: the newest changes, in bounded time)
#   --thread-safety  instead of the checks, clang's -Wthread-safety as errors
#                    on every .cc file under server/ and core/ whose code or
#                    own header names absl::Mutex: members ABSL_GUARDED_BY a
#                    mutex used without it held, helpers called without the
#                    lock they require
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/dev
recent=
thread_safety=
while [ $# -gt 0 ]; do
  case "$1" in
    --recent) recent=$2; shift 2 ;;
    --thread-safety) thread_safety=1; shift ;;
    *) build=$1; shift ;;
  esac
done
[ -f "$build/compile_commands.json" ] || {
  echo "tidy: no $build/compile_commands.json; run scripts/build.sh first" >&2
  exit 2
}
changed=
if [ -n "$thread_safety" ]; then
  changed=$(git grep -l 'absl::Mutex' -- 'server/*.cc' 'server/*.h' 'core/*.cc' 'core/*.h' |
    sed 's/\.h$/.cc/' | sort -u | while read -r f; do [ -f "$f" ] && echo "$f"; done)
elif [ -n "$recent" ]; then
  # Newest commits first; each file where it last changed; files still here.
  changed=$(git log --name-only --format= -- core server client tests |
    awk '/\.cc$/ && !seen[$0]++' | while read -r f; do [ -f "$f" ] && echo "$f"; done |
    head -n "$recent" || true)
fi
commands=$(mktemp -d)
trap 'rm -rf "$commands"' EXIT
# One entry per project file: a unity batch's files take its command.
CHANGED="$changed" /usr/bin/python3 - "$build/compile_commands.json" "$commands" <<'PY' |
import json, os, re, sys
entries = json.load(open(sys.argv[1]))
changed = set(os.environ["CHANGED"].split()) if os.environ["CHANGED"] else None
out = []
for e in entries:
    path = os.path.join(e["directory"], e["file"])
    if "/Unity/" in path:
        members = re.findall(r'#include "([^"]+)"', open(path).read())
    else:
        members = [path]
    for m in members:
        entry = dict(e)
        entry["file"] = m
        if "command" in entry:
            entry["command"] = entry["command"].replace(path, m)
        else:
            entry["arguments"] = [m if a == path else a for a in entry["arguments"]]
        out.append(entry)
json.dump(out, open(os.path.join(sys.argv[2], "compile_commands.json"), "w"))
files = sorted({os.path.relpath(e["file"]) for e in out})
for f in files:
    if f.split(os.sep)[0] not in ("core", "server", "client", "tests") or not f.endswith(".cc"):
        continue
    if changed is None or f in changed:
        sys.stdout.write(f + "\0")
PY
  if [ -n "$thread_safety" ]; then
    # clang itself, parsing only: each file's command with clang++ for g++.
    xargs -0 -r -n 1 -P "${LABELMESH_TIDY_JOBS:-1}" /usr/bin/python3 -c '
import json, shlex, subprocess, sys
entries = json.load(open(sys.argv[1]))
entry = next(e for e in entries if e["file"].endswith("/" + sys.argv[2]))
words = entry.get("arguments") or shlex.split(entry["command"])
keep, skip = [], False
for w in words[1:]:
    if skip:
        skip = False
    elif w == "-o":
        skip = True
    elif w != "-c":
        keep.append(w)
sys.exit(subprocess.call(["clang++", "-fsyntax-only", "-Wthread-safety", "-Werror=thread-safety",
                          "-Wno-unknown-warning-option"] + keep, cwd=entry["directory"]))
' "$commands/compile_commands.json"
  else
    xargs -0 -r -n 1 -P "${LABELMESH_TIDY_JOBS:-1}" clang-tidy -p "$commands" --quiet 2>&1 |
      { grep -Ev '^[0-9]+ (warning|error)s? (and [0-9]+ errors? )?generated\.$' || true; }
  fi
[ -n "$thread_safety" ] && echo "thread safety: clean" || echo "tidy: clean"
