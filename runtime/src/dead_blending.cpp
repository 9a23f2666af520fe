#include "mm/runtime/dead_blending.hpp"

#include <algorithm>
#include <cmath>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/spring.hpp"

namespace mm {

namespace {

glm::vec3 at_or_zero(std::span<const glm::vec3> values, size_t i) {
  return values.empty() ? glm::vec3(0.0f) : values[i];
}

// A decaying velocity below kSpringNegligible is exactly zero (spring.hpp).
glm::vec3 negligible_to_zero(const glm::vec3& v) {
  return glm::dot(v, v) < kSpringNegligible * kSpringNegligible ? glm::vec3(0.0f) : v;
}

// The blend's weight and its rate (1/s) at `time` into a blend of `length` seconds: smoothstep,
// whose rate is zero at both ends, so the velocity is continuous where the blend starts and ends.
struct Weight {
  float value = 1.0f;
  float rate = 0.0f;
};

Weight weight_at(float time, float length) {
  if (!(time < length)) return {};
  const float x = time / length;
  return {x * x * (3.0f - 2.0f * x), 6.0f * x * (1.0f - x) / length};
}

float usable_length(float blend_time) {
  return std::isfinite(blend_time) ? std::max(blend_time, 0.0f) : 0.0f;
}

// Moves the source on by dt with velocities decaying at rate `decay` (1/s), exactly, so the
// result does not depend on how a span of time is cut into updates.
void extrapolate(DeadBlend& blend, float decay, float dt) {
  const float keep = std::exp(-decay * dt);
  const float travel = decay > 0.0f ? (1.0f - keep) / decay : dt;
  for (size_t i = 0; i < blend.source.size(); ++i) {
    Transform& s = blend.source[i];
    s.translation += blend.source_velocities[i] * travel;
    s.rotation = glm::normalize(
        quat_from_scaled_angle_axis(blend.source_angular_velocities[i] * travel) * s.rotation);
    blend.source_velocities[i] = negligible_to_zero(blend.source_velocities[i] * keep);
    blend.source_angular_velocities[i] =
        negligible_to_zero(blend.source_angular_velocities[i] * keep);
  }
}

// One joint of the blend: rotation exp(w * d) * source with d = log(incoming * source^-1), and
// position lerp(source, incoming, w).
struct JointBlend {
  Transform pose;
  glm::vec3 velocity{0.0f};
  glm::vec3 angular_velocity{0.0f};
};

JointBlend blend_joint(const DeadBlend& blend, size_t i, const PoseMotion& incoming, Weight w,
                       bool with_velocities) {
  const Transform& s = blend.source[i];
  const Transform& in = incoming.local[i];
  const glm::vec3 d = quat_to_scaled_angle_axis(in.rotation * glm::conjugate(s.rotation));
  const glm::quat partial = quat_from_scaled_angle_axis(w.value * d);
  JointBlend out;
  out.pose.rotation = glm::normalize(partial * s.rotation);
  out.pose.translation = glm::mix(s.translation, in.translation, w.value);
  out.pose.scale = in.scale;
  if (!with_velocities) return out;
  const glm::vec3& vs = blend.source_velocities[i];
  const glm::vec3& ws = blend.source_angular_velocities[i];
  const glm::vec3 vi = at_or_zero(incoming.velocities, i);
  const glm::vec3 wi = at_or_zero(incoming.angular_velocities, i);
  out.velocity = glm::mix(vs, vi, w.value) + w.rate * (in.translation - s.translation);
  // incoming = exp(d) * source, so wi = J(d) d' + exp(d) ws; the output's angular velocity is
  // J(w d) (w' d + w d') + exp(w d) ws.
  const glm::vec3 d_rate =
      angular_velocity_to_rotation_vector_rate(d, wi - quat_from_scaled_angle_axis(d) * ws);
  out.angular_velocity =
      rotation_vector_rate_to_angular_velocity(w.value * d, w.rate * d + w.value * d_rate) +
      partial * ws;
  return out;
}

}  // namespace

void DeadBlend::resize(int joint_count) {
  MM_ASSERT(joint_count >= 0);
  const size_t n = static_cast<size_t>(joint_count);
  source.assign(n, Transform{});
  source_velocities.assign(n, glm::vec3(0.0f));
  source_angular_velocities.assign(n, glm::vec3(0.0f));
  clear();
}

void DeadBlend::clear() {
  time = 0.0f;
  active = false;
}

void dead_blend_transition(DeadBlend& blend, const PoseMotion& outgoing, float blend_time) {
  const size_t n = blend.source.size();
  MM_ASSERT(outgoing.local.size() == n);
  MM_ASSERT(outgoing.velocities.empty() || outgoing.velocities.size() == n);
  MM_ASSERT(outgoing.angular_velocities.empty() || outgoing.angular_velocities.size() == n);
  const Weight w = blend.active ? weight_at(blend.time, usable_length(blend_time)) : Weight{};
  for (size_t i = 0; i < n; ++i) {
    if (w.value < 1.0f) {
      const JointBlend shown = blend_joint(blend, i, outgoing, w, true);
      blend.source[i] = shown.pose;
      blend.source_velocities[i] = shown.velocity;
      blend.source_angular_velocities[i] = shown.angular_velocity;
    } else {
      blend.source[i] = outgoing.local[i];
      blend.source_velocities[i] = at_or_zero(outgoing.velocities, i);
      blend.source_angular_velocities[i] = at_or_zero(outgoing.angular_velocities, i);
    }
  }
  blend.time = 0.0f;
  blend.active = true;
}

void dead_blend_update(DeadBlend& blend, const PoseMotion& incoming, float blend_time,
                       float decay_halflife, float dt, std::span<Transform> out_local,
                       std::span<glm::vec3> out_velocities,
                       std::span<glm::vec3> out_angular_velocities) {
  const size_t n = blend.source.size();
  MM_ASSERT(incoming.local.size() == n && out_local.size() == n);
  MM_ASSERT(incoming.velocities.empty() || incoming.velocities.size() == n);
  MM_ASSERT(incoming.angular_velocities.empty() || incoming.angular_velocities.size() == n);
  MM_ASSERT(out_velocities.empty() || out_velocities.size() == n);
  MM_ASSERT(out_angular_velocities.empty() || out_angular_velocities.size() == n);
  if (!(dt >= 0.0f) || !std::isfinite(dt)) dt = 0.0f;
  Weight w;
  if (blend.active) {
    blend.time += dt;
    w = weight_at(blend.time, usable_length(blend_time));
    blend.active = w.value < 1.0f;
  }
  if (blend.active) {
    const float halflife = std::max(decay_halflife, kMinSpringHalflife);
    extrapolate(blend, std::isfinite(halflife) ? std::log(2.0f) / halflife : 0.0f, dt);
  }
  const bool with_velocities = !out_velocities.empty() || !out_angular_velocities.empty();
  for (size_t i = 0; i < n; ++i) {
    JointBlend out;
    if (blend.active) {
      out = blend_joint(blend, i, incoming, w, with_velocities);
    } else {
      out.pose = incoming.local[i];
      out.velocity = at_or_zero(incoming.velocities, i);
      out.angular_velocity = at_or_zero(incoming.angular_velocities, i);
    }
    out_local[i] = out.pose;
    if (!out_velocities.empty()) out_velocities[i] = out.velocity;
    if (!out_angular_velocities.empty()) out_angular_velocities[i] = out.angular_velocity;
  }
}

}  // namespace mm
