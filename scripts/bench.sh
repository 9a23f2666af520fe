#!/usr/bin/env bash
# The measurements: the controller on every shipped input script (mm eval: a table of the
# feet, tracking, responses, standing and transitions, then a second of the body metrics: hips
# turn rate, foot pivot, turns on the spot, strafing chest, idle head, lowest toe), the crowd
# benchmark, every search method, on the database of ../shared/mocap/bandai-normal and
# ../shared/mocap/reactidle/genuine (or $MM_DATA). Builds Release first; writes JSON of each to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
source scripts/default_data.sh

scripts/setup.sh release
mm=build/release/tools/mm
mkdir -p out

printf '\n=== 1/4 Building the motion database from %s ===\n' "${inputs[*]}"
"$mm" build "${inputs[@]}" -o out/database.mmdb

printf '\n=== 2/4 Scripted controller runs (mm eval, every script in scripts/input, dt 1/60, IK on; two tables) ===\n'
scripts=()
for f in scripts/input/*.txt; do scripts+=(--script "$f"); done
"$mm" eval --db out/database.mmdb "${scripts[@]}" --json out/eval.json

# The test course (data/levels/course.glb, docs/world-levels.md): every lane walked along with
# scripts/input/course-walk.txt, measured against the level's ground (one JSON per lane).
printf '\n=== 2/4 (continued) The test course (mm eval --world, every lane) ===\n'
for lane in ramp_10:1 ramp_20:4 ramp_30:7 stairs:10 rough:13.5 wall_head_on:17.5 wall_30:22 \
            box_low:28 box_high:31; do
  printf -- '--- %s\n' "${lane%%:*}"
  "$mm" eval --db out/database.mmdb --script scripts/input/course-walk.txt \
    --world data/levels/course.glb --start "${lane##*:},0" --json "out/course-${lane%%:*}.json" |
    grep -E '^(foot_skate_geom|toe_clearance|foot_penetration|hips_|wall_depth|stuck|update_us)'
done

# Two minutes of game time: the steady state of a long run, whose last 20 s the table compares
# with the first (a cost that creeps up as the characters' state ages shows in that ratio).
printf '\n=== 3/4 Crowd benchmark (mm crowd-bench, 1500 characters, 120 s at 60 Hz) ===\n'
"$mm" crowd-bench --db out/database.mmdb --characters 1500 --seconds 120 --json out/crowd-bench.json

# The same cost in the test course (Bullet) against flat ground, in one run.
printf '\n=== 3/4 (continued) Crowd in the test course (mm crowd-bench --world, 300 characters, 30 s) ===\n'
"$mm" crowd-bench --db out/database.mmdb --characters 300 --seconds 30 \
  --world data/levels/course.glb --json out/crowd-bench-world.json

# The issue's target: 10,000 characters under a 14 ms frame budget on 2 threads, the level of
# detail deciding who updates at which rate (docs/crowd.md), 2 minutes of game time.
printf '\n=== 3/4 (continued) A crowd of 10000 under a 14 ms budget (mm crowd-bench --budget-ms) ===\n'
"$mm" crowd-bench --db out/database.mmdb --characters 10000 --threads 2 --seconds 120 \
  --budget-ms 14 --json out/crowd-bench-budget.json

printf '\n=== 4/4 Search benchmark (every method, 2000 queries, noise 0.1) ===\n'
"$mm" search-bench --db out/database.mmdb --queries 2000 --noise 0.1 --json out/search-bench.json

printf '\nDone: out/eval.json, out/course-<lane>.json, out/crowd-bench.json, out/crowd-bench-world.json,\n'
printf 'out/crowd-bench-budget.json, '
printf 'out/search-bench.json\n'
