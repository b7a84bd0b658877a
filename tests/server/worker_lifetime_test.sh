#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Workers belong to their server: a worker starts with no signal blocked, a
# SIGTERM or SIGKILL from outside fails its job with that cause named, a
# worker dies with a server killed by SIGKILL, and a server starting on a
# spool kills the workers an earlier server left there.
# A stand-in worker (a shell script) records its pid and blocked signals,
# then sleeps, so that each case is decided by signals alone.
# Usage: worker_lifetime_test.sh LABELMESHD LABELMESH
set -euo pipefail
labelmeshd=$1 labelmesh=$2
work=$(mktemp -d)
server_pid=
stray_pid=
cleanup() {
  [ -n "$server_pid" ] && kill -KILL "$server_pid" 2>/dev/null
  [ -n "$stray_pid" ] && kill -KILL "$stray_pid" 2>/dev/null
  pkill -KILL -f "$work/worker.sh" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; tail -20 "$work/server.log" 2>/dev/null; exit 1; }
free_port() { /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
unset LABELMESH_SERVER LABELMESH_TOKEN
for v in $(env | grep -o '^LABELMESHD_[A-Z_]*' || true); do unset "$v"; done

version=$("$(dirname "$labelmeshd")/labelmesh-worker" --version)
cat >"$work/worker.sh" <<EOF
#!/bin/sh
[ "\$1" = --version ] && { echo '$version'; exit 0; }
grep '^SigBlk' /proc/self/status >"\$2/blocked"
echo \$\$ >"\$2/pid"
# No exec: the shell keeps the worker's command line, as a real worker has.
while :; do sleep 1; done
EOF
chmod +x "$work/worker.sh"
"$labelmesh" phantom sphere --out "$work/sphere.nii.gz" >/dev/null

port=$(free_port)
export LABELMESH_SERVER=127.0.0.1:$port
start_server() {
  "$labelmeshd" --listen "127.0.0.1:$port" --spool-dir "$work/spool" \
    --spool-reserve-bytes 16777216 --workers 1 --worker-executable "$work/worker.sh" \
    2>>"$work/server.log" &
  server_pid=$!
  for _ in $(seq 100); do
    "$labelmesh" health >/dev/null 2>&1 && return 0
    kill -0 "$server_pid" 2>/dev/null || fail "labelmeshd exited at start"
    sleep 0.1
  done
  fail "labelmeshd not serving after 10 s"
}
# Submits the sphere and prints the job id once its worker has started.
start_job() {
  local job
  job=$("$labelmesh" submit "$work/sphere.nii.gz" --surface repaired --detach --json |
    /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["job_id"])')
  for _ in $(seq 100); do
    [ -s "$work/spool/jobs/$job/pid" ] && { echo "$job"; return 0; }
    sleep 0.1
  done
  fail "the worker of job $job did not start"
}
worker_of() { cat "$work/spool/jobs/$1/pid"; }
# Running, and not a zombie waiting for its parent to reap it.
alive() { [ -e "/proc/$1" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status" 2>/dev/null; }
# The job's error message once it has failed.
failure_of() {
  local message
  for _ in $(seq 100); do
    message=$("$labelmesh" status "$1" --json | /usr/bin/python3 -c '
import json, sys
job = json.load(sys.stdin)
if job["state"] == "JOB_STATE_FAILED": print(job["error"]["message"])')
    [ -n "$message" ] && { echo "$message"; return 0; }
    sleep 0.1
  done
  fail "job $1 did not fail within 10 s"
}

start_server

job=$(start_job)
grep -q $'^SigBlk:\t0*$' "$work/spool/jobs/$job/blocked" ||
  fail "the worker started with signals blocked: $(cat "$work/spool/jobs/$job/blocked")"
kill -TERM "$(worker_of "$job")"
message=$(failure_of "$job")
grep -q "killed from outside labelmeshd by signal 15 (SIGTERM)" <<<"$message" ||
  fail "SIGTERM from outside reported as: $message"

job=$(start_job)
kill -KILL "$(worker_of "$job")"
message=$(failure_of "$job")
grep -q "killed from outside labelmeshd by signal 9 (SIGKILL)" <<<"$message" ||
  fail "SIGKILL from outside reported as: $message"
grep -q "CPU time" <<<"$message" && fail "SIGKILL from outside blamed on the CPU limit"

# kill -9 of the server: its worker goes with it.
job=$(start_job)
worker=$(worker_of "$job")
kill -KILL "$server_pid"
wait "$server_pid" 2>/dev/null || true
server_pid=
for _ in $(seq 20); do
  alive "$worker" || break
  sleep 0.1
done
alive "$worker" && fail "worker $worker outlived its server by 2 s"

# A worker of an earlier server still running on the spool (one that the
# server's death did not reach) is killed when the next server starts.
stray_dir="$work/spool/jobs/0123456789abcdef0123456789abcdef"
mkdir -p "$stray_dir"
setsid "$work/worker.sh" --worker "$stray_dir" &
stray_pid=$!
for _ in $(seq 50); do [ -s "$stray_dir/pid" ] && break; sleep 0.1; done
start_server
for _ in $(seq 20); do
  alive "$stray_pid" || break
  sleep 0.1
done
alive "$stray_pid" && fail "the stray worker $stray_pid is still running"
stray_pid=
grep -q "left running by an earlier server" "$work/server.log" || fail "no log line for the stray"
echo "PASS"
