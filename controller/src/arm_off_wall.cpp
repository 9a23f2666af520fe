// An arm swung out of a wall (mm/controller/arm_off_wall.hpp).

#include "mm/controller/arm_off_wall.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/interpolation.hpp"

namespace mm {
namespace {

bool below(std::span<const int> parents, int joint, int ancestor) {
  for (int j = parents[static_cast<size_t>(joint)]; j >= 0; j = parents[static_cast<size_t>(j)]) {
    if (j == ancestor) return true;
  }
  return false;
}

// The joint below `upper_arm` deepest past the plane `margin` in front of the wall, and how deep
// (<= 0 when none is).
float deepest(std::span<const Transform> globals, std::span<const int> parents, int upper_arm,
              const WallPlane& wall, float margin, int& joint) {
  float depth = 0.0f;
  joint = -1;
  for (size_t j = static_cast<size_t>(upper_arm) + 1; j < globals.size(); ++j) {
    if (!below(parents, static_cast<int>(j), upper_arm)) continue;
    const float d = glm::dot(wall.point - globals[j].translation, wall.normal) + margin;
    if (d > depth) {
      depth = d;
      joint = static_cast<int>(j);
    }
  }
  return depth;
}

// The smallest turn about `pivot` taking `joint` to `needed` along the normal from the pivot
// (or as near as the joint's distance from the pivot allows).
glm::quat turn_out(const glm::vec3& pivot, const glm::vec3& joint, const glm::vec3& normal,
                   float needed) {
  const glm::vec3 v = joint - pivot;
  const float length = glm::length(v);
  if (length < 1e-6f) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  const float along = std::clamp(needed, -length, length);
  glm::vec3 side = v - normal * glm::dot(v, normal);
  const float side_length = glm::length(side);
  // Straight into the wall: any side will do; the one that keeps the joint's height.
  side = side_length > 1e-6f ? side / side_length
                             : glm::normalize(glm::cross(normal, glm::vec3(0.0f, 1.0f, 0.0f)));
  const glm::vec3 target = side * std::sqrt(length * length - along * along) + normal * along;
  return quat_between(v, target);
}

}  // namespace

float swing_arm_out_of_wall(std::span<Transform> globals, std::span<const int> parents,
                            int upper_arm, const WallPlane& wall, float margin) {
  if (upper_arm < 0 || static_cast<size_t>(upper_arm) >= globals.size()) return 0.0f;
  const glm::vec3 pivot = globals[static_cast<size_t>(upper_arm)].translation;
  int joint = -1;
  const float first = deepest(globals, parents, upper_arm, wall, margin, joint);
  for (int pass = 0; pass < 2 && joint >= 0; ++pass) {
    const glm::vec3 p = globals[static_cast<size_t>(joint)].translation;
    const float needed = glm::dot(wall.point - pivot, wall.normal) + margin;
    const glm::quat turn = turn_out(pivot, p, wall.normal, needed);
    Transform& upper = globals[static_cast<size_t>(upper_arm)];
    upper.rotation = glm::normalize(turn * upper.rotation);
    for (size_t j = static_cast<size_t>(upper_arm) + 1; j < globals.size(); ++j) {
      if (!below(parents, static_cast<int>(j), upper_arm)) continue;
      globals[j].translation = pivot + turn * (globals[j].translation - pivot);
      globals[j].rotation = glm::normalize(turn * globals[j].rotation);
    }
    if (deepest(globals, parents, upper_arm, wall, margin, joint) <= 1e-5f) break;
  }
  return first;
}

}  // namespace mm
