// libFuzzer target for the glTF importer, byte level: the input is a whole .glb or .gltf file
// (binary when it starts with "glTF"), parsed from memory with external files refused. Whatever
// the bytes, parse_gltf must return: no crash, no sanitizer report, no hang, and the contract
// of gltf_fuzz_common.hpp (a valid asset, or a message naming the file).
// Seeds (written into the corpus by LLVMFuzzerInitialize): exported .glb and .gltf files.
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_gltf.

#include <cstddef>
#include <cstdint>
#include <span>

#include "gltf_fuzz_common.hpp"

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  mm::fuzz::write_seeds(*argc, *argv, /*text_too=*/true);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mm::fuzz::parse_and_check(std::span<const unsigned char>(data, size));
  return 0;
}
