#!/usr/bin/env bash
# The style measurements of docs/styles.md (issue 31's "Done when"): every style of an
# all-styles database at 1/30, 1/60 and 1/144 s on the style scripts of scripts/input, one
# markdown row per style and time step on stdout; the JSON of each run is kept in OUT_DIR.
#   scripts/measure_styles.sh DB [OUT_DIR]      (mm from build/release, or $MM)
# STYLE_DTS="0.033333 0.016667" measures only those time steps; REUSE=1 keeps the JSON files
# already in OUT_DIR and only prints their rows (to gather runs made in parallel).
# Build the database as docs/styles.md says. Each style's moves (mm info) decide which scripts
# judge it: styles-side-moves.txt only for the styles with "backward, strafes".
set -euo pipefail
cd "$(dirname "$0")/.."
db=${1:?usage: scripts/measure_styles.sh DB [OUT_DIR]}
out=${2:-out/styles}
mm=${MM:-build/release/tools/mm}
mkdir -p "$out"

# name, thin or rich, whether it has sidesteps and backward walks: from mm info's style lines.
styles=$("$mm" info "$db" | awk '/^styles:/{on=1; next} on && /^  [a-z]/ && $1 != "(none)" {
  print $1, ($0 ~ /turns/ ? "rich" : "thin"), ($0 ~ /strafes/ ? "side" : "-") } on && !/^  /{on=0}')

printf '| style | dt | style_match moves / own / side | response max (s) | skating geom moves / own / side (data) | accel ratio moves / own / side / switch | accel ratio played moves / own / side / switch | root dist mean / max (cm) | stand turns err mean / max (deg), unsettled |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for dt in ${STYLE_DTS:-0.033333 0.016667 0.0069444}; do
  case $dt in 0.033333) label=1/30 ;; 0.016667) label=1/60 ;; *) label=1/144 ;; esac
  while read -r style kind side; do
    json="$out/$style-${label/\//-}.json"
    scripts=(--script scripts/input/styles-moves.txt --script scripts/input/styles-own-moves.txt)
    [[ $side == side ]] && scripts+=(--script scripts/input/styles-side-moves.txt)
    scripts+=(--script scripts/input/styles-response.txt --script scripts/input/stand-turns.txt)
    if [[ ${REUSE:-0} != 1 || ! -f $json ]]; then
      "$mm" eval --db "$db" --style "$style" --dt "$dt" "${scripts[@]}" --json "$json" >/dev/null
    fi
    jq -r --arg style "$style" --arg kind "$kind" --arg dt "$label" '
      def run(name): (.runs[] | select(.script | endswith(name))) // null;
      def n2: if . == null then "-" else (. * 100 | round) as $c |
        "\($c / 100 | floor).\($c % 100 | tostring | if length < 2 then "0" + . else . end)" end;
      def f(x): x | n2;
      run("styles-moves.txt") as $m | run("styles-own-moves.txt") as $o |
      run("styles-side-moves.txt") as $s | run("styles-response.txt") as $r |
      run("stand-turns.txt") as $t |
      "| \($style)\(if $kind == "thin" then " (thin)" else "" end) | \($dt) | " +
      "\(f($m.style_match)) / \(f($o.style_match)) / \(f($s.style_match)) | " +
      "\(f($r.style_response_s_max)) | " +
      "\(f($m.foot_skate_geom_cm_s_mean)) / \(f($o.foot_skate_geom_cm_s_mean)) / " +
      "\(f($s.foot_skate_geom_cm_s_mean)) (\(f($m.foot_skate_geom_data_cm_s_mean))) | " +
      "\(f($m.transition_accel_ratio)) / \(f($o.transition_accel_ratio)) / " +
      "\(f($s.transition_accel_ratio)) / \(f($r.transition_accel_ratio)) | " +
      "\(f($m.transition_accel_ratio_played)) / \(f($o.transition_accel_ratio_played)) / " +
      "\(f($s.transition_accel_ratio_played)) / \(f($r.transition_accel_ratio_played)) | " +
      "\(f($m.root_sim_distance_cm_mean)) / \(f($m.root_sim_distance_cm_max)) | " +
      "\(f($t.stand_turn_final_error_deg_mean)) / \(f($t.stand_turn_final_error_deg_max)), " +
      "\($t.stand_turn_unsettled) of \($t.stand_turns) |"' "$json"
  done <<<"$styles"
done
