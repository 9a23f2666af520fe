#pragma once
// What the generated courses' tests share (course_test.cpp, course2_test.cpp): a shipped course
// loaded into Bullet, a ground probe and a lane's sweep as the controller makes them, a part of
// a course's table by name.

#include <gtest/gtest.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace mm::test {

// The course at `path` in Bullet (the test fails if it cannot be loaded; an empty world then).
inline BulletWorld course_world(const std::filesystem::path& path) {
  Result<Level> level = load_level(path);
  EXPECT_TRUE(level.ok()) << level.message();
  if (!level) return std::move(BulletWorld::create(Level{})).value();
  Result<BulletWorld> world = BulletWorld::create(*level);
  EXPECT_TRUE(world.ok()) << world.message();
  return std::move(world).value();
}

inline GroundHit probe(const BulletWorld& world, double x, double z,
                       float min_walkable_normal_y = 0.7f) {
  const GroundProbe query{
      {static_cast<float>(x), 3.0f, static_cast<float>(z)}, 4.0f, min_walkable_normal_y};
  GroundHit hit;
  world.probe_ground(glm::dvec3(0.0), std::span(&query, 1), std::span(&hit, 1));
  return hit;
}

// A walk along +Z at x from z0 to z1, as the controller sweeps: lifted 0.35 m.
inline SweepHit walk(const BulletWorld& world, double x, double z0, double z1) {
  const ShapeSweep query{{static_cast<float>(x), 0.35f, static_cast<float>(z0)},
                         {static_cast<float>(x), 0.35f, static_cast<float>(z1)},
                         0.3f,
                         1.7f};
  SweepHit hit;
  world.sweep(glm::dvec3(0.0), std::span(&query, 1), std::span(&hit, 1));
  return hit;
}

// The row of `parts` named `name` (the test fails if there is none; the first row then).
inline const CoursePart& course_part(const std::vector<CoursePart>& parts,
                                     const std::string& name) {
  for (const CoursePart& p : parts) {
    if (p.name == name) return p;
  }
  ADD_FAILURE() << "no part " << name;
  return parts.front();
}

}  // namespace mm::test
