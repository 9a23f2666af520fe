// The compact database file on real motion capture: every clip of the normal-style set (472
// clips, ~55k frames) built, saved, loaded and compared with what the builder made in memory.
// Positions and rotations are stored losslessly and must come back bit for bit; velocities and
// angular velocities are recomputed on load, clip by clip, and must equal the builder's, which
// never looked across a clip boundary either.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "database_helpers.hpp"
#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/offline/preprocess.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

template <class T>
bool same_bits(const T* a, const T* b, size_t count) {
  return std::memcmp(a, b, count * sizeof(T)) == 0;
}

TEST(DatabaseFileRealData, EveryNormalClipRoundTripsLosslessly) {
  const fs::path folder = test::data_dir();
  BuildReport report;
  Result<Database> built =
      build_database(std::span<const fs::path>(&folder, 1), BuildOptions{}, &report);
  ASSERT_TRUE(built.ok()) << built.message();
  const Database& db = *built;
  ASSERT_GE(db.clips().size(), 472u);
  const fs::path path = test::scratch_dir() / "normal.mmdb";
  ASSERT_TRUE(save_database(db, path).ok());
  Result<Database> loaded = load_database(path);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const Database& back = *loaded;
  std::printf("normal set: %zu clips, %d frames, file %.1f MB\n", db.clips().size(),
              db.frame_count(), static_cast<double>(fs::file_size(path)) / 1e6);

  const size_t joints = static_cast<size_t>(db.joint_count());
  ASSERT_EQ(back.joint_count(), db.joint_count());
  ASSERT_EQ(back.frame_count(), db.frame_count());
  ASSERT_EQ(back.clips().size(), db.clips().size());
  for (size_t c = 0; c < db.clips().size(); ++c) {
    const ClipRange& clip = db.clips()[c];
    if (c % 100 == 0)
      std::printf("  clip %zu of %zu: %s\n", c, db.clips().size(), clip.name.c_str());
    ASSERT_EQ(back.clips()[c].name, clip.name);
    ASSERT_EQ(back.clips()[c].start, clip.start);
    ASSERT_EQ(back.clips()[c].end, clip.end);
    const size_t first = static_cast<size_t>(clip.start) * joints;
    const size_t count = static_cast<size_t>(clip.frame_count()) * joints;
    // Locals bit for bit (so global positions agree exactly too; checked below on a few frames),
    // and the recomputed velocities the builder's bit for bit (both come from the clip's own
    // frames): the clip's frames of the pose, every joint's four quantities and the padding.
    const size_t floats = static_cast<size_t>(clip.frame_count()) * db.frame_pose_lanes(0).size();
    EXPECT_TRUE(same_bits(back.frame_pose_lanes(clip.start).data(),
                          db.frame_pose_lanes(clip.start).data(), floats))
        << clip.name;
    for (const int f : {clip.start, (clip.start + clip.end) / 2, clip.end - 1}) {
      const std::vector<Transform> a = test::frame_globals(db, f);
      const std::vector<Transform> b = test::frame_globals(back, f);
      for (size_t j = 0; j < joints; ++j) {
        EXPECT_LE(glm::length(a[j].translation - b[j].translation), 1e-6f)
            << clip.name << " frame " << f << " joint " << j;
      }
    }
    // Every angular velocity (four joints at a time where possible) has the bits of the
    // one-sample function: central inside the clip, one-sided at its ends.
    for (int f = 0; f < clip.frame_count(); ++f) {
      const int a = std::max(0, f - 1), b = std::min(clip.frame_count() - 1, f + 1);
      if (a == b) break;
      const float inv_dt = 1.0f / (static_cast<float>(b - a) * back.frame_time());
      for (size_t j = 0; j < joints; ++j) {
        const int joint = static_cast<int>(j);
        const glm::vec3 expected =
            angular_velocity_between(back.local_rotation(clip.start + a, joint),
                                     back.local_rotation(clip.start + b, joint), inv_dt);
        const glm::vec3 got = back.local_angular_velocity(clip.start + f, joint);
        ASSERT_TRUE(same_bits(&got, &expected, 1))
            << clip.name << " frame " << f << " joint " << j << ": " << got.x << " " << got.y << " "
            << got.z << " instead of " << expected.x << " " << expected.y << " " << expected.z;
      }
    }
    // No velocity looks across the boundary: the first and last frames of a clip (of more than
    // one frame) are one-sided differences of the clip's own positions.
    if (clip.frame_count() > 1) {
      const float inv_dt = 1.0f / db.frame_time();
      const auto p = [&](int f, size_t j) {
        return back.local_positions()[static_cast<size_t>(f) * joints + j];
      };
      for (size_t j = 0; j < joints; ++j) {
        EXPECT_EQ(back.local_velocities()[first + j],
                  (p(clip.start + 1, j) - p(clip.start, j)) * inv_dt)
            << clip.name << " joint " << j;
        EXPECT_EQ(back.local_velocities()[first + count - joints + j],
                  (p(clip.end - 1, j) - p(clip.end - 2, j)) * inv_dt)
            << clip.name << " joint " << j;
      }
    }
  }
  test::expect_same_database(back, db);  // and everything else, field by field
  // Saving the loaded database gives the same file.
  EXPECT_EQ(serialize_database(back), serialize_database(db));
}

}  // namespace
}  // namespace mm
