// The pace on steep ground (climb_pace.hpp): the grade read off a trajectory, the rate's goal
// from grade and speed, its smooth approach, and garbage.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "mm/controller/climb_pace.hpp"

namespace mm {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(ClimbPace, TheGradeIsTheSteepestRiseOrDropOverRunAhead) {
  const glm::vec3 from(1.0f, 0.5f, 2.0f);
  // 0.3 m up over 0.5 m, 0.1 m down over 1.0 m, and a sample too close to read.
  const std::array<glm::vec3, 3> up = {glm::vec3(1.0f, 0.9f, 2.1f), glm::vec3(1.0f, 0.8f, 2.5f),
                                       glm::vec3(2.0f, 0.4f, 2.0f)};
  EXPECT_NEAR(grade_ahead(from, up), 0.6f, 1e-5f);
  // Down a stair reads as steep as up one.
  const std::array<glm::vec3, 1> down = {glm::vec3(1.0f, 0.1f, 3.0f)};
  EXPECT_NEAR(grade_ahead(from, down), 0.4f, 1e-5f);
  // Standing (every sample within kClimbMinRun), nothing read; an empty trajectory either.
  const std::array<glm::vec3, 2> standing = {glm::vec3(1.0f, 2.0f, 2.05f),
                                             glm::vec3(1.1f, 2.0f, 2.1f)};
  EXPECT_EQ(grade_ahead(from, standing), 0.0f);
  EXPECT_EQ(grade_ahead(from, {}), 0.0f);
}

TEST(ClimbPace, GarbageSamplesAreSkipped) {
  const glm::vec3 from(0.0f);
  const std::array<glm::vec3, 4> samples = {
      glm::vec3(kNaN, 0.0f, 1.0f), glm::vec3(0.0f, kInf, 1.0f), glm::vec3(0.0f, kNaN, 1.0f),
      glm::vec3(0.0f, 0.2f, 1.0f)};
  EXPECT_NEAR(grade_ahead(from, samples), 0.2f, 1e-6f);
  EXPECT_EQ(grade_ahead(glm::vec3(kNaN), samples), 0.0f);
}

TEST(ClimbPace, TheGoalClimbsAtTheLimitWithinItsFloor) {
  // 1.2 m/s up a grade of 0.5 climbs 0.6 m/s: at 0.3 m/s the clip plays at half its rate.
  EXPECT_NEAR(ClimbPace::goal(0.5f, 1.2f, 0.3f, 0.4f), 0.5f, 1e-6f);
  // Steeper than the floor allows: the floor.
  EXPECT_EQ(ClimbPace::goal(2.0f, 1.2f, 0.3f, 0.4f), 0.4f);
  // Within the limit, flat ground, standing, or no limit set: the clip's own rate.
  EXPECT_EQ(ClimbPace::goal(0.2f, 1.2f, 0.3f, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(0.0f, 1.2f, 0.3f, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(0.5f, 0.0f, 0.3f, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(0.5f, 1.2f, 0.0f, 0.4f), 1.0f);
  // A floor under kMinRate (times are divided by the rate) or above 1 is held to the range.
  EXPECT_EQ(ClimbPace::goal(100.0f, 1.2f, 0.3f, 0.0f), ClimbPace::kMinRate);
  EXPECT_EQ(ClimbPace::goal(0.5f, 1.2f, 0.3f, 2.0f), 1.0f);
  // Garbage: no limit, or the floor.
  EXPECT_EQ(ClimbPace::goal(kNaN, 1.2f, 0.3f, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(0.5f, kNaN, 0.3f, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(0.5f, 1.2f, kNaN, 0.4f), 1.0f);
  EXPECT_EQ(ClimbPace::goal(kInf, 1.2f, 0.3f, 0.4f), 0.4f);
  EXPECT_EQ(ClimbPace::goal(0.5f, 1.2f, 0.3f, kNaN), 1.0f);
}

TEST(ClimbPace, TheRateMovesTowardItsGoalSmoothlyAtEveryUpdateRate) {
  // Half way in a halflife, whatever the update rate; never past the goal.
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    ClimbPace pace;
    float before = pace.rate();
    const int updates = static_cast<int>(std::round(ClimbPace::kHalflife / dt));
    for (int i = 0; i < updates; ++i) {
      pace.update(2.0f, 1.2f, 0.3f, 0.4f, dt);
      EXPECT_LT(pace.rate(), before);
      EXPECT_GE(pace.rate(), 0.4f);
      // No faster than the first update's step: a smooth slowing, no jump.
      EXPECT_LE(before - pace.rate(),
                0.6f * (1.0f - std::exp2(-dt / ClimbPace::kHalflife)) + 1e-6f);
      before = pace.rate();
    }
    // 0.4 + 0.6 * 2^(-t / halflife) after t: the same curve at every rate.
    const float t = static_cast<float>(updates) * dt;
    EXPECT_NEAR(pace.rate(), 0.4f + 0.6f * std::exp2(-t / ClimbPace::kHalflife), 1e-4f) << dt;
    for (int i = 0; i < 200; ++i) pace.update(0.0f, 1.2f, 0.3f, 0.4f, dt);
    EXPECT_NEAR(pace.rate(), 1.0f, 1e-3f) << dt;
    pace.reset();
    EXPECT_EQ(pace.rate(), 1.0f);
  }
}

TEST(ClimbPace, GarbageOrNoTimeLeavesTheRateAlone) {
  ClimbPace pace;
  for (int i = 0; i < 10; ++i) pace.update(2.0f, 1.2f, 0.3f, 0.4f, 1.0f / 30.0f);
  const float rate = pace.rate();
  ASSERT_LT(rate, 0.9f);
  pace.update(kNaN, 1.2f, 0.3f, 0.4f, 1.0f / 30.0f);
  pace.update(2.0f, kInf, 0.3f, 0.4f, 1.0f / 30.0f);
  pace.update(-1.0f, 1.2f, 0.3f, 0.4f, 1.0f / 30.0f);
  pace.update(0.0f, -1.0f, 0.3f, 0.4f, 1.0f / 30.0f);
  pace.update(0.0f, 1.2f, 0.3f, 0.4f, 0.0f);
  pace.update(0.0f, 1.2f, 0.3f, 0.4f, -1.0f);
  pace.update(0.0f, 1.2f, 0.3f, 0.4f, kNaN);
  EXPECT_EQ(pace.rate(), rate);
}

}  // namespace
}  // namespace mm
