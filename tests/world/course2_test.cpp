// The second test course (mm/world/course.hpp, course2_*): the shipped data/levels/course2.glb is
// exactly what the generator writes, docs/world-levels.md holds its table, and the loaded course
// has every part where the table says (ground probes across it, slopes, treads, and sweeps along
// the lanes into its walls).

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "course_support.hpp"
#include "mm/database/files.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

const fs::path kShipped = fs::path(MM_SOURCE_DIR) / "data" / "levels" / "course2.glb";

BulletWorld shipped_world() {
  return test::course_world(kShipped);
}

using test::probe;
using test::walk;

const CoursePart& part(const std::string& name) {
  static const std::vector<CoursePart> parts = course2_parts();
  return test::course_part(parts, name);
}

double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

TEST(Course2, TheGeneratorReproducesTheShippedFile) {
  auto shipped = read_whole_file(kShipped, "course");
  ASSERT_TRUE(shipped.ok()) << shipped.message();
  const std::vector<unsigned char> generated = course2_glb();
  const std::vector<unsigned char> bytes(
      reinterpret_cast<const unsigned char*>(shipped->data.get()),
      reinterpret_cast<const unsigned char*>(shipped->data.get()) + shipped->size);
  EXPECT_TRUE(bytes == generated)
      << kShipped << " (" << bytes.size() << " bytes) is not what world/src/course2.cpp writes ("
      << generated.size() << " bytes): regenerate it with "
      << "mm-make-course --course 2 data/levels/course2.glb, never edit it by hand";
}

TEST(Course2, TheDocumentationHoldsTheTable) {
  auto docs = read_whole_file(fs::path(MM_SOURCE_DIR) / "docs" / "world-levels.md");
  ASSERT_TRUE(docs.ok()) << docs.message();
  EXPECT_NE(docs->text().find(course2_table()), std::string::npos)
      << "docs/world-levels.md lacks the table mm-make-course --course 2 prints:\n"
      << course2_table();
}

TEST(Course2, ItsNumbersDifferFromTheFirstCourse) {
  // Every part's shape and place differ from the first course's (the ground is flat in both).
  for (const CoursePart& second : course2_parts()) {
    if (second.name == "ground") continue;
    for (const CoursePart& first : course_parts()) {
      if (second.name != "rough") {
        EXPECT_NE(second.name, first.name);
      }
      EXPECT_NE(second.what, first.what) << second.name;
      EXPECT_FALSE(second.x_range == first.x_range && second.z_range == first.z_range)
          << second.name << " lies where the first course's " << first.name << " does";
    }
  }
}

TEST(Course2, ProbesAcrossTheCourseFollowItsHeight) {
  // Every 0.37 m over the whole ground, but within 2 cm of a step in the surface.
  const BulletWorld world = shipped_world();
  const CoursePart& ground = part("ground");
  int probes = 0;
  for (double x = ground.x_range.x + 0.1; x < ground.x_range.y; x += 0.37) {
    for (double z = ground.z_range.x + 0.1; z < ground.z_range.y; z += 0.37) {
      const double h = course2_height(x, z);
      bool edge = false;
      for (const auto& [dx, dz] : {std::pair{0.02, 0.0}, std::pair{-0.02, 0.0},
                                   std::pair{0.0, 0.02}, std::pair{0.0, -0.02}}) {
        edge = edge || std::abs(course2_height(x + dx, z + dz) - h) > 0.05;
      }
      if (edge) continue;
      const GroundHit hit = probe(world, x, z);
      ASSERT_TRUE(hit.hit) << x << ", " << z;
      EXPECT_NEAR(hit.point.y, h, 1e-4) << "at " << x << ", " << z;
      ++probes;
    }
  }
  EXPECT_GT(probes, 5500);
}

TEST(Course2, RampsAndTheCrossSlopeAreAsSteepAsTheirNames) {
  const BulletWorld world = shipped_world();
  // Up a third of the rise from the foot of each side: 0.8 m rises.
  for (const auto& [name, degrees] : {std::pair{"ramp_15", 15.0}, std::pair{"ramp_25", 25.0}}) {
    const CoursePart& p = part(name);
    const double x = 0.5 * (p.x_range.x + p.x_range.y);
    const double run = 0.8 / std::tan(radians(degrees));
    for (const double z : {p.z_range.x + run / 3.0, p.z_range.y - run / 3.0}) {
      const GroundHit hit = probe(world, x, z);
      ASSERT_TRUE(hit.hit) << name;
      EXPECT_NEAR(hit.point.y, 0.8 / 3.0, 1e-4) << name;
      EXPECT_NEAR(hit.normal.y, std::cos(radians(degrees)), 1e-5) << name;
    }
  }
  // Down from the 0.7 m platform's edge at z = 4: a third of the way down.
  const double run = 0.7 / std::tan(radians(20.0));
  const GroundHit down = probe(world, 6.0, 4.0 + run / 3.0);
  EXPECT_NEAR(down.point.y, 0.7 * 2.0 / 3.0, 1e-4);
  EXPECT_NEAR(down.normal.z, std::sin(radians(20.0)), 1e-5);  // facing the walk down
  EXPECT_NEAR(probe(world, 6.0, 2.0).point.y, 0.7, 1e-5);     // the lane starts on top
  // Across the slope: the walk's lane at mid-width, the normal leaning toward -X.
  const GroundHit across = probe(world, 42.15, 5.0);
  EXPECT_NEAR(across.point.y, 1.5 * std::tan(radians(12.0)), 1e-4);
  EXPECT_NEAR(across.normal.x, -std::sin(radians(12.0)), 1e-4);
  EXPECT_NEAR(across.normal.z, 0.0, 1e-4);
}

