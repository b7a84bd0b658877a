#!/usr/bin/env bash
# SPDX-License-Identifier: AGPL-3.0-or-later
# Benchmark of the delivery guard on every multi-label volume in ../shared/data:
# per file, labels delivered within tolerance, labels that kept Poisson, that
# fell back, that were warned about, seconds and peak RSS of `labelmesh mesh`.
# Usage: scripts/bench-labels.sh [FILE ...]   (default: every multi-label file)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${LABELMESH_BIN:-build/bench}/client/labelmesh
[ -x "$bin" ] || bash scripts/build.sh bench
data=../shared/data
files=("$@")
if [ ${#files[@]} -eq 0 ]; then
  files=(totalseg_example_seg_fast_force_split.nii.gz totalseg_example_seg_dicom.nii.gz
    totalseg_example_seg_mr.nii.gz iso2mesh_brain_seg_converted.nii.gz
    MRIcrop-seg_converted.nii.gz msd_prostate_mask_00.nii frogtissue.mhd vb-seg.mha)
fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
printf '%-45s %6s %7s %7s %8s %7s %8s %9s\n' file labels within poisson fellback warned seconds rss_MiB
for f in "${files[@]}"; do
  out="$scratch/${f//\//_}"
  /usr/bin/time -f '%e %M' -o "$out.time" "$bin" mesh "$data/$f" --out "$out" --json \
    >/dev/null 2>"$out.err" || true
  read -r seconds kib <"$out.time" || { seconds=-; kib=0; }
  /usr/bin/python3 - "$out/report.json" "$f" "$seconds" "$kib" <<'PY'
import json, sys
path, name, seconds, kib = sys.argv[1:]
try:
    report = json.load(open(path))
except OSError:
    print(f"{name:45s} failed (see stderr)")
    sys.exit(0)
outputs = [s for s in report["surfaces"] if s.get("output")]
labels = len(report["input"]["labels"])
within = sum(1 for s in outputs if s["fidelity"]["within_tolerance"])
poisson = sum(1 for s in outputs if s["stage"].startswith("poisson"))
fellback = len(outputs) - poisson
warned = len(report.get("warnings", []))
print(f"{name:45s} {labels:6d} {within:7d} {poisson:7d} {fellback:8d} {warned:7d} "
      f"{seconds:>8s} {int(kib) // 1024:9d}")
PY
done
