#!/usr/bin/env bash
# Installs the Debian packages the project needs (only those missing), then configures and
# builds one configuration. Usage: scripts/setup.sh [release|asan|tsan]   (default: release;
# fuzz is asan, whose tree holds the libFuzzer targets)
set -euo pipefail
cd "$(dirname "$0")/.."

# The python3-* and pybind11 packages build and test the Python module (python/);
# assimp-testmodels holds real-world BVH files the importer's tests read; Bullet answers the
# world's queries in the tools and the viewer (world/), never in the libraries a game links.
packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libeigen3-dev libtinygltf-dev libflann-dev nlohmann-json3-dev libstb-dev
  libglfw3-dev libgl-dev libegl-dev libosmesa6-dev libgl1-mesa-dri xvfb xauth libimgui-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang clang-format libclang-rt-14-dev xz-utils
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
  assimp-testmodels libbullet-dev
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing missing Debian packages: ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

config=${1:-release}
jobs=$(nproc)
targets=()  # empty: every target
case "$config" in
  release)
    cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DMM_WERROR=ON >/dev/null ;;
  asan)
    # clang, with the libFuzzer targets (fuzz/, MM_BUILD_FUZZ) in the same tree: the libraries are
    # compiled once for the tests and the fuzzers. The libraries optimized (the tests, tools and
    # viewer not: MM_DRIVER_COMPILE_OPTIONS in CMakeLists.txt) but with asserts on (no NDEBUG),
    # so the sanitizer pass also checks them. Line tables (-g1) are all a sanitizer's stack
    # trace reads; full debug information costs much of an instrumented build's time. A tree
    # configured with another compiler (gcc, before) is configured afresh.
    if [ -f build/asan/CMakeCache.txt ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang' build/asan/CMakeCache.txt; then
      rm -rf build/asan
    fi
    CXX=clang++ cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMM_SANITIZE=ON \
      -DMM_BUILD_FUZZ=ON -DMM_WERROR=ON "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
      -DMM_BUILD_BENCH=OFF >/dev/null ;;
  tsan)
    # ThreadSanitizer, optimized like asan, over the thread tests only (the target
    # mm_thread_tests of tests/CMakeLists.txt): the rest runs on one thread, and the tools and the
    # viewer are not built.
    cmake -S . -B build/tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMM_SANITIZE_THREAD=ON \
      -DMM_WERROR=ON "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" -DMM_BUILD_BENCH=OFF >/dev/null
    targets=(--target mm_thread_tests) ;;
  fuzz)
    # The fuzz targets are built by the asan configuration (build/asan/fuzz/).
    exec "$0" asan ;;
  *) echo "setup: unknown configuration '$config' (release, asan, tsan or fuzz)" >&2; exit 2 ;;
esac
echo "setup: building build/$config with $jobs jobs"
cmake --build "build/$config" -j "$jobs" "${targets[@]}"
