#pragma once
// Inertialization: switching from one animation to another without a visible pop. At the
// switch, per-joint offsets are set to the difference between what the character shows
// (the outgoing animation plus any offsets still decaying) and the incoming animation, both in
// value and in first derivative. Every frame the offsets decay toward zero with a critically
// damped spring (spring.hpp, halflife in seconds) and are applied to the incoming animation:
//   position: out = incoming + offset,   rotation: out = exp(offset) * incoming,
// with the rotation offset kept as a rotation vector e (angle * axis, parent frame). So the
// output and its velocity are continuous at the switch, also when a switch happens while the
// previous one is still decaying. Offsets come to rest at exactly zero (spring.hpp's
// kSpringNegligible), never lingering as slow subnormal floats.
//
// Angular velocities everywhere here are in the joint's parent frame (rad/s, axis times rate):
// dq/dt = 0.5 * (0, w) * q. Converting between d(e)/dt and the angular velocity of exp(e) uses
// the exact left Jacobian of the rotation exponential, so the derivative matches exactly even
// for large offsets (not just to first order in the offset).
//
// Per-joint state lives in caller-sized arrays (InertializationOffsets::resize, a cold call);
// the transition and the update never allocate.

#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/spring.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// The decaying per-joint offsets of an inertialized transition.
struct InertializationOffsets {
  std::vector<glm::vec3> rotations;       // rotation offsets e as angle * axis (radians)
  std::vector<glm::vec3> rotation_rates;  // de/dt (rad/s)
  std::vector<glm::vec3> positions;       // translation offsets (metres)
  std::vector<glm::vec3> velocities;      // d/dt of the translation offsets (m/s)

  // Sizes every array for joint_count joints and zeroes it (allocates: call at setup).
  void resize(int joint_count);
  // Zeroes every offset, keeping the size (no allocation): the output becomes the incoming pose.
  void clear();
  // The number of joints the arrays were sized for.
  int joint_count() const { return static_cast<int>(rotations.size()); }
};

// A pose with its first derivatives, as views of caller-owned per-joint arrays.
struct PoseMotion {
  std::span<const Transform> local;               // local transforms, one per joint
  std::span<const glm::vec3> velocities;          // d/dt of local translations (m/s); empty = 0
  std::span<const glm::vec3> angular_velocities;  // parent-frame angular velocities; empty = 0
};

// Starts a transition at the current time: afterwards, offsets applied to `incoming` give the
// same pose and velocities as the current offsets applied to `outgoing`. `outgoing` is the
// outgoing animation at this time without offsets; `incoming` the incoming one at this time.
// Both must have offsets.joint_count() joints.
void inertialize_transition(InertializationOffsets& offsets, const PoseMotion& outgoing,
                            const PoseMotion& incoming);

// Advances the offsets by dt seconds (dt = 0 just applies them) and writes incoming + offsets
// to out_local, and the output's velocities and angular velocities when those spans are
// non-empty. `incoming` is the incoming animation at the new time. Scale is passed through.
// A non-finite dt or halflife leaves the offsets as they are (see spring.hpp).
void inertialize_update(InertializationOffsets& offsets, const PoseMotion& incoming, float halflife,
                        float dt, std::span<Transform> out_local,
                        std::span<glm::vec3> out_velocities,
                        std::span<glm::vec3> out_angular_velocities);
// The same with the offsets' step precomputed (critical_spring_step of the halflife and dt,
// which a caller at a fixed rate keeps: CriticalSpringStepCache).
void inertialize_update(InertializationOffsets& offsets, const PoseMotion& incoming,
                        const CriticalSpringStep& step, std::span<Transform> out_local,
                        std::span<glm::vec3> out_velocities,
                        std::span<glm::vec3> out_angular_velocities);

// One joint's position transition: the offset and its velocity such that incoming + offset
// equals outgoing + old offset, in value and velocity.
void inertialize_position_transition(glm::vec3& offset, glm::vec3& offset_velocity,
                                     const glm::vec3& outgoing, const glm::vec3& outgoing_velocity,
                                     const glm::vec3& incoming, const glm::vec3& incoming_velocity);

// One joint's rotation transition: the offset (angle * axis) and its rate such that
// exp(offset) * incoming equals exp(old offset) * outgoing, in value and angular velocity.
void inertialize_rotation_transition(glm::vec3& offset, glm::vec3& offset_rate,
                                     const glm::quat& outgoing,
                                     const glm::vec3& outgoing_angular_velocity,
                                     const glm::quat& incoming,
                                     const glm::vec3& incoming_angular_velocity);

// The parent-frame angular velocity of exp(e) when e changes at rate de/dt (left Jacobian).
glm::vec3 rotation_vector_rate_to_angular_velocity(const glm::vec3& e, const glm::vec3& e_rate);

// The rate de/dt that gives exp(e) the parent-frame angular velocity w (inverse left Jacobian;
// valid for |e| < 2*pi, which the shortest-path offsets satisfy).
glm::vec3 angular_velocity_to_rotation_vector_rate(const glm::vec3& e, const glm::vec3& w);

}  // namespace mm
