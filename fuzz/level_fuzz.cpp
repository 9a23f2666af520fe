// libFuzzer target for the level reader (mm/world/level.hpp): the input is a whole .glb or
// .gltf file (binary when it starts with "glTF"), parsed from memory with external files
// refused. Whatever the bytes, parse_level must return: no crash, no sanitizer report, no hang.
// Contract: a refusal's message starts with the file's name; an accepted level has triangles and
// passes Level::validate, and a small one (up to kWorldTriangles) makes a BulletWorld that
// answers a probe and a sweep through its first triangle with finite values (so whatever the
// reader accepts, Bullet can take).
// Seeds (written into the corpus by LLVMFuzzerInitialize): the test course as a .glb, and a
// small .gltf of two triangles under a node hierarchy, with its buffer as a data: URI.
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_level.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include "fuzz_checks.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace {

constexpr const char* kName = "fuzz.gltf";
// Bullet's tree over a bigger level takes longer to build than an input should.
constexpr size_t kWorldTriangles = 20'000;

// Two triangles (a unit square, scaled to 2 by 2 m) under a parent node turned and moved: 48
// bytes of positions and 24 of indices, in base64.
constexpr const char* kSmallLevel =
    R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
    R"("nodes":[{"name":"parent","translation":[10,1,0],"rotation":[0,0.7071068,0,0.7071068],)"
    R"("children":[1]},{"name":"floor","mesh":0,"scale":[2,1,2]}],)"
    R"("meshes":[{"name":"tiles","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
    R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},)"
    R"({"bufferView":1,"componentType":5125,"count":6,"type":"SCALAR"}],)"
    R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},)"
    R"({"buffer":0,"byteOffset":48,"byteLength":24}],)"
    R"("buffers":[{"byteLength":72,"uri":"data:application/octet-stream;base64,)"
    R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAACAPwAAAAAAAIA/AAAAAAAAAAAAAIA/AAAAAAIAAAABAAAAAAAAAAMAAAACAAAA"}]})";

// The folder libFuzzer writes its corpus to (the first positional argument), or empty.
std::filesystem::path corpus_folder(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-') continue;
    std::error_code error;
    return std::filesystem::is_directory(argv[i], error) ? argv[i] : "";
  }
  return {};
}

void write_seeds(int argc, char** argv) {
  const std::filesystem::path folder = corpus_folder(argc, argv);
  std::error_code error;
  if (folder.empty() || std::filesystem::exists(folder / "seed_course.glb", error)) return;
  const std::vector<unsigned char> course = mm::course_glb();
  std::ofstream(folder / "seed_course.glb", std::ios::binary)
      .write(reinterpret_cast<const char*>(course.data()),
             static_cast<std::streamsize>(course.size()));
  std::ofstream(folder / "seed_small.gltf") << kSmallLevel;
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// A world of the level, asked about its first triangle: a probe down onto its centroid and a
// sweep through it, relative to the level's own origin.
void query(const mm::Level& level) {
  mm::Result<mm::BulletWorld> world = mm::BulletWorld::create(level);
  if (!world) mm::fuzz::fail("a valid level makes no world", world.message());
  const glm::vec3 centroid =
      (level.positions[level.indices[0]] + level.positions[level.indices[1]] +
       level.positions[level.indices[2]]) /
      3.0f;
  const mm::GroundProbe probe{centroid + glm::vec3(0.0f, 1.0f, 0.0f), 2.0f, 0.7f};
  mm::GroundHit ground;
  world->probe_ground(level.origin, std::span(&probe, 1), std::span(&ground, 1));
  const mm::ShapeSweep sweep{centroid - glm::vec3(1.0f, 0.5f, 1.0f),
                             centroid + glm::vec3(1.0f, -0.5f, 1.0f), 0.3f, 1.0f};
  mm::SweepHit swept;
  world->sweep(level.origin, std::span(&sweep, 1), std::span(&swept, 1));
  if (ground.hit && (!finite(ground.point) || !finite(ground.normal) || ground.normal.y < 0.0f)) {
    mm::fuzz::fail("probe answer", "not finite or facing down");
  }
  if (swept.hit && (!finite(swept.normal) || !(swept.fraction >= 0.0f && swept.fraction <= 1.0f))) {
    mm::fuzz::fail("sweep answer", "not finite or fraction outside [0, 1]");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  write_seeds(*argc, *argv);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const mm::Result<mm::Level> level = mm::parse_level(std::span<const unsigned char>(data, size),
                                                      kName, {.allow_external_files = false});
  if (!level.ok()) {
    if (level.message().rfind(std::string(kName) + ": ", 0) != 0) {
      mm::fuzz::fail("message without the file", level.message());
    }
    return 0;
  }
  if (level->triangle_count() == 0) mm::fuzz::fail("accepted a level without triangles", "");
  if (const mm::Status valid = level->validate(); !valid) {
    mm::fuzz::fail("accepted an invalid level", valid.message());
  }
  if (level->triangle_count() <= kWorldTriangles) query(*level);
  return 0;
}
