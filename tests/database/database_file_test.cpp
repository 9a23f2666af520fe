#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

// ---------------------------------------------------------------------------------------------
// Fixture: a small but complete database with random valid arrays.

constexpr int kJoints = 4;
constexpr int kClip0Frames = 12;
constexpr int kClip1Frames = 8;
constexpr int kFrames = kClip0Frames + kClip1Frames;
constexpr int kDims = 3 + 4;  // left foot position + 2 trajectory times x (x, z)
constexpr float nan = std::numeric_limits<float>::quiet_NaN();

glm::quat random_unit_quat(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  glm::quat q(n(rng), n(rng), n(rng), n(rng));
  return glm::normalize(q);
}

glm::vec3 random_vec3(std::mt19937& rng, float range) {
  std::uniform_real_distribution<float> u(-range, range);
  return {u(rng), u(rng), u(rng)};
}

FeatureSchema two_channel_schema() {
  FeatureSchema schema;
  FeatureChannel foot;
  foot.name = "left_foot_position";
  foot.kind = FeatureKind::BonePosition;
  foot.bone = "left_foot";
  foot.weight = 0.75f;
  schema.channels.push_back(foot);
  FeatureChannel trajectory;
  trajectory.name = "trajectory_position";
  trajectory.kind = FeatureKind::TrajectoryPosition;
  trajectory.times = {0.33f, 0.67f};
  trajectory.weight = 1.5f;
  schema.channels.push_back(trajectory);
  return schema;
}

// `frames_in_clip1` lets one test make a large database with the same shape.
Database make_database(int clip1_frames = kClip1Frames, uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  Database db;
  std::vector<Transform> rest(kJoints);
  for (Transform& t : rest) {
    t.rotation = random_unit_quat(rng);
    t.translation = random_vec3(rng, 0.5f);
    t.scale = glm::vec3(1.0f, 1.0f + unit(rng), 1.0f);
  }
  db.skeleton =
      Skeleton::create({"Simulation", "Hips", "Foot_L", "Foot_R"}, {-1, 0, 1, 1}, rest).value();
  db.roles.hips = 1;
  db.roles.left_foot = 2;
  db.roles.right_foot = 3;
  db.frame_time = 1.0f / 60.0f;
  db.frame_count = kClip0Frames + clip1_frames;
  const size_t samples = static_cast<size_t>(db.frame_count) * kJoints;
  for (size_t i = 0; i < samples; ++i) {
    db.local_positions.push_back(random_vec3(rng, 2.0f));
    db.local_rotations.push_back(random_unit_quat(rng));
    db.local_velocities.push_back(random_vec3(rng, 5.0f));
    db.local_angular_velocities.push_back(random_vec3(rng, 10.0f));
  }
  for (int f = 0; f < db.frame_count * 2; ++f) db.contacts.push_back(unit(rng) < 0.5f ? 1 : 0);
  db.clips.push_back({"walk_take", 0, kClip0Frames, 0b001, false});
  db.clips.push_back({"run_take_mirror", kClip0Frames, db.frame_count, 0b110, true});
  db.tag_names = {"walk", "run", "mirror"};
  db.schema = two_channel_schema();
  for (int i = 0; i < db.frame_count * kDims; ++i) db.features.push_back(unit(rng) * 4.0f - 2.0f);
  for (int c = 0; c < kDims; ++c) {
    db.feature_offset.push_back(unit(rng) - 0.5f);
    db.feature_scale.push_back(0.5f + unit(rng));
  }
  for (int f = 0; f < db.frame_count; ++f) db.searchable.push_back(unit(rng) < 0.8f ? 1 : 0);
  db.frame_clip.assign(kClip0Frames, 0);
  db.frame_clip.insert(db.frame_clip.end(), clip1_frames, 1);
  return db;
}

