#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "database_helpers.hpp"
#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/velocities.hpp"
#include "mm/offline/database_writer.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

// ---------------------------------------------------------------------------------------------
// Fixture: a small but complete database with random valid arrays.

constexpr int kJoints = 4;
constexpr int kClip0Frames = 12;
constexpr int kClip1Frames = 8;
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

// Velocities and angular velocities as the builder makes them and load recomputes them: clip by
// clip, never across a boundary.
void derive_velocities(DatabaseContents& db) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  db.local_velocities.resize(db.local_positions.size());
  db.local_angular_velocities.resize(db.local_positions.size());
  for (const ClipRange& clip : db.clips) {
    const size_t first = static_cast<size_t>(clip.start) * joints;
    const size_t count = static_cast<size_t>(clip.frame_count()) * joints;
    compute_local_velocities(std::span(db.local_positions).subspan(first, count),
                             std::span(db.local_rotations).subspan(first, count),
                             clip.frame_count(), db.joint_count(), db.frame_time,
                             std::span(db.local_velocities).subspan(first, count),
                             std::span(db.local_angular_velocities).subspan(first, count));
  }
}

// `frames_in_clip1` lets one test make a large database with the same shape. Joint 3 keeps one
// position through clip 0 (a constant column, stored once); every other column varies.
DatabaseContents make_contents(int clip1_frames = kClip1Frames, uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  DatabaseContents db;
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
  }
  for (int f = 1; f < kClip0Frames; ++f)
    db.local_positions[f * kJoints + 3] = db.local_positions[3];
  for (int f = 0; f < db.frame_count * 2; ++f) db.contacts.push_back(unit(rng) < 0.5f ? 1 : 0);
  db.clips.push_back({"walk_take", 0, kClip0Frames, 0b001, false});
  db.clips.push_back({"run_take_mirror", kClip0Frames, db.frame_count, 0b110, true});
  derive_velocities(db);
  db.tag_names = {"walk", "run", "mirror"};
  db.schema = two_channel_schema();
  for (int i = 0; i < db.frame_count * kDims; ++i) db.features.push_back(unit(rng) * 4.0f - 2.0f);
  for (int c = 0; c < kDims; ++c) {
    db.feature_offset.push_back(unit(rng) - 0.5f);
    db.feature_scale.push_back(0.5f + unit(rng));
  }
  for (int f = 0; f < db.frame_count; ++f) db.searchable.push_back(unit(rng) < 0.8f ? 1 : 0);
  return db;
}

Database make_database(int clip1_frames = kClip1Frames, uint32_t seed = 7) {
  return Database::create(make_contents(clip1_frames, seed)).value();
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
  const DatabaseContents db = make_contents();
  ASSERT_TRUE(validate_database(db).ok()) << validate_database(db).message();
  const auto path = test::scratch_dir() / "small.mmdb";
  const Status saved = save_database(db, path);
  ASSERT_TRUE(saved.ok()) << saved.message();
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));

  Result<Database> loaded = load_database(path);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  test::expect_same_database(db, *loaded);
  // Writing the loaded database again gives the identical bytes.
  EXPECT_EQ(serialize_database(db), serialize_database(*loaded));
}

