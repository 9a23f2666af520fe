// Sliding along a wall the capsule touches, against a real physics engine (character_mover.hpp,
// docs/world.md "The moves"): stopped kSkin short along a move that met the face at a glancing
// angle, the capsule is left nearly touching it, and Bullet's sweep along the face from there
// meets the face where it starts. Swept from there, the slide stopped at once: off the lanes the
// character stood pushed along the second course's 60° wall for 0.85 s.

#include <gtest/gtest.h>

#include <vector>

#include "level_builder.hpp"
#include "mm/controller/character_mover.hpp"
#include "mm/world/bullet_world.hpp"

namespace mm {
namespace {

TEST(MoverSlide, AlongAWallItTouchesTheCapsuleSlides) {
  // A wall whose face is the plane z = 5, the capsule's side half a millimetre from it.
  test::LevelBuilder b;
  b.floor(20.0f);
  b.box({-10.0f, 0.0f, 5.0f}, {10.0f, 2.0f, 5.3f});
  Result<BulletWorld> world = BulletWorld::create(b.level);
  ASSERT_TRUE(world.ok()) << world.message();
  CharacterMover mover;
  const CharacterShape shape;
  glm::vec3 at(0.0f, 0.0f, 5.0f - shape.radius - 5e-4f);
  // Pushed along the wall (-X) and a little into it, 4 mm a move (0.6 m/s at 1/144 s).
  const glm::vec3 step(-4e-3f, 0.0f, 5e-4f);
  for (int move = 0; move < 100; ++move) {
    const MoveResult m = mover.move(*world, glm::dvec3(0.0), shape, at, at + step);
    // Every move slides on by nearly the whole of its part along the wall.
    ASSERT_LT(m.position.x - at.x, -0.9f * 4e-3f) << "move " << move;
    // And never into it.
    ASSERT_LE(m.position.z, 5.0f - shape.radius) << "move " << move;
    at = m.position;
  }
}

}  // namespace
}  // namespace mm