// Exact equality of every field, float for float.
void expect_same_database(const Database& a, const Database& b) {
  EXPECT_EQ(a.skeleton.names(), b.skeleton.names());
  EXPECT_EQ(a.skeleton.parents(), b.skeleton.parents());
  EXPECT_EQ(a.skeleton.subtree_sizes(), b.skeleton.subtree_sizes());
  ASSERT_EQ(a.skeleton.rest().size(), b.skeleton.rest().size());
  for (size_t j = 0; j < a.skeleton.rest().size(); ++j) {
    EXPECT_EQ(a.skeleton.rest()[j].rotation, b.skeleton.rest()[j].rotation) << j;
    EXPECT_EQ(a.skeleton.rest()[j].translation, b.skeleton.rest()[j].translation) << j;
    EXPECT_EQ(a.skeleton.rest()[j].scale, b.skeleton.rest()[j].scale) << j;
  }
  EXPECT_EQ(a.roles.hips, b.roles.hips);
  EXPECT_EQ(a.roles.left_foot, b.roles.left_foot);
  EXPECT_EQ(a.roles.right_foot, b.roles.right_foot);
  EXPECT_EQ(a.roles.left_toe, b.roles.left_toe);
  EXPECT_EQ(a.roles.right_toe, b.roles.right_toe);
  EXPECT_EQ(a.roles.head, b.roles.head);
  EXPECT_EQ(a.frame_time, b.frame_time);
  EXPECT_EQ(a.frame_count, b.frame_count);
  EXPECT_TRUE(a.local_positions == b.local_positions);
  EXPECT_TRUE(a.local_rotations == b.local_rotations);
  EXPECT_TRUE(a.local_velocities == b.local_velocities);
  EXPECT_TRUE(a.local_angular_velocities == b.local_angular_velocities);
  EXPECT_EQ(a.contacts, b.contacts);
  ASSERT_EQ(a.clips.size(), b.clips.size());
  for (size_t c = 0; c < a.clips.size(); ++c) {
    EXPECT_EQ(a.clips[c].name, b.clips[c].name);
    EXPECT_EQ(a.clips[c].start, b.clips[c].start);
    EXPECT_EQ(a.clips[c].end, b.clips[c].end);
    EXPECT_EQ(a.clips[c].tags, b.clips[c].tags);
    EXPECT_EQ(a.clips[c].mirrored, b.clips[c].mirrored);
  }
  EXPECT_EQ(a.tag_names, b.tag_names);
  ASSERT_EQ(a.schema.channels.size(), b.schema.channels.size());
  for (size_t c = 0; c < a.schema.channels.size(); ++c) {
    const FeatureChannel& x = a.schema.channels[c];
    const FeatureChannel& y = b.schema.channels[c];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.kind, y.kind);
    EXPECT_EQ(x.bone, y.bone);
    EXPECT_EQ(x.times, y.times);
    EXPECT_EQ(x.axis, y.axis);
    EXPECT_EQ(x.weight, y.weight);
  }
  EXPECT_EQ(a.features, b.features);
  EXPECT_EQ(a.feature_offset, b.feature_offset);
  EXPECT_EQ(a.feature_scale, b.feature_scale);
  EXPECT_EQ(a.searchable, b.searchable);
  EXPECT_EQ(a.frame_clip, b.frame_clip);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string load_error(const std::vector<std::byte>& bytes) {
  Result<Database> db = deserialize_database(bytes, "fixture.mmdb");
  if (db) return "";
  return db.message();
}

void write_file(const std::filesystem::path& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// Overwrites a value at `offset`, then recomputes the trailing checksum with the public hash so
// the structural and semantic checks behind the checksum are reached.
template <class T>
std::vector<std::byte> patched(std::vector<std::byte> bytes, uint64_t offset, const T& value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
  const uint64_t checksum = database_checksum(std::span(bytes).first(bytes.size() - 8));
  std::memcpy(bytes.data() + bytes.size() - 8, &checksum, 8);
  return bytes;
}

uint64_t section_offset(const std::vector<std::byte>& bytes, DatabaseSection s) {
  Result<DatabaseFileInfo> info = parse_database_header(bytes, "fixture");
  EXPECT_TRUE(info.ok()) << (info ? "" : info.message());
  return info ? info->section(s).offset : 0;
}

// ---------------------------------------------------------------------------------------------
// Round trips.

TEST(DatabaseFile, SaveLoadRoundTripIsExact) {
  const Database db = make_database();
  ASSERT_TRUE(db.validate().ok()) << db.validate().message();
  const auto path = test::scratch_dir() / "small.mmdb";
  const Status saved = save_database(db, path);
  ASSERT_TRUE(saved.ok()) << saved.message();
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));

  Result<Database> loaded = load_database(path);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  expect_same_database(db, *loaded);
  // Writing the loaded database again gives the identical bytes.
  EXPECT_EQ(serialize_database(db), serialize_database(*loaded));
}

