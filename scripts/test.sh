#!/usr/bin/env bash
# The test command. Installs missing Debian packages, then:
#   0. every tracked C++ file is clang-formatted (.clang-format);
#   1. Release build with -Wall -Wextra -Werror, every test;
#   2. ASan + UBSan build (clang, with the libFuzzer targets), every test;
#   3. ThreadSanitizer build of the thread tests only (suites named *Threads, see
#      tests/CMakeLists.txt), those tests;
#   4. the libFuzzer targets of step 2, each for a bounded time (MM_FUZZ_SECONDS, default 30).
# Each step's wall time is printed when the next begins, and all of them at the end.
# Usage: scripts/test.sh [--fast]   (--fast: Release tests only)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

# Prints the previous step's wall time and this step's title.
started=$SECONDS
step_name=""
step_start=$SECONDS
timings=()
step() {
  if [ -n "$step_name" ]; then
    timings+=("$(printf '%5d s  %s' $((SECONDS - step_start)) "$step_name")")
    printf '\n(%s: %d s)\n' "$step_name" $((SECONDS - step_start))
  fi
  step_name=$1
  step_start=$SECONDS
  printf '\n=== %s ===\n' "$*"
}

step "Release build"
scripts/setup.sh release
scripts/check_format.sh
step "Release tests"
ctest --test-dir build/release --output-on-failure -j "$jobs"
[ "${1:-}" = "--fast" ] && exit 0

step "ASan + UBSan build"
scripts/setup.sh asan
step "ASan + UBSan tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs"

step "ThreadSanitizer build (the thread tests only)"
scripts/setup.sh tsan
step "ThreadSanitizer tests (suites named *Threads)"
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
  ctest --test-dir build/tsan -R 'Threads\.' --no-tests=error --output-on-failure -j "$jobs"

step "Fuzz targets (${MM_FUZZ_SECONDS:-30} s each)"
scripts/fuzz.sh "${MM_FUZZ_SECONDS:-30}"

step "All tests passed"
printf '%s\n' "${timings[@]}"
printf '%5d s  in all\n' $((SECONDS - started))
