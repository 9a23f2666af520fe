// approach(): a bounded acceleration toward a goal, arriving at rest (approach.hpp).

#include "mm/runtime/approach.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mm {
namespace {

// From rest to a goal 20 cm away, at every update rate: the velocity never changes by more than
// the bound allows in an update (twice that in the update that lands), it arrives, and it is at
// rest there.
TEST(Approach, ReachesTheGoalAtRestNeverFasterThanTheBoundAllows) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    float x = 0.0f, v = 0.0f;
    const float a = 30.0f;
    int updates = 0;
    while ((x != 0.2f || v != 0.0f) && updates < 1000) {
      const float before = v;
      approach(x, v, 0.2f, a, dt);
      // The update that lands stops from the speed it had: at most two updates' change.
      const float bound = (x == 0.2f ? 2.0f : 1.0f) * a * dt * (1.0f + 1e-5f);
      EXPECT_LE(std::abs(v - before), bound) << dt << " update " << updates;
      EXPECT_LE(x, 0.2f);
      ++updates;
    }
    EXPECT_EQ(x, 0.2f) << dt;
    EXPECT_EQ(v, 0.0f) << dt;
    // Rest to rest over 20 cm at 30 m/s^2 takes 2 sqrt(0.2 / 30) = 0.163 s, within a few updates.
    EXPECT_NEAR(static_cast<float>(updates) * dt, 0.163f, 4.0f * dt) << dt;
  }
}

// Moving away from the goal, it first brakes at the bound, then comes back.
TEST(Approach, AStateMovingAwayBrakesBeforeItTurnsBack) {
  float x = 0.0f, v = -1.0f;
  const float dt = 1.0f / 60.0f;
  approach(x, v, 0.1f, 20.0f, dt);
  EXPECT_NEAR(v, -1.0f + 20.0f * dt, 1e-5f);
  EXPECT_LT(x, 0.0f);
  for (int i = 0; i < 200; ++i) approach(x, v, 0.1f, 20.0f, dt);
  EXPECT_EQ(x, 0.1f);
  EXPECT_EQ(v, 0.0f);
}

TEST(Approach, NoTimeOrGarbageLeavesTheStateAndABrokenStateLandsOnTheGoal) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  float x = 0.5f, v = 0.25f;
  approach(x, v, 1.0f, 10.0f, 0.0f);
  approach(x, v, 1.0f, 10.0f, -0.1f);
  approach(x, v, nan, 10.0f, 0.1f);
  approach(x, v, 1.0f, nan, 0.1f);
  approach(x, v, 1.0f, 0.0f, 0.1f);
  approach(x, v, 1.0f, 10.0f, nan);
  EXPECT_EQ(x, 0.5f);
  EXPECT_EQ(v, 0.25f);
  x = nan;
  approach(x, v, 1.0f, 10.0f, 0.1f);
  EXPECT_EQ(x, 1.0f);
  EXPECT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace mm
