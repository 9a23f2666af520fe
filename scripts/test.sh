#!/usr/bin/env bash
# The test command. Installs missing Debian packages, then:
#   0. every tracked C++ file is clang-formatted (.clang-format);
#   1. Release build with -Wall -Wextra -Werror, every test;
#   2. ASan + UBSan build, every test;
#   3. the libFuzzer targets (clang), each for a bounded time (MM_FUZZ_SECONDS, default 30).
# Usage: scripts/test.sh [--fast]   (--fast: Release tests only)
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

step() { printf '\n=== %s ===\n' "$*"; }

step "Release build and tests"
scripts/setup.sh release
scripts/check_format.sh
ctest --test-dir build/release --output-on-failure -j "$jobs"
[ "${1:-}" = "--fast" ] && exit 0

step "ASan + UBSan build and tests"
scripts/setup.sh asan
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j "$jobs"

step "Fuzz targets (${MM_FUZZ_SECONDS:-30} s each)"
scripts/setup.sh fuzz
scripts/fuzz.sh "${MM_FUZZ_SECONDS:-30}"

step "All tests passed"
