// The test course (mm/world/course.hpp): the shipped data/levels/course.glb is exactly what the
// generator writes, docs/world-levels.md holds its table, and the loaded course has every part
// where the table says (ground probes across it, and sweeps along the lanes).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "course_support.hpp"
#include "mm/database/files.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

const fs::path kShipped = fs::path(MM_SOURCE_DIR) / "data" / "levels" / "course.glb";

BulletWorld shipped_world() {
  return test::course_world(kShipped);
}

using test::probe;
using test::walk;

const CoursePart& part(const std::string& name) {
  static const std::vector<CoursePart> parts = course_parts();
  return test::course_part(parts, name);
}

TEST(Course, TheGeneratorReproducesTheShippedFile) {
  auto shipped = read_whole_file(kShipped, "course");
  ASSERT_TRUE(shipped.ok()) << shipped.message();
  const std::vector<unsigned char> generated = course_glb();
  const std::vector<unsigned char> bytes(
      reinterpret_cast<const unsigned char*>(shipped->data.get()),
      reinterpret_cast<const unsigned char*>(shipped->data.get()) + shipped->size);
  EXPECT_TRUE(bytes == generated)
      << kShipped << " (" << bytes.size() << " bytes) is not what world/src/course.cpp writes ("
      << generated.size() << " bytes): regenerate it with mm-make-course data/levels/course.glb, "
      << "never edit it by hand";
}

TEST(Course, TheDocumentationHoldsTheTable) {
  auto docs = read_whole_file(fs::path(MM_SOURCE_DIR) / "docs" / "world-levels.md");
  ASSERT_TRUE(docs.ok()) << docs.message();
  EXPECT_NE(docs->text().find(course_table()), std::string::npos)
      << "docs/world-levels.md lacks the table mm-make-course prints:\n"
      << course_table();
}

TEST(Course, EveryPartStandsWhereTheTableSays) {
  const BulletWorld world = shipped_world();
  for (const CoursePart& p : course_parts()) {
    // The middle of its footprint is on its top (the turned wall is symmetric about its middle),
    // but for the ground (under the head-on wall there) and the rough patch (whose top is its
    // highest bump).
    if (p.name == "ground" || p.name == "rough") continue;
    const double x = 0.5 * (p.x_range.x + p.x_range.y);
    const double z = 0.5 * (p.z_range.x + p.z_range.y);
    const GroundHit hit = probe(world, x, z);
    ASSERT_TRUE(hit.hit) << p.name;
    EXPECT_NEAR(hit.point.y, p.top, 1e-4) << p.name;
  }
  EXPECT_NEAR(probe(world, -2.5, -2.5).point.y, 0.0, 1e-6);
  EXPECT_NEAR(probe(world, 34.5, 19.5).point.y, 0.0, 1e-6);
  EXPECT_FALSE(probe(world, 36.0, 0.0).hit);  // off the ground
  const CoursePart& rough = part("rough");
  const GroundHit bump = probe(world, 0.5 * (rough.x_range.x + rough.x_range.y),
                               0.5 * (rough.z_range.x + rough.z_range.y));
  EXPECT_GT(bump.point.y, 0.0f);
  EXPECT_LE(bump.point.y, rough.top + 1e-6);
}

TEST(Course, ProbesAcrossTheCourseFollowItsHeight) {
  // Every 0.37 m over the whole ground; points within 2 cm of a step in the surface (an edge
  // of a step, box or wall) are left out, where the ray may meet either side.
  const BulletWorld world = shipped_world();
  const CoursePart& ground = part("ground");
  int probes = 0;
  for (double x = ground.x_range.x + 0.1; x < ground.x_range.y; x += 0.37) {
    for (double z = ground.z_range.x + 0.1; z < ground.z_range.y; z += 0.37) {
      const double h = course_height(x, z);
      bool edge = false;
      for (const auto& [dx, dz] : {std::pair{0.02, 0.0}, std::pair{-0.02, 0.0},
                                   std::pair{0.0, 0.02}, std::pair{0.0, -0.02}}) {
        edge = edge || std::abs(course_height(x + dx, z + dz) - h) > 0.05;
      }
      if (edge) continue;
      const GroundHit hit = probe(world, x, z);
      ASSERT_TRUE(hit.hit) << x << ", " << z;
      EXPECT_NEAR(hit.point.y, h, 1e-4) << "at " << x << ", " << z;
      ++probes;
    }
  }
  EXPECT_GT(probes, 6000);
}