TEST(DatabaseFile, LayoutMatchesTheDocumentedFormat) {
  const DatabaseContents db = make_contents();
  const std::vector<std::byte> bytes = serialize_database(db);
  const unsigned char magic[8] = {0x8A, 'M', 'M', 'D', '\r', '\n', 0x1A, '\n'};
  EXPECT_EQ(std::memcmp(bytes.data(), magic, 8), 0);
  uint32_t version = 0, marker = 0;
  uint64_t size = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  std::memcpy(&marker, bytes.data() + 12, 4);
  std::memcpy(&size, bytes.data() + 16, 8);
  EXPECT_EQ(version, 4u);
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
  // Fixed sections hold exactly the arrays, by hand: 20 frames x 4 joints x 12 bytes of
  // rotation components and one code byte each.
  EXPECT_EQ(info->section(DatabaseSection::RotationComponents).length, 20u * 4 * 12);
  EXPECT_EQ(info->section(DatabaseSection::RotationCodes).length, 20u * 4);
  EXPECT_EQ(info->section(DatabaseSection::Features).length, 20u * 7 * 4);
  for (const DatabaseFileSection& s : info->sections) EXPECT_EQ(s.offset % 16, 0u);
  // Positions: one flag per clip and joint; joint 3 of clip 0 is the only constant column, stored
  // once; the other 7 columns store every frame (12 x 3 + 8 x 4 = 68 values).
  EXPECT_EQ(info->section(DatabaseSection::PositionColumns).length, 2u * 4);
  const uint64_t columns = info->section(DatabaseSection::PositionColumns).offset;
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(std::to_integer<int>(bytes[columns + i]), i == 3 ? 1 : 0) << i;
  }
  EXPECT_EQ(info->section(DatabaseSection::ConstantPositions).length, 12u);
  EXPECT_EQ(info->section(DatabaseSection::VaryingPositions).length, 68u * 12);
  float p[3];
  std::memcpy(p, bytes.data() + info->section(DatabaseSection::ConstantPositions).offset, 12);
  EXPECT_EQ(glm::vec3(p[0], p[1], p[2]), db.local_positions[3]);
  // Rotation 5 by hand: its code names the left-out component, its sign and its distance in ulps
  // from sqrt(1 - a^2 - b^2 - c^2) of the three stored ones (x, y, z, w order).
  const uint64_t rot = info->section(DatabaseSection::RotationComponents).offset;
  const uint64_t codes = info->section(DatabaseSection::RotationCodes).offset;
  float three[3];
  std::memcpy(three, bytes.data() + rot + 12 * 5, 12);
  const int code = std::to_integer<int>(bytes[codes + 5]);
  ASSERT_NE(code >> 3, 31);  // no escape in a freshly normalized quaternion
  const float q[4] = {db.local_rotations[5].x, db.local_rotations[5].y, db.local_rotations[5].z,
                      db.local_rotations[5].w};
  const int left_out = code & 3;
  for (int k = 0, n = 0; k < 4; ++k) {
    if (k != left_out) {
      EXPECT_EQ(three[n++], q[k]) << k;
    }
  }
  for (int k = 0; k < 4; ++k) EXPECT_LE(std::abs(q[k]), std::abs(q[left_out])) << k;
  EXPECT_EQ((code >> 2) & 1, std::signbit(q[left_out]) ? 1 : 0);
  const double sum =
      double{three[0]} * three[0] + double{three[1]} * three[1] + double{three[2]} * three[2];
  const float predicted = static_cast<float>(std::sqrt(1.0 - sum));
  int32_t predicted_bits = 0, actual_bits = 0;
  const float magnitude = std::abs(q[left_out]);
  std::memcpy(&predicted_bits, &predicted, 4);
  std::memcpy(&actual_bits, &magnitude, 4);
  EXPECT_EQ(actual_bits - predicted_bits, (code >> 3) - 16);
  // Velocities are not stored at all; the style names (none here: a count of 0) come last.
  EXPECT_EQ(bytes.size(), info->section(DatabaseSection::StyleNames).offset + 4 + 8);
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

TEST(DatabaseFileThreads, LargeFileRoundTripsAndCatchesCorruptionWithParallelHash) {
  // 70k frames make a file over 8 MiB, which takes the two-thread path.
  const DatabaseContents db = make_contents(70000, 11);
  std::vector<std::byte> bytes = serialize_database(db);
  ASSERT_GT(bytes.size(), size_t{8} << 20);
  Result<Database> loaded = deserialize_database(bytes, "large");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  test::expect_same_database(db, *loaded);

  // A NaN deep in the positions without resealing: the checksum reports it, not the NaN.
  const uint64_t varying = section_offset(bytes, DatabaseSection::VaryingPositions);
  std::vector<std::byte> corrupt = bytes;
  std::memcpy(corrupt.data() + varying + 12 * 100000 + 4, &nan, 4);
  EXPECT_TRUE(contains(load_error(corrupt), "checksum mismatch")) << load_error(corrupt);
  // Resealed, the value check finds it. Varying value 100000: clip 0 stores 12 frames x 3
  // varying joints, so it is value 99964 of clip 1 (4 joints a frame from frame 12): frame 25003,
  // joint 0.
  const std::string message = load_error(patched(bytes, varying + 12 * 100000 + 4, nan));
  EXPECT_TRUE(contains(message, "local_positions[frame 25003, joint 0 'Simulation'] is not finite"))
      << message;
}

