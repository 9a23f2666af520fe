#include "mm/controller/wall_slide.hpp"

#include <algorithm>
#include <cmath>

namespace mm {

namespace {

// How far inside each of the two distances the object is (m): from the wall's plane through
// where it met it, and from that point (negative: not beside it).
glm::vec2 inside(const glm::vec3& position, const WallMet& wall, float radius) {
  return {kBesideObstacle - glm::dot(position - wall.point, wall.normal),
          radius - glm::distance(position, wall.point)};
}

}  // namespace

bool beside_wall(const glm::vec3& position, const WallMet& wall, float radius) {
  if (std::hypot(wall.normal.x, wall.normal.z) < 0.5f) return false;
  const glm::vec2 in = inside(position, wall, radius);
  return in.x >= 0.0f && in.y >= 0.0f;
}

float beside_weight(const glm::vec3& position, const WallMet& wall, float radius) {
  if (!beside_wall(position, wall, radius)) return 0.0f;
  const glm::vec2 in = inside(position, wall, radius);
  return std::min(1.0f, in.x / kBesideFade) * std::min(1.0f, in.y / kBesideFade);
}

glm::vec3 without_slide_back(const glm::vec3& step, const glm::vec3& velocity,
                             const glm::vec3& normal, float weight, float dt) {
  const float n_length = std::hypot(normal.x, normal.z);
  if (!(weight > 0.0f) || !(dt > 0.0f) || !(n_length > 0.0f)) return step;
  const glm::vec3 n = glm::vec3(normal.x, 0.0f, normal.z) / n_length;
  const glm::vec3 slide = (velocity - n * glm::dot(velocity, n)) * dt;
  const float slide_length = glm::length(slide);
  if (!(slide_length > 0.0f)) return step;
  const glm::vec3 direction = slide / slide_length;
  const float back = -glm::dot(step, direction);
  const float allowed = kMaxSlideBack * slide_length;
  if (!(back > allowed)) return step;
  return step + direction * ((back - allowed) * std::min(weight, 1.0f));
}

}  // namespace mm
