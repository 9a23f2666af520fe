// A ledge's edge beside the capsule, against a real physics engine (character_mover.hpp,
// docs/world.md "The moves"): on a platform 0.64 m high (the second course's `stairs_down`), a move
// along its side edge or slanting toward it keeps the capsule's centre a radius from the edge and
// goes on along it; a move away from the edge is never held back. With the probe ahead only, a
// character circling on the platform ran with its centre a few centimetres from the side edge, one
// foot planted on air.

#include <gtest/gtest.h>

#include <cmath>

#include "level_builder.hpp"
#include "mm/controller/character_mover.hpp"
#include "mm/world/bullet_world.hpp"

namespace mm {
namespace {

constexpr float kPlatformHeight = 0.64f;
constexpr float kSideEdge = 1.0f;  // the platform's side face is the plane x = 1

Result<BulletWorld> platform_world() {
  test::LevelBuilder b;
  b.floor(20.0f);
  b.box({-1.0f, 0.0f, -5.0f}, {kSideEdge, kPlatformHeight, 5.0f});
  return BulletWorld::create(b.level);
}

TEST(LedgeEdge, AlongThePlatformsSideEdgeTheCentreStaysARadiusBackAndMovesOn) {
  Result<BulletWorld> world = platform_world();
  ASSERT_TRUE(world.ok()) << world.message();
  CharacterMover mover;
  const CharacterShape shape;
  // From the platform's middle, slanting toward the side edge (22 degrees off it), 2 cm a move.
  glm::vec3 at(0.0f, kPlatformHeight, -4.0f);
  const glm::vec3 step(0.0075f, 0.0f, 0.0185f);
  int held = 0;
  for (int move = 0; move < 300; ++move) {
    const MoveResult m = mover.move(*world, glm::dvec3(0.0), shape, at, at + step);
    ASSERT_FALSE(m.no_ground) << "move " << move;
    // Never nearer the edge than a radius, always on the platform's top.
    ASSERT_LE(m.position.x, kSideEdge - shape.radius) << "move " << move;
    ASSERT_NEAR(m.position.y, kPlatformHeight, 1e-3f) << "move " << move;
    // The part along the edge is never held back.
    ASSERT_NEAR(m.position.z - at.z, step.z, 1e-4f) << "move " << move;
    held += m.edge ? 1 : 0;
    at = m.position;
  }
  EXPECT_GT(held, 0);  // it did reach the edge
  EXPECT_GT(at.x, kSideEdge - 1.1f * shape.radius);
}

TEST(LedgeEdge, AwayFromThePlatformsSideEdgeNothingIsHeldBack) {
  Result<BulletWorld> world = platform_world();
  ASSERT_TRUE(world.ok()) << world.message();
  CharacterMover mover;
  const CharacterShape shape;
  // A radius from the edge, every direction with no part toward it goes the whole way.
  const glm::vec3 at(kSideEdge - shape.radius, kPlatformHeight, 0.0f);
  for (int k = 0; k <= 8; ++k) {
    const float angle = glm::radians(90.0f + 22.5f * static_cast<float>(k));  // +z round to -z
    const glm::vec3 step(0.02f * std::cos(angle), 0.0f, 0.02f * std::sin(angle));
    const MoveResult m = mover.move(*world, glm::dvec3(0.0), shape, at, at + step);
    EXPECT_FALSE(m.blocked || m.no_ground) << "angle " << k;
    EXPECT_NEAR(m.position.x, at.x + step.x, 1e-4f) << "angle " << k;
    EXPECT_NEAR(m.position.z, at.z + step.z, 1e-4f) << "angle " << k;
    // And the edge is known, for the trajectory.
    EXPECT_LT(m.edge_normal.x, -0.9f) << "angle " << k;
  }
}

}  // namespace
}  // namespace mm
