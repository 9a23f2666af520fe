// libFuzzer target for the database loader: no input may crash it, hang it, allocate without
// bound, or be accepted and then fail to round-trip.
//
// A random byte string almost never gets past the checksum, so each input is tried three ways:
//   1. as a file image, exactly as given;
//   2. the same bytes with the trailing checksum recomputed, so the header and section parsers
//      see the fuzzer's bytes;
//   3. as a list of patches (2 bytes offset, 1 byte value) applied to a small valid database,
//      resealed, so the fuzzer can reach the compact sections' decoders (position columns,
//      rotation codes and their exceptions) and every semantic check of Database::validate().
// The seed has a constant position column and a rotation stored through an exception, so both
// paths are in the valid file the patches start from.
// LLVMFuzzerInitialize builds that valid database in memory and, when the first corpus folder
// given on the command line exists, writes it there as a seed (seed_valid.mmdb), so nothing
// binary is committed.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/velocities.hpp"
#include "mm/offline/database_writer.hpp"

namespace {

std::vector<std::byte> g_valid_file;

mm::DatabaseContents make_seed_database() {
  mm::DatabaseContents db;
  std::vector<mm::Transform> rest(3);
  rest[1].translation = {0.0f, 0.9f, 0.0f};
  rest[2].translation = {0.1f, -0.8f, 0.0f};
  db.skeleton = mm::Skeleton::create({"Simulation", "Hips", "Foot_L"}, {-1, 0, 1}, rest).value();
  db.roles.hips = 1;
  db.roles.left_foot = 2;
  db.frame_count = 6;
  for (int i = 0; i < db.frame_count * 3; ++i) {
    const float t = 0.1f * static_cast<float>(i);
    // Joint 2 (the foot) keeps its offset: one constant column per clip.
    db.local_positions.push_back(i % 3 == 2 ? glm::vec3(0.1f, -0.8f, 0.0f)
                                            : glm::vec3(t, 0.5f, -t));
    db.local_rotations.push_back(glm::angleAxis(t, glm::vec3(0.0f, 1.0f, 0.0f)));
  }
  db.local_rotations[4] = glm::quat(1.0004f, 0.0f, 0.0f, 0.0f);  // not exactly unit: an exception
  db.contacts = {1, 0, 1, 0, 0, 1, 0, 1, 1, 1, 0, 0};
  db.clips = {{"walk", 0, 4, 1, false}, {"walk_mirror", 4, 6, 3, true}};
  db.tag_names = {"walk", "mirror"};
  mm::FeatureChannel foot;
  foot.name = "left_foot_position";
  foot.kind = mm::FeatureKind::BonePosition;
  foot.bone = "left_foot";
  mm::FeatureChannel trajectory;
  trajectory.name = "trajectory_direction";
  trajectory.kind = mm::FeatureKind::TrajectoryDirection;
  trajectory.times = {0.5f};
  db.schema.channels = {foot, trajectory};
  for (int i = 0; i < db.frame_count * 5; ++i)
    db.features.push_back(0.25f * static_cast<float>(i % 7) - 1.0f);
  db.feature_offset = {0.0f, 0.1f, 0.2f, 0.3f, 0.4f};
  db.feature_scale = {1.0f, 2.0f, 0.5f, 1.5f, 3.0f};
  db.searchable = {1, 1, 0, 0, 1, 0};
  // The velocities the file does not store, as load recomputes them (clip by clip).
  db.local_velocities.resize(db.local_positions.size());
  db.local_angular_velocities.resize(db.local_positions.size());
  for (const mm::ClipRange& clip : db.clips) {
    const size_t first = static_cast<size_t>(clip.start) * 3;
    const size_t count = static_cast<size_t>(clip.frame_count()) * 3;
    mm::compute_local_velocities(std::span(db.local_positions).subspan(first, count),
                                 std::span(db.local_rotations).subspan(first, count),
                                 clip.frame_count(), 3, db.frame_time,
                                 std::span(db.local_velocities).subspan(first, count),
                                 std::span(db.local_angular_velocities).subspan(first, count));
  }
  return db;
}

void reseal(std::vector<std::byte>& bytes) {
  if (bytes.size() < 8) return;
  const uint64_t checksum = mm::database_checksum(std::span(bytes).first(bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &checksum, 8);
}

// Loads the image; whatever loads must validate and survive serialize -> deserialize unchanged
// (the velocities it recomputed included).
void try_load(std::span<const std::byte> bytes) {
  mm::Result<mm::Database> db = mm::deserialize_database(bytes, "fuzz input");
  if (!db) {
    if (db.message().empty()) __builtin_trap();  // every refusal says why
    return;
  }
  if (!db->validate().ok()) __builtin_trap();
  const std::vector<std::byte> again = mm::serialize_database(*db);
  mm::Result<mm::Database> reloaded = mm::deserialize_database(again, "fuzz round trip");
  if (!reloaded) __builtin_trap();
  if (mm::serialize_database(*reloaded) != again) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const mm::DatabaseContents seed = make_seed_database();
  if (!mm::validate_database(seed).ok()) __builtin_trap();
  g_valid_file = mm::serialize_database(seed);
  for (int i = 1; i < *argc; ++i) {
    const char* arg = (*argv)[i];
    if (arg[0] == '-') continue;
    std::error_code error;
    if (std::filesystem::is_directory(arg, error)) {
      const std::filesystem::path path = std::filesystem::path(arg) / "seed_valid.mmdb";
      if (!std::filesystem::exists(path, error)) {
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(g_valid_file.data()),
                  static_cast<std::streamsize>(g_valid_file.size()));
      }
    }
    break;  // only the first positional argument is the corpus that libFuzzer writes to
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto* bytes = reinterpret_cast<const std::byte*>(data);
  try_load({bytes, size});

  std::vector<std::byte> resealed(bytes, bytes + size);
  reseal(resealed);
  try_load(resealed);

  std::vector<std::byte> patched = g_valid_file;
  for (size_t i = 0; i + 3 <= size; i += 3) {
    const size_t offset = (static_cast<size_t>(data[i]) << 8 | data[i + 1]) % patched.size();
    patched[offset] = static_cast<std::byte>(data[i + 2]);
  }
  reseal(patched);
  try_load(patched);
  return 0;
}