TEST(DatabaseFile, LayoutMatchesTheDocumentedFormat) {
  const Database db = make_database();
  const std::vector<std::byte> bytes = serialize_database(db);
  const unsigned char magic[8] = {0x8A, 'M', 'M', 'D', '\r', '\n', 0x1A, '\n'};
  EXPECT_EQ(std::memcmp(bytes.data(), magic, 8), 0);
  uint32_t version = 0, marker = 0;
  uint64_t size = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&marker, bytes.data() + 12, 4);
  std::memcpy(&size, bytes.data() + 16, 8);
  EXPECT_EQ(version, 1u);
  EXPECT_EQ(marker, 0x01020304u);
  EXPECT_EQ(size, bytes.size());

  Result<DatabaseFileInfo> info = parse_database_header(bytes, "fixture");
  ASSERT_TRUE(info.ok()) << info.message();
  EXPECT_EQ(info->joint_count, 4u);
  EXPECT_EQ(info->frame_count, 20u);
  EXPECT_EQ(info->clip_count, 2u);
  EXPECT_EQ(info->tag_count, 3u);
  EXPECT_EQ(info->feature_dims, 7u);
  EXPECT_EQ(info->channel_count, 2u);
  // Fixed sections hold exactly the arrays, by hand: 20 frames x 4 joints x 16 bytes.
  EXPECT_EQ(info->section(DatabaseSection::LocalRotations).length, 20u * 4 * 16);
  EXPECT_EQ(info->section(DatabaseSection::Features).length, 20u * 7 * 4);
  for (const DatabaseFileSection& s : info->sections) EXPECT_EQ(s.offset % 16, 0u);
  // The rotations are stored x, y, z, w with one memcpy: check one quaternion by hand.
  const uint64_t rot = info->section(DatabaseSection::LocalRotations).offset;
  float q[4];
  std::memcpy(q, bytes.data() + rot + 16 * 5, 16);
  EXPECT_EQ(q[0], db.local_rotations[5].x);
  EXPECT_EQ(q[3], db.local_rotations[5].w);
  // The last 8 bytes are the checksum of everything before them.
  uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  EXPECT_EQ(stored, database_checksum(std::span(bytes).first(bytes.size() - 8)));
  EXPECT_EQ(info->stored_checksum, stored);
}

TEST(DatabaseFile, HeaderReaderReportsSizes) {
  const auto path = test::scratch_dir() / "header.mmdb";
  ASSERT_TRUE(save_database(make_database(), path).ok());
  Result<DatabaseFileInfo> info = read_database_header(path);
  ASSERT_TRUE(info.ok()) << info.message();
  EXPECT_EQ(info->format_version, kDatabaseFormatVersion);
  EXPECT_EQ(info->file_size, std::filesystem::file_size(path));
  EXPECT_EQ(info->frame_count, 20u);
  EXPECT_EQ(info->joint_count, 4u);
  EXPECT_FLOAT_EQ(info->frame_time, 1.0f / 60.0f);
}

TEST(DatabaseFile, LargeFileRoundTripsAndCatchesCorruptionWithParallelHash) {
  // 40k frames make a file over 8 MiB, which takes the two-thread path.
  const Database db = make_database(40000, 11);
  std::vector<std::byte> bytes = serialize_database(db);
  ASSERT_GT(bytes.size(), size_t{8} << 20);
  Result<Database> loaded = deserialize_database(bytes, "large");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  expect_same_database(db, *loaded);

  // A NaN deep in the velocities without resealing: the checksum reports it, not the NaN.
  const uint64_t vel = section_offset(bytes, DatabaseSection::LocalVelocities);
  std::vector<std::byte> corrupt = bytes;
  std::memcpy(corrupt.data() + vel + 12 * 100000 + 4, &nan, 4);
  EXPECT_TRUE(contains(load_error(corrupt), "checksum mismatch")) << load_error(corrupt);
  // Resealed, the value check finds it: sample 100000 is frame 25000, joint 0.
  const std::string message = load_error(patched(bytes, vel + 12 * 100000 + 4, nan));
  EXPECT_TRUE(
      contains(message, "local_velocities[frame 25000, joint 0 'Simulation'] is not finite"))
      << message;
}

