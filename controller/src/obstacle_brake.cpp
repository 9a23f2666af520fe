#include "mm/controller/obstacle_brake.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace mm {

ObstacleAhead obstacle_ahead(std::span<const glm::vec3> goals, std::span<const glm::vec3> reached,
                             std::span<const glm::vec3> normals) {
  const size_t n = std::min({goals.size(), reached.size(), normals.size()});
  for (size_t i = 0; i < n; ++i) {
    const float short_by = std::hypot(goals[i].x - reached[i].x, goals[i].z - reached[i].z);
    const float normal = std::hypot(normals[i].x, normals[i].z);
    if (!std::isfinite(short_by) || !std::isfinite(normal) || !std::isfinite(reached[i].x) ||
        !std::isfinite(reached[i].z)) {
      return {};
    }
    if (short_by > kBlockedShort && normal > 0.5f) {
      return ObstacleAhead{true, glm::vec3(-normals[i].x, 0.0f, -normals[i].z) / normal,
                           reached[i]};
    }
  }
  return {};
}

glm::vec3 braked_velocity(const glm::vec3& velocity, const glm::vec3& position,
                          const ObstacleAhead& ahead, float deceleration) {
  if (!ahead.found || !(deceleration > 0.0f) || !std::isfinite(deceleration) ||
      !std::isfinite(position.x) || !std::isfinite(position.z)) {
    return velocity;
  }
  const glm::vec3& d = ahead.direction;
  const float room =
      std::max(0.0f, (ahead.stop.x - position.x) * d.x + (ahead.stop.z - position.z) * d.z);
  const float toward = velocity.x * d.x + velocity.z * d.z;
  const float along = std::abs(velocity.x * d.z - velocity.z * d.x);
  if (!(along < kAlongShare * std::hypot(velocity.x, velocity.z))) return velocity;
  const float allowed = std::sqrt(2.0f * deceleration * room);
  if (!(toward > allowed)) return velocity;  // also a NaN room or velocity: left as it is
  return velocity - d * (toward - allowed);
}

}  // namespace mm
