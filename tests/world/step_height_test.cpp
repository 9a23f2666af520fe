// The step height against a real physics engine (character_mover.hpp, docs/world.md "The
// moves"): a box exactly step_height high, whose top Bullet's sweep meets within millimetres of
// the lifted capsule's bottom, is climbed like any lower step; a higher one is slid along. Read
// as a wall head-on, the 0.35 m box of the second course stalled the character at its edge for
// seconds (strafe at 1/60 s: 5.6 s stuck).

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../controller/controller_support.hpp"
#include "level_builder.hpp"
#include "mm/controller/character_mover.hpp"
#include "mm/controller/controller.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/level.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;
// The box's footprint: x in [-0.6, 0.6], z in [kBoxNear, kBoxFar].
constexpr float kBoxNear = 5.0f;
constexpr float kBoxFar = 6.2f;

// A floor and one box of `top` (m) standing on it, as a level's triangles (the courses' boxes are
// meshes, not Bullet boxes).
BulletWorld box_world(float top) {
  test::LevelBuilder b;
  b.floor(20.0f);
  b.box({-0.6f, 0.0f, kBoxNear}, {0.6f, top, kBoxFar});
  Result<BulletWorld> world = BulletWorld::create(b.level);
  EXPECT_TRUE(world.ok()) << world.message();
  return std::move(world).value();
}

bool over_box(const glm::vec3& p) {
  return std::abs(p.x) < 0.6f && p.z > kBoxNear && p.z < kBoxFar;
}

constexpr float kSpeed = 1.4f;  // m/s

// The capsule walked at kSpeed toward yaw `degrees` from +Z, one move per 1/60 s, from 3 m before
// the box's centre, aimed at it: every move's result.
std::vector<MoveResult> walk_at(const BulletWorld& world, float degrees, float seconds) {
  CharacterMover mover;
  const CharacterShape shape;  // radius 0.3, step_height 0.35
  const float yaw = glm::radians(degrees);
  const glm::vec3 direction(std::sin(yaw), 0.0f, std::cos(yaw));
  const glm::vec3 step = kSpeed * kDt * direction;
  glm::vec3 at = glm::vec3(0.0f, 0.0f, 0.5f * (kBoxNear + kBoxFar)) - 3.0f * direction;
  std::vector<MoveResult> moves;
  for (int f = 0; f < static_cast<int>(seconds / kDt); ++f) {
    moves.push_back(mover.move(world, glm::dvec3(0.0), shape, at, at + step));
    at = moves.back().position;
  }
  EXPECT_EQ(mover.rejected(), 0);
  return moves;
}

TEST(StepHeight, ABoxUpToTheStepHeightIsClimbedNeverAWall) {
  // Lower than the step, exactly the step, and the millimetres above it where Bullet's sweep
  // still meets the top at the capsule's bottom.
  for (const float top : {0.3f, 0.35f, 0.352f}) {
    const BulletWorld world = box_world(top);
    for (const float degrees : {0.0f, 30.0f, 60.0f}) {
      const std::vector<MoveResult> moves = walk_at(world, degrees, 3.0f);
      int on_top = 0;
      for (size_t f = 0; f < moves.size(); ++f) {
        const MoveResult& m = moves[f];
        ASSERT_FALSE(m.blocked) << "top " << top << " at " << degrees << "°, move " << f;
        ASSERT_FALSE(m.no_ground) << "top " << top << " at " << degrees << "°, move " << f;
        if (over_box(m.position)) {
          EXPECT_NEAR(m.position.y, top, 1e-4f) << "top " << top << " at " << degrees << "°";
          ++on_top;
        } else {
          EXPECT_NEAR(m.position.y, 0.0f, 1e-4f) << "top " << top << " at " << degrees << "°";
        }
      }
      // Every move went the whole way: from 3 m before the box's centre to past its far side.
      const float yaw = glm::radians(degrees);
      const glm::vec3 start = glm::vec3(0.0f, 0.0f, 0.5f * (kBoxNear + kBoxFar)) -
                              3.0f * glm::vec3(std::sin(yaw), 0.0f, std::cos(yaw));
      const glm::vec3 end = moves.back().position;
      EXPECT_NEAR(std::hypot(end.x - start.x, end.z - start.z),
                  kSpeed * kDt * static_cast<float>(moves.size()), 0.01f)
          << "top " << top << " at " << degrees << "°";
      EXPECT_GT(on_top, 10) << "top " << top << " at " << degrees << "°";
    }
  }
}

TEST(StepHeight, ABoxHigherThanTheStepIsSlidAlong) {
  // A centimetre and more above the step the sweep meets the box's edge up the capsule's lower
  // hemisphere: a wall. Met at 30° from head-on, the capsule keeps moving along it.
  for (const float top : {0.37f, 0.45f}) {
    const BulletWorld world = box_world(top);
    const std::vector<MoveResult> moves = walk_at(world, 30.0f, 3.0f);
    int blocked = 0;
    for (size_t f = 1; f < moves.size(); ++f) {
      const MoveResult& m = moves[f];
      ASSERT_FALSE(over_box(m.position)) << "top " << top << ", move " << f;
      EXPECT_NEAR(m.position.y, 0.0f, 1e-4f) << "top " << top;
      // Along the face (+X) at no less than 80% of the move's part along it.
      EXPECT_GT(m.position.x - moves[f - 1].position.x,
                0.8f * kSpeed * kDt * std::sin(glm::radians(30.0f)))
          << "top " << top << ", move " << f;
      if (m.blocked) {
        ++blocked;
        EXPECT_NEAR(m.normal.z, -1.0f, 1e-3f) << "top " << top;
      }
    }
    EXPECT_GT(blocked, 10) << "top " << top;
  }
}

// The controller on the normal database, pushed at 30° from head-on toward a box exactly its
// step height high (the second course's box_35): it climbs on and walks over, never standing
// still at the edge.
TEST(StepHeight, TheControllerWalksOverABoxAsHighAsItsStep) {
  const BulletWorld world = box_world(0.35f);
  Controller c = test::make_controller();
  c.set_world(&world);
  c.teleport_world(glm::dvec3(-1.5, 0.0, 2.5), 0.0f);
  int still = 0, longest_still = 0;
  float highest = 0.0f;
  glm::vec3 before(c.simulation_position_world());
  // 8 s: the walk slows to step onto the box (climb_pace.hpp).
  for (int f = 0; f < static_cast<int>(8.0f / kDt); ++f) {
    c.update(kDt, test::push_toward(30.0f));
    const glm::vec3 now(c.simulation_position_world());
    still = test::horizontal_speed(now, before, kDt) < 0.05f && f > 30 ? still + 1 : 0;
    longest_still = std::max(longest_still, still);
    if (over_box(now)) highest = std::max(highest, now.y);
    before = now;
  }
  EXPECT_LT(longest_still, 3);
  EXPECT_NEAR(highest, 0.35f, 1e-4f);
  // Past the box, back on the floor.
  EXPECT_GT(before.z, kBoxFar);
  EXPECT_NEAR(before.y, 0.0f, 1e-4f);
}

}  // namespace
}  // namespace mm