// ---------------------------------------------------------------------------------------------
// Damaged files.

TEST(DatabaseFile, EveryTruncationIsRefusedWithItsSize) {
  const std::vector<std::byte> bytes = serialize_database(make_database());
  ASSERT_LT(bytes.size(), 16384u);  // small enough to try every length
  for (size_t length = 0; length < bytes.size(); ++length) {
    const std::vector<std::byte> cut(bytes.begin(), bytes.begin() + static_cast<ptrdiff_t>(length));
    const std::string message = load_error(cut);
    std::string expected;
    if (length == 0) {
      expected = "empty file";
    } else if (length < kDatabaseHeaderSize) {
      expected =
          "truncated: expected at least 336 bytes of header, file has " + std::to_string(length);
    } else {
      expected = "truncated: expected " + std::to_string(bytes.size()) + " bytes, file has " +
                 std::to_string(length);
    }
    ASSERT_TRUE(contains(message, expected)) << "length " << length << ": " << message;
  }
}

TEST(DatabaseFile, EveryFlippedByteIsRefused) {
  const std::vector<std::byte> bytes = serialize_database(make_database());
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::vector<std::byte> flipped = bytes;
    flipped[i] ^= std::byte{0xFF};
    const std::string message = load_error(flipped);
    // Which check must fire follows from the documented layout.
    std::string expected = "checksum mismatch";
    if (i < 8) {
      expected = "not a motion database file";
    } else if (i < 12) {
      expected = "format version";
    } else if (i < 16) {
      expected = "endianness marker";
    } else if (i < 24) {
      expected = "bytes";  // the declared size no longer matches: truncated or trailing
    }
    ASSERT_TRUE(contains(message, expected)) << "byte " << i << ": " << message;
    if (i >= 24) {
      ASSERT_TRUE(contains(message, "fixture.mmdb: checksum mismatch")) << i;
    }
  }
}

TEST(DatabaseFile, EverySingleBitFlipIsRefused) {
  const std::vector<std::byte> bytes = serialize_database(make_database());
  // Every bit of the first 1024 bytes and of 200 bytes spread over the rest.
  std::vector<size_t> positions;
  for (size_t i = 0; i < 1024; ++i) positions.push_back(i);
  for (size_t k = 0; k < 200; ++k) positions.push_back(1024 + k * (bytes.size() - 1025) / 199);
  for (size_t i : positions) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<std::byte> flipped = bytes;
      flipped[i] ^= std::byte{static_cast<unsigned char>(1u << bit)};
      ASSERT_FALSE(load_error(flipped).empty()) << "byte " << i << " bit " << bit;
    }
  }
}

TEST(DatabaseFile, TrailingBytesAreRefused) {
  std::vector<std::byte> bytes = serialize_database(make_database());
  const size_t size = bytes.size();
  bytes.push_back(std::byte{0});
  EXPECT_TRUE(contains(load_error(bytes), "file has " + std::to_string(size + 1) +
                                              " bytes but its header says " + std::to_string(size)))
      << load_error(bytes);
}

