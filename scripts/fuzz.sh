#!/usr/bin/env bash
# Runs every libFuzzer target (fuzz/*_fuzz.cpp) for a bounded time on its corpus and fails on
# any finding. Usage: scripts/fuzz.sh [seconds per target, default 30]  (after setup.sh fuzz)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
status=0
for source in fuzz/*_fuzz.cpp; do
  name=$(basename "$source" _fuzz.cpp)
  bin=build/fuzz/fuzz/${name}_fuzz
  corpus=build/fuzz/fuzz/corpus/$name
  log=build/fuzz/fuzz/$name.log
  mkdir -p "$corpus"
  if (cd build/fuzz/fuzz && "./${name}_fuzz" -max_total_time="$seconds" -rss_limit_mb=2048 \
        -timeout=10 -print_final_stats=1 "corpus/$name") >"$log" 2>&1; then
    runs=$(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz: $name: $runs inputs in $seconds s, no findings"
  else
    echo "fuzz: $name FOUND A PROBLEM (log: $log, reproducer in build/fuzz/fuzz/):" >&2
    grep -E "ERROR|SUMMARY|runtime error|#0 |#1 |#2 " "$log" | head -20 >&2 || tail -30 "$log" >&2
    status=1
  fi
done
exit $status
