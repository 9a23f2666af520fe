#!/usr/bin/env bash
# compare_dumps.sh MM DB OUTDIR: the per-frame dump (mm eval --dump) and metrics (--json) of every
# shipped script at 1/60 and 1/30 s, IK on. Two OUTDIRs from two binaries compare with
# `cmp` file by file (scripts/compare_dumps.sh ... && diff -r OUT_A OUT_B).
set -euo pipefail
mm=$1; db=$2; out=$3
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
for n in circle zigzag stop-and-go strafe walk-run camera-turns tag-wave random-long stand-turns \
         reversals strafe-run showcase; do
  for dt in 0.0166667 0.0333333; do
    "$mm" eval --db "$db" --script "$here/input/$n.txt" --dt $dt --ik on \
      --dump "$out/$n-$dt.csv" --json "$out/$n-$dt.json" >/dev/null
    # Wall-clock figures differ run to run; everything else must not.
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); [d.pop(k) for k in
      ('update_us_mean', 'search_us_mean') if k in d]; json.dump(d, open(sys.argv[1], 'w'),
      indent=1, sort_keys=True)" "$out/$n-$dt.json"
  done
done
