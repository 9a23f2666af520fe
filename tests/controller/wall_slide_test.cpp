// The simulation object beside the wall it slid along (wall_slide.hpp): when it is beside it, how
// far its yield toward the character may take it back along the slide, the limit's fade at the
// ends of "beside", and garbage.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "mm/controller/wall_slide.hpp"

namespace mm {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kRadius = 0.3f;
// A wall along X (its face at z = -kRadius), met with the object's centre at the origin.
const WallMet kWall{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, 1.0f)};

TEST(WallSlide, BesideIsWithinTheRadiusOfWhereTheWallWasMetAndCloseToItsPlane) {
  EXPECT_TRUE(beside_wall(glm::vec3(0.2f, 0.0f, 0.04f), kWall, kRadius));
  EXPECT_FALSE(beside_wall(glm::vec3(0.31f, 0.0f, 0.0f), kWall, kRadius));  // past the radius
  EXPECT_FALSE(beside_wall(glm::vec3(0.0f, 0.0f, 0.06f), kWall, kRadius));  // off the plane
  // A floor's normal is no wall.
  EXPECT_FALSE(
      beside_wall(glm::vec3(0.0f), {glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f)}, kRadius));
}

TEST(WallSlide, TheLimitFadesToNothingAtTheEndsOfBeside) {
  EXPECT_EQ(beside_weight(glm::vec3(0.1f, 0.0f, 0.0f), kWall, kRadius), 1.0f);
  // Halfway into the fade along the wall, and off the plane; both at once multiply.
  EXPECT_NEAR(beside_weight(glm::vec3(kRadius - 0.5f * kBesideFade, 0.0f, 0.0f), kWall, kRadius),
              0.5f, 1e-3f);
  EXPECT_NEAR(
      beside_weight(glm::vec3(0.0f, 0.0f, kBesideObstacle - 0.5f * kBesideFade), kWall, kRadius),
      0.5f, 1e-3f);
  // Continuous at the end: next to nothing just inside, nothing outside.
  EXPECT_LT(beside_weight(glm::vec3(kRadius - 1e-4f, 0.0f, 0.0f), kWall, kRadius), 0.01f);
  EXPECT_EQ(beside_weight(glm::vec3(kRadius + 1e-4f, 0.0f, 0.0f), kWall, kRadius), 0.0f);
}

TEST(WallSlide, TheYieldTakesBackAtMostHalfTheSlideWeighted) {
  const glm::vec3 velocity(1.0f, 0.0f, -0.5f);  // sliding along +X (its part into the wall aside)
  const float dt = 0.1f;                        // a slide of 0.1 m
  const glm::vec3 back(-0.2f, 0.0f, 0.0f);
  EXPECT_NEAR(without_slide_back(back, velocity, kWall.normal, 1.0f, dt).x, -0.05f, 1e-6f);
  EXPECT_NEAR(without_slide_back(back, velocity, kWall.normal, 0.5f, dt).x, -0.125f, 1e-6f);
  EXPECT_EQ(without_slide_back(back, velocity, kWall.normal, 0.0f, dt), back);
  // Within the limit, along the slide or away from the wall: unchanged.
  for (const glm::vec3& step :
       {glm::vec3(-0.04f, 0.0f, 0.0f), glm::vec3(0.2f, 0.0f, 0.1f), glm::vec3(0.0f, 0.0f, 0.3f)}) {
    EXPECT_EQ(without_slide_back(step, velocity, kWall.normal, 1.0f, dt), step);
  }
}

TEST(WallSlide, GarbageLeavesTheStepAsItIs) {
  const glm::vec3 step(-0.2f, 0.0f, 0.0f), velocity(1.0f, 0.0f, 0.0f);
  EXPECT_EQ(without_slide_back(step, velocity, kWall.normal, kNaN, 0.1f), step);
  EXPECT_EQ(without_slide_back(step, velocity, kWall.normal, 1.0f, kNaN), step);
  EXPECT_EQ(without_slide_back(step, velocity, kWall.normal, 1.0f, -0.1f), step);
  EXPECT_EQ(without_slide_back(step, velocity, glm::vec3(0.0f), 1.0f, 0.1f), step);
  EXPECT_EQ(without_slide_back(step, glm::vec3(kNaN), kWall.normal, 1.0f, 0.1f), step);
  EXPECT_EQ(beside_weight(glm::vec3(kNaN), kWall, kRadius), 0.0f);
  EXPECT_FALSE(beside_wall(glm::vec3(0.0f), {glm::vec3(0.0f), glm::vec3(kNaN)}, kRadius));
}

// The jitter the fade removes: an object sliding along a wall while its yield pulls it back
// toward a character lagging behind (held at the clamp's distance), more than the slide itself
// when whole. With the limit cut off at the radius, the object crossed the line and back on
// alternate updates; faded, it settles where the two balance. Returns the largest change of the
// object's step from one update to the next over the run's second half (m).
float largest_step_change(bool faded) {
  const float dt = 1.0f / 144.0f, speed = 0.7f;
  const glm::vec3 velocity(speed, 0.0f, 0.0f);
  const float yield = 1.5f * speed * dt;  // the whole yield's length, toward -X
  glm::vec3 position(0.25f, 0.0f, 0.0f);
  float previous = 0.0f, largest = 0.0f;
  for (int update = 0; update < 400; ++update) {
    const glm::vec3 before = position;
    position += velocity * dt;
    const float weight = faded ? beside_weight(position, kWall, kRadius)
                               : (beside_wall(position, kWall, kRadius) ? 1.0f : 0.0f);
    position +=
        without_slide_back(glm::vec3(-yield, 0.0f, 0.0f), velocity, kWall.normal, weight, dt);
    const float step = position.x - before.x;
    if (update >= 200) largest = std::max(largest, std::abs(step - previous));
    previous = step;
  }
  return largest;
}

TEST(WallSlide, NearTheEndOfBesideTheObjectDoesNotShake) {
  const float slide = 0.7f / 144.0f;
  EXPECT_GT(largest_step_change(false), 0.5f * slide);  // what the fade is for
  EXPECT_LT(largest_step_change(true), 0.01f * slide);
}

}  // namespace
}  // namespace mm