TEST(DatabaseFile, VelocitiesThatOverflowOnLoadAreRefusedByName) {
  // Finite positions whose difference overflows: the velocities recomputed on load are
  // infinite, and the load fails naming the first one (frame 4 differences frames 3 and 5).
  DatabaseContents db = make_contents();
  const size_t joints = static_cast<size_t>(db.joint_count());
  db.local_positions[5 * joints + 1].x = 3e38f;
  db.local_positions[6 * joints + 1].x = -3e38f;
  const std::string message = load_error(serialize_database(db));
  EXPECT_TRUE(contains(message, "local_velocities[frame 4, joint 1 'Hips'] is not finite"))
      << message;
}

TEST(DatabaseFile, TheLoadedPerFrameArraysShareOneAllocation) {
  // Loaded or created, a database's per-frame arrays are consecutive cache-line aligned runs of
  // one block, none overlapping another.
  Result<Database> loaded = deserialize_database(serialize_database(make_contents(300, 7)), "db");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const Database created = make_database();
  for (const Database* db : std::array<const Database*, 2>{&*loaded, &created}) {
    struct Run {
      const std::byte* begin;
      size_t bytes;
    };
    const auto run = [](auto span) {
      return Run{reinterpret_cast<const std::byte*>(span.data()), span.size_bytes()};
    };
    std::vector<Run> runs = {run(db->pose_lanes()),     run(db->features()),
                             run(db->feature_offset()), run(db->feature_scale()),
                             run(db->frame_clip()),     run(db->contacts()),
                             run(db->searchable())};
    std::sort(runs.begin(), runs.end(),
              [](const Run& a, const Run& b) { return a.begin < b.begin; });
    for (size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(reinterpret_cast<uintptr_t>(runs[i].begin) % 64, 0u) << i;
      if (i == 0) continue;
      const std::byte* previous_end = runs[i - 1].begin + runs[i - 1].bytes;
      EXPECT_GE(runs[i].begin, previous_end) << i;
      EXPECT_LT(runs[i].begin - previous_end, 64) << i;  // no more than the alignment's padding
    }
  }
}

TEST(DatabaseFile, ThePoseIsHeldInGroupsOfFourJoints) {
  // Loaded or created, frame f's group g, row r, lane l is component r of joint 4 g + l of frame
  // f, read here from the per-joint arrays it was made from (a lane past the last joint: a joint
  // at rest), and nothing else is kept of the pose: one frame is 13 rows of 4 floats per group.
  const DatabaseContents contents = make_contents(300, 7);
  Result<Database> loaded = deserialize_database(serialize_database(contents), "db");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const Database created = Database::create(contents).value();
  for (const Database* db : std::array<const Database*, 2>{&*loaded, &created}) {
    const size_t joints = static_cast<size_t>(db->joint_count());
    const size_t groups = (joints + 3) / 4;
    ASSERT_EQ(db->pose_lanes().size(), static_cast<size_t>(db->frame_count()) * 52 * groups);
    for (int f = 0; f < db->frame_count(); ++f) {
      const std::span<const float> lanes = db->frame_pose_lanes(f);
      for (size_t j = 0; j < groups * 4; ++j) {
        const size_t k = static_cast<size_t>(f) * joints + j;
        const bool real = j < joints;
        const glm::quat q = real ? contents.local_rotations[k] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
        const glm::vec3 p = real ? contents.local_positions[k] : glm::vec3(0.0f);
        const glm::vec3 v = real ? contents.local_velocities[k] : glm::vec3(0.0f);
        const glm::vec3 w = real ? contents.local_angular_velocities[k] : glm::vec3(0.0f);
        const float expected[13] = {q.w, q.x, q.y, q.z, p.x, p.y, p.z,
                                    v.x, v.y, v.z, w.x, w.y, w.z};
        for (size_t r = 0; r < 13; ++r) {
          ASSERT_EQ(lanes[(j / 4) * 52 + 4 * r + j % 4], expected[r])
              << "frame " << f << " joint " << j << " row " << r;
        }
        if (!real) continue;
        // The per-joint readers give the same values.
        const int joint = static_cast<int>(j);
        EXPECT_EQ(db->local_rotation(f, joint), q);
        EXPECT_EQ(db->local_position(f, joint), p);
        EXPECT_EQ(db->local_velocity(f, joint), v);
        EXPECT_EQ(db->local_angular_velocity(f, joint), w);
        EXPECT_EQ(db->local_rotations()[k], q);
        EXPECT_EQ(db->local_positions()[k], p);
        EXPECT_EQ(db->local_velocities()[k], v);
        EXPECT_EQ(db->local_angular_velocities()[k], w);
      }
    }
  }
}

