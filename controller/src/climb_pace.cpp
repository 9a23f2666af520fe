#include "mm/controller/climb_pace.hpp"

#include <algorithm>
#include <cmath>

#include "mm/runtime/spring.hpp"

namespace mm {

float grade_ahead(const glm::vec3& from, std::span<const glm::vec3> trajectory) {
  float steepest = 0.0f;
  for (const glm::vec3& p : trajectory) {
    const float run = std::hypot(p.x - from.x, p.z - from.z);
    if (!(run >= kClimbMinRun)) continue;  // also skips NaN
    const float grade = std::abs(p.y - from.y) / run;
    if (std::isfinite(grade)) steepest = std::max(steepest, grade);
  }
  return steepest;
}

float ClimbPace::goal(float grade, float speed, float max_climb_speed, float min_rate) {
  if (!(max_climb_speed > 0.0f) || !(grade > 0.0f) || !(speed > 0.0f)) return 1.0f;
  const float floor = std::isfinite(min_rate) ? std::clamp(min_rate, kMinRate, 1.0f) : 1.0f;
  const float climb = grade * speed;
  if (!std::isfinite(climb)) return floor;
  return std::clamp(max_climb_speed / climb, floor, 1.0f);
}

void ClimbPace::update(float grade, float speed, float max_climb_speed, float min_rate, float dt) {
  if (!(dt > 0.0f) || !std::isfinite(dt)) return;
  if (!std::isfinite(grade) || !std::isfinite(speed) || grade < 0.0f || speed < 0.0f) return;
  const float target = goal(grade, speed, max_climb_speed, min_rate);
  rate_ += (target - rate_) * pull_fraction(kHalflife, dt);
}

}  // namespace mm
