#pragma once
// Interpolation of rotations and rigid transforms, and sampling a clip between its keyframes.
//
// Three methods, from cheapest to most uniform:
// - Nlerp: rotation by normalized linear interpolation of quaternions, translation and scale
//   by linear interpolation. Cheap; the angular speed is not constant (fastest mid-way).
// - Slerp: rotation by the log/exp of the relative rotation (constant angular speed),
//   translation and scale linear (constant linear speed); the two are independent.
// - Sclerp: screw-linear interpolation of the whole rigid motion as a dual quaternion. The
//   relative motion is a screw (rotation about an axis plus a slide along it) and the path
//   follows that screw at constant speed: every point moves along a helix with constant
//   speed. Scale, which a dual quaternion cannot hold, is interpolated linearly.
// Every method takes the shortest path: a quaternion whose dot product with the start is
// negative is negated first (q and -q are the same rotation). All functions are exact at
// t = 0 and t = 1 up to float rounding, never divide by a near-zero angle (limits are used
// instead), and return unit quaternions.

#include <cmath>
#include <span>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/atan2_polynomial.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// ---- Rotation maps -------------------------------------------------------------------------

// The same rotation with w >= 0: its rotation angle is at most pi (the shorter way round).
glm::quat quat_abs(const glm::quat& q);

// Logarithm of a unit quaternion: half the rotation angle times the unit axis. Identity gives
// zero; a quaternion with w < 0 gives a half angle above pi/2 (call quat_abs first for the
// shortest rotation). Well defined for every unit quaternion, including near identity.
glm::vec3 quat_log(const glm::quat& q);

// Exponential map, the inverse of quat_log: a half angle times an axis to a unit quaternion.
// Uses a Taylor series near zero, so tiny vectors keep their first-order term.
glm::quat quat_exp(const glm::vec3& half_angle_axis);

// The shortest rotation of q as a rotation vector: angle (radians, in [0, pi]) times axis.
glm::vec3 quat_to_scaled_angle_axis(const glm::quat& q);

// The rotation of a rotation vector (angle in radians times unit axis).
glm::quat quat_from_scaled_angle_axis(const glm::vec3& scaled_angle_axis);

// The angle in radians, in [0, pi], of the shortest rotation taking a to b.
float quat_angle_between(const glm::quat& a, const glm::quat& b);

// The heading of a rotation: the yaw (radians, about +Y) of where it takes the forward axis +Z,
// atan2(forward.x, forward.z). A forward axis along +Y or -Y gives 0. Inline: the controller
// takes several an update.
inline float quat_yaw(const glm::quat& q) {
  // The x and z of q * (0, 0, 1), GLM's rotation written out for that vector (the same
  // expression for any q, unit or not): two products and a sum each instead of two cross
  // products of a general vector.
  const float x = 2.0f * (q.w * q.y + q.x * q.z);
  const float z = 1.0f - 2.0f * (q.x * q.x + q.y * q.y);
  return atan2_polynomial(x, z);
}

// The angle in [-pi, pi) equal to `angle` modulo 2 pi (a non-finite angle stays non-finite).
// Inline, and the library's fmod only for an angle more than a turn off: fmod is exact and
// returns its argument unchanged when that is less than the divisor in magnitude, which nearly
// every call's is (a difference of two wrapped angles), so both paths give the same bits.
inline float wrap_angle(float angle) {
  float a = angle + glm::pi<float>();
  if (!(std::abs(a) < glm::two_pi<float>())) a = std::fmod(a, glm::two_pi<float>());
  if (a < 0.0f) a += glm::two_pi<float>();
  return a - glm::pi<float>();
}

// The shortest rotation taking direction `from` to direction `to` (neither needs unit length).
// Opposite directions give a half turn about an axis perpendicular to `from`; a zero vector
// gives identity.
glm::quat quat_between(const glm::vec3& from, const glm::vec3& to);

// Normalized linear interpolation from a to b along the shortest path (not constant speed).
glm::quat quat_nlerp(const glm::quat& a, const glm::quat& b, float t);

// Spherical linear interpolation a * exp(t * log(a^-1 * b)) along the shortest path: the
// angle from a grows exactly linearly with t. Identical and opposite (q, -q) inputs give a
// constant result; rotations 180 degrees apart pick one of the two equal-length paths.
glm::quat quat_slerp(const glm::quat& a, const glm::quat& b, float t);

// ---- Dual quaternions ----------------------------------------------------------------------

// A unit dual quaternion real + eps * dual encoding a rigid motion: real is the rotation and
// dual = 0.5 * (0, translation) * real. Composition and application follow the quaternions'
// conventions: (a * b) applies b first.
struct DualQuat {
  glm::quat real{1.0f, 0.0f, 0.0f, 0.0f};  // the rotation (unit)
  glm::quat dual{0.0f, 0.0f, 0.0f, 0.0f};  // half the translation times the rotation
};

