#include "mm/runtime/constraints.hpp"

#include <algorithm>
#include <cmath>
#include "mm/runtime/assert.hpp"

namespace mm {

namespace {

// Ends closer than this (metres) are treated as coinciding: their direction is noise.
constexpr float kCoincidentDistance = 1e-9f;

}  // namespace

bool relax_distance_constraint(glm::vec3& a, glm::vec3& b, float rest_length, float weight_a,
                               float weight_b) {
  if (!std::isfinite(rest_length) || !std::isfinite(weight_a) || !std::isfinite(weight_b)) {
    return false;
  }
  const float wa = std::max(weight_a, 0.0f);
  const float wb = std::max(weight_b, 0.0f);
  const float total = wa + wb;
  if (!(total > 0.0f)) return false;
  const glm::vec3 delta = b - a;
  const float distance = glm::length(delta);
  if (!(distance > kCoincidentDistance) || !std::isfinite(distance)) return false;
  // The full correction brings the distance to the rest length along the current direction.
  const glm::vec3 correction = (distance - std::max(rest_length, 0.0f)) / distance * delta;
  a += (wa / total) * correction;
  b -= (wb / total) * correction;
  return true;
}

void relax_distance_constraints(std::span<glm::vec3> points,
                                std::span<const DistanceConstraint> constraints, int iterations) {
  for (int iteration = 0; iteration < iterations; ++iteration) {
    for (const DistanceConstraint& c : constraints) {
      MM_ASSERT(c.a >= 0 && static_cast<size_t>(c.a) < points.size());
      MM_ASSERT(c.b >= 0 && static_cast<size_t>(c.b) < points.size());
      if (c.a == c.b) continue;  // a point cannot keep a distance from itself
      relax_distance_constraint(points[c.a], points[c.b], c.rest_length, c.weight_a, c.weight_b);
    }
  }
}

float max_distance_constraint_error(std::span<const glm::vec3> points,
                                    std::span<const DistanceConstraint> constraints) {
  float worst = 0.0f;
  for (const DistanceConstraint& c : constraints) {
    MM_ASSERT(c.a >= 0 && static_cast<size_t>(c.a) < points.size());
    MM_ASSERT(c.b >= 0 && static_cast<size_t>(c.b) < points.size());
    worst = std::max(worst, std::abs(glm::distance(points[c.a], points[c.b]) - c.rest_length));
  }
  return worst;
}

}  // namespace mm