TEST(DatabaseCreate, RefusesWhatValidateRefusesAndCopiesTheRest) {
  DatabaseContents contents = make_contents();
  contents.feature_scale[2] = 0.0f;
  Result<Database> refused = Database::create(contents);
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(contains(refused.message(), "feature_scale[2]")) << refused.message();
  contents.feature_scale[2] = 1.0f;
  Result<Database> created = Database::create(contents);
  ASSERT_TRUE(created.ok()) << created.message();
  test::expect_same_database(contents, *created);
  // frame_clip is derived from the clips.
  EXPECT_EQ(created->frame_clip()[kClip0Frames - 1], 0);
  EXPECT_EQ(created->frame_clip()[kClip0Frames], 1);
  // contents() gives back what went in; a move leaves the source without frames.
  test::expect_same_database(created->contents(), *created);
  Database moved = std::move(created).value();
  EXPECT_EQ(moved.frame_count(), contents.frame_count);
}

TEST(DatabaseWeight, ANewChannelWeightRescalesThatChannelsColumnsOnly) {
  const Database db = make_database();
  // Channel 1 (trajectory_position, weight 1.5, columns 3-6) to weight 3: twice the weight.
  Result<Database> heavier = with_channel_weight(db, 1, 3.0f);
  ASSERT_TRUE(heavier.ok()) << heavier.message();
  EXPECT_EQ(heavier->schema().channels[1].weight, 3.0f);
  EXPECT_EQ(heavier->schema().channels[0].weight, db.schema().channels[0].weight);
  for (int c = 0; c < kDims; ++c) {
    const float ratio = c >= 3 ? 2.0f : 1.0f;
    EXPECT_FLOAT_EQ(heavier->feature_scale()[c], db.feature_scale()[c] / ratio) << c;
    EXPECT_EQ(heavier->feature_offset()[c], db.feature_offset()[c]) << c;
    for (int f = 0; f < db.frame_count(); f += 7) {
      EXPECT_FLOAT_EQ(heavier->feature_row(f)[c], db.feature_row(f)[c] * ratio) << f << " " << c;
    }
  }
  // Everything but the features is the same database.
  DatabaseContents expected = db.contents();
  DatabaseContents got = heavier->contents();
  got.schema = expected.schema;
  got.features = expected.features;
  got.feature_scale = expected.feature_scale;
  test::expect_same_database(expected, Database::create(got).value());

  Result<Database> no_channel = with_channel_weight(db, 2, 1.0f);
  ASSERT_FALSE(no_channel.ok());
  EXPECT_EQ(no_channel.message(), "feature weight: no channel 2 (the schema has 2)");
  for (const float bad : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity()}) {
    Result<Database> refused = with_channel_weight(db, 0, bad);
    ASSERT_FALSE(refused.ok()) << bad;
    EXPECT_EQ(refused.message(),
              "feature weight: the weight of left_foot_position must be finite and > 0");
  }
}

