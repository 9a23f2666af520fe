#pragma once
// The cubic Hermite of transform_hermite (interpolation.hpp) for every joint of a pose at once.
// Playback samples all joints between the same two frames at the same time, so the joints are
// interpolated four at a time, one per SIMD lane, from the frames' per-joint arrays as stored.
// Each lane does transform_hermite's operations in its order, so every joint's result equals
// transform_hermite's to the bit.

#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/transform.hpp"

namespace mm {

// One frame of a pose: per joint, its local rotation, translation, linear velocity and angular
// velocity (all the same length).
struct PoseFrameView {
  std::span<const glm::quat> rotations;
  std::span<const glm::vec3> positions;
  std::span<const glm::vec3> velocities;
  std::span<const glm::vec3> angular_velocities;
};

// out[j] = transform_hermite(a's joint j (unit scale), its velocities, b's joint j, its
// velocities, duration, t) for every joint j; `out` has one entry per joint.
void pose_hermite(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                  std::span<Transform> out);

}  // namespace mm
