// How far a leg reaches (leg_reach.hpp): the softened reach, and a foot reaching down to ground
// below the body's that falls short below the point it reaches for, not back toward the hip.

#include <gtest/gtest.h>

#include <cmath>

#include <glm/glm.hpp>

#include "mm/controller/leg_reach.hpp"

namespace mm {
namespace {

constexpr float kLength = 0.9f;  // a leg's upper plus lower length (m)

void expect_near(const glm::vec3& a, const glm::vec3& b, float tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(LegReach, WithinTheSoftReachTheTargetIsKept) {
  const glm::vec3 target(0.1f, -0.8f, 0.2f);  // 0.83 m of a 0.9 m leg: under kSoftReach
  expect_near(soft_reach(target, 0.8f, 0.0f, kLength), target, 1e-6f);
}

// Beyond it the reach approaches the leg's length along the hip-to-target line, never past it,
// and the farther the target the farther the reach.
TEST(LegReach, BeyondTheSoftReachTheLegFallsShortAlongTheLine) {
  const glm::vec3 near(0.0f, -0.88f, 0.1f), far(0.0f, -1.2f, 0.1f);
  const glm::vec3 a = soft_reach(near, 0.8f, 0.0f, kLength);
  const glm::vec3 b = soft_reach(far, 0.8f, 0.0f, kLength);
  EXPECT_LT(glm::length(a), glm::length(near));
  EXPECT_GT(glm::length(a), kSoftReach * kLength);
  EXPECT_LT(glm::length(b), kLength);
  EXPECT_GT(glm::length(b), glm::length(a));
  EXPECT_NEAR(glm::dot(glm::normalize(b), glm::normalize(far)), 1.0f, 1e-6f);
  // Standing, the animation's own straighter leg is kept.
  EXPECT_NEAR(glm::length(soft_reach(near, 0.89f, 1.0f, kLength)), glm::length(near), 1e-5f);
}

// Standing with the animation's leg within kMinSoftSpan of straight (the idle's legs stand at
// about 99.7 % of their length), a target held beyond it is still reached short of the full
// length: the kept distance stops kMinSoftSpan short of it. Kept at the animation's, the reach
// went on past the length, and the leg was clamped straight, its knee moving fastest there as the
// foot then stepped.
TEST(LegReach, StandingNearlyStraightTheReachStaysShortOfTheLength) {
  const glm::vec3 way = glm::normalize(glm::vec3(0.0f, -1.0f, 0.1f));
  const float animated = 0.997f * kLength;
  // A held toe just out of reach: short of the length by more than a millimetre a metre, so the
  // knee keeps a bend.
  const float reached = glm::length(soft_reach(way * (1.003f * kLength), animated, 1.0f, kLength));
  EXPECT_LT(reached, 0.999f * kLength);
  // A target at the animation's own distance is reached within a few millimetres of it.
  EXPECT_NEAR(glm::length(soft_reach(way * animated, animated, 1.0f, kLength)), animated, 0.004f);
}

TEST(LegReach, ShortBelowKeepsTheHorizontalOffset) {
  const glm::vec3 target(0.1f, -1.2f, -0.2f);
  const glm::vec3 r = short_below(target, 0.85f);
  EXPECT_NEAR(glm::length(r), 0.85f, 1e-5f);
  EXPECT_NEAR(r.x, 0.1f, 1e-6f);
  EXPECT_NEAR(r.z, -0.2f, 1e-6f);
  EXPECT_LT(r.y, 0.0f);
  // Farther out than the length itself: out at the hip's height, toward the target.
  const glm::vec3 wide = short_below(glm::vec3(1.0f, -0.5f, 0.0f), 0.85f);
  expect_near(wide, glm::vec3(0.85f, 0.0f, 0.0f), 1e-6f);
}

// A foot over a drop behind the body (the target 0.35 m below a step's top, 0.1 m behind the
// hip): along the line the ankle swings forward toward the hip's vertical, under the step's
// edge; reaching down it stays 0.1 m behind, at the same length, and a partial weight is between.
TEST(LegReach, ReachingDownTheFootStaysOverItsTarget) {
  const glm::vec3 target(0.0f, -1.25f, -0.1f);
  const glm::vec3 along = soft_reach(target, 0.8f, 0.0f, kLength);
  ASSERT_LT(glm::length(along), glm::length(target));
  const glm::vec3 down = reach_down(target, along, 1.0f);
  EXPECT_NEAR(glm::length(down), glm::length(along), 1e-5f);
  EXPECT_NEAR(down.z, -0.1f, 1e-5f);
  EXPECT_GT(along.z, -0.1f + 0.02f);  // the line's fall-short swung it 2 cm and more forward
  const glm::vec3 half = reach_down(target, along, 0.5f);
  EXPECT_NEAR(glm::length(half), glm::length(along), 1e-5f);
  EXPECT_LT(half.z, along.z);
  EXPECT_GT(half.z, down.z);
}

TEST(LegReach, ReachingDownChangesNothingWhereTheLegReachesOrTheWeightIsNone) {
  const glm::vec3 target(0.0f, -0.8f, -0.1f);
  expect_near(reach_down(target, target, 1.0f), target, 0.0f);  // reached: nothing short
  const glm::vec3 far(0.0f, -1.25f, -0.1f);
  const glm::vec3 along = soft_reach(far, 0.8f, 0.0f, kLength);
  expect_near(reach_down(far, along, 0.0f), along, 0.0f);
  expect_near(reach_down(far, along, -3.0f), along, 0.0f);
  expect_near(reach_down(far, along, NAN), along, 0.0f);
  // A target above the hip is not reached down to.
  const glm::vec3 up(0.0f, 1.25f, -0.1f);
  const glm::vec3 up_along = soft_reach(up, 0.8f, 0.0f, kLength);
  expect_near(reach_down(up, up_along, 1.0f), up_along, 0.0f);
}

// A heel lifted about a held toe puts the ankle somewhere the leg may still not reach: cut to the
// leg's length, a foot reaching down stays over its point as the reach itself does (cut along the
// hip's line, a foot held behind the body on the tread below was taken 3 cm forward into the
// riser above it: camera-turns from x = 11.25, z = 1.5 on the second course at 1/60 s, the
// default database), and one on the body's ground falls short along the line.
TEST(LegReach, ALiftedAnkleOutOfReachIsCutAsTheReachIs) {
  const glm::vec3 lifted(0.0f, -0.77f, -0.38f);
  const float length = 0.8f;
  ASSERT_GT(glm::length(lifted), length);
  const glm::vec3 down = reach_at_most(lifted, length, 1.0f);
  EXPECT_NEAR(glm::length(down), length, 1e-5f);
  EXPECT_NEAR(down.z, -0.38f, 1e-5f);
  const glm::vec3 along = reach_at_most(lifted, length, 0.0f);
  expect_near(along, lifted * (length / glm::length(lifted)), 1e-6f);
  EXPECT_GT(along.z, -0.38f + 0.02f);
  // Within reach nothing is cut.
  const glm::vec3 near(0.0f, -0.7f, -0.2f);
  expect_near(reach_at_most(near, length, 1.0f), near, 0.0f);
}

}  // namespace
}  // namespace mm