TEST(DatabaseFile, WrongMagicVersionAndEndiannessHaveSpecificMessages) {
  const std::vector<std::byte> bytes = serialize_database(make_database());

  std::vector<std::byte> text = bytes;
  text[0] = std::byte{'{'};
  EXPECT_TRUE(contains(load_error(text), "not a motion database file")) << load_error(text);

  // A text-mode copy turns "\r\n" into "\n": the magic catches it.
  std::vector<std::byte> mangled;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] == std::byte{'\r'} && i + 1 < bytes.size() && bytes[i + 1] == std::byte{'\n'})
      continue;
    mangled.push_back(bytes[i]);
  }
  EXPECT_TRUE(contains(load_error(mangled), "text-mode")) << load_error(mangled);

  const std::string newer = load_error(patched(bytes, 8, uint32_t{2}));
  EXPECT_TRUE(contains(newer, "format version 2 is newer than the version this program reads (1)"))
      << newer;
  const std::string older = load_error(patched(bytes, 8, uint32_t{0}));
  EXPECT_TRUE(contains(older, "format version 0 is older than the version this program reads (1)"))
      << older;

  const std::string swapped = load_error(patched(bytes, 12, uint32_t{0x04030201}));
  EXPECT_TRUE(contains(swapped, "written on a machine of the other endianness")) << swapped;
  const std::string garbage = load_error(patched(bytes, 12, uint32_t{0x12345678}));
  EXPECT_TRUE(contains(garbage, "corrupt endianness marker 0x0000000012345678")) << garbage;
}

TEST(DatabaseFile, EmptyAndMissingFilesNameThePath) {
  const auto dir = test::scratch_dir();
  const auto empty = dir / "empty.mmdb";
  write_file(empty, {});
  Result<Database> from_empty = load_database(empty);
  ASSERT_FALSE(from_empty.ok());
  EXPECT_TRUE(contains(from_empty.message(), empty.string() + ": empty file"))
      << from_empty.message();

  const auto missing = dir / "no_such_database.mmdb";
  Result<Database> from_missing = load_database(missing);
  ASSERT_FALSE(from_missing.ok());
  EXPECT_TRUE(contains(from_missing.message(), missing.string())) << from_missing.message();
  EXPECT_TRUE(contains(from_missing.message(), "No such file")) << from_missing.message();

  Result<Database> from_folder = load_database(dir);
  ASSERT_FALSE(from_folder.ok());
  EXPECT_TRUE(contains(from_folder.message(), "folder")) << from_folder.message();

  EXPECT_FALSE(read_database_header(missing).ok());
  Result<DatabaseFileInfo> empty_header = read_database_header(empty);
  ASSERT_FALSE(empty_header.ok());
  EXPECT_TRUE(contains(empty_header.message(), "empty file"));
}

TEST(DatabaseFile, SaveRefusesAnInvalidDatabaseAndWritesNothing) {
  Database db = make_database();
  db.feature_scale[2] = 0.0f;
  const auto path = test::scratch_dir() / "invalid.mmdb";
  const Status saved = save_database(db, path);
  ASSERT_FALSE(saved.ok());
  EXPECT_TRUE(contains(saved.message(), "feature_scale[2]")) << saved.message();
  EXPECT_FALSE(std::filesystem::exists(path));
}

// ---------------------------------------------------------------------------------------------
// Corruptions behind a valid checksum: each structural and semantic check on its own.

TEST(DatabaseFile, ResealedCorruptionsAreFoundByStructuralChecks) {
  const std::vector<std::byte> bytes = serialize_database(make_database());
  struct Case {
    const char* what;
    std::vector<std::byte> file;
    std::string expected;
  };
  const uint64_t names = section_offset(bytes, DatabaseSection::SkeletonNames);
  const uint64_t schema = section_offset(bytes, DatabaseSection::Schema);
  const uint64_t clips = section_offset(bytes, DatabaseSection::Clips);
  const uint64_t table = 88;
  const std::vector<Case> cases = {
      {"huge frame count", patched(bytes, 36, uint32_t{0xFFFFFFF0}),
       "frame_count 4294967280 is outside the valid range"},
      {"huge joint count", patched(bytes, 32, uint32_t{100000}),
       "joint_count 100000 is outside the valid range"},
      {"frame count one more", patched(bytes, 36, uint32_t{21}),
       "section 'local_positions': 960 bytes, expected 1008"},
      {"zero channels", patched(bytes, 52, uint32_t{0}), "channel_count 0 is outside"},
      {"too many tags", patched(bytes, 44, uint32_t{65}), "tag_count 65 is outside"},
      {"more clips than the section holds", patched(bytes, 40, uint32_t{20}), "section 'clips'"},
      {"section past the end", patched(bytes, table + 16 * 14, uint64_t{1} << 40),
       "section 'tag_names': offset 1099511627776"},
      {"misaligned section",
       patched(bytes, table + 16 * 4, section_offset(bytes, DatabaseSection::LocalPositions) + 4),
       "section 'local_positions': offset"},
      {"huge string length", patched(bytes, names, uint32_t{0x7FFFFFFF}),
       "section 'skeleton_names': string 0 claims 2147483647 bytes"},
      // Channel 0: kind, 3 padding, name "left_foot_position" (4 + 18), bone "left_foot"
      // (4 + 9), then the time count at 4 + 22 + 13 = 39.
      {"huge time count", patched(bytes, schema + 39, uint32_t{0x40000000}),
       "section 'schema': channel 0 claims 1073741824 times"},
      {"unknown feature kind", patched(bytes, schema, uint8_t{9}), "unknown feature kind 9"},
      {"mirrored flag 2", patched(bytes, clips + 16, uint8_t{2}), "mirrored flag is 2"},
      {"header size", patched(bytes, 24, uint32_t{320}), "corrupt header"},
  };
  for (const Case& c : cases) {
    const std::string message = load_error(c.file);
    EXPECT_TRUE(contains(message, c.expected)) << c.what << ": " << message;
    EXPECT_FALSE(contains(message, "checksum")) << c.what;
  }
}

