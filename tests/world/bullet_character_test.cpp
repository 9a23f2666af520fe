// The game-owned mode (docs/world.md, "A game that owns its capsule") with a real physics
// engine: a Bullet kinematic character controller (BulletCharacters,
// mm/world/bullet_character.hpp) walks a capsule on the shipped course, driven by the
// controller's simulation object, and hands its resolved position back every frame. The
// controller is given no world unless a test says so: all it knows of the course comes from the
// capsule.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../controller/controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/world/bullet_character.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace mm {
namespace {

using test::make_controller;
using test::push_toward;

constexpr float kDt = 1.0f / 60.0f;
constexpr double kRadius = 0.3;  // CapsuleSettings' default, the controller's character_radius

Level course_level() {
  const std::vector<unsigned char> glb = course_glb();
  Result<Level> level = parse_level(glb, "course.glb", {.allow_external_files = false});
  EXPECT_TRUE(level.ok()) << level.message();
  return std::move(level).value();
}

// What each frame of a walk saw.
struct Walk {
  std::vector<glm::dvec3> capsule;  // the capsule's feet after Bullet's move
  std::vector<glm::vec3> root;      // the animated root after the hand-back
  std::vector<float> hips_y;
  glm::vec3 final_velocity{0.0f};
  float clamp_max_distance = 0.0f;
};

// One character walked from (x, 0) with the stick held toward +Z for `seconds`, its capsule
// moved by Bullet every frame. With `world`, the controller also collides its prediction and
// root with it (both integrations combined).
Walk walk_lane(double x, float seconds, const WorldQueries* world = nullptr) {
  Result<BulletCharacters> physics = BulletCharacters::create(course_level());
  EXPECT_TRUE(physics.ok()) << physics.message();
  Controller c = make_controller();
  c.set_world(world);
  c.teleport_world(glm::dvec3(x, 0.0, 0.0), 0.0f);
  Result<size_t> capsule = physics->add(c.simulation_position_world());
  EXPECT_TRUE(capsule.ok()) << capsule.message();
  const size_t hips = static_cast<size_t>(c.controller_database().database().roles().hips);
  Walk walk;
  walk.clamp_max_distance = c.settings().clamp_max_distance;
  for (int f = 0; f < static_cast<int>(seconds / kDt); ++f) {
    c.update(kDt, push_toward(0.0f));
    const glm::dvec3 resolved = physics->move(*capsule, c.simulation_position_world(), kDt);
    c.set_simulation_position_world(resolved);
    walk.capsule.push_back(resolved);
    walk.root.push_back(c.root_transform().translation);
    walk.hips_y.push_back(c.global_transforms()[hips].translation.y);
  }
  walk.final_velocity = c.simulation_velocity();
  return walk;
}

double horizontal_distance(const glm::vec3& a, const glm::dvec3& b) {
  return std::hypot(a.x - b.x, a.z - b.z);
}

float largest_frame_step(const std::vector<float>& values) {
  float largest = 0.0f;
  for (size_t f = 1; f < values.size(); ++f) {
    largest = std::max(largest, std::abs(values[f] - values[f - 1]));
  }
  return largest;
}

// The highest point of the course's surface within `radius` of (x, z) (sampled every 2.5 cm):
// what a capsule's rounded bottom may rest on, at a step's edge.
double highest_surface_within(double x, double z, double radius) {
  double highest = course_height(x, z);
  constexpr int kSteps = 12;
  for (int i = -kSteps; i <= kSteps; ++i) {
    for (int j = -kSteps; j <= kSteps; ++j) {
      const double dx = radius * i / kSteps;
      const double dz = radius * j / kSteps;
      if (dx * dx + dz * dz <= radius * radius) {
        highest = std::max(highest, course_height(x + dx, z + dz));
      }
    }
  }
  return highest;
}

// Every frame: the capsule stands on the course's surface (never below the surface under it,
// never above the highest point under its footprint but by a slope's rounding of its bottom, 2
// cm at 20°), and the animated root is within the controller's clamping distance of it.
void expect_on_surface_and_clamped(const Walk& walk) {
  for (size_t f = 0; f < walk.capsule.size(); ++f) {
    const glm::dvec3& p = walk.capsule[f];
    ASSERT_GT(p.y, course_height(p.x, p.z) - 0.01) << "frame " << f << " at z " << p.z;
    ASSERT_LT(p.y, highest_surface_within(p.x, p.z, kRadius) + 0.03)
        << "frame " << f << " at z " << p.z;
    ASSERT_LE(horizontal_distance(walk.root[f], p), walk.clamp_max_distance + 1e-3) << f;
  }
}

TEST(BulletCharacter, TheCapsuleClimbsTheStairsAndTheBodyRisesWithoutPopping) {
  const Walk walk = walk_lane(10.0, 10.0f);  // the stairs' lane: up 6 risers, landing, down 6
  expect_on_surface_and_clamped(walk);
  double top = 0.0;
  for (const glm::dvec3& p : walk.capsule) top = std::max(top, p.y);
  EXPECT_NEAR(top, 1.02, 0.01);  // stood on the landing
  // Over the stairs and down them: back on the ground past their end (z = 7.5).
  EXPECT_GT(walk.capsule.back().z, 8.0);
  EXPECT_NEAR(walk.capsule.back().y, 0.0, 0.01);
  // Bullet steps the capsule up a riser (17 cm) in one frame; the body's spring spreads it.
  EXPECT_LT(largest_frame_step(walk.hips_y), 0.05f);
}

TEST(BulletCharacter, TheCapsuleWalksUpAndDownTheRamp) {
  const Walk walk = walk_lane(4.0, 12.0f);  // the 20° ramp: up, a 1 m plateau, down
  expect_on_surface_and_clamped(walk);
  double top = 0.0;
  for (const glm::dvec3& p : walk.capsule) top = std::max(top, p.y);
  EXPECT_NEAR(top, 1.0, 0.01);
  EXPECT_GT(walk.capsule.back().z, 10.49);  // past the ramp's foot
  EXPECT_LT(largest_frame_step(walk.hips_y), 0.05f);
}

TEST(BulletCharacter, TheCapsuleStopsAtAWallHeadOnAndTheSimulationStopsPushing) {
  const Walk walk = walk_lane(17.5, 10.0f);  // into the wall whose face is at z = 8
  expect_on_surface_and_clamped(walk);
  double deepest = -1.0;
  for (const glm::dvec3& p : walk.capsule) deepest = std::max(deepest, p.z);
  EXPECT_LE(deepest, 8.0 - kRadius + 1e-3);                // never into the wall
  EXPECT_GT(walk.capsule.back().z, 8.0 - kRadius - 0.02);  // but right at it
  // What Bullet refused was taken out of the simulation's velocity: it stands.
  EXPECT_LT(std::abs(walk.final_velocity.z), 0.05f);
}

TEST(BulletCharacter, TheCapsuleSlidesAlongAWallMetAtAnAngle) {
  const Walk walk = walk_lane(22.0, 14.0f);  // meets the wall turned 30° at z = 7.6
  expect_on_surface_and_clamped(walk);
  // The wall's face runs from (20.5, 5) to (23.5, 10.2): the capsule never came nearer to it than
  // its radius (less the few millimetres short of the contact Bullet's sweeps stop).
  const glm::dvec2 a(20.5, 5.0);
  const glm::dvec2 b(23.5, 10.2);
  for (const glm::dvec3& p : walk.capsule) {
    const glm::dvec2 q(p.x, p.z);
    const double t = std::clamp(glm::dot(q - a, b - a) / glm::dot(b - a, b - a), 0.0, 1.0);
    ASSERT_GE(glm::distance(q, a + t * (b - a)), kRadius - 0.005) << p.z;
  }
  // It kept walking along the wall (toward +X and +Z) instead of sticking where it met it.
  EXPECT_GT(walk.capsule.back().x, 22.0 + 0.5);
  EXPECT_GT(walk.capsule.back().z, 7.6 + 0.8);
  EXPECT_GT(glm::length(glm::vec2(walk.final_velocity.x, walk.final_velocity.z)), 0.5f);
}

// The game's capsule alone stops the character; the animation, predicted without the wall,
// walks on in place and its root leans up to the clamping distance into the wall. Giving the
// controller the world as well (its prediction and root swept) keeps the root out of it.
TEST(BulletCharacter, WithTheWorldAlsoGivenTheRootStaysOutOfTheWall) {
  Result<BulletWorld> world = BulletWorld::create(course_level());
  ASSERT_TRUE(world.ok()) << world.message();
  const Walk alone = walk_lane(17.5, 10.0f);
  const Walk combined = walk_lane(17.5, 10.0f, &*world);
  expect_on_surface_and_clamped(combined);
  float alone_deepest = -1.0f;
  float combined_deepest = -1.0f;
  for (const glm::vec3& r : alone.root) alone_deepest = std::max(alone_deepest, r.z);
  for (const glm::vec3& r : combined.root) combined_deepest = std::max(combined_deepest, r.z);
  EXPECT_GT(alone_deepest, 8.0f - static_cast<float>(kRadius) + 0.1f);
  EXPECT_LE(combined_deepest, 8.0f - static_cast<float>(kRadius) + 0.01f);
}

TEST(BulletCharacter, BadCapsulesAndLevelsAreRefusedByMessage) {
  Result<BulletCharacters> empty = BulletCharacters::create(Level{});
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.message(), "the level has no triangles to walk on");
  Result<BulletCharacters> physics = BulletCharacters::create(course_level());
  ASSERT_TRUE(physics.ok()) << physics.message();
  Result<size_t> thin = physics->add(glm::dvec3(0.0), {.radius = 0.5f, .height = 0.9f});
  ASSERT_FALSE(thin.ok());
  EXPECT_EQ(thin.message(), "capsule: the height must be at least twice the radius");
  Result<size_t> nan = physics->add(glm::dvec3(std::nan(""), 0.0, 0.0));
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.message(),
            "capsule: the feet must be finite and within ±100000 m of the world origin");
  Result<size_t> no_gravity = physics->add(glm::dvec3(0.0), {.gravity = 0.0f});
  ASSERT_FALSE(no_gravity.ok());
  EXPECT_EQ(no_gravity.message(),
            "capsule: radius, height, step height, max slope and gravity must be finite and "
            "positive");
  EXPECT_EQ(physics->size(), 0u);
  // A goal that is not finite moves nothing.
  Result<size_t> one = physics->add(glm::dvec3(1.0, 0.0, 0.0));
  ASSERT_TRUE(one.ok());
  const glm::dvec3 stood = physics->move(*one, glm::dvec3(1.0, 0.0, 0.0), kDt);
  const glm::dvec3 after = physics->move(*one, glm::dvec3(INFINITY, 0.0, 0.0), kDt);
  EXPECT_EQ(after.x, stood.x);
  EXPECT_EQ(after.z, stood.z);
  EXPECT_NEAR(after.y, stood.y, 1e-6);
  EXPECT_TRUE(physics->on_ground(*one));
}

}  // namespace
}  // namespace mm
