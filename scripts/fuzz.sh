#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Fuzzes the checks of untrusted input: builds the fuzz preset (clang,
# libFuzzer, ASan + UBSan) and runs each harness of tests/fuzz for SECONDS
# over a copy of its kept corpus (tests/fuzz/corpus/<harness>). Prints, per
# harness and in total, executions, seconds, coverage (libFuzzer's final cov:
# and ft:) and crashes (crash, leak, timeout or out-of-memory inputs, kept in
# out/fuzz/<harness>/). The grown corpora stay in out/fuzz/<harness>/corpus
# for a merge into the kept ones. Exits 1 on any crash.
# Usage: scripts/fuzz.sh [SECONDS_PER_HARNESS]   (default 600)
#        LABELMESH_FUZZ_JOBS=N runs N harnesses at once (default 1)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
jobs=${LABELMESH_FUZZ_JOBS:-1}
harnesses=(volume_header_fuzzer payload_stream_fuzzer upload_checks_fuzzer job_spec_fuzzer
  dicom_seg_header_fuzzer)
# Longest input per harness, bytes: a compressed payload decodes to up to a
# thousand times its size, and the stream harness decodes all of it.
declare -A max_len=([volume_header_fuzzer]=65536 [payload_stream_fuzzer]=4096
  [upload_checks_fuzzer]=65536 [job_spec_fuzzer]=16384 [dicom_seg_header_fuzzer]=65536)

if ! command -v clang++-14 >/dev/null; then
  echo "fuzz.sh: needs clang++-14 with libFuzzer (Debian: apt-get install clang-14)" >&2
  exit 2
fi
bash scripts/build.sh fuzz
bin=build/fuzz/tests/fuzz
out=out/fuzz
# The harnesses' scratch files go here, so that none outlives a crashed run.
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
export TMPDIR=$scratch
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

run_one() {
  local harness=$1 dir=$out/$1
  rm -rf "$dir"
  mkdir -p "$dir/corpus"
  cp tests/fuzz/corpus/"$harness"/* "$dir/corpus/"
  local start
  start=$(date +%s)
  "$bin/$harness" -max_total_time="$seconds" -max_len="${max_len[$harness]}" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$dir/" "$dir/corpus" \
    >"$dir/log" 2>&1 || true
  echo $(($(date +%s) - start)) >"$dir/seconds"
}

running=0
for harness in "${harnesses[@]}"; do
  run_one "$harness" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait

printf '%-24s %12s %8s %9s %7s %7s %8s\n' harness executions seconds exec/s cov ft crashes
total_execs=0 total_seconds=0 total_crashes=0
for harness in "${harnesses[@]}"; do
  dir=$out/$harness
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log" | tail -n 1)
  # The last status line holds the final coverage ("#N DONE cov: C ft: F ...").
  status=$(grep -E '^#[0-9]+.* cov: ' "$dir/log" | tail -n 1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")
  crashes=$(find "$dir" -maxdepth 1 -type f \
    \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
  elapsed=$(cat "$dir/seconds")
  execs=${execs:-0}
  printf '%-24s %12d %8d %9d %7s %7s %8d\n' "$harness" "$execs" "$elapsed" \
    $((execs / (elapsed > 0 ? elapsed : 1))) "${cov:--}" "${ft:--}" "$crashes"
  total_execs=$((total_execs + execs))
  total_seconds=$((total_seconds + elapsed))
  total_crashes=$((total_crashes + crashes))
done
printf '%-24s %12d %8d %9s %7s %7s %8d\n' total "$total_execs" "$total_seconds" - - - \
  "$total_crashes"
if [ "$total_crashes" -gt 0 ]; then
  echo "fuzz: $total_crashes crashing inputs; see $out/<harness>/ and its log" >&2
  exit 1
fi