TEST(FeatureSchema, ColumnNamesNameEveryColumnInOrder) {
  const std::vector<std::string> names = two_channel_schema().column_names();
  EXPECT_EQ(names, (std::vector<std::string>{
                       "left_foot_position_x", "left_foot_position_y", "left_foot_position_z",
                       "trajectory_position_0.33s_x", "trajectory_position_0.33s_z",
                       "trajectory_position_0.67s_x", "trajectory_position_0.67s_z"}));
  const FeatureSchema schema = FeatureSchema::default_schema();
  const std::vector<std::string> all = schema.column_names();
  ASSERT_EQ(all.size(), static_cast<size_t>(schema.dims()));
  EXPECT_EQ(all[12], "hips_velocity_x");
  EXPECT_EQ(all[20], "trajectory_position_1s_z");
  EXPECT_EQ(all[26], "trajectory_direction_1s_z");
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
      expected = "truncated: expected at least " + std::to_string(kDatabaseHeaderSize) +
                 " bytes of header, file has " + std::to_string(length);
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

  const std::string newer = load_error(patched(bytes, 8, uint32_t{5}));
  EXPECT_TRUE(contains(newer, "format version 5 is newer than the version this program reads (4)"))
      << newer;
  const std::string older = load_error(patched(bytes, 8, uint32_t{0}));
  EXPECT_TRUE(contains(older, "format version 0 is older than the version this program reads (4)"))
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
  DatabaseContents db = make_contents();
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
  const uint64_t columns = section_offset(bytes, DatabaseSection::PositionColumns);
  const uint64_t codes = section_offset(bytes, DatabaseSection::RotationCodes);
  const uint8_t escaped_code = std::to_integer<uint8_t>(bytes[codes + 5]) | uint8_t{31 << 3};
  const uint64_t table = 88;
  const std::vector<Case> cases = {
      {"huge frame count", patched(bytes, 36, uint32_t{0xFFFFFFF0}),
       "frame_count 4294967280 is outside the valid range"},
      {"huge joint count", patched(bytes, 32, uint32_t{100000}),
       "joint_count 100000 is outside the valid range"},
      {"frame count one more", patched(bytes, 36, uint32_t{21}),
       "section 'rotation_components': 960 bytes, expected 1008"},
      {"zero channels", patched(bytes, 52, uint32_t{0}), "channel_count 0 is outside"},
      {"too many tags", patched(bytes, 44, uint32_t{65}), "tag_count 65 is outside"},
      {"more clips than the section holds", patched(bytes, 40, uint32_t{20}), "section 'clips'"},
      {"section past the end", patched(bytes, table + 16 * 17, uint64_t{1} << 40),
       "section 'searchable': offset 1099511627776"},
      {"misaligned section",
       patched(bytes, table + 16 * 10,
               section_offset(bytes, DatabaseSection::RotationComponents) + 4),
       "section 'rotation_components': offset"},
      {"position flag 2", patched(bytes, columns + 1, uint8_t{2}),
       "section 'position_columns': clip 0, joint 1: flag 2, expected 0 or 1"},
      {"varying column marked constant", patched(bytes, columns, uint8_t{1}),
       "section 'constant_positions': 12 bytes, but position_columns and the clips call for 2 "
       "positions"},
      {"varying positions not whole", patched(bytes, table + 16 * 9 + 8, uint64_t{68 * 12 - 4}),
       "section 'varying_positions': 812 bytes cannot hold"},
      {"escape code without exception", patched(bytes, codes + 5, escaped_code),
       "section 'rotation_exceptions': no exception for the escape code of sample 5 [frame 1, "
       "joint 1]"},
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
  const DatabaseContents db = make_contents();
  const std::vector<std::byte> bytes = serialize_database(db);
  const uint64_t parents = section_offset(bytes, DatabaseSection::SkeletonParents);
  const uint64_t clips = section_offset(bytes, DatabaseSection::Clips);
  const uint64_t clip1 = clips + 28 + db.clips[0].name.size();
  const uint64_t features = section_offset(bytes, DatabaseSection::Features);
  const uint64_t scale = section_offset(bytes, DatabaseSection::FeatureScale);
  const uint64_t rotations = section_offset(bytes, DatabaseSection::RotationComponents);
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
      {"style out of range", patched(bytes, clips + 20, int32_t{3}),
       "clip 0 'walk_take' has style 3, but only 0 styles exist (-1: none)"},
      {"unknown tag bit", patched(bytes, clip1 + 8, uint64_t{1} << 5),
       "clip 1 'run_take_mirror' has tag bit 5 set, but only 3 tags exist"},
      {"NaN feature", patched(bytes, features + 4 * (3 * kDims + 2), nan),
       "features[frame 3, column 2] is not finite"},
      {"zero scale", patched(bytes, scale + 4 * 5, 0.0f), "feature_scale[5] is 0"},
      {"non-unit quaternion", patched(bytes, rotations + 12 * 6 + 8, 2.0f),
       "local_rotations[frame 1, joint 2 'Foot_L'] is not a finite unit quaternion"},
      {"contact of 2", patched(bytes, contacts + 7, uint8_t{2}), "contacts[frame 3, right] is 2"},
      {"searchable of 3", patched(bytes, searchable + 4, uint8_t{3}), "searchable[4] is 3"},
      {"role out of range",
       patched(bytes,
               section_offset(bytes, DatabaseSection::SkeletonRoles) +
                   4 * static_cast<uint64_t>(find_joint_role("left_foot") - kJointRoles.data()),
               int32_t{9}),
       "role left_foot is joint 9, out of range [-1, 4)"},
      {"zero frame time", patched(bytes, 56, 0.0f), "frame_time"},
  };
  for (const Case& c : cases) {
    const std::string message = load_error(c.file);
    EXPECT_TRUE(contains(message, "fixture.mmdb: ")) << c.what << ": " << message;
    EXPECT_TRUE(contains(message, c.expected)) << c.what << ": " << message;
  }
}

