#!/usr/bin/env bash
# The main job. Installs missing Debian packages, builds Release, then runs the most complete
# real pipeline on the motion capture in ../shared/mocap/bandai-normal (or $MM_DATA):
#   build the motion database -> show its summary -> run the character controller on every
#   shipped input script and print its quality metrics -> the crowd benchmark -> benchmark
#   every search method -> export one clip of it to glTF.
# Outputs go to out/ (a database, JSON of every benchmark, a .glb).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

data=${MM_DATA:-$root/../shared/mocap/bandai-normal}
if [ ! -d "$data" ] || [ -z "$(find "$data" -maxdepth 1 \( -name '*.bvh' -o -name '*.glb' -o -name '*.gltf' \) -print -quit)" ]; then
  cat >&2 <<MSG
run: no motion capture found in '$data'.
  Put the BVH files of the Bandai Namco Research Motion Dataset in ../shared/mocap/bandai-normal
  (next to this project), or point MM_DATA at a folder of .bvh/.gltf/.glb files.
  The dataset: https://github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset
  (licence CC BY-NC 4.0; the 'normal' style files of datasets 1 and 2).
MSG
  exit 1
fi

scripts/setup.sh release
mm=build/release/tools/mm
mkdir -p out

printf '\n=== 1/6 Building the motion database from %s ===\n' "$data"
"$mm" build "$data" -o out/database.mmdb

printf '\n=== 2/6 Database summary ===\n'
"$mm" info out/database.mmdb

printf '\n=== 3/6 Scripted controller runs (mm eval, every script in scripts/input, dt 1/60, IK on) ===\n'
scripts=()
for f in scripts/input/*.txt; do scripts+=(--script "$f"); done
"$mm" eval --db out/database.mmdb "${scripts[@]}" --json out/eval.json

printf '\n=== 4/6 Crowd benchmark (mm crowd-bench, 1500 characters, 5 s at 60 Hz) ===\n'
"$mm" crowd-bench --db out/database.mmdb --characters 1500 --seconds 5 --json out/crowd-bench.json

printf '\n=== 5/6 Search benchmark (every method, 2000 queries, noise 0.1) ===\n'
"$mm" search-bench --db out/database.mmdb --queries 2000 --noise 0.1 --json out/search-bench.json

printf '\n=== 6/6 Exporting one walk clip to glTF ===\n'
"$mm" export out/database.mmdb --clip dataset-2_walk_normal_001 -o out/walk.glb

printf '\nDone: out/database.mmdb, out/eval.json, out/crowd-bench.json, out/search-bench.json,\n'
printf 'out/walk.glb (opens in Blender). mm eval --help explains the metrics; add --dump FILE.csv for\n'
printf 'one row per frame of a run.\n'