// The dual quaternion of a transform's rotation and translation (its scale is ignored).
DualQuat dual_quat_from_transform(const Transform& t);

// The rigid transform of a unit dual quaternion (scale 1).
Transform dual_quat_to_transform(const DualQuat& q);

// The composition a * b: applies b, then a.
DualQuat operator*(const DualQuat& a, const DualQuat& b);

// Dual quaternions add and scale component-wise (used by blending before normalization).
DualQuat operator+(const DualQuat& a, const DualQuat& b);
// Scales both parts by s.
DualQuat operator*(float s, const DualQuat& q);

// The quaternion conjugate of both parts: the inverse motion of a unit dual quaternion.
DualQuat dual_quat_conjugate(const DualQuat& q);

// Projects a blended dual quaternion back to a unit one: divides by the real part's length
// and removes the dual part's component along the real part. A zero real part gives identity.
DualQuat dual_quat_normalize(const DualQuat& q);

// The translation encoded by a unit dual quaternion: 2 * dual * conjugate(real).
glm::vec3 dual_quat_translation(const DualQuat& q);

// Applies a unit dual quaternion's rigid motion to a point.
glm::vec3 dual_quat_transform_point(const DualQuat& q, const glm::vec3& p);

// The rigid motion q raised to the power t, following q's screw at constant speed: rotation by
// t times the angle about the screw axis and a slide of t times the pitch distance along it.
// q and -q are the same motion; the shorter rotation (|angle| <= pi) is used. A pure
// translation (no rotation) scales linearly without dividing by the zero angle.
DualQuat dual_quat_pow(const DualQuat& q, float t);

// Screw-linear interpolation a * (a^-1 * b)^t of two unit dual quaternions.
DualQuat dual_quat_sclerp(const DualQuat& a, const DualQuat& b, float t);

// ---- Transforms and clips ------------------------------------------------------------------

// How rotations (and, for Sclerp, translations) are interpolated between two transforms.
enum class InterpolationMethod {
  Nlerp,   // normalized lerp of rotations, lerp of translations: cheap, not constant speed
  Slerp,   // constant angular speed rotation, lerp of translations, independently
  Sclerp,  // constant speed along the screw of the whole rigid motion (dual quaternions)
};

// What sampling does with times outside a clip.
enum class WrapMode {
  Clamp,  // before the start holds the first frame, past the end holds the last frame
  Loop,   // the clip repeats with period frame_count * frame_time; the last frame blends into
          // the first over one frame time, so a looping clip must not repeat its first frame
};

// Normalized lerp of two transforms (rotation nlerp, translation and scale lerp).
Transform transform_nlerp(const Transform& a, const Transform& b, float t);

// Slerp of the rotation, lerp of translation and scale.
Transform transform_slerp(const Transform& a, const Transform& b, float t);

// Screw-linear interpolation of the rigid part, lerp of the scale.
Transform transform_sclerp(const Transform& a, const Transform& b, float t);

// Interpolates a to b at t in [0, 1] with the chosen method.
Transform interpolate(const Transform& a, const Transform& b, float t, InterpolationMethod method);

// Cubic Hermite interpolation of a moving rigid transform between two samples `duration`
// seconds apart, from their values and first derivatives: translation velocities (m/s) and
// angular velocities (rad/s, parent frame, dq/dt = 0.5 * (0, w) * q). Translations follow the
// cubic Hermite curve; rotations follow the Hermite curve of the quaternion's components (its
// tangent 0.5 * (0, w) * q * duration), normalized, after aligning b with a's hemisphere. Exact
// at t = 0 and 1; consecutive intervals sharing a sample meet with matching first derivatives,
// so playback has no velocity kinks at the samples (linear interpolation has one at each).
// Scale is interpolated linearly.
Transform transform_hermite(const Transform& a, const glm::vec3& a_velocity,
                            const glm::vec3& a_angular_velocity, const Transform& b,
                            const glm::vec3& b_velocity, const glm::vec3& b_angular_velocity,
                            float duration, float t);

// Samples a clip at `time` seconds into `out` (joint_count transforms). `frames` holds
// frame_count * joint_count local transforms, frame-major; frame k is at time k * frame_time.
// Times exactly on a keyframe copy it; between keyframes the two neighbours are interpolated.
// A non-finite time samples frame 0. Does not allocate. Requires joint_count > 0, frames
// non-empty and a multiple of joint_count, frame_time > 0 and out.size() == joint_count.
void sample_pose(std::span<const Transform> frames, int joint_count, float frame_time, float time,
                 InterpolationMethod method, WrapMode wrap, std::span<Transform> out);

}  // namespace mm
