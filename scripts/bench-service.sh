#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Service benchmark: upload throughput, start latency and job throughput of
# labelmeshd on loopback, beside their targets. Prints figures only: it never
# fails on speed, only when a server, an upload or a job breaks.
set -euo pipefail
shopt -s inherit_errexit # a command failing inside $(...) fails the run too
cd "$(dirname "$0")/.."

BIN=${LABELMESH_BIN:-build/dev} # scripts/bench.sh passes its release-flag build
CLI=$BIN/client/labelmesh
SERVER=$BIN/server/labelmeshd
PY=/usr/bin/python3 # Debian's interpreter, never whichever python3 comes first on PATH
T=$(mktemp -d)
PIDS=()

stop_servers() { # SIGTERM, then wait, so no labelmeshd outlives the run
  local pid
  for pid in "${PIDS[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
  PIDS=()
}
trap 'stop_servers; rm -rf "$T"' EXIT

# start_server NAME WORKERS: labelmeshd on a free loopback port; sets ADDR.
start_server() {
  local port
  port=$($PY -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  "$SERVER" --listen "127.0.0.1:$port" --spool-dir "$T/spool-$1" --workers "$2" >"$T/$1.log" 2>&1 &
  PIDS+=("$!")
  ADDR=127.0.0.1:$port
  for _ in $(seq 50); do # up to ~5 s
    "$CLI" health --server "$ADDR" >/dev/null 2>&1 && return 0
    kill -0 "${PIDS[-1]}" 2>/dev/null || break
    sleep 0.1
  done
  echo "labelmeshd ($1) did not come up:" >&2 && cat "$T/$1.log" >&2 && return 1
}

now_us() { echo "${EPOCHREALTIME/./}"; } # bash 5 wall clock, microseconds
calc() { $PY -c "print(format($2, '$1'))"; } # calc FORMAT EXPRESSION

# best_us CMD...: fastest of 3 runs in microseconds; the first run also pays
# for a cold page cache and a fresh server.
best_us() {
  local best=0 t0 t
  for _ in 1 2 3; do
    t0=$(now_us)
    "$@" >/dev/null
    t=$(($(now_us) - t0))
    if ((best == 0 || t < best)); then best=$t; fi
  done
  echo "$best"
}

# watch_times JOB: "queued started end" in unix seconds, from the job's events.
# watch --json prints one object per line (decoded in turn either way); a job
# that did not finish, or events out of order, fail the run.
watch_times() {
  "$CLI" watch "$1" --server "$ADDR" --json | $PY -c '
import json, sys
text, decoder, pos, times, event = sys.stdin.read(), json.JSONDecoder(), 0, {}, None
while True:
    while pos < len(text) and text[pos].isspace():
        pos += 1
    if pos == len(text):
        break
    event, pos = decoder.raw_decode(text, pos)
    for kind in ("queued", "started", "finished"):
        if kind in event:
            times.setdefault(kind, float(event["time"]))
if "finished" not in times:
    sys.exit(f"job {sys.argv[1]} did not finish: {json.dumps(event)}")
q, s, f = (times.get(k) for k in ("queued", "started", "finished"))
if None in (q, s) or not q <= s <= f:
    sys.exit(f"job {sys.argv[1]}: events missing or out of order: {times}")
print(q, s, f)' "$1"
}

job_id() { $PY -c 'import json, sys; print(json.load(sys.stdin)["job_id"])'; }

echo "== service benchmark =="

# 1. Upload. A --workers 0 server only queues, so no job competes with the
#    transfer. The client hashes the file (OpenSSL SHA-256) before sending;
#    openssl dgst uses the same library, so total - openssl is the upload.
$CLI phantom sphere --out "$T/small.nii.gz" >/dev/null
for scale in 2 4 6 8; do # volume grows as scale^3; stop at 50 MB
  $CLI phantom sphere --scale "$scale" --out "$T/big.nii" >/dev/null
  (($(stat -c %s "$T/big.nii") >= 50000000)) && break
done
start_server upload 0
connect=$(best_us "$CLI" health --server "$ADDR")
printf '%-26s %8s ms  (labelmesh health: process start + connect, in every total)\n' \
  "client start + connect" "$(calc .1f "$connect / 1e3")"
for file in ../shared/data/liver.inr.gz "$T/big.nii"; do
  bytes=$(stat -c %s "$file")
  total=$(best_us "$CLI" submit "$file" --server "$ADDR" --detach --json)
  sha=$(best_us sha256sum "$file")
  ossl=$(best_us openssl dgst -sha256 "$file")
  printf '%-26s %8s MB  total %7s ms %7s MB/s  sha256sum %6s ms  openssl %6s ms  upload ≈ %7s MB/s  (target ≥ 200)\n' \
    "upload $(basename "$file")" "$(calc .2f "$bytes / 1e6")" "$(calc .1f "$total / 1e3")" \
    "$(calc .1f "$bytes / $total")" "$(calc .1f "$sha / 1e3")" "$(calc .1f "$ossl / 1e3")" \
    "$(calc .1f "$bytes / max($total - $ossl, 1)")"
done
if (($(stat -c %s "$T/big.nii") < 50000000)); then
  echo "  note: phantom sphere --scale $scale is the largest and only $(calc .1f "$(stat -c %s "$T/big.nii") / 1e6") MB, short of 50 MB"
fi
stop_servers # queued uploads go with it; they never ran

# 2. Start latency on an idle 2-worker server: Queued to Started event, one
#    job at a time so each finds a free worker.
start_server jobs 2
latencies=() runs=()
for _ in 1 2 3 4 5; do
  id=$($CLI submit "$T/small.nii.gz" --server "$ADDR" --detach --json | job_id)
  times=$(watch_times "$id") # an assignment, so a failed job stops the run
  read -r q s f <<<"$times"
  latencies+=("$(calc .6f "($s - $q) * 1e3")") runs+=("$(calc .6f "$f - $s")")
done
$PY - "${latencies[@]}" <<'EOF'
import statistics, sys
ms = sorted(float(v) for v in sys.argv[1:])
print(f"{'start latency':<26} min {ms[0]:.1f} ms  median {statistics.median(ms):.1f} ms  "
      f"max {ms[-1]:.1f} ms  (target < 50 ms, {len(ms)} jobs)")
EOF

# 3. Throughput: 20 small jobs submitted at once, timed from the first submit
#    to the last Finished event. Poisson unless one job alone takes > 5 s.
run=$($PY -c 'import statistics, sys; print(statistics.median(map(float, sys.argv[1:])))' "${runs[@]}")
surface=poisson
$PY -c "import sys; sys.exit(not $run > 5)" && surface=repaired
t0=$(now_us)
for _ in $(seq 20); do
  $CLI submit "$T/small.nii.gz" --server "$ADDR" --surface "$surface" --detach --json >>"$T/submitted.json"
done
t1=$(now_us)
for id in $($PY -c 'import json, sys; [print(json.loads(l)["job_id"]) for l in sys.stdin]' <"$T/submitted.json"); do
  watch_times "$id" >>"$T/times.txt"
done
# The mean run beside the lone job's shows how much the 2 workers slow each other.
$PY - "$T/times.txt" "$t0" "$t1" "$run" "$surface" <<'EOF'
import sys
path, t0, t1, alone, surface = sys.argv[1:]
t0, t1, alone = int(t0) / 1e6, int(t1) / 1e6, float(alone)
jobs = [tuple(map(float, line.split())) for line in open(path)]
wall = max(f for _, _, f in jobs) - t0
run = sum(f - s for _, s, f in jobs) / len(jobs)
print(f"{f'{len(jobs)} jobs, 2 workers':<26} wall {wall:.1f} s  {len(jobs) * 60 / wall:.1f} jobs/min  "
      f"(surface {surface}; a job ran {run:.2f} s on average, {alone:.2f} s alone; "
      f"submits took {t1 - t0:.2f} s)")
EOF
[[ $surface == poisson ]] || echo "  note: one poisson job took > 5 s, so these used --surface repaired"