TEST(DatabaseFile, ResealedCorruptionsAreFoundBySemanticValidation) {
  const Database db = make_database();
  const std::vector<std::byte> bytes = serialize_database(db);
  const uint64_t parents = section_offset(bytes, DatabaseSection::SkeletonParents);
  const uint64_t clips = section_offset(bytes, DatabaseSection::Clips);
  const uint64_t clip1 = clips + 24 + db.clips[0].name.size();
  const uint64_t features = section_offset(bytes, DatabaseSection::Features);
  const uint64_t scale = section_offset(bytes, DatabaseSection::FeatureScale);
  const uint64_t rotations = section_offset(bytes, DatabaseSection::LocalRotations);
  const uint64_t contacts = section_offset(bytes, DatabaseSection::Contacts);
  const uint64_t searchable = section_offset(bytes, DatabaseSection::Searchable);
  struct Case {
    const char* what;
    std::vector<std::byte> file;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"parent out of range", patched(bytes, parents + 4 * 2, int32_t{7}),
       "joint 'Foot_L' has parent index 7, out of range [-1, 4)"},
      {"parent after child", patched(bytes, parents + 4 * 2, int32_t{3}),
       "joint 'Foot_L' (index 2) comes before its parent 'Foot_R' (index 3)"},
      {"clip past the frames", patched(bytes, clips + 4, int32_t{25}),
       "clip 0 'walk_take' has range [0, 25)"},
      {"clips overlap", patched(bytes, clip1, int32_t{10}),
       "clip 1 'run_take_mirror' starts at frame 10, expected 12"},
      {"unknown tag bit", patched(bytes, clip1 + 8, uint64_t{1} << 5),
       "clip 1 'run_take_mirror' has tag bit 5 set, but only 3 tags exist"},
      {"NaN feature", patched(bytes, features + 4 * (3 * kDims + 2), nan),
       "features[frame 3, column 2] is not finite"},
      {"zero scale", patched(bytes, scale + 4 * 5, 0.0f), "feature_scale[5] is 0"},
      {"non-unit quaternion", patched(bytes, rotations + 16 * 6 + 12, 2.0f),
       "local_rotations[frame 1, joint 2 'Foot_L'] is not a finite unit quaternion"},
      {"contact of 2", patched(bytes, contacts + 7, uint8_t{2}), "contacts[frame 3, right] is 2"},
      {"searchable of 3", patched(bytes, searchable + 4, uint8_t{3}), "searchable[4] is 3"},
      {"role out of range", patched(bytes, 60 + 4, int32_t{9}),
       "role left_foot is joint 9, out of range [-1, 4)"},
      {"zero frame time", patched(bytes, 56, 0.0f), "frame_time"},
  };
  for (const Case& c : cases) {
    const std::string message = load_error(c.file);
    EXPECT_TRUE(contains(message, "fixture.mmdb: ")) << c.what << ": " << message;
    EXPECT_TRUE(contains(message, c.expected)) << c.what << ": " << message;
  }
}

