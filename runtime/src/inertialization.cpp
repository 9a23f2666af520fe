#include "mm/runtime/inertialization.hpp"

#include <cmath>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/spring.hpp"

namespace mm {

namespace {

glm::vec3 at_or_zero(std::span<const glm::vec3> values, size_t i) {
  return values.empty() ? glm::vec3(0.0f) : values[i];
}

}  // namespace

void InertializationOffsets::resize(int joint_count) {
  MM_ASSERT(joint_count >= 0);
  const size_t n = static_cast<size_t>(joint_count);
  rotations.assign(n, glm::vec3(0.0f));
  rotation_rates.assign(n, glm::vec3(0.0f));
  positions.assign(n, glm::vec3(0.0f));
  velocities.assign(n, glm::vec3(0.0f));
}

void InertializationOffsets::clear() {
  for (size_t i = 0; i < rotations.size(); ++i) {
    rotations[i] = rotation_rates[i] = positions[i] = velocities[i] = glm::vec3(0.0f);
  }
}

glm::vec3 rotation_vector_rate_to_angular_velocity(const glm::vec3& e, const glm::vec3& e_rate) {
  // J(e) r = r + a (e x r) + b (e x (e x r)), a = (1 - cos t)/t^2, b = (t - sin t)/t^3, t = |e|.
  // Computed in double with series near 0, where the differences cancel.
  const double t = glm::length(glm::dvec3(e));
  double a = 0.0;
  double b = 0.0;
  if (t < 1e-2) {
    const double t2 = t * t;
    a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    a = (1.0 - std::cos(t)) / (t * t);
    b = (t - std::sin(t)) / (t * t * t);
  }
  const glm::dvec3 ed(e);
  const glm::dvec3 rd(e_rate);
  const glm::dvec3 exr = glm::cross(ed, rd);
  return glm::vec3(rd + a * exr + b * glm::cross(ed, exr));
}

glm::vec3 angular_velocity_to_rotation_vector_rate(const glm::vec3& e, const glm::vec3& w) {
  // J^-1(e) w = w - 1/2 (e x w) + c (e x (e x w)), c = 1/t^2 - cot(t/2) / (2 t). The
  // cotangent form has no division by sin(t), so it is finite for every t in (0, 2 pi).
  const double t = glm::length(glm::dvec3(e));
  double c = 0.0;
  if (t < 1e-2) {
    const double t2 = t * t;
    c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    c = 1.0 / (t * t) - (std::cos(0.5 * t) / std::sin(0.5 * t)) / (2.0 * t);
  }
  const glm::dvec3 ed(e);
  const glm::dvec3 wd(w);
  const glm::dvec3 exw = glm::cross(ed, wd);
  return glm::vec3(wd - 0.5 * exw + c * glm::cross(ed, exw));
}

void inertialize_position_transition(glm::vec3& offset, glm::vec3& offset_velocity,
                                     const glm::vec3& outgoing, const glm::vec3& outgoing_velocity,
                                     const glm::vec3& incoming,
                                     const glm::vec3& incoming_velocity) {
  offset = (outgoing + offset) - incoming;
  offset_velocity = (outgoing_velocity + offset_velocity) - incoming_velocity;
}

void inertialize_rotation_transition(glm::vec3& offset, glm::vec3& offset_rate,
                                     const glm::quat& outgoing,
                                     const glm::vec3& outgoing_angular_velocity,
                                     const glm::quat& incoming,
                                     const glm::vec3& incoming_angular_velocity) {
  // What the character shows now: the outgoing animation with the current offset applied.
  const glm::quat old_offset = quat_from_scaled_angle_axis(offset);
  const glm::quat shown = old_offset * outgoing;
  const glm::vec3 shown_angular_velocity =
      rotation_vector_rate_to_angular_velocity(offset, offset_rate) +
      old_offset * outgoing_angular_velocity;
  // The new offset takes the incoming animation to exactly that, along the shortest rotation.
  offset = quat_to_scaled_angle_axis(shown * glm::conjugate(incoming));
  const glm::quat new_offset = quat_from_scaled_angle_axis(offset);
  offset_rate = angular_velocity_to_rotation_vector_rate(
      offset, shown_angular_velocity - new_offset * incoming_angular_velocity);
}

void inertialize_transition(InertializationOffsets& offsets, const PoseMotion& outgoing,
                            const PoseMotion& incoming) {
  const size_t n = offsets.rotations.size();
  MM_ASSERT(outgoing.local.size() == n && incoming.local.size() == n);
  MM_ASSERT(outgoing.velocities.empty() || outgoing.velocities.size() == n);
  MM_ASSERT(outgoing.angular_velocities.empty() || outgoing.angular_velocities.size() == n);
  MM_ASSERT(incoming.velocities.empty() || incoming.velocities.size() == n);
  MM_ASSERT(incoming.angular_velocities.empty() || incoming.angular_velocities.size() == n);
  for (size_t i = 0; i < n; ++i) {
    inertialize_position_transition(
        offsets.positions[i], offsets.velocities[i], outgoing.local[i].translation,
        at_or_zero(outgoing.velocities, i), incoming.local[i].translation,
        at_or_zero(incoming.velocities, i));
    inertialize_rotation_transition(
        offsets.rotations[i], offsets.rotation_rates[i], outgoing.local[i].rotation,
        at_or_zero(outgoing.angular_velocities, i), incoming.local[i].rotation,
        at_or_zero(incoming.angular_velocities, i));
  }
}

void inertialize_update(InertializationOffsets& offsets, const PoseMotion& incoming, float halflife,
                        float dt, std::span<Transform> out_local,
                        std::span<glm::vec3> out_velocities,
                        std::span<glm::vec3> out_angular_velocities) {
  // The sizes are checked where the step is applied.
  inertialize_update(offsets, incoming, critical_spring_step(halflife, dt), out_local,
                     out_velocities, out_angular_velocities);
}

void inertialize_update(InertializationOffsets& offsets, const PoseMotion& incoming,
                        const CriticalSpringStep& step, std::span<Transform> out_local,
                        std::span<glm::vec3> out_velocities,
                        std::span<glm::vec3> out_angular_velocities) {
  const size_t n = offsets.rotations.size();
  MM_ASSERT(incoming.local.size() == n && out_local.size() == n);
  MM_ASSERT(incoming.velocities.empty() || incoming.velocities.size() == n);
  MM_ASSERT(incoming.angular_velocities.empty() || incoming.angular_velocities.size() == n);
  MM_ASSERT(out_velocities.empty() || out_velocities.size() == n);
  MM_ASSERT(out_angular_velocities.empty() || out_angular_velocities.size() == n);
  const glm::vec3 zero(0.0f);
  for (size_t i = 0; i < n; ++i) {
    critical_spring_apply(offsets.positions[i], offsets.velocities[i], zero, step);
    critical_spring_apply(offsets.rotations[i], offsets.rotation_rates[i], zero, step);

    const Transform& in = incoming.local[i];
    const glm::quat offset_rotation = quat_from_scaled_angle_axis(offsets.rotations[i]);
    out_local[i].rotation = glm::normalize(offset_rotation * in.rotation);
    out_local[i].translation = in.translation + offsets.positions[i];
    out_local[i].scale = in.scale;
    if (!out_velocities.empty()) {
      out_velocities[i] = at_or_zero(incoming.velocities, i) + offsets.velocities[i];
    }
    if (!out_angular_velocities.empty()) {
      out_angular_velocities[i] = rotation_vector_rate_to_angular_velocity(
                                      offsets.rotations[i], offsets.rotation_rates[i]) +
                                  offset_rotation * at_or_zero(incoming.angular_velocities, i);
    }
  }
}

}  // namespace mm
