#pragma once
// Dead blending (Holden, "Dead Blending", 2023): switching from one animation to another by
// cross-fading into the incoming animation from an extrapolation of the outgoing one. At the
// switch, the pose last shown and its velocities become the source; from then on the source
// moves on by itself, its velocities decaying with a halflife (so it coasts to rest rather than
// flying off), and the output is the source blended into the incoming animation by a weight
// that eases from 0 to 1 over the blend time (smoothstep: zero rate at both ends):
//   position: out = lerp(source, incoming, w),   rotation: out = slerp(source, incoming, w).
// The output and its velocity are continuous at the switch, also when a switch happens while
// the previous blend is still running (the new source is the blended pose and its velocity).
// Unlike inertialization, which adds a decaying offset to the whole incoming motion, the blend
// averages the two motions while it runs, so the incoming clip's own sharpest moments are
// softened instead of kept whole.
//
// Angular velocities are in the joint's parent frame (rad/s, axis times rate), as in
// inertialization.hpp. Decaying velocities come to rest at exactly zero (spring.hpp's
// kSpringNegligible).
//
// The blend's output velocities are exact (the left Jacobian of the rotation exponential, as in
// inertialization.hpp), and computed only when asked for: an update that only shows the pose
// pays for none, and a switch computes them once for the new source.
//
// Per-joint state lives in caller-sized arrays (DeadBlend::resize, a cold call); the transition
// and the update never allocate.

#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/inertialization.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// Four joints of a dead blend's source, each component of the four side by side (rows of four
// floats, one per joint), so that the update's SIMD lanes load and store them without
// transposing.
struct DeadBlendSourceGroup {
  alignas(16) float rotation[4][4] = {{1.0f, 1.0f, 1.0f, 1.0f}};  // w, x, y, z; unit
  float translation[3][4] = {};                                   // metres
  float velocity[3][4] = {};                                      // m/s, decaying
  float angular_velocity[3][4] = {};                              // rad/s, parent frame, decaying
};

// The state of a dead blend: the extrapolated source and the time since the switch.
struct DeadBlend {
  // Joints 4 g .. 4 g + 3 of the source in groups[g]; the lanes past the last joint hold a
  // joint at rest (identity, no motion), updated with the others and never read out.
  std::vector<DeadBlendSourceGroup> groups;
  int joints = 0;
  float time = 0.0f;    // seconds since the switch
  bool active = false;  // a blend is running

  // Sizes the source for joint_count joints, with no blend running (allocates: call at setup).
  void resize(int joint_count);
  // Ends any blend (no allocation): the next update outputs the incoming pose.
  void clear();
  int joint_count() const { return joints; }

  // Joint j of the source (its scale is one: the output takes the incoming pose's), and its
  // decaying velocity and angular velocity.
  Transform source(size_t j) const;
  glm::vec3 source_velocity(size_t j) const;
  glm::vec3 source_angular_velocity(size_t j) const;
  void set_source(size_t j, const Transform& pose, const glm::vec3& velocity,
                  const glm::vec3& angular_velocity);
};

// Starts a blend at the current time. `outgoing` is the animation that was playing, at this
// time, with its velocities: what the last update blended into (or showed, with no blend
// running). The new source is what was shown: that animation, or its blend with the running
// source, and the shown velocities. blend_time as in dead_blend_update.
void dead_blend_transition(DeadBlend& blend, const PoseMotion& outgoing, float blend_time);

// Advances the blend by dt seconds and writes the output (and, when the spans are non-empty,
// its velocities and angular velocities) for `incoming`, the incoming animation at the new
// time. blend_time is the cross-fade's length and decay_halflife the source velocities'
// halflife (s); a blend_time of 0 (or not finite) ends the blend at once. Scale is passed through
// from `incoming`. A non-finite or negative dt is taken as 0.
void dead_blend_update(DeadBlend& blend, const PoseMotion& incoming, float blend_time,
                       float decay_halflife, float dt, std::span<Transform> out_local,
                       std::span<glm::vec3> out_velocities,
                       std::span<glm::vec3> out_angular_velocities);

}  // namespace mm