// ---------------------------------------------------------------------------------------------
// Database::validate and tag_mask on in-memory databases.

TEST(DatabaseValidate, CatchesEachInconsistency) {
  ASSERT_TRUE(make_database().validate().ok());
  struct Case {
    const char* what;
    void (*damage)(Database&);
    const char* expected;
  };
  const Case cases[] = {
      {"frame time", [](Database& d) { d.frame_time = -1.0f; }, "frame_time"},
      {"no frames", [](Database& d) { d.frame_count = 0; }, "has no frames"},
      {"role", [](Database& d) { d.roles.head = 4; }, "role head is joint 4"},
      {"positions size", [](Database& d) { d.local_positions.pop_back(); },
       "local_positions has 79 values, expected 80"},
      {"rotations size", [](Database& d) { d.local_rotations.emplace_back(); },
       "local_rotations has 81 values, expected 80"},
      {"contacts size", [](Database& d) { d.contacts.pop_back(); }, "contacts has 39 values"},
      {"features size", [](Database& d) { d.features.pop_back(); }, "features has 139 values"},
      {"offset size", [](Database& d) { d.feature_offset.pop_back(); }, "feature_offset has 6"},
      {"scale size", [](Database& d) { d.feature_scale.push_back(1.0f); }, "feature_scale has 8"},
      {"searchable size", [](Database& d) { d.searchable.clear(); }, "searchable has 0 values"},
      {"frame_clip size", [](Database& d) { d.frame_clip.pop_back(); }, "frame_clip has 19"},
      {"frame_clip value", [](Database& d) { d.frame_clip[13] = 0; },
       "frame_clip[13] is 0, but the frame is in clip 1"},
      {"no clips", [](Database& d) { d.clips.clear(); }, "no clips"},
      {"clip gap", [](Database& d) { d.clips[1].start = 13; }, "starts at frame 13, expected 12"},
      {"clips short", [](Database& d) { d.clips[1].end = 19; }, "the clips end at frame 19"},
      {"clip past end", [](Database& d) { d.clips[1].end = 21; }, "range [12, 21)"},
      {"empty clip",
       [](Database& d) {
         d.clips[0].end = 0;
         d.clips[1].start = 0;
       },
       "range [0, 0)"},
      {"tag bit", [](Database& d) { d.clips[0].tags = uint64_t{1} << 63; }, "tag bit 63"},
      {"too many tags", [](Database& d) { d.tag_names.resize(65, "x"); }, "65 tag names"},
      {"duplicate tag", [](Database& d) { d.tag_names[2] = "walk"; }, "duplicate tag name 'walk'"},
      {"empty tag", [](Database& d) { d.tag_names[1].clear(); }, "tag name 1 is empty"},
      {"unknown bone", [](Database& d) { d.schema.channels[0].bone = "Tail"; },
       "names bone 'Tail', which is neither a role nor a joint"},
      {"missing role", [](Database& d) { d.roles.left_foot = -1; }, "uses role 'left_foot'"},
      {"bad schema", [](Database& d) { d.schema.channels[1].weight = 0.0f; }, "schema:"},
      {"rotation", [](Database& d) { d.local_rotations[77] = glm::quat(0.9f, 0, 0, 0); },
       "local_rotations[frame 19, joint 1 'Hips']"},
      {"rotation nan", [](Database& d) { d.local_rotations[3].x = nan; },
       "local_rotations[frame 0, joint 3 'Foot_R']"},
      {"position", [](Database& d) { d.local_positions[9].y = INFINITY; },
       "local_positions[frame 2, joint 1 'Hips'] is not finite"},
      {"velocity", [](Database& d) { d.local_velocities[0].z = nan; }, "local_velocities[frame 0"},
      {"angular velocity", [](Database& d) { d.local_angular_velocities[79].x = nan; },
       "local_angular_velocities[frame 19, joint 3"},
      {"contact", [](Database& d) { d.contacts[4] = 7; }, "contacts[frame 2, left] is 7"},
      {"feature", [](Database& d) { d.features[15] = nan; }, "features[frame 2, column 1]"},
      {"offset", [](Database& d) { d.feature_offset[6] = nan; }, "feature_offset[6]"},
      {"scale inf", [](Database& d) { d.feature_scale[0] = INFINITY; }, "feature_scale[0] is inf"},
      {"searchable", [](Database& d) { d.searchable[19] = 2; }, "searchable[19] is 2"},
      {"rest",
       [](Database& d) {
         std::vector<Transform> rest = d.skeleton.rest();
         rest[2].translation.x = nan;
         d.skeleton = Skeleton::create(d.skeleton.names(), d.skeleton.parents(), rest).value();
       },
       "rest transform of joint 2 'Foot_L'"},
  };
  for (const Case& c : cases) {
    Database db = make_database();
    c.damage(db);
    const Status s = db.validate();
    ASSERT_FALSE(s.ok()) << c.what;
    EXPECT_TRUE(contains(s.message(), c.expected)) << c.what << ": " << s.message();
  }
}

