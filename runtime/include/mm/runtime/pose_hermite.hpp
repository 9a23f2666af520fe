#pragma once
// The cubic Hermite of transform_hermite (interpolation.hpp) for every joint of a pose at once.
// Playback samples all joints between the same two frames at the same time, so the joints are
// interpolated four at a time, one per SIMD lane, from per-joint arrays (transposed into the
// lanes) or from frames in the lanes' layout (pose_lanes.hpp, the database's: loaded as stored).
// Each lane does transform_hermite's operations in its order, so every joint's result equals
// transform_hermite's to the bit.

#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/pose_lanes.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// out[j] = transform_hermite(a's joint j (unit scale), its velocities, b's joint j, its
// velocities, duration, t) for every joint j; `out` has one entry per joint.
void pose_hermite(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                  std::span<Transform> out);

// pose_hermite between two frames in the lanes' layout (pose_to_lanes of `out.size()` joints),
// to the bit.
void pose_hermite(std::span<const float> a, std::span<const float> b, float duration, float t,
                  std::span<Transform> out);

// The velocities between two frames in the lanes' layout (pose_to_lanes of
// `velocities.size()` joints), the two-point mix the Hermite's velocities take: for every joint j
// from `first` on, velocities[j] = glm::mix(a's velocity j, b's, weight) and the same of the
// angular velocities, to the bit. The joints before `first` are left alone.
void pose_velocity_mix(std::span<const float> a, std::span<const float> b, float weight,
                       size_t first, std::span<glm::vec3> velocities,
                       std::span<glm::vec3> angular_velocities);

}  // namespace mm
