// An arm swung out of a wall (mm/controller/arm_off_wall.hpp): the smallest turn about the upper
// arm that brings its deepest joint a margin in front of the wall, bones kept their length, the
// joints' rotations turned with them, nothing outside the arm moved.

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "mm/controller/arm_off_wall.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {
namespace {

// A chest (0), its upper arm (1), lower arm (2) and hand (3) straight along +X from (0.2, 1.4,
// 0), and the other upper arm (4) along -X; every rotation identity (the bones along local +X).
std::vector<Transform> straight_arm() {
  std::vector<Transform> globals(5);
  globals[0].translation = {0.0f, 1.4f, 0.0f};
  globals[1].translation = {0.2f, 1.4f, 0.0f};
  globals[2].translation = {0.5f, 1.4f, 0.0f};
  globals[3].translation = {0.75f, 1.4f, 0.0f};
  globals[4].translation = {-0.2f, 1.4f, 0.0f};
  return globals;
}
const std::array<int, 5> kParents = {-1, 0, 1, 2, 0};

TEST(ArmOffWall, TheHandComesToTheMarginAndTheBonesKeepTheirLength) {
  std::vector<Transform> globals = straight_arm();
  // A wall whose face is x = 0.6, facing -X: the hand is 15 cm in, the elbow 10 cm out.
  const WallPlane wall{{0.6f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}};
  const float depth = swing_arm_out_of_wall(globals, kParents, 1, wall, 0.01f);
  EXPECT_NEAR(depth, 0.16f, 1e-5f);
  EXPECT_NEAR(globals[3].translation.x, 0.59f, 1e-4f);
  EXPECT_LT(globals[2].translation.x, 0.59f);
  EXPECT_NEAR(glm::distance(globals[1].translation, globals[2].translation), 0.3f, 1e-5f);
  EXPECT_NEAR(glm::distance(globals[2].translation, globals[3].translation), 0.25f, 1e-5f);
  // The arm turned in a plane through it (the straight arm stays straight): no joint left its
  // height, as the turn about the smallest axis keeps the side the arm was on.
  const glm::vec3 upper = globals[2].translation - globals[1].translation;
  const glm::vec3 lower = globals[3].translation - globals[2].translation;
  EXPECT_NEAR(glm::dot(glm::normalize(upper), glm::normalize(lower)), 1.0f, 1e-5f);
  // The upper arm stayed where it was and its rotation turned with its bone: local +X still
  // points at the elbow. So did the hand's.
  EXPECT_EQ(globals[1].translation, glm::vec3(0.2f, 1.4f, 0.0f));
  EXPECT_NEAR(glm::dot(globals[1].rotation * glm::vec3(1.0f, 0.0f, 0.0f), glm::normalize(upper)),
              1.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(globals[3].rotation * glm::vec3(1.0f, 0.0f, 0.0f), glm::normalize(lower)),
              1.0f, 1e-5f);
  // The chest and the other arm did not move.
  EXPECT_EQ(globals[0].translation, glm::vec3(0.0f, 1.4f, 0.0f));
  EXPECT_EQ(globals[4].translation, glm::vec3(-0.2f, 1.4f, 0.0f));
  EXPECT_EQ(globals[4].rotation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
}

TEST(ArmOffWall, AnArmOutOfTheWallIsLeftAlone) {
  std::vector<Transform> globals = straight_arm();
  const std::vector<Transform> before = globals;
  // The face 2 cm beyond the hand, farther than the margin.
  const WallPlane wall{{0.77f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}};
  EXPECT_EQ(swing_arm_out_of_wall(globals, kParents, 1, wall, 0.01f), 0.0f);
  for (size_t j = 0; j < globals.size(); ++j) {
    EXPECT_EQ(globals[j].translation, before[j].translation) << j;
    EXPECT_EQ(globals[j].rotation, before[j].rotation) << j;
  }
}

TEST(ArmOffWall, AWallAtAnAngleTurnsTheArmAlongItsNormal) {
  std::vector<Transform> globals = straight_arm();
  // A face through (0.55, 1.4, 0) turned 45 degrees: its normal (-1, 0, -1) / sqrt 2.
  const glm::vec3 n = glm::normalize(glm::vec3(-1.0f, 0.0f, -1.0f));
  const WallPlane wall{{0.55f, 1.4f, 0.0f}, n};
  EXPECT_GT(swing_arm_out_of_wall(globals, kParents, 1, wall, 0.01f), 0.0f);
  for (const int j : {2, 3}) {
    EXPECT_GE(glm::dot(globals[static_cast<size_t>(j)].translation - wall.point, n), 0.01f - 1e-4f)
        << j;
  }
  // Out along the normal's side: the hand went toward -Z.
  EXPECT_LT(globals[3].translation.z, 0.0f);
}

TEST(ArmOffWall, AWallNoTurnCanClearTakesTheArmAsFarOutAsItReaches) {
  std::vector<Transform> globals = straight_arm();
  // The face at x = -0.5, farther behind the upper arm (x = 0.2) than the arm is long: the arm
  // ends pointing straight out of the wall, the rest left to the body's push.
  const WallPlane wall{{-0.5f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}};
  EXPECT_GT(swing_arm_out_of_wall(globals, kParents, 1, wall, 0.01f), 0.0f);
  EXPECT_NEAR(globals[3].translation.x, 0.2f - 0.55f, 1e-4f);
  EXPECT_NEAR(globals[2].translation.x, 0.2f - 0.3f, 1e-4f);
}

}  // namespace
}  // namespace mm
