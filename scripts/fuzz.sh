#!/usr/bin/env bash
# Runs every libFuzzer target (fuzz/*_fuzz.cpp) for a bounded time on its corpus and fails on
# any finding. Targets run as many at a time as there are cores (each fuzzer is one process on
# one core), so the whole run takes the per-target time times targets / cores.
# Usage: scripts/fuzz.sh [seconds per target, default 30]  (after setup.sh asan, whose tree
# holds the fuzz targets)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
parallel=$(nproc)

# One target: its report line on stdout, its finding on stderr; fails on a finding.
run_target() {
  local name=$1
  local corpus=build/asan/fuzz/corpus/$name
  local log=build/asan/fuzz/$name.log
  mkdir -p "$corpus"
  if (cd build/asan/fuzz && "./${name}_fuzz" -max_total_time="$seconds" -rss_limit_mb=2048 \
        -timeout=10 -print_final_stats=1 "corpus/$name") >"$log" 2>&1; then
    local runs
    runs=$(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $name: $runs inputs in $seconds s, no findings"
  else
    {
      echo "fuzz: $name FOUND A PROBLEM (log: $log, reproducer in build/asan/fuzz/):"
      grep -E "ERROR|SUMMARY|runtime error|#0 |#1 |#2 " "$log" | head -20 || tail -30 "$log"
    } >&2
    return 1
  fi
}

status=0
pids=()
for source in fuzz/*_fuzz.cpp; do
  run_target "$(basename "$source" _fuzz.cpp)" &
  pids+=($!)
  if ((${#pids[@]} >= parallel)); then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for pid in "${pids[@]}"; do
  wait "$pid" || status=1
done
exit $status
