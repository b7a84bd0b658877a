#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# End to end through the real executables: labelmeshd on a free loopback port,
# `labelmesh submit` of the liver compared with `labelmesh mesh` of the same
# file and options, the job commands and their exit codes, the metrics
# endpoint, `labelmesh watch` across a server restart, TLS with a token,
# mutual TLS, and SIGTERM shutdown.
# Usage: client_end_to_end_test.sh LABELMESHD LABELMESH SHARED_DATA
set -euo pipefail
labelmeshd=$1 labelmesh=$2 data=$3
if [ ! -f "$data/liver.inr.gz" ]; then
  echo "SKIP: missing shared data file $data/liver.inr.gz"
  exit 77
fi
work=$(mktemp -d)
server_pid=
stop_server() {
  if [ -n "$server_pid" ] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid"
    wait "$server_pid" || { echo "FAIL: labelmeshd exited non-zero on SIGTERM"; exit 1; }
  fi
  server_pid=
}
trap 'stop_server; rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; tail -20 "$work/server.log" 2>/dev/null; exit 1; }
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
# Environment variables of the server and client are part of what is tested.
unset LABELMESH_SERVER LABELMESH_TOKEN
for v in $(env | grep -o '^LABELMESHD_[A-Z_]*' || true); do unset "$v"; done

start_server() {  # extra flags...
  "$labelmeshd" --spool-dir "$work/spool" --spool-reserve-bytes 16777216 --workers 2 "$@" 2>>"$work/server.log" &
  server_pid=$!
  for _ in $(seq 100); do
    "$labelmesh" health "${client_flags[@]}" >/dev/null 2>&1 && return 0
    kill -0 "$server_pid" 2>/dev/null || fail "labelmeshd exited at start"
    sleep 0.1
  done
  fail "labelmeshd not serving after 10 s"
}

port=$(free_port)
metrics_port=$(free_port)
export LABELMESH_SERVER=127.0.0.1:$port
client_flags=()
# No grace on SIGTERM: a running job is interrupted and runs at next start.
plain_flags=(--listen "127.0.0.1:$port" --metrics-listen "127.0.0.1:$metrics_port"
  --shutdown-grace 0s)
start_server "${plain_flags[@]}"

# The liver through the server and in-process: the same report figures.
"$labelmesh" submit "$data/liver.inr.gz" --labels 255 --surface poisson --out "$work/remote" --json \
  >"$work/remote.json" || fail "submit of the liver exited $?"
"$labelmesh" mesh "$data/liver.inr.gz" --labels 255 --surface poisson --out "$work/local" --json \
  >"$work/local.json" || fail "local mesh of the liver exited $?"
/usr/bin/python3 - "$work" <<'PY' || fail "remote and local reports differ"
import json, os, sys
work = sys.argv[1]
def figures(path):
    report = json.load(open(path))
    return [(s["label"], s["stage"], s["nodes"], s["triangles"], round(s["volume_mm3"], 3))
            for s in report["surfaces"]]
remote, local = figures(f"{work}/remote.json"), figures(f"{work}/local.json")
print("remote", remote)
print("local ", local)
# Every stage is deterministic across processes, so the figures and the
# surface files are identical, byte for byte.
assert remote == local, "remote and local surfaces differ"
assert [f[:2] for f in remote] == [(255, "marching_cubes"), (255, "repaired"), (255, "poisson")]
assert remote[2][2] > 5000, "too few output nodes"
fetched = sorted(os.listdir(f"{work}/remote"))
written = sorted(os.listdir(f"{work}/local"))
assert fetched == written, (fetched, written)
for name in written:
    if name.startswith("surface-"):
        same = open(f"{work}/remote/{name}", "rb").read() == open(f"{work}/local/{name}", "rb").read()
        assert same, f"{name} differs between submit and mesh"
fetched_report = json.load(open(f"{work}/remote/report.json"))
assert [s["nodes"] for s in fetched_report["surfaces"]] == [f[2] for f in remote]
PY

# --detach --json, status, watch, fetch, list.
"$labelmesh" phantom torus --out "$work/torus.nii.gz" >/dev/null
job=$("$labelmesh" submit "$work/torus.nii.gz" --surface repaired --detach --json |
  /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["job_id"])')
