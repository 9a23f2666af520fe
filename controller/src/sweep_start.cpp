#include "mm/controller/sweep_start.hpp"

#include <glm/glm.hpp>

namespace mm {

bool backed_into_face(const ShapeSweep& sweep, const SweepHit& hit, float radius) {
  const glm::vec3 way(sweep.to.x - sweep.from.x, 0.0f, sweep.to.z - sweep.from.z);
  const float length = glm::length(way);
  if (!(length > 1e-6f) || !hit.hit || hit.fraction * length >= 0.5f * radius) return false;
  const glm::vec3 n(hit.normal.x, 0.0f, hit.normal.z);
  return glm::dot(n, way / length) < -kAcrossTheWay;
}

}  // namespace mm
