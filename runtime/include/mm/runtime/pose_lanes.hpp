#pragma once
// A pose laid out for SIMD lanes: the joints of one frame in groups of four, each component of
// the four joints side by side, so that a group loads straight into registers (one register per
// component) without transposing. The database keeps its frames this way (one copy, no per-joint
// arrays beside it) and playback's Hermite (pose_hermite.hpp) reads them as they are; a reader
// of one joint takes it out with the accessors below.
//
// A group is 13 rows of four floats: the rotations' w, x, y and z, then the positions', the
// velocities' and the angular velocities' x, y and z. The last group is padded with joints at
// rest (identity rotation, zero position and velocities), which the lanes compute and nobody
// reads.

#include <cstddef>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm {

// The rows of a group, each four floats (one per joint of the group).
enum PoseLaneRow : size_t {
  kPoseLaneRotationW,
  kPoseLaneRotationX,
  kPoseLaneRotationY,
  kPoseLaneRotationZ,
  kPoseLanePosition,                                 // x, y, z
  kPoseLaneVelocity = kPoseLanePosition + 3,         // x, y, z
  kPoseLaneAngularVelocity = kPoseLaneVelocity + 3,  // x, y, z
  kPoseLaneRows = kPoseLaneAngularVelocity + 3,
};

inline constexpr size_t kPoseLaneGroupFloats = kPoseLaneRows * 4;
inline constexpr size_t pose_lane_groups(size_t joints) {
  return (joints + 3) / 4;
}
// Floats of one frame of `joints` joints.
inline constexpr size_t pose_lane_floats(size_t joints) {
  return pose_lane_groups(joints) * kPoseLaneGroupFloats;
}

// The first float of joint `joint`'s component `row` in a frame (its next components, for a
// vector or a rotation, are 4 floats apart each).
inline const float* pose_lane_at(const float* frame, size_t joint, size_t row) {
  return frame + (joint / 4) * kPoseLaneGroupFloats + 4 * row + joint % 4;
}
inline float* pose_lane_at(float* frame, size_t joint, size_t row) {
  return frame + (joint / 4) * kPoseLaneGroupFloats + 4 * row + joint % 4;
}

// One joint's vector (rows kPoseLanePosition, kPoseLaneVelocity or kPoseLaneAngularVelocity) and
// rotation of a frame in the lanes' layout.
inline glm::vec3 pose_lane_vec3(const float* frame, size_t joint, size_t row) {
  const float* v = pose_lane_at(frame, joint, row);
  return glm::vec3(v[0], v[4], v[8]);
}
inline glm::quat pose_lane_rotation(const float* frame, size_t joint) {
  const float* q = pose_lane_at(frame, joint, kPoseLaneRotationW);
  return glm::quat(q[0], q[4], q[8], q[12]);
}

// One frame's per-joint values, all the same length: what pose_to_lanes lays out.
struct PoseFrameView {
  std::span<const glm::quat> rotations;
  std::span<const glm::vec3> positions;
  std::span<const glm::vec3> velocities;
  std::span<const glm::vec3> angular_velocities;
};

// Writes `frame` in the lanes' layout: `out` has pose_lane_floats(joint count) floats.
void pose_to_lanes(const PoseFrameView& frame, std::span<float> out);

}  // namespace mm