TEST(Course2, StairsHaveTheirRisers) {
  const BulletWorld world = shipped_world();
  struct Expected {
    const char* name;
    std::vector<double> along;  // from the lane's start at z = 2 (stairs_down: from z = 0)
    std::vector<double> height;
  };
  const std::vector<Expected> all = {
      {"stairs_12_35",
       {0.175, 0.525, 0.875, 1.225, 2.0, 2.775, 3.125, 3.475, 3.825, 4.2},
       {0.12, 0.24, 0.36, 0.48, 0.6, 0.48, 0.36, 0.24, 0.12, 0.0}},
      {"stairs_20_25",
       {0.125, 0.375, 0.625, 1.25, 1.875, 2.125, 2.375, 2.625},
       {0.2, 0.4, 0.6, 0.8, 0.6, 0.4, 0.2, 0.0}},
      {"stairs_down", {3.0, 4.14, 4.42, 4.7, 4.98}, {0.64, 0.48, 0.32, 0.16, 0.0}},
  };
  for (const Expected& e : all) {
    const CoursePart& p = part(e.name);
    const double x = 0.5 * (p.x_range.x + p.x_range.y);
    const double z0 = std::string(e.name) == "stairs_down" ? 0.0 : 2.0;
    for (size_t i = 0; i < e.along.size(); ++i) {
      const GroundHit hit = probe(world, x, z0 + e.along[i]);
      ASSERT_TRUE(hit.hit) << e.name << " " << i;
      EXPECT_NEAR(hit.point.y, e.height[i], 1e-5) << e.name << " tread " << i;
    }
  }
}

TEST(Course2, WalksAlongTheLanesMeetWhatTheTableSays) {
  const BulletWorld world = shipped_world();
  // The turned walls: the capsule (radius 0.3) stops 0.3 m before the face along its normal.
  for (const auto& [x, start_x, degrees] :
       {std::tuple{21.2, 20.2, 45.0}, std::tuple{25.8, 24.8, 60.0}}) {
    const SweepHit hit = walk(world, x, 2.0, 12.0);
    ASSERT_TRUE(hit.hit) << degrees;
    const double angle = radians(degrees);
    const double meet = 4.0 + (x - start_x) / std::tan(angle);
    EXPECT_NEAR(2.0 + hit.fraction * 10.0, meet - 0.3 / std::sin(angle), 1e-3) << degrees;
    EXPECT_NEAR(hit.normal.x, std::cos(angle), 1e-4) << degrees;
    EXPECT_NEAR(hit.normal.z, -std::sin(angle), 1e-4) << degrees;
  }
  // The corner: its lane passes 0.2 m clear of the side wall and meets the far wall at z = 7.
  const SweepHit corner = walk(world, 31.3, 2.0, 12.0);
  ASSERT_TRUE(corner.hit);
  EXPECT_NEAR(2.0 + corner.fraction * 10.0, 7.0 - 0.3, 1e-3);
  EXPECT_NEAR(corner.normal.z, -1.0f, 1e-4f);
  // A step to the side from the corner's lane meets the side wall, facing -X.
  const ShapeSweep sideways{{31.3f, 0.35f, 5.0f}, {32.5f, 0.35f, 5.0f}, 0.3f, 1.7f};
  SweepHit side;
  world.sweep(glm::dvec3(0.0), std::span(&sideways, 1), std::span(&side, 1));
  ASSERT_TRUE(side.hit);
  EXPECT_NEAR(31.3 + side.fraction * 1.2, 31.8 - 0.3, 1e-3);
  EXPECT_NEAR(side.normal.x, -1.0f, 1e-4f);
  // The corridor is 1 m wide: its lane runs through, a capsule of 0.55 m does not fit.
  EXPECT_FALSE(walk(world, 33.75, 2.0, 12.0).hit);
  const ShapeSweep wide{{33.75f, 0.35f, 1.0f}, {33.75f, 0.35f, 5.0f}, 0.55f, 1.7f};
  SweepHit wide_hit;
  world.sweep(glm::dvec3(0.0), std::span(&wide, 1), std::span(&wide_hit, 1));
  EXPECT_TRUE(wide_hit.hit);
  // The kerb is a step under the lifted capsule.
  EXPECT_FALSE(walk(world, 36.45, 2.0, 10.0).hit);
  // Lanes are clear between their parts.
  for (const double x :
       {2.1, 4.7, 7.3, 10.1, 12.9, 15.7, 19.35, 24.2, 28.8, 32.55, 34.95, 37.95, 40.15, 44.3}) {
    EXPECT_FALSE(walk(world, x, -1.9, 15.9).hit) << "between lanes at x = " << x;
  }
}

}  // namespace
}  // namespace mm
