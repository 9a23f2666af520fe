#pragma once
// Moving toward a goal with a bounded acceleration, arriving at rest: what follows a goal that
// jumps (a step in the ground, a wall that starts to hold a toe) without the jump a spring
// answers one with. A critically damped spring (spring.hpp) accelerates hardest at once, in
// proportion to the jump; here the acceleration never exceeds its bound, whatever the jump.
//
// Each update the velocity turns by at most acceleration * dt toward the fastest velocity that
// can still stop at the goal braking at that rate in updates of dt (v^2 / 2a + v dt / 2 =
// distance); a goal within an update's reach of a slow state is taken at once, and a step that
// would pass the goal lands on it (that update stops from at most two updates' change). Units are
// the caller's (m, m/s, m/s^2 for heights).
//
// Robustness: dt <= 0, or a non-finite goal, acceleration or dt, leaves the state unchanged;
// a state that is not finite is put at the goal at rest. Nothing here allocates.

#include <algorithm>
#include <cmath>

namespace mm {

inline void approach(float& x, float& velocity, float goal, float acceleration, float dt) {
  if (!(dt > 0.0f) || !std::isfinite(dt) || !std::isfinite(goal) || !(acceleration > 0.0f) ||
      !std::isfinite(acceleration)) {
    return;
  }
  if (!std::isfinite(x) || !std::isfinite(velocity)) {
    x = goal;
    velocity = 0.0f;
    return;
  }
  const float change = acceleration * dt;
  const float distance = goal - x;
  if (std::abs(distance) <= change * dt && std::abs(velocity) <= change) {
    x = goal;
    velocity = 0.0f;
    return;
  }
  const float braking =
      std::sqrt(0.25f * change * change + 2.0f * acceleration * std::abs(distance)) - 0.5f * change;
  velocity += std::clamp(std::copysign(braking, distance) - velocity, -change, change);
  if (velocity * distance > 0.0f && std::abs(velocity * dt) >= std::abs(distance)) {
    x = goal;
    velocity = 0.0f;
    return;
  }
  x += velocity * dt;
}

}  // namespace mm