TEST(DatabaseFile, FormatVersion1FileIsRefusedWithARebuildMessage) {
  // A version-1 file has the same magic, version and endianness fields, then its own layout.
  const std::vector<std::byte> version1 = patched(serialize_database(make_database()), 8, 1u);
  const auto path = test::scratch_dir() / "version1.mmdb";
  write_file(path, version1);
  for (const std::string& message : {load_error(version1), load_database(path).message(),
                                     read_database_header(path).message()}) {
    EXPECT_TRUE(contains(message,
                         "format version 1 is older than the version this program "
                         "reads (4); rebuild the database with `mm build`"))
        << message;
  }
}

TEST(DatabaseFile, Version3FileWithoutStylesIsRefusedWithARebuildMessage) {
  const std::vector<std::byte> version3 = patched(serialize_database(make_database()), 8, 3u);
  EXPECT_TRUE(contains(load_error(version3),
                       "format version 3 is older than the version this program reads (4); "
                       "rebuild the database with `mm build`"))
      << load_error(version3);
}

TEST(DatabaseFile, ClipStylesAndStyleNamesRoundTrip) {
  DatabaseContents contents = make_database().contents();
  ASSERT_GE(contents.clips.size(), 1u);
  contents.style_names = {"proud", "tired"};
  contents.clips[0].style = 1;
  for (size_t c = 1; c < contents.clips.size(); ++c) contents.clips[c].style = -1;
  Result<Database> db = Database::create(contents);
  ASSERT_TRUE(db) << db.message();
  const auto path = test::scratch_dir() / "styles.mmdb";
  write_file(path, serialize_database(*db));
  Result<Database> loaded = load_database(path);
  ASSERT_TRUE(loaded) << loaded.message();
  ASSERT_EQ(loaded->style_names().size(), 2u);
  EXPECT_EQ(loaded->style_names()[0], "proud");
  EXPECT_EQ(loaded->style_names()[1], "tired");
  EXPECT_EQ(loaded->clips()[0].style, 1);
  if (loaded->clips().size() > 1) {
    EXPECT_EQ(loaded->clips()[1].style, -1);
  }
}

TEST(DatabaseFile, AClipStyleOutsideTheStyleNamesIsRefused) {
  DatabaseContents contents = make_database().contents();
  contents.style_names = {"proud"};
  contents.clips[0].style = 1;
  const Result<Database> db = Database::create(contents);
  ASSERT_FALSE(db);
  EXPECT_TRUE(contains(db.message(), "has style 1, but only 1 styles exist (-1: none)"))
      << db.message();
  contents.clips[0].style = 0;
  contents.style_names = {"proud", "proud"};
  const Result<Database> twice = Database::create(contents);
  ASSERT_FALSE(twice);
  EXPECT_TRUE(contains(twice.message(), "duplicate style name 'proud' (styles 0 and 1)"))
      << twice.message();
}

// ---------------------------------------------------------------------------------------------
// What the compact layout derives or encodes: bit-exact rotations, recomputed velocities.

