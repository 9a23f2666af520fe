#include "mm/runtime/pose.hpp"

#include <cmath>
#include "mm/runtime/assert.hpp"
#include "mm/runtime/atan2_polynomial.hpp"

namespace mm {

void forward_kinematics(std::span<const int> parents, std::span<const Transform> local,
                        std::span<Transform> global) {
  MM_ASSERT(local.size() == parents.size() && global.size() == parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    const int p = parents[i];
    MM_ASSERT(p < static_cast<int>(i));
    global[i] = p < 0 ? local[i] : compose(global[p], local[i]);
  }
}

Transform forward_kinematics_joint(std::span<const int> parents, std::span<const Transform> local,
                                   int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
  Transform t = local[joint];
  for (int p = parents[joint]; p >= 0; p = parents[p]) t = compose(local[p], t);
  return t;
}

glm::vec3 forward_kinematics_position(std::span<const int> parents,
                                      std::span<const Transform> local, int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
  glm::vec3 position = local[joint].translation;
  // compose(parent, t).translation, step by step up the chain.
  for (int p = parents[joint]; p >= 0; p = parents[p]) {
    position = local[p].rotation * (local[p].scale * position) + local[p].translation;
  }
  return position;
}

glm::quat forward_kinematics_rotation(std::span<const int> parents,
                                      std::span<const Transform> local, int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
  glm::quat rotation = local[joint].rotation;
  for (int p = parents[joint]; p >= 0; p = parents[p]) rotation = local[p].rotation * rotation;
  return rotation;
}

void bone_lengths(std::span<const int> parents, std::span<const Transform> global,
                  std::span<float> lengths) {
  MM_ASSERT(global.size() == parents.size() && lengths.size() == parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    const int p = parents[i];
    lengths[i] = p < 0 ? glm::length(global[i].translation)
                       : glm::distance(global[i].translation, global[p].translation);
  }
}

float pair_yaw(const glm::vec3& left, const glm::vec3& right, float fallback) {
  const glm::vec3 across = left - right;
  // (left - right) x up = (-across.z, 0, across.x). Squared: a product underflowing to 0 or
  // overflowing to infinity lands on the same side of the threshold as the length would.
  if (across.x * across.x + across.z * across.z <= 1e-12f) return fallback;
  return atan2_polynomial(-across.z, across.x);
}

}  // namespace mm
