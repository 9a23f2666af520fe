#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/float_to_integer.hpp"

#include <cmath>
#include "mm/runtime/assert.hpp"
#include "mm/runtime/atan2_polynomial.hpp"

#include <glm/gtc/constants.hpp>

namespace mm {

namespace {

glm::quat negated_if_far(const glm::quat& from, const glm::quat& q) {
  return glm::dot(from, q) < 0.0f ? -q : q;
}

}  // namespace

glm::quat quat_abs(const glm::quat& q) {
  return q.w < 0.0f ? -q : q;
}

// Below these half angles (radians, squared) the exponential and the logarithm sum their Taylor
// series instead of calling sin, cos and atan2: the series' first dropped term is below float
// rounding there, and its terms need only the squared length, so no square root either. Every
// update's small rotations (a frame's turn, an extrapolation step, the offsets of a blend
// between similar poses) land here.
constexpr float kExpSeriesLimit2 = 0.25f;    // |half angle| < 0.5
constexpr float kLogSeriesLimit2 = 0.0625f;  // |tan(half angle)| < 0.25

glm::vec3 quat_log(const glm::quat& q) {
  const glm::vec3 v(q.x, q.y, q.z);
  const float s2 = glm::dot(v, v);
  // atan2(s, w) / s = atan(x) / (x w) with x = s / w: the series of atan(x) / x in x^2 while
  // w is positive and x small.
  if (q.w > 0.0f && s2 < kLogSeriesLimit2 * q.w * q.w) {
    const float x2 = s2 / (q.w * q.w);
    const float atan_x_over_x =
        1.0f + x2 * (-1.0f / 3.0f +
                     x2 * (1.0f / 5.0f +
                           x2 * (-1.0f / 7.0f +
                                 x2 * (1.0f / 9.0f + x2 * (-1.0f / 11.0f + x2 * (1.0f / 13.0f))))));
    return v * (atan_x_over_x / q.w);
  }
  const float s = std::sqrt(s2);
  // Only an exactly (or denormally) zero vector part is special; atan2(s, w) / s is accurate
  // for every other s, tiny ones included, because atan2 keeps relative precision near 0.
  if (s < 1e-30f) return q.w >= 0.0f ? v : glm::vec3(glm::pi<float>(), 0.0f, 0.0f);
  return v * (atan2_polynomial(s, q.w) / s);
}

glm::quat quat_exp(const glm::vec3& half_angle_axis) {
  const float a2 = glm::dot(half_angle_axis, half_angle_axis);
  if (a2 < kExpSeriesLimit2) {
    const float cosine =
        1.0f +
        a2 * (-1.0f / 2.0f + a2 * (1.0f / 24.0f + a2 * (-1.0f / 720.0f + a2 * (1.0f / 40320.0f))));
    const float sine_over_a =
        1.0f + a2 * (-1.0f / 6.0f +
                     a2 * (1.0f / 120.0f + a2 * (-1.0f / 5040.0f + a2 * (1.0f / 362880.0f))));
    const glm::vec3 v = half_angle_axis * sine_over_a;
    return glm::quat(cosine, v.x, v.y, v.z);
  }
  const float a = std::sqrt(a2);
  const glm::vec3 v = half_angle_axis * (std::sin(a) / a);
  return glm::quat(std::cos(a), v.x, v.y, v.z);
}

glm::vec3 quat_to_scaled_angle_axis(const glm::quat& q) {
  return 2.0f * quat_log(quat_abs(q));
}

glm::quat quat_from_scaled_angle_axis(const glm::vec3& scaled_angle_axis) {
  return quat_exp(0.5f * scaled_angle_axis);
}

float quat_angle_between(const glm::quat& a, const glm::quat& b) {
  return glm::length(quat_to_scaled_angle_axis(glm::conjugate(a) * b));
}

glm::quat quat_between(const glm::vec3& from, const glm::vec3& to) {
  const float from_length = glm::length(from);
  const float to_length = glm::length(to);
  if (!(from_length > 1e-20f) || !(to_length > 1e-20f)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  const glm::vec3 u = from / from_length;
  const glm::vec3 v = to / to_length;
  const float d = glm::dot(u, v);
  if (d < -1.0f + 1e-6f) {
    // Half a turn: any axis perpendicular to u; take the one least aligned with u's largest axis.
    const glm::vec3 other = std::abs(u.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::vec3 axis = glm::normalize(glm::cross(u, other));
    return glm::quat(0.0f, axis.x, axis.y, axis.z);
  }
  // The half-way quaternion (1 + d, u x v), normalized: no trigonometry, exact at d = 1.
  const glm::vec3 c = glm::cross(u, v);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

glm::quat quat_nlerp(const glm::quat& a, const glm::quat& b, float t) {
  const glm::quat bs = negated_if_far(a, b);
  const glm::quat m = (1.0f - t) * a + t * bs;
  const float len = glm::length(m);
  // After the sign flip a and bs are less than 90 degrees apart in 4D, so m vanishes only for
  // non-unit input; fall back to a rather than divide by zero.
  return len > 1e-20f ? m / len : a;
}

glm::quat quat_slerp(const glm::quat& a, const glm::quat& b, float t) {
  const glm::quat bs = negated_if_far(a, b);
  const glm::quat relative = glm::conjugate(a) * bs;  // w >= 0: the short way round
  return glm::normalize(a * quat_exp(t * quat_log(relative)));
}

DualQuat dual_quat_from_transform(const Transform& t) {
  DualQuat q;
  q.real = t.rotation;
  q.dual = 0.5f * (glm::quat(0.0f, t.translation.x, t.translation.y, t.translation.z) * t.rotation);
  return q;
}

Transform dual_quat_to_transform(const DualQuat& q) {
  Transform t;
  t.rotation = q.real;
  t.translation = dual_quat_translation(q);
  return t;
}

DualQuat operator*(const DualQuat& a, const DualQuat& b) {
  DualQuat q;
  q.real = a.real * b.real;
  q.dual = a.real * b.dual + a.dual * b.real;
  return q;
}

DualQuat operator+(const DualQuat& a, const DualQuat& b) {
  DualQuat q;
  q.real = a.real + b.real;
  q.dual = a.dual + b.dual;
  return q;
}

DualQuat operator*(float s, const DualQuat& q) {
  DualQuat r;
  r.real = s * q.real;
  r.dual = s * q.dual;
  return r;
}

DualQuat dual_quat_conjugate(const DualQuat& q) {
  DualQuat r;
  r.real = glm::conjugate(q.real);
  r.dual = glm::conjugate(q.dual);
  return r;
}

DualQuat dual_quat_normalize(const DualQuat& q) {
  const float len = glm::length(q.real);
  if (!(len > 1e-20f)) return DualQuat{};
  DualQuat r;
  r.real = q.real / len;
  r.dual = q.dual / len;
  // A unit dual quaternion has dot(real, dual) == 0; blending breaks that slightly.
  r.dual = r.dual - glm::dot(r.real, r.dual) * r.real;
  return r;
}

glm::vec3 dual_quat_translation(const DualQuat& q) {
  const glm::quat t = 2.0f * (q.dual * glm::conjugate(q.real));
  return {t.x, t.y, t.z};
}

glm::vec3 dual_quat_transform_point(const DualQuat& q, const glm::vec3& p) {
  return q.real * p + dual_quat_translation(q);
}

DualQuat dual_quat_pow(const DualQuat& q_in, float t) {
  // The motion x -> R x + p as a screw: R turns by angle 2*alpha about the unit axis l, and p
  // splits into a slide `pitch` along l and a part p_perp across it. Raising to the power t
  // turns by 2*t*alpha about the same axis line and slides t*pitch along it, which gives
  //   p(t) = t*pitch*l + (sin(t*alpha) / sin(alpha)) * rotate(l, (t - 1)*alpha, p_perp).
  // (Derived from p(t) = (I - R(t)) c + t*pitch*l with c the axis point solving
  // (I - R) c = p_perp.) As alpha -> 0 the ratio tends to t, so p(t) -> t*p.
  const DualQuat q = q_in.real.w < 0.0f ? -1.0f * q_in : q_in;
  const glm::vec3 p = dual_quat_translation(q);
  const glm::vec3 half_angle_axis = quat_log(q.real);
  const float alpha = glm::length(half_angle_axis);  // in [0, pi/2] since w >= 0

  Transform out;
  out.rotation = glm::normalize(quat_exp(t * half_angle_axis));
  if (alpha < 1e-6f) {
    out.translation = t * p;
  } else {
    const glm::vec3 axis = half_angle_axis / alpha;
    const float pitch = glm::dot(p, axis);
    const glm::vec3 p_perp = p - pitch * axis;
    const float ratio = std::sin(t * alpha) / std::sin(alpha);
    const glm::vec3 turned = glm::angleAxis((t - 1.0f) * alpha, axis) * p_perp;
    out.translation = t * pitch * axis + ratio * turned;
  }
  return dual_quat_from_transform(out);
}

DualQuat dual_quat_sclerp(const DualQuat& a, const DualQuat& b, float t) {
  return a * dual_quat_pow(dual_quat_conjugate(a) * b, t);
}

namespace {

// Translation and scale mixed linearly, with the rotation the caller interpolated.
Transform mixed_with_rotation(const Transform& a, const Transform& b, float t,
                              const glm::quat& rotation) {
  Transform out;
  out.rotation = rotation;
  out.translation = glm::mix(a.translation, b.translation, t);
  out.scale = glm::mix(a.scale, b.scale, t);
  return out;
}

}  // namespace

Transform transform_nlerp(const Transform& a, const Transform& b, float t) {
  return mixed_with_rotation(a, b, t, quat_nlerp(a.rotation, b.rotation, t));
}

Transform transform_slerp(const Transform& a, const Transform& b, float t) {
  return mixed_with_rotation(a, b, t, quat_slerp(a.rotation, b.rotation, t));
}

Transform transform_sclerp(const Transform& a, const Transform& b, float t) {
  const DualQuat q = dual_quat_sclerp(dual_quat_from_transform(a), dual_quat_from_transform(b), t);
  Transform out = dual_quat_to_transform(q);
  out.rotation = glm::normalize(out.rotation);
  out.scale = glm::mix(a.scale, b.scale, t);
  return out;
}

Transform interpolate(const Transform& a, const Transform& b, float t, InterpolationMethod method) {
  switch (method) {
    case InterpolationMethod::Nlerp:
      return transform_nlerp(a, b, t);
    case InterpolationMethod::Slerp:
      return transform_slerp(a, b, t);
    case InterpolationMethod::Sclerp:
      return transform_sclerp(a, b, t);
  }
  return transform_nlerp(a, b, t);
}

Transform transform_hermite(const Transform& a, const glm::vec3& a_velocity,
                            const glm::vec3& a_angular_velocity, const Transform& b,
                            const glm::vec3& b_velocity, const glm::vec3& b_angular_velocity,
                            float duration, float t) {
  const float t2 = t * t;
  const float t3 = t2 * t;
  const float h00 = 2.0f * t3 - 3.0f * t2 + 1.0f;
  const float h10 = t3 - 2.0f * t2 + t;
  const float h01 = -2.0f * t3 + 3.0f * t2;
  const float h11 = t3 - t2;
  Transform out;
  out.translation = h00 * a.translation + h10 * duration * a_velocity + h01 * b.translation +
                    h11 * duration * b_velocity;
  out.scale = glm::mix(a.scale, b.scale, t);
  // Quaternion tangents: dq/dt = 0.5 * (0, w) * q, over the interval.
  const glm::quat qa = a.rotation;
  const float sign = glm::dot(a.rotation, b.rotation) < 0.0f ? -1.0f : 1.0f;
  const glm::quat qb = sign * b.rotation;
  const glm::quat ta = (0.5f * duration) * (glm::quat(0.0f, a_angular_velocity) * qa);
  const glm::quat tb = (0.5f * duration) * (glm::quat(0.0f, b_angular_velocity) * qb);
  const glm::quat q = h00 * qa + h10 * ta + h01 * qb + h11 * tb;
  const float length = glm::length(q);
  out.rotation = length > 1e-6f ? q / length : quat_nlerp(a.rotation, b.rotation, t);
  return out;
}

void sample_pose(std::span<const Transform> frames, int joint_count, float frame_time, float time,
                 InterpolationMethod method, WrapMode wrap, std::span<Transform> out) {
  MM_ASSERT(joint_count > 0 && frame_time > 0.0f);
  MM_ASSERT(!frames.empty() && frames.size() % static_cast<size_t>(joint_count) == 0);
  MM_ASSERT(out.size() == static_cast<size_t>(joint_count));
  const size_t joints = static_cast<size_t>(joint_count);
  const long frame_count = static_cast<long>(frames.size() / joints);

  // Frame positions are computed in double so long clips keep sub-frame precision.
  double position = std::isfinite(time) ? static_cast<double>(time) / frame_time : 0.0;
  long i0 = 0;
  long i1 = 0;
  if (wrap == WrapMode::Loop) {
    position = std::fmod(position, static_cast<double>(frame_count));
    if (position < 0.0) position += static_cast<double>(frame_count);
    i0 = clamped_integer<long>(std::floor(position));
    if (i0 >= frame_count) {  // fmod + frame_count can round up to exactly frame_count
      i0 = 0;
      position = 0.0;
    }
    i1 = (i0 + 1) % frame_count;
  } else {
    const double last = static_cast<double>(frame_count - 1);
    position = position < 0.0 ? 0.0 : (position > last ? last : position);
    i0 = clamped_integer<long>(std::floor(position));
    i1 = i0 + 1 < frame_count ? i0 + 1 : i0;
  }
  const float alpha = static_cast<float>(position - static_cast<double>(i0));

  const Transform* a = frames.data() + static_cast<size_t>(i0) * joints;
  const Transform* b = frames.data() + static_cast<size_t>(i1) * joints;
  if (alpha == 0.0f || i0 == i1) {
    for (size_t j = 0; j < joints; ++j) out[j] = a[j];
    return;
  }
  for (size_t j = 0; j < joints; ++j) out[j] = interpolate(a[j], b[j], alpha, method);
}

}  // namespace mm