TEST(DatabaseFile, RotationsRoundTripBitForBitThroughTheirEscapes) {
  DatabaseContents db = make_contents();
  // Quaternions the "smallest three" code cannot predict to within 15 ulps (not exactly unit,
  // though within validation's 1e-3) go to the exception list; signed zeros, a negative left-out
  // component and a rotation of exactly 180 degrees (w = 0) round-trip too.
  db.local_rotations[0] = glm::quat(1.0004f, 0.0f, 0.0f, 0.0f);
  db.local_rotations[1] = glm::quat(-0.0f, 0.0f, -1.0f, 0.0f);
  db.local_rotations[2] = glm::quat(0.0f, 0.6f, -0.0f, -0.8f);
  db.local_rotations[7] = glm::normalize(glm::quat(0.3f, -0.2f, 0.9f, 0.1f)) * 0.9997f;
  db.local_rotations[45] = glm::quat(-0.5f, -0.5f, -0.5f, -0.5f);
  derive_velocities(db);
  ASSERT_TRUE(validate_database(db).ok()) << validate_database(db).message();
  const std::vector<std::byte> bytes = serialize_database(db);
  Result<DatabaseFileInfo> info = parse_database_header(bytes, "fixture");
  ASSERT_TRUE(info.ok()) << info.message();
  EXPECT_EQ(info->section(DatabaseSection::RotationExceptions).length, 2u * 16);
  Result<Database> loaded = deserialize_database(bytes, "fixture");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_EQ(loaded->local_rotations().size(), db.local_rotations.size());
  for (size_t k = 0; k < db.local_rotations.size(); ++k) {
    const glm::quat got = loaded->local_rotations()[k];
    EXPECT_EQ(std::memcmp(&got, &db.local_rotations[k], sizeof(glm::quat)), 0) << k;
  }
  test::expect_same_database(db, *loaded);

  // The exceptions are records {sample, value, 0} in sample order, one per escape code.
  const uint64_t exceptions = info->section(DatabaseSection::RotationExceptions).offset;
  uint64_t first = 0;
  std::memcpy(&first, bytes.data() + exceptions, 8);
  EXPECT_EQ(first, 0u);
  const std::string unmatched = load_error(patched(bytes, exceptions, uint64_t{3}));
  EXPECT_TRUE(contains(unmatched,
                       "section 'rotation_exceptions': no exception for the escape "
                       "code of sample 0 [frame 0, joint 0]"))
      << unmatched;
  const std::string misplaced = load_error(patched(bytes, exceptions + 16, uint64_t{8}));
  EXPECT_TRUE(contains(misplaced,
                       "section 'rotation_exceptions': no exception for the escape "
                       "code of sample 7"))
      << misplaced;
  const std::string unordered = load_error(patched(bytes, exceptions, uint64_t{7}));
  EXPECT_TRUE(contains(unordered, "exception 1: sample 7 is not in increasing order")) << unordered;
  const std::string padding = load_error(patched(bytes, exceptions + 12, uint32_t{1}));
  EXPECT_TRUE(contains(padding, "exception 0 padding: non-zero padding")) << padding;
}

TEST(DatabaseFile, VelocitiesAreRecomputedOnLoadClipByClip) {
  DatabaseContents db = make_contents();
  // Whatever velocities the database holds, the file keeps only the poses.
  for (glm::vec3& v : db.local_velocities) v = glm::vec3(7.0f);
  for (glm::vec3& v : db.local_angular_velocities) v = glm::vec3(-7.0f);
  Result<Database> loaded = deserialize_database(serialize_database(db), "fixture");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  derive_velocities(db);
  test::expect_same_database(db, *loaded);
  // At the boundary between the clips (frames 11 | 12) the differences are one-sided, inside
  // each clip: frame 11 looks back at frame 10, frame 12 ahead at frame 13.
  const float inv_dt = 1.0f / db.frame_time;
  for (int j = 0; j < kJoints; ++j) {
    const auto p = [&](int f) { return db.local_positions[f * kJoints + j]; };
    EXPECT_EQ(loaded->local_velocities()[11 * kJoints + j], (p(11) - p(10)) * inv_dt) << j;
    EXPECT_EQ(loaded->local_velocities()[12 * kJoints + j], (p(13) - p(12)) * inv_dt) << j;
    EXPECT_EQ(loaded->local_velocities()[5 * kJoints + j], (p(6) - p(4)) * (inv_dt / 2.0f)) << j;
  }
}

// ---------------------------------------------------------------------------------------------
// Database::validate and tag_mask on in-memory databases.

