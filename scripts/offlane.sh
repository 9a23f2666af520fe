#!/usr/bin/env bash
# The course off its lanes (docs/world.md, "Measured on the course"): six shipped scripts started
# at z = 3 in eight lanes of data/levels/course.glb, at each time step; one line per run with the
# lowest toe clearance (cm), the deepest toe below its surface, the deepest joint in a wall, the
# time stuck, the planted toes' float against the same script's on flat ground and the geometric
# skating against the data's own; BAD marks a run that breaks a target (a toe below 1 cm, a toe in
# the ground, a joint 2 cm in a wall, skating over the data's, planted toes floating more than
# 1.5 cm higher than on flat ground). The flat run's float is read for what the level played:
# each run's float stands beside the played clips' own (foot_float_data_cm_mean), and where a
# course stops the character (standing at a wall while the flat run walks on) the two runs plant
# different steps; the reference is the flat float moved by the difference of the two runs'
# played float.
#   scripts/offlane.sh DB OUT_DIR [DT...]        (mm from build/release, or $MM)
# Its lines, saved to a file, sum into docs/world.md's table rows: scripts/offlane_summary.py FILE.
# Another course: COURSE (the .glb), LANES (the lanes' x, from the course's table in
# docs/world-levels.md), START_Z (where the lanes start), SCRIPTS (names in scripts/input/), e.g.
#   COURSE=data/levels/course2.glb START_Z=2 \
#   LANES="0.8 3.4 6 8.7 11.5 14.3 17.45 21.2 25.8 31.3 33.75 36.45 39.05 42.15" \
#   scripts/offlane.sh DB OUT_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
db=${1:?usage: scripts/offlane.sh DB OUT_DIR [DT...]}
out=${2:?usage: scripts/offlane.sh DB OUT_DIR [DT...]}
shift 2
mm=${MM:-build/release/tools/mm}
course=${COURSE:-data/levels/course.glb}
lanes=${LANES:-1 4 7 10 13.5 17.5 22 28}
start_z=${START_Z:-3}
scripts=${SCRIPTS:-stop-and-go walk-run strafe zigzag circle reversals}
mkdir -p "$out"
[[ $# -gt 0 ]] || set -- 0.0333333 0.0166667 0.00694444
for dt in "$@"; do
  for script in $scripts; do
    # How much higher the planted toes float on flat ground than the played clips' own, the
    # level's is read against (issue 29: at most 1.5 cm higher on a level).
    flat="$out/$script-flat-$dt.json"
    "$mm" eval --db "$db" --script "scripts/input/$script.txt" --dt "$dt" --json "$flat" >/dev/null
    flat_float=$(jq '.foot_float_cm_mean - .foot_float_data_cm_mean' "$flat")
    for x in $lanes; do
      json="$out/$script-$x-$dt.json"
      "$mm" eval --db "$db" --script "scripts/input/$script.txt" --dt "$dt" \
        --world "$course" --start "$x,$start_z" --json "$json" >/dev/null
      jq -r --arg s "$script" --arg x "$x" --arg dt "$dt" --argjson above "$flat_float" '
        def f: . * 100 | round / 100;
        (.foot_float_data_cm_mean + $above) as $flat |
        (.toe_clearance_cm_min < 1 or .foot_penetration_cm_max > 0 or .wall_depth_cm_max > 2
         or .foot_skate_geom_cm_s_mean > .foot_skate_geom_data_cm_s_mean
         or .foot_float_cm_mean > $flat + 1.5) as $bad |
        "\(if $bad then "BAD" else "ok " end) \($s) x=\($x) dt=\($dt) " +
        "clearance=\(.toe_clearance_cm_min | f) penetration=\(.foot_penetration_cm_max | f) " +
        "wall=\(.wall_depth_cm_max | f) stuck=\(.stuck_s | f) " +
        "float=\(.foot_float_cm_mean | f)/\($flat | f) " +
        "skate=\(.foot_skate_geom_cm_s_mean | f)/\(.foot_skate_geom_data_cm_s_mean | f)"' "$json"
    done
  done
done