[ ${#job} -eq 32 ] || fail "submit --detach --json gave no job id"
"$labelmesh" watch "$job" >/dev/null 2>&1 || fail "watch of a good job exited $?"
# Whole outputs are captured before grep: `grep -q` stops reading at its first
# match, and with pipefail the writer's SIGPIPE would fail the pipeline.
status_json=$("$labelmesh" status "$job" --json) || fail "status exited $?"
grep -q '"state": "JOB_STATE_SUCCEEDED"' <<<"$status_json" || fail "status"
"$labelmesh" fetch "$job" --out "$work/fetched" >/dev/null || fail "fetch exited $?"
[ -s "$work/fetched/surface-label1.stl" ] || fail "fetch wrote no surface"
listed=$("$labelmesh" list) || fail "list exited $?"
grep -q "$job" <<<"$listed" || fail "list does not show the job"

# Labels not delivered are named on stderr by submit, status, watch and
# fetch: the thin-shapes phantom's one- and two-voxel labels are too small to
# mesh.
"$labelmesh" phantom thin-shapes --out "$work/thin.nii.gz" >/dev/null
"$labelmesh" submit "$work/thin.nii.gz" --surface repaired --out "$work/thin" \
  >"$work/thin.out" 2>"$work/thin.err" || fail "submit of the thin shapes exited $?"
grep -q "label(s) outside tolerance or not delivered" "$work/thin.err" ||
  fail "submit printed no warnings"
grep -q "too small to mesh" "$work/thin.err" || fail "submit did not say which label is too small"
thin_job=$(sed -n 's/^job \([0-9a-f]\{32\}\) finished.*/\1/p' "$work/thin.out")
"$labelmesh" status "$thin_job" >/dev/null 2>"$work/thin-status.err" || fail "status exited $?"
grep -q "too small to mesh" "$work/thin-status.err" || fail "status printed no warnings"
"$labelmesh" watch "$thin_job" >/dev/null 2>"$work/thin-watch.err" || fail "watch exited $?"
grep -q "too small to mesh" "$work/thin-watch.err" || fail "watch printed no warnings"
"$labelmesh" fetch "$thin_job" --out "$work/thin-fetched" >/dev/null 2>"$work/thin-fetch.err" ||
  fail "fetch exited $?"
grep -q "too small to mesh" "$work/thin-fetch.err" || fail "fetch printed no warnings"

# Exit codes: unknown job 3, cancel of an ended job 4, a volume that fails 3.
set +e
"$labelmesh" status 00000000000000000000000000000000 >/dev/null 2>&1
[ $? -eq 3 ] || fail "status of an unknown job should exit 3"
"$labelmesh" cancel "$job" >/dev/null 2>&1
[ $? -eq 4 ] || fail "cancel of an ended job should exit 4"
head -c 5000 /dev/urandom >"$work/noise.nii"
"$labelmesh" submit "$work/noise.nii" --out "$work/noise" >/dev/null 2>&1
[ $? -eq 3 ] || fail "submit of a bad volume should exit 3"
set -e
grep -q "noise" "$work/server.log" && fail "the server log names an uploaded file"

# The metrics endpoint of the same labelmeshd that runs the jobs counts them:
# the liver, the torus and the thin shapes.
metrics=$(curl -sf "http://127.0.0.1:$metrics_port/metrics") || fail "no /metrics"
/usr/bin/python3 - "$metrics" <<'PY' || fail "metrics do not count the jobs"
import sys
samples = {}
for line in sys.argv[1].splitlines():
    if line and not line.startswith("#"):
        name, value = line.rsplit(" ", 1)
        samples[name] = float(value)
print({k: v for k, v in samples.items() if k.startswith(("labelmesh_jobs", "labelmesh_rej"))})
assert samples['labelmesh_jobs_total{outcome="succeeded"}'] == 3
assert samples["labelmesh_jobs_running"] == 0
# The noise upload was refused at its header, before it became a job.
assert sum(v for k, v in samples.items() if k.startswith("labelmesh_rejections_total")) == 1
PY

# A job interrupted by a restart: SIGTERM (no grace) stops it while it runs,
# the next labelmeshd on the same spool runs it again, and `labelmesh watch`,
# started before the restart, reconnects and exits 0 when it succeeds.
"$labelmesh" phantom sphere --scale 4 --out "$work/sphere.nii.gz" >/dev/null
job=$("$labelmesh" submit "$work/sphere.nii.gz" --volume tet --detach --json |
  /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["job_id"])')
"$labelmesh" watch "$job" >"$work/watch.txt" 2>&1 &
watch_pid=$!
state=
for _ in $(seq 200); do
  state=$("$labelmesh" status "$job" --json) || fail "status exited $?"
  grep -q '"state": "JOB_STATE_RUNNING"' <<<"$state" && break
  sleep 0.05
done
grep -q '"state": "JOB_STATE_RUNNING"' <<<"$state" || fail "the sphere job never ran"
stop_server
kill -0 "$watch_pid" 2>/dev/null || fail "watch ended with the server: $(cat "$work/watch.txt")"
start_server "${plain_flags[@]}"
wait "$watch_pid" || fail "watch across the restart exited $?: $(tail -3 "$work/watch.txt")"
state=$("$labelmesh" status "$job" --json) || fail "status exited $?"
grep -q '"state": "JOB_STATE_SUCCEEDED"' <<<"$state" || fail "the restarted job did not succeed"
grep -q "spool: 1 jobs queued again" "$work/server.log" || fail "the log does not say the job was queued again"
stop_server

# TLS and a bearer token: refused without the token, served with it.
openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost \
  -addext subjectAltName=DNS:localhost,IP:127.0.0.1 \
  -keyout "$work/key.pem" -out "$work/cert.pem" 2>/dev/null
echo "token-for-the-end-to-end-test" >"$work/token"
port=$(free_port)
export LABELMESH_SERVER=localhost:$port
client_flags=(--tls-ca "$work/cert.pem" --token-file "$work/token")
start_server --listen "127.0.0.1:$port" --tls-cert "$work/cert.pem" --tls-key "$work/key.pem" \
  --auth-token-file "$work/token"
set +e
"$labelmesh" list --tls-ca "$work/cert.pem" >/dev/null 2>&1
[ $? -eq 5 ] || fail "a call without the token should exit 5"
"$labelmesh" list >/dev/null 2>&1
[ $? -eq 5 ] || fail "a plaintext call to a TLS server should exit 5"
set -e
LABELMESH_TOKEN=token-for-the-end-to-end-test "$labelmesh" submit "$work/torus.nii.gz" \
  --surface repaired --tls-ca "$work/cert.pem" --out "$work/tls" >/dev/null 2>&1 ||
  fail "submit over TLS with the token exited $?"
[ -s "$work/tls/report.json" ] || fail "no report over TLS"
stop_server

# Mutual TLS: a client certificate signed by --client-ca is required.
openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=test-ca \
  -keyout "$work/ca-key.pem" -out "$work/ca.pem" 2>/dev/null
openssl req -newkey rsa:2048 -nodes -subj /CN=client -keyout "$work/client-key.pem" \
  -out "$work/client.csr" 2>/dev/null
openssl x509 -req -in "$work/client.csr" -CA "$work/ca.pem" -CAkey "$work/ca-key.pem" \
  -CAcreateserial -days 1 -out "$work/client.pem" 2>/dev/null
port=$(free_port)
export LABELMESH_SERVER=localhost:$port
client_flags=(--tls-ca "$work/cert.pem" --tls-cert "$work/client.pem" --tls-key "$work/client-key.pem")
start_server --listen "127.0.0.1:$port" --tls-cert "$work/cert.pem" --tls-key "$work/key.pem" \
  --client-ca "$work/ca.pem"
set +e
"$labelmesh" health --tls-ca "$work/cert.pem" >/dev/null 2>&1
[ $? -eq 5 ] || fail "a client without a certificate should be refused (exit 5)"
set -e
"$labelmesh" list "${client_flags[@]}" >/dev/null || fail "a client with its certificate exited $?"
stop_server

# Without TLS the server refuses a non-loopback address unless --insecure.
set +e
"$labelmeshd" --listen 0.0.0.0:$port --spool-dir "$work/spool2" 2>"$work/refusal.txt"
code=$?
set -e
[ $code -eq 2 ] && grep -q "needs TLS" "$work/refusal.txt" || fail "plaintext 0.0.0.0 was not refused"
echo PASSED