TEST(DatabaseValidate, CatchesEachInconsistency) {
  ASSERT_TRUE(validate_database(make_contents()).ok());
  struct Case {
    const char* what;
    void (*damage)(DatabaseContents&);
    const char* expected;
  };
  const Case cases[] = {
      {"frame time", [](DatabaseContents& d) { d.frame_time = -1.0f; }, "frame_time"},
      {"no frames", [](DatabaseContents& d) { d.frame_count = 0; }, "has no frames"},
      {"role", [](DatabaseContents& d) { d.roles.head = 4; }, "role head is joint 4"},
      {"positions size", [](DatabaseContents& d) { d.local_positions.pop_back(); },
       "local_positions has 79 values, expected 80"},
      {"rotations size", [](DatabaseContents& d) { d.local_rotations.emplace_back(); },
       "local_rotations has 81 values, expected 80"},
      {"contacts size", [](DatabaseContents& d) { d.contacts.pop_back(); },
       "contacts has 39 values"},
      {"features size", [](DatabaseContents& d) { d.features.pop_back(); },
       "features has 139 values"},
      {"offset size", [](DatabaseContents& d) { d.feature_offset.pop_back(); },
       "feature_offset has 6"},
      {"scale size", [](DatabaseContents& d) { d.feature_scale.push_back(1.0f); },
       "feature_scale has 8"},
      {"searchable size", [](DatabaseContents& d) { d.searchable.clear(); },
       "searchable has 0 values"},
      {"no clips", [](DatabaseContents& d) { d.clips.clear(); }, "no clips"},
      {"clip gap", [](DatabaseContents& d) { d.clips[1].start = 13; },
       "starts at frame 13, expected 12"},
      {"clips short", [](DatabaseContents& d) { d.clips[1].end = 19; },
       "the clips end at frame 19"},
      {"clip past end", [](DatabaseContents& d) { d.clips[1].end = 21; }, "range [12, 21)"},
      {"empty clip",
       [](DatabaseContents& d) {
         d.clips[0].end = 0;
         d.clips[1].start = 0;
       },
       "range [0, 0)"},
      {"tag bit", [](DatabaseContents& d) { d.clips[0].tags = uint64_t{1} << 63; }, "tag bit 63"},
      {"too many tags", [](DatabaseContents& d) { d.tag_names.resize(65, "x"); }, "65 tag names"},
      {"duplicate tag", [](DatabaseContents& d) { d.tag_names[2] = "walk"; },
       "duplicate tag name 'walk'"},
      {"empty tag", [](DatabaseContents& d) { d.tag_names[1].clear(); }, "tag name 1 is empty"},
      {"unknown bone", [](DatabaseContents& d) { d.schema.channels[0].bone = "Tail"; },
       "names bone 'Tail', which is neither a role nor a joint"},
      {"missing role", [](DatabaseContents& d) { d.roles.left_foot = -1; },
       "uses role 'left_foot'"},
      {"bad schema", [](DatabaseContents& d) { d.schema.channels[1].weight = 0.0f; }, "schema:"},
      {"rotation", [](DatabaseContents& d) { d.local_rotations[77] = glm::quat(0.9f, 0, 0, 0); },
       "local_rotations[frame 19, joint 1 'Hips']"},
      {"rotation nan", [](DatabaseContents& d) { d.local_rotations[3].x = nan; },
       "local_rotations[frame 0, joint 3 'Foot_R']"},
      {"position", [](DatabaseContents& d) { d.local_positions[9].y = INFINITY; },
       "local_positions[frame 2, joint 1 'Hips'] is not finite"},
      {"velocity", [](DatabaseContents& d) { d.local_velocities[0].z = nan; },
       "local_velocities[frame 0"},
      {"angular velocity", [](DatabaseContents& d) { d.local_angular_velocities[79].x = nan; },
       "local_angular_velocities[frame 19, joint 3"},
      {"contact", [](DatabaseContents& d) { d.contacts[4] = 7; }, "contacts[frame 2, left] is 7"},
      {"feature", [](DatabaseContents& d) { d.features[15] = nan; }, "features[frame 2, column 1]"},
      {"offset", [](DatabaseContents& d) { d.feature_offset[6] = nan; }, "feature_offset[6]"},
      {"scale inf", [](DatabaseContents& d) { d.feature_scale[0] = INFINITY; },
       "feature_scale[0] is inf"},
      {"searchable", [](DatabaseContents& d) { d.searchable[19] = 2; }, "searchable[19] is 2"},
      {"rest",
       [](DatabaseContents& d) {
         std::vector<Transform> rest = d.skeleton.rest();
         rest[2].translation.x = nan;
         d.skeleton = Skeleton::create(d.skeleton.names(), d.skeleton.parents(), rest).value();
       },
       "rest transform of joint 2 'Foot_L'"},
  };
  for (const Case& c : cases) {
    DatabaseContents db = make_contents();
    c.damage(db);
    const Status s = validate_database(db);
    ASSERT_FALSE(s.ok()) << c.what;
    EXPECT_TRUE(contains(s.message(), c.expected)) << c.what << ": " << s.message();
  }
}

TEST(DatabaseValidateThreads, LargeArraysReportTheFirstBadValue) {
  // Over a million values the scans split across two threads; the first bad index must win
  // whichever half it is in.
  DatabaseContents db = make_contents(300000, 3);
  ASSERT_TRUE(validate_database(db).ok()) << validate_database(db).message();
  db.local_positions[1000000].x = nan;  // second half of 1.2M samples
  EXPECT_TRUE(contains(validate_database(db).message(), "local_positions[frame 250000, joint 0"))
      << validate_database(db).message();
  db.local_positions[10].z = nan;  // now also one in the first half, which comes first
  EXPECT_TRUE(contains(validate_database(db).message(), "local_positions[frame 2, joint 2"))
      << validate_database(db).message();
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