TEST(DatabaseValidate, LargeArraysReportTheFirstBadValue) {
  // Over a million values the scans split across two threads; the first bad index must win
  // whichever half it is in.
  Database db = make_database(300000, 3);
  ASSERT_TRUE(db.validate().ok()) << db.validate().message();
  db.local_positions[1000000].x = nan;  // second half of 1.2M samples
  EXPECT_TRUE(contains(db.validate().message(), "local_positions[frame 250000, joint 0"))
      << db.validate().message();
  db.local_positions[10].z = nan;  // now also one in the first half, which comes first
  EXPECT_TRUE(contains(db.validate().message(), "local_positions[frame 2, joint 2"))
      << db.validate().message();
}

TEST(DatabaseTagMask, KnownNamesSetTheirBitsUnknownNamesNone) {
  const Database db = make_database();
  const std::vector<std::string> walk_mirror = {"walk", "mirror"};
  EXPECT_EQ(db.tag_mask(walk_mirror), 0b101u);
  const std::vector<std::string> run = {"run"};
  EXPECT_EQ(db.tag_mask(run), 0b010u);
  const std::vector<std::string> unknown = {"swim", "Walk", ""};
  EXPECT_EQ(db.tag_mask(unknown), 0u);
  const std::vector<std::string> mixed = {"swim", "run", "run"};
  EXPECT_EQ(db.tag_mask(mixed), 0b010u);
  EXPECT_EQ(db.tag_mask({}), 0u);
}

// ---------------------------------------------------------------------------------------------
// The checksum itself.

TEST(DatabaseChecksum, DetectsEverySingleWordChangeAndDependsOnLength) {
  std::mt19937 rng(5);
  std::vector<std::byte> data(1000);
  for (std::byte& b : data) b = static_cast<std::byte>(rng());
  const uint64_t base = database_checksum(data);
  EXPECT_EQ(base, database_checksum(data));  // deterministic
  // Any change confined to one aligned word, in the blocks or in the tail, is seen.
  for (size_t i = 0; i + 8 <= data.size(); i += 8) {
    std::vector<std::byte> changed = data;
    changed[i + rng() % 8] ^= static_cast<std::byte>(1 + rng() % 255);
    ASSERT_NE(database_checksum(changed), base) << i;
  }
  // Every prefix length hashes differently from its neighbour (the tail and length handling).
  for (size_t n = 1; n <= data.size(); ++n) {
    ASSERT_NE(database_checksum(std::span(data).first(n)),
              database_checksum(std::span(data).first(n - 1)))
        << n;
  }
  // Zero bytes appended change the hash (the length is mixed in).
  std::vector<std::byte> zeros(64, std::byte{0});
  EXPECT_NE(database_checksum(std::span(zeros).first(63)), database_checksum(zeros));
  // Swapping two blocks changes it (lanes are order-dependent).
  std::vector<std::byte> swapped = data;
  std::swap_ranges(swapped.begin(), swapped.begin() + 32, swapped.begin() + 32);
  EXPECT_NE(database_checksum(swapped), base);
}

}  // namespace
}  // namespace mm
