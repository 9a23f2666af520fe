#!/usr/bin/env bash
# compare_metrics.sh MM DB OUTDIR: the metrics (mm eval --json, wall-clock keys removed) of every
# shipped script at 1/30, 1/60 and 1/144 s with IK on and off, and of the course's lanes
# (course-walk.txt on data/levels/course.glb) at 1/60 and 1/30. Two OUTDIRs from two binaries
# compare with scripts/compare_metrics.py OUT_A OUT_B, which prints each metric's largest
# difference: for a change of arithmetic, where the dumps cannot be identical.
# compare_metrics.sh MM DB OUTDIR --perturb: the same runs with every time step one unit larger in
# its last printed digit (1/30 as 0.0333334, ...), under the same file names: the base against
# itself perturbed is the noise a change of arithmetic is measured against.
set -euo pipefail
mm=$1; db=$2; out=$3
perturb=${4:-}
if [ -n "$perturb" ] && [ "$perturb" != --perturb ]; then
  echo "compare_metrics.sh: unknown option '$perturb' (expected --perturb)" >&2; exit 2
fi
# The step each file is named after, and the step run (the same unless perturbed).
step() {
  if [ -n "$perturb" ]; then
    case $1 in 0.0333333) echo 0.0333334;; 0.0166667) echo 0.0166668;; 0.00694444) echo 0.00694445;; esac
  else
    echo "$1"
  fi
}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
strip() {
  # Wall-clock figures differ run to run; everything else is the motion.
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); [d.pop(k) for k in
    ('update_us_mean', 'search_us_mean') if k in d]; json.dump(d, open(sys.argv[1], 'w'),
    indent=1, sort_keys=True)" "$1"
}
for n in circle zigzag stop-and-go strafe walk-run camera-turns tag-wave random-long stand-turns \
         reversals strafe-run showcase; do
  for dt in 0.0333333 0.0166667 0.00694444; do
    for ik in on off; do
      "$mm" eval --db "$db" --script "$here/input/$n.txt" --dt "$(step $dt)" --ik $ik \
        --json "$out/$n-$dt-ik$ik.json" >/dev/null
      strip "$out/$n-$dt-ik$ik.json"
    done
  done
done
for x in -3 1 4 7 10 13.5 17.5 22 28 31; do
  for dt in 0.0166667 0.0333333; do
    "$mm" eval --db "$db" --script "$here/input/course-walk.txt" \
      --world "$here/../data/levels/course.glb" --start "$x,0" --dt "$(step $dt)" \
      --json "$out/course$x-$dt.json" >/dev/null
    strip "$out/course$x-$dt.json"
  done
done
