#!/usr/bin/env bash
# The main job. Installs missing Debian packages, builds Release, then runs the most complete
# real pipeline on the motion capture in ../shared/mocap/bandai-normal (or $MM_DATA):
#   build the motion database -> show its summary -> benchmark every search method on it
#   -> export one clip of it to glTF.
# Outputs go to out/ (a database, a search benchmark JSON, a .glb).
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

printf '\n=== 1/4 Building the motion database from %s ===\n' "$data"
"$mm" build "$data" -o out/database.mmdb

printf '\n=== 2/4 Database summary ===\n'
"$mm" info out/database.mmdb

printf '\n=== 3/4 Search benchmark (every method, 2000 queries, noise 0.1) ===\n'
"$mm" search-bench --db out/database.mmdb --queries 2000 --noise 0.1 --json out/search-bench.json

printf '\n=== 4/4 Exporting one walk clip to glTF ===\n'
"$mm" export out/database.mmdb --clip dataset-2_walk_normal_001 -o out/walk.glb

printf '\nDone: out/database.mmdb, out/search-bench.json, out/walk.glb (opens in Blender).\n'
