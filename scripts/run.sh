#!/usr/bin/env bash
# The main job: the motion-matching demo on the motion capture in ../shared/mocap/bandai-normal
# with the ReActIdle idles of ../shared/mocap/reactidle/genuine (or $MM_DATA). Installs missing
# Debian packages, builds Release, builds the motion database, then:
# - with a display: opens mm-viewer (gamepad or keyboard; its --help lists the controls);
# - without one: runs the viewer headless on scripts/input/showcase.txt (walk, turn, run, stop
#   and stand, walk back, strafe), writing a screenshot every 1.5 s, the last frame and a
#   top-down plot of the run, then measures the same script with `mm eval`; then walks three
#   lanes of the test course (stairs, a 20-degree ramp, a wall at 30 degrees) the same way; then,
#   when ../shared/mocap/bandai-all-styles.tar.xz is there, a style sequence: the archive is
#   extracted once to out/bandai-all-styles, built into out/styles.mmdb and walked and run
#   through 16 style switches (scripts/input/styles-switch.txt), a screenshot 1 s into each.
# The default database stays the normal style: building it is what CI and every metric use, and
# the style sequence adds about 10 s (extracting 214 MB, building an 89 MB database).
# Everything goes to out/. Set MM_HEADLESS=1 to run headless even with a display; MM_STYLES=1
# opens the window on the all-styles database (the panel's style selector, D-pad, keys 1-9/0).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

source scripts/default_data.sh
data=${inputs[0]}
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
viewer=build/release/viewer/mm-viewer
mkdir -p out/viewer

printf '\n=== Building the motion database from %s ===\n' "${inputs[*]}"
"$mm" build "${inputs[@]}" -o out/database.mmdb

# The all-styles database, when the archive is there (docs/controller.md, Styles).
styles_archive=../shared/mocap/bandai-all-styles.tar.xz
build_styles() {
  if [ ! -f "$styles_archive" ]; then
    printf 'run: no %s, no style sequence\n' "$styles_archive"
    return 1
  fi
  if [ ! -d out/bandai-all-styles/bandai-all-styles ]; then
    printf '\n=== Extracting %s (once) ===\n' "$styles_archive"
    rm -rf out/bandai-all-styles.partial
    mkdir -p out/bandai-all-styles.partial
    tar -xJf "$styles_archive" -C out/bandai-all-styles.partial || return 1
    mv out/bandai-all-styles.partial out/bandai-all-styles || return 1
  fi
  printf '\n=== Building the all-styles database ===\n'
  "$mm" build out/bandai-all-styles/bandai-all-styles "${inputs[@]:1}" -o out/styles.mmdb
}

if [ -z "${MM_HEADLESS:-}" ] && { [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; }; then
  printf '\n=== mm-viewer (close the window or press Esc to quit; F1 hides the panel) ===\n'
  if [ -n "${MM_STYLES:-}" ] && build_styles; then exec "$viewer" --db out/styles.mmdb; fi
  exec "$viewer" --db out/database.mmdb
fi

script=scripts/input/showcase.txt
printf '\n=== No display: mm-viewer headless on %s ===\n' "$script"
rm -f out/viewer/*.png
"$viewer" --db out/database.mmdb --headless --script "$script" --every 90 \
  --screenshot out/viewer/showcase.png --plot out/viewer/plot.png

printf '\n=== The same script measured (mm eval, dt 1/60, IK on) ===\n'
"$mm" eval --db out/database.mmdb --script "$script" --json out/viewer/eval.json

# The test course (data/levels/course.glb, docs/world-levels.md): three of its lanes walked
# straight along, each rendered and measured against the level's ground.
for lane in stairs:10 ramp_20:4 wall_30:22; do
  name=${lane%%:*}
  x=${lane##*:}
  printf '\n=== The test course, lane %s (x = %s): mm-viewer headless and mm eval --world ===\n' \
    "$name" "$x"
  "$viewer" --db out/database.mmdb --headless --script scripts/input/course-walk.txt \
    --world data/levels/course.glb --start "$x,0" --every 60 \
    --screenshot "out/viewer/course-$name.png" --plot "out/viewer/course-$name-plot.png"
  "$mm" eval --db out/database.mmdb --script scripts/input/course-walk.txt \
    --world data/levels/course.glb --start "$x,0" --json "out/viewer/course-$name.json" |
    grep -E '^(root_sim|foot_skate|toe_clearance|foot_penetration|hips_|wall_depth|stuck|update_us)'
done

if build_styles; then
  printf '\n=== Styles: mm-viewer headless and mm eval on scripts/input/styles-switch.txt ===\n'
  "$viewer" --db out/styles.mmdb --headless --script scripts/input/styles-switch.txt --every 120 \
    --screenshot out/viewer/styles.png
  "$mm" eval --db out/styles.mmdb --script scripts/input/styles-switch.txt \
    --json out/viewer/styles.json |
    grep -E '^(style_|transition_accel|foot_skate_geom|root_sim)'
fi

printf '\nDone. In out/viewer/: showcase-<frame>.png every 1.5 s of the run and showcase.png (the\n'
printf 'last frame), plot.png (the whole run from above), eval.json (the metrics printed above);\n'
printf 'course-<lane>-<frame>.png every second on the test course (stairs, the 20-degree ramp, the\n'
printf 'wall at 30 degrees), course-<lane>-plot.png and course-<lane>.json;\n'
printf 'styles-<frame>.png 1 s into each style switch (the panel names the style), styles.json.\n'
printf 'With a display, scripts/run.sh opens the interactive viewer instead; scripts/bench.sh runs\n'
printf 'every shipped script, the crowd and the search benchmarks.\n'