TEST(Course, RampsAreAsSteepAsTheirNames) {
  const BulletWorld world = shipped_world();
  for (const auto& [name, degrees] :
       {std::pair{"ramp_10", 10.0}, std::pair{"ramp_20", 20.0}, std::pair{"ramp_30", 30.0}}) {
    const CoursePart& p = part(name);
    const double x = 0.5 * (p.x_range.x + p.x_range.y);
    const double cosine = std::cos(degrees * std::numbers::pi / 180.0);
    // A third of the way up, and a third of the way down from the far end.
    const double run = 1.0 / std::tan(degrees * std::numbers::pi / 180.0);
    for (const double z : {p.z_range.x + run / 3.0, p.z_range.y - run / 3.0}) {
      const GroundHit hit = probe(world, x, z, 0.7f);
      ASSERT_TRUE(hit.hit) << name;
      EXPECT_NEAR(hit.point.y, 1.0 / 3.0, 1e-4) << name;
      EXPECT_NEAR(hit.normal.y, cosine, 1e-5) << name;
      EXPECT_TRUE(hit.walkable) << name;
      EXPECT_EQ(probe(world, x, z, static_cast<float>(cosine) + 0.01f).walkable, false) << name;
    }
  }
}

TEST(Course, StairsHaveTheirRisers) {
  const BulletWorld world = shipped_world();
  const CoursePart& stairs = part("stairs");
  const double x = 0.5 * (stairs.x_range.x + stairs.x_range.y);
  // The middle of every tread going up, then the landing, then every tread going down.
  const std::vector<double> expected = {0.17, 0.34, 0.51, 0.68, 0.85, 1.02,
                                        0.85, 0.68, 0.51, 0.34, 0.17};
  const std::vector<double> along = {0.15, 0.45, 0.75, 1.05, 1.35, 2.25,
                                     3.15, 3.45, 3.75, 4.05, 4.35};
  for (size_t i = 0; i < expected.size(); ++i) {
    const GroundHit hit = probe(world, x, stairs.z_range.x + along[i]);
    ASSERT_TRUE(hit.hit) << i;
    EXPECT_NEAR(hit.point.y, expected[i], 1e-5) << "tread " << i;
  }
}

TEST(Course, WalksAlongTheLanesMeetWhatTheTableSays) {
  const BulletWorld world = shipped_world();
  // Head-on: the capsule (radius 0.3) stops with its front at the face, z = 8.
  const SweepHit head_on = walk(world, 17.5, 3.0, 12.0);
  ASSERT_TRUE(head_on.hit);
  EXPECT_NEAR(3.0 + head_on.fraction * 9.0, 8.0 - 0.3, 1e-3);
  EXPECT_NEAR(head_on.normal.z, -1.0f, 1e-4f);
  // The turned wall: met at x = 22 where the capsule's axis is 0.3 m from the face (the table
  // gives where the axis crosses the face: z = 7.6), its normal turned 30° from -Z toward +X.
  const SweepHit turned = walk(world, 22.0, 3.0, 12.0);
  ASSERT_TRUE(turned.hit);
  const double angle = 30.0 * std::numbers::pi / 180.0;
  const double meet = 5.0 + 1.5 / std::tan(angle);  // 7.6
  EXPECT_NEAR(3.0 + turned.fraction * 9.0, meet - 0.3 / std::sin(angle), 1e-3);
  EXPECT_NEAR(turned.normal.x, std::cos(angle), 1e-4);
  EXPECT_NEAR(turned.normal.z, -std::sin(angle), 1e-4);
  // The low box is a step under the lifted capsule; the high one stops it at z = 6.
  EXPECT_FALSE(walk(world, 28.0, 3.0, 10.0).hit);
  const SweepHit high = walk(world, 31.0, 3.0, 10.0);
  ASSERT_TRUE(high.hit);
  EXPECT_NEAR(3.0 + high.fraction * 7.0, 6.0 - 0.3, 1e-3);
  // Lanes are clear between their parts: a walk between two lanes meets nothing.
  for (const double x : {2.5, 5.5, 8.5, 11.5, 15.5, 19.6, 26.5, 29.5}) {
    EXPECT_FALSE(walk(world, x, -2.0, 19.0).hit) << "between lanes at x = " << x;
  }
}

}  // namespace
}  // namespace mm
