#!/usr/bin/env bash
# profile.sh MM DB OUTDIR [SCRIPT...]: where Controller::update's instructions go.
#
# Runs `MM eval` of each script (default: every shipped script listed in scripts/input/README.md)
# at 1/60 s under callgrind, counting only inside mm::Controller::update, and prints one table:
# instructions per update of each phase (the inclusive cost of update's direct callees, and of
# refresh_outputs' callees), summed over the scripts and divided by the updates made. The phases
# are real (out-of-line) member functions of Controller; callgrind's call graph attributes each
# call site's inclusive cost to its caller, so a function called by two phases (sample_playback by
# the update and by a transition) is counted in each, never twice. Cost left in update itself
# (inlined helpers: advance_playback, simulate, the displayed root's rates) is the `update (self)`
# row. Time per phase is estimated as its share of the instructions times the mean wall-clock
# time of an update measured natively (a shared machine: noisy). Per-script totals are written to OUTDIR/totals.tsv.
set -euo pipefail
mm=$1; db=$2; out=$3; shift 3
here=$(cd "$(dirname "$0")" && pwd)
scripts=("$@")
if [ ${#scripts[@]} -eq 0 ]; then
  for n in circle zigzag stop-and-go strafe walk-run camera-turns tag-wave random-long stand-turns \
           reversals strafe-run showcase; do scripts+=("$here/input/$n.txt"); done
fi
mkdir -p "$out"
: > "$out/totals.tsv"
for s in "${scripts[@]}"; do
  n=$(basename "$s" .txt)
  valgrind --tool=callgrind --callgrind-out-file="$out/$n.cg" \
    --toggle-collect='mm::Controller::update(*' \
    "$mm" eval --db "$db" --script "$s" --dt 0.0166667 --json "$out/$n.json" >/dev/null 2>"$out/$n.log"
  # Updates made: the script's duration plus the 2 s eval adds, at 60 Hz (frames in the JSON).
  frames=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['frames'])" "$out/$n.json")
  callgrind_annotate --tree=calling --inclusive=yes --threshold=100 "$out/$n.cg" > "$out/$n.tree"
  total=$(grep -m1 'PROGRAM TOTALS' "$out/$n.tree" | awk '{gsub(",","",$1); print $1}')
  # Time: the same run natively (not under callgrind), its mean wall-clock time per update.
  "$mm" eval --db "$db" --script "$s" --dt 0.0166667 --json "$out/$n.time.json" >/dev/null
  us=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['update_us_mean'])" \
    "$out/$n.time.json")
  printf '%s\t%s\t%s\t%s\n' "$n" "$frames" "$total" "$us" >> "$out/totals.tsv"
done
python3 "$here/profile_table.py" "$out"
