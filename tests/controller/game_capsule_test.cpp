// A game that owns the character's capsule (docs/world.md): it moves the capsule toward where
// the controller's simulation object went (simulation_position_world()) with its own physics
// and hands the resolved position back (Controller::set_simulation_position_world). Here the
// "physics" is a stand-in that keeps the capsule out of a wall and puts it on a staircase;
// tests/world/ drives a Bullet capsule.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"

namespace mm {
namespace {

using test::make_controller;
using test::push_toward;

constexpr float kDt = 1.0f / 60.0f;

// The stand-in for a game's character controller: moves the capsule toward `goal` (x and z),
// stops it `radius` short of a wall at z = 5, and stands it on stairs of 17 cm risers from z = 2.
glm::dvec3 game_physics(const glm::dvec3& capsule, const glm::dvec3& goal) {
  glm::dvec3 next(goal.x, capsule.y, goal.z);
  next.z = std::min(next.z, 5.0 - 0.3);
  next.y = next.z < 2.0 ? 0.0 : 0.17 * std::floor((next.z - 2.0) / 0.3 + 1.0);
  return next;
}

TEST(GameCapsule, TheCharacterFollowsTheGamesCapsuleUpStairsAndStopsAtItsWall) {
  Controller c = make_controller();
  glm::dvec3 capsule = c.simulation_position_world();
  std::vector<float> hips;
  const Database& db = c.controller_database().database();
  for (int f = 0; f < 8 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    capsule = game_physics(capsule, c.simulation_position_world());
    c.set_simulation_position_world(capsule);
    ASSERT_LT(glm::length(c.simulation_position_world() - capsule), 1e-6) << f;
    hips.push_back(c.global_transforms()[static_cast<size_t>(db.roles().hips)].translation.y);
  }
  // The capsule reached the wall; the controller's simulation stopped pushing into it (its
  // velocity into the wall taken away), and the character stands within the clamp of it.
  EXPECT_NEAR(capsule.z, 4.7, 1e-6);
  EXPECT_LT(std::abs(c.simulation_velocity().z), 0.05f);
  EXPECT_LT(c.root_transform().translation.z, 4.7f + c.settings().clamp_max_distance + 1e-3f);
  // Up the stairs the body rose with the capsule, and never by a riser in one frame.
  EXPECT_NEAR(c.debug().ground_height, capsule.y, 0.02);
  EXPECT_GT(capsule.y, 1.0);
  float largest_step = 0.0f;
  for (size_t f = 1; f < hips.size(); ++f) {
    largest_step = std::max(largest_step, std::abs(hips[f] - hips[f - 1]));
  }
  EXPECT_LT(largest_step, 0.05f);
}

// A game that moves its capsule in one frame, again and again (a teleport of its own, a push):
// the displayed root is pulled within reach of the capsule at once, the held feet following, in
// an update of no time. Nothing a foot works out per second may divide by that time: the held
// toe's rate and its heel's rise did, and the joints went to NaN for good.
TEST(GameCapsule, ACapsuleMovedFarInOneFrameLeavesEveryJointFinite) {
  Controller c = make_controller();
  for (int f = 0; f < 90; ++f) c.update(kDt, push_toward(0.0f));
  for (int jump = 0; jump < 12; ++jump) {
    const glm::dvec3 capsule =
        c.simulation_position_world() + glm::dvec3(0.1 * (jump + 1), 0.0, -0.15 * jump);
    c.set_simulation_position_world(capsule);
    for (int f = 0; f < 30; ++f) {
      c.update(kDt, push_toward(0.0f));
      for (const Transform& t : c.global_transforms()) {
        ASSERT_TRUE(std::isfinite(t.translation.x) && std::isfinite(t.translation.y) &&
                    std::isfinite(t.translation.z))
            << jump << " " << f;
      }
    }
  }
}

TEST(GameCapsule, ANonFinitePositionIsIgnored) {
  Controller c = make_controller();
  for (int f = 0; f < 30; ++f) c.update(kDt, push_toward(90.0f));
  const glm::dvec3 before = c.simulation_position_world();
  c.set_simulation_position_world(glm::dvec3(std::nan(""), 0.0, 1.0));
  c.set_simulation_position(glm::vec3(1.0f, INFINITY, 0.0f));
  EXPECT_EQ(c.simulation_position_world(), before);
  c.update(kDt, push_toward(90.0f));
  EXPECT_TRUE(std::isfinite(c.root_transform().translation.x));
}

}  // namespace
}  // namespace mm
