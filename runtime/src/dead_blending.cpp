#include "mm/runtime/dead_blending.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include "mm/runtime/assert.hpp"
#include "mm/runtime/atan2_polynomial.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/spring.hpp"
#include "quat_lanes.hpp"

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

// One joint of extrapolate() below.
void extrapolate_joint(DeadBlend& blend, size_t i, float keep, float travel) {
  Transform s = blend.source(i);
  const glm::vec3 v = blend.source_velocity(i);
  const glm::vec3 w = blend.source_angular_velocity(i);
  s.translation += v * travel;
  s.rotation = glm::normalize(quat_from_scaled_angle_axis(w * travel) * s.rotation);
  blend.set_source(i, s, negligible_to_zero(v * keep), negligible_to_zero(w * keep));
}

#if defined(__SSE2__)
using namespace lanes;

// quat_exp's series branch (interpolation.cpp), lane by lane; `ok` marks the lanes inside it.
Quat4 exp_series(const Vec4x3& h, __m128& ok) {
  const __m128 a2 = dot(h, h);
  ok = _mm_cmplt_ps(a2, c(0.25f));
  // k + a2 * rest, nested as the scalar series nests it.
  const auto term = [&](float k, __m128 rest) { return add(c(k), mul(a2, rest)); };
  const __m128 cosine =
      term(1.0f, term(-1.0f / 2.0f, term(1.0f / 24.0f, term(-1.0f / 720.0f, c(1.0f / 40320.0f)))));
  const __m128 sine_over_a = term(
      1.0f, term(-1.0f / 6.0f, term(1.0f / 120.0f, term(-1.0f / 5040.0f, c(1.0f / 362880.0f)))));
  return {cosine, mul(h.x, sine_over_a), mul(h.y, sine_over_a), mul(h.z, sine_over_a)};
}

// quat_to_scaled_angle_axis of quaternions through quat_log's series branch, lane by lane; `ok`
// marks the lanes inside it.
[[gnu::always_inline]] inline Vec4x3 scaled_angle_axis_series(const Quat4& q, __m128& ok) {
  const Quat4 a = negate_where(q, _mm_cmplt_ps(q.w, _mm_setzero_ps()));  // quat_abs
  const Vec4x3 v{a.x, a.y, a.z};
  const __m128 s2 = dot(v, v);
  const __m128 w2 = mul(a.w, a.w);
  ok = _mm_and_ps(_mm_cmpgt_ps(a.w, _mm_setzero_ps()),
                  _mm_cmplt_ps(s2, mul(mul(c(0.0625f), a.w), a.w)));
  const __m128 x2 = _mm_div_ps(s2, w2);
  // k + x2 * rest, nested as the scalar series nests it.
  const auto term = [&](float k, __m128 rest) { return add(c(k), mul(x2, rest)); };
  const __m128 atan_x_over_x = term(
      1.0f, term(-1.0f / 3.0f,
                 term(1.0f / 5.0f, term(-1.0f / 7.0f,
                                        term(1.0f / 9.0f, term(-1.0f / 11.0f, c(1.0f / 13.0f)))))));
  return scale(scale(v, _mm_div_ps(atan_x_over_x, a.w)), c(2.0f));
}

// atan2_polynomial(y, x) lane by lane (its coefficients, kAtanFit, in its order), for
// lanes whose larger magnitude is positive and finite (`ok`); the others are the library's in the
// scalar function. DeadBlending's tests hold the lanes to the scalar blend's bits.
__m128 atan2_polynomial_lanes(__m128 y, __m128 x, __m128& ok) {
  const __m128 sign = c(-0.0f);
  const __m128 ax = _mm_andnot_ps(sign, x);
  const __m128 ay = _mm_andnot_ps(sign, y);
  const __m128 x_larger = _mm_cmpgt_ps(ax, ay);
  const auto select = [](__m128 mask, __m128 a, __m128 b) {
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
  };
  const __m128 largest = select(x_larger, ax, ay);
  ok = _mm_and_ps(_mm_cmpgt_ps(largest, _mm_setzero_ps()), _mm_cmple_ps(largest, c(FLT_MAX)));
  const __m128 t = _mm_div_ps(select(x_larger, ay, ax), largest);
  const __m128 s = mul(t, t);
  __m128 p = c(kAtanFit[0]);
  for (int k = 1; k < 9; ++k) p = add(mul(p, s), c(kAtanFit[k]));
  __m128 angle = mul(t, p);
  angle = select(_mm_cmpgt_ps(ay, ax), sub(c(kAtanHalfPi), angle), angle);
  angle = select(_mm_cmplt_ps(x, _mm_setzero_ps()), sub(c(kAtanPi), angle), angle);
  return _mm_or_ps(_mm_andnot_ps(sign, angle), _mm_and_ps(sign, y));
}

// quat_to_scaled_angle_axis through quat_log's general branch (atan2_polynomial), lane by lane;
// `ok` marks the lanes it covers (not a zero vector part, nor the library's atan2).
[[gnu::always_inline]] inline Vec4x3 scaled_angle_axis_general(const Quat4& q, __m128& ok) {
  const Quat4 a = negate_where(q, _mm_cmplt_ps(q.w, _mm_setzero_ps()));  // quat_abs
  const Vec4x3 v{a.x, a.y, a.z};
  const __m128 s = _mm_sqrt_ps(dot(v, v));
  __m128 atan_ok;
  const __m128 angle = atan2_polynomial_lanes(s, a.w, atan_ok);
  ok = _mm_and_ps(_mm_cmpge_ps(s, c(1e-30f)), atan_ok);
  return scale(scale(v, _mm_div_ps(angle, s)), c(2.0f));
}

// The lanes outside a series (`ok` clear) take the logarithm's general branch in the lanes too;
// only a lane outside both (a vector part of zero length, or a quaternion that is not finite)
// and the exponential's lanes outside its series are redone by the scalar function. Lane by lane
// each result equals the scalar quat_to_scaled_angle_axis' and quat_exp's to the bit. The redoing
// is out of line so that the lanes' common path keeps its registers.
struct Lanes {
  alignas(16) float w[4], x[4], y[4], z[4];
};

[[gnu::noinline]] void scaled_angle_axis_outside(const Quat4& q, int inside, Vec4x3& d) {
  Lanes in, out;
  _mm_store_ps(in.w, q.w);
  _mm_store_ps(in.x, q.x);
  _mm_store_ps(in.y, q.y);
  _mm_store_ps(in.z, q.z);
  _mm_store_ps(out.x, d.x);
  _mm_store_ps(out.y, d.y);
  _mm_store_ps(out.z, d.z);
  for (int l = 0; l < 4; ++l) {
    if (inside & (1 << l)) continue;
    const glm::vec3 r = quat_to_scaled_angle_axis(glm::quat(in.w[l], in.x[l], in.y[l], in.z[l]));
    out.x[l] = r.x;
    out.y[l] = r.y;
    out.z[l] = r.z;
  }
  d = {_mm_load_ps(out.x), _mm_load_ps(out.y), _mm_load_ps(out.z)};
}

[[gnu::always_inline]] inline Vec4x3 scaled_angle_axis_lanes(const Quat4& q) {
  __m128 ok;
  Vec4x3 d = scaled_angle_axis_series(q, ok);
  int inside = _mm_movemask_ps(ok);
  if (inside != 0xF) {
    __m128 general_ok;
    const Vec4x3 g = scaled_angle_axis_general(q, general_ok);
    const __m128 take = _mm_andnot_ps(ok, general_ok);
    const auto pick = [&](__m128 a, __m128 b) {
      return _mm_or_ps(_mm_and_ps(take, a), _mm_andnot_ps(take, b));
    };
    d = {pick(g.x, d.x), pick(g.y, d.y), pick(g.z, d.z)};
    inside |= _mm_movemask_ps(take);
    if (inside != 0xF) scaled_angle_axis_outside(q, inside, d);
  }
  return d;
}

[[gnu::noinline]] void exp_outside(const Vec4x3& h, int inside, Quat4& q) {
  Lanes in, out;
  _mm_store_ps(in.x, h.x);
  _mm_store_ps(in.y, h.y);
  _mm_store_ps(in.z, h.z);
  _mm_store_ps(out.w, q.w);
  _mm_store_ps(out.x, q.x);
  _mm_store_ps(out.y, q.y);
  _mm_store_ps(out.z, q.z);
  for (int l = 0; l < 4; ++l) {
    if (inside & (1 << l)) continue;
    const glm::quat r = quat_exp(glm::vec3(in.x[l], in.y[l], in.z[l]));
    out.w[l] = r.w;
    out.x[l] = r.x;
    out.y[l] = r.y;
    out.z[l] = r.z;
  }
  q = {_mm_load_ps(out.w), _mm_load_ps(out.x), _mm_load_ps(out.y), _mm_load_ps(out.z)};
}

[[gnu::always_inline]] inline Quat4 exp_lanes(const Vec4x3& h) {
  __m128 ok;
  Quat4 q = exp_series(h, ok);
  const int inside = _mm_movemask_ps(ok);
  if (inside != 0xF) exp_outside(h, inside, q);
  return q;
}

// A group's rows as registers, and back.
Quat4 load_rotations(const DeadBlendSourceGroup& g) {
  return {_mm_load_ps(g.rotation[0]), _mm_load_ps(g.rotation[1]), _mm_load_ps(g.rotation[2]),
          _mm_load_ps(g.rotation[3])};
}

void store_rotations(const Quat4& q, DeadBlendSourceGroup& g) {
  _mm_store_ps(g.rotation[0], q.w);
  _mm_store_ps(g.rotation[1], q.x);
  _mm_store_ps(g.rotation[2], q.y);
  _mm_store_ps(g.rotation[3], q.z);
}

Vec4x3 load_rows(const float (&rows)[3][4]) {
  return {_mm_load_ps(rows[0]), _mm_load_ps(rows[1]), _mm_load_ps(rows[2])};
}

void store_rows(const Vec4x3& v, float (&rows)[3][4]) {
  _mm_store_ps(rows[0], v.x);
  _mm_store_ps(rows[1], v.y);
  _mm_store_ps(rows[2], v.z);
}

// The four joints of group g of extrapolate_joint; false (nothing written) when a lane's
// rotation has no length: the caller then steps that group's joints one by one.
bool extrapolate_x4(DeadBlendSourceGroup& g, float keep, float travel) {
  const __m128 travel4 = c(travel), keep4 = c(keep);
  const Vec4x3 v = load_rows(g.velocity);
  const Vec4x3 w = load_rows(g.angular_velocity);
  const Quat4 step = exp_lanes(scale(scale(w, travel4), c(0.5f)));
  __m128 length;
  const Quat4 rotation = normalize(multiply(step, load_rotations(g)), length);
  if (_mm_movemask_ps(_mm_cmpgt_ps(length, _mm_setzero_ps())) != 0xF) return false;
  store_rows(add(load_rows(g.translation), scale(v, travel4)), g.translation);
  store_rotations(rotation, g);
  // negligible_to_zero of the decayed velocities.
  const __m128 negligible = c(kSpringNegligible * kSpringNegligible);
  const auto decayed = [&](const Vec4x3& u) {
    const Vec4x3 k = scale(u, keep4);
    const __m128 zero = _mm_cmplt_ps(dot(k, k), negligible);
    return Vec4x3{_mm_andnot_ps(zero, k.x), _mm_andnot_ps(zero, k.y), _mm_andnot_ps(zero, k.z)};
  };
  store_rows(decayed(v), g.velocity);
  store_rows(decayed(w), g.angular_velocity);
  return true;
}
#endif

// Moves the source on by dt with velocities decaying at rate `decay` (1/s), exactly, so the
// result does not depend on how a span of time is cut into updates. Four joints at a time (every
// lane equal to extrapolate_joint's result to the bit).
void extrapolate(DeadBlend& blend, float decay, float dt) {
  const float keep = std::exp(-decay * dt);
  const float travel = decay > 0.0f ? (1.0f - keep) / decay : dt;
  const size_t n = static_cast<size_t>(blend.joints);
#if defined(__SSE2__)
  // Every group in the lanes, padding included (a joint at rest stays at rest).
  for (size_t g = 0; g < blend.groups.size(); ++g) {
    if (!extrapolate_x4(blend.groups[g], keep, travel)) {
      for (size_t j = 4 * g; j < std::min(n, 4 * g + 4); ++j)
        extrapolate_joint(blend, j, keep, travel);
    }
  }
#else
  for (size_t i = 0; i < n; ++i) extrapolate_joint(blend, i, keep, travel);
#endif
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
  const Transform s = blend.source(i);
  const Transform& in = incoming.local[i];
  const glm::vec3 d = quat_to_scaled_angle_axis(in.rotation * glm::conjugate(s.rotation));
  const glm::quat partial = quat_from_scaled_angle_axis(w.value * d);
  JointBlend out;
  out.pose.rotation = glm::normalize(partial * s.rotation);
  out.pose.translation = glm::mix(s.translation, in.translation, w.value);
  out.pose.scale = in.scale;
  if (!with_velocities) return out;
  const glm::vec3 vs = blend.source_velocity(i);
  const glm::vec3 ws = blend.source_angular_velocity(i);
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

#if defined(__SSE2__)
// The four joints of group g of blend_joint without velocities: `in` holds the group's four
// incoming joints (padding lanes at rest), the results go to out[0 .. count - 1]. A lane whose
// rotation has no length is done by blend_joint itself.
void blend_x4(const DeadBlend& blend, size_t g, const Transform* in, const PoseMotion& incoming,
              Weight w, size_t count, Transform* out) {
  const DeadBlendSourceGroup& s = blend.groups[g];
  const Quat4 source = load_rotations(s);
  __m128 length;
  const Vec4x3 d = scaled_angle_axis_lanes(multiply(transform_rotations(in), conjugate(source)));
  const Quat4 partial = exp_lanes(scale(scale(d, c(w.value)), c(0.5f)));
  const Quat4 rotation = normalize(multiply(partial, source), length);
  const int ok = _mm_movemask_ps(_mm_cmpgt_ps(length, _mm_setzero_ps()));
  // glm::mix: source (1 - w) + incoming w; the scale is the incoming one.
  const Translations4 ti = load_translations(in);
  const Vec4x3 translation =
      add(scale(load_rows(s.translation), c(1.0f - w.value)), scale(ti.t, c(w.value)));
  Transform full[4];
  Transform* o = count == 4 ? out : full;
  store_quats(rotation, &o[0].rotation, sizeof(Transform));
  store_translations(translation, ti.scale_x, o);
  for (size_t l = 0; l < count; ++l) {
    o[l].scale.y = in[l].scale.y;
    o[l].scale.z = in[l].scale.z;
    if (!(ok & (1 << l))) o[l] = blend_joint(blend, 4 * g + l, incoming, w, false).pose;
    if (o != out) out[l] = o[l];
  }
}

// The incoming side of four joints for the switch: poses and velocities.
struct Incoming4 {
  const Transform* local;
  Vec4x3 velocity, angular_velocity;
};

// A blend's velocity terms one lane at a time: what the lanes leave to the scalar Jacobians.
struct Rates4 {
  Lanes d, relative, partial_ws;
};

// The angular velocity of blend_joint, its Jacobians lane by lane (in double with the library's
// sine and cosine: they stay scalar), the vector sums in its order.
Vec4x3 blend_angular_velocities(const Vec4x3& d, const Vec4x3& relative, const Vec4x3& partial_ws,
                                Weight w) {
  Rates4 r;
  const auto put = [](const Vec4x3& v, Lanes& l) {
    _mm_store_ps(l.x, v.x);
    _mm_store_ps(l.y, v.y);
    _mm_store_ps(l.z, v.z);
  };
  put(d, r.d);
  put(relative, r.relative);
  put(partial_ws, r.partial_ws);
  Lanes out;
  for (int l = 0; l < 4; ++l) {
    const glm::vec3 dl(r.d.x[l], r.d.y[l], r.d.z[l]);
    const glm::vec3 d_rate = angular_velocity_to_rotation_vector_rate(
        dl, glm::vec3(r.relative.x[l], r.relative.y[l], r.relative.z[l]));
    const glm::vec3 a =
        rotation_vector_rate_to_angular_velocity(w.value * dl, w.rate * dl + w.value * d_rate) +
        glm::vec3(r.partial_ws.x[l], r.partial_ws.y[l], r.partial_ws.z[l]);
    out.x[l] = a.x;
    out.y[l] = a.y;
    out.z[l] = a.z;
  }
  return {_mm_load_ps(out.x), _mm_load_ps(out.y), _mm_load_ps(out.z)};
}

// Group g of the switch: blend_joint with velocities of its joints, written back as the new
// source. Lanes past `count` keep the source's joints at rest; a lane whose rotation has no
// length is done by blend_joint itself (before the group is overwritten: it reads the source).
void blend_switch_x4(DeadBlend& blend, size_t g, const Incoming4& in, const PoseMotion& outgoing,
                     Weight w, size_t count) {
  DeadBlendSourceGroup& s = blend.groups[g];
  const Quat4 source = load_rotations(s);
  const Vec4x3 st = load_rows(s.translation);
  const Vec4x3 vs = load_rows(s.velocity);
  const Vec4x3 ws = load_rows(s.angular_velocity);
  const Vec4x3 d =
      scaled_angle_axis_lanes(multiply(transform_rotations(in.local), conjugate(source)));
  const Quat4 partial = exp_lanes(scale(scale(d, c(w.value)), c(0.5f)));
  __m128 length;
  const Quat4 rotation = normalize(multiply(partial, source), length);
  const int ok = _mm_movemask_ps(_mm_cmpgt_ps(length, _mm_setzero_ps()));
  JointBlend redone[4];
  for (size_t l = 0; l < count; ++l) {
    if (!(ok & (1 << l))) redone[l] = blend_joint(blend, 4 * g + l, outgoing, w, true);
  }
  // glm::mix: a (1 - w) + b w.
  const Vec4x3 ti = load_translations(in.local).t;
  const __m128 keep = c(1.0f - w.value), take = c(w.value);
  const Vec4x3 translation = add(scale(st, keep), scale(ti, take));
  const Vec4x3 velocity =
      add(add(scale(vs, keep), scale(in.velocity, take)),
          scale(Vec4x3{sub(ti.x, st.x), sub(ti.y, st.y), sub(ti.z, st.z)}, c(w.rate)));
  const Vec4x3 exp_d_ws = rotate(exp_lanes(scale(d, c(0.5f))), ws);
  const Vec4x3 relative = {sub(in.angular_velocity.x, exp_d_ws.x),
                           sub(in.angular_velocity.y, exp_d_ws.y),
                           sub(in.angular_velocity.z, exp_d_ws.z)};
  const Vec4x3 angular_velocity = blend_angular_velocities(d, relative, rotate(partial, ws), w);
  // The joints' lanes replace the source's; the padding lanes keep theirs.
  const __m128 real = _mm_castsi128_ps(
      _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(static_cast<int>(count))));
  const auto keep_rest = [&](__m128 joint, __m128 rest) {
    return _mm_or_ps(_mm_and_ps(real, joint), _mm_andnot_ps(real, rest));
  };
  const auto put_rows = [&](const Vec4x3& v, float(&rows)[3][4]) {
    store_rows({keep_rest(v.x, _mm_load_ps(rows[0])), keep_rest(v.y, _mm_load_ps(rows[1])),
                keep_rest(v.z, _mm_load_ps(rows[2]))},
               rows);
  };
  store_rotations({keep_rest(rotation.w, source.w), keep_rest(rotation.x, source.x),
                   keep_rest(rotation.y, source.y), keep_rest(rotation.z, source.z)},
                  s);
  put_rows(translation, s.translation);
  put_rows(velocity, s.velocity);
  put_rows(angular_velocity, s.angular_velocity);
  for (size_t l = 0; l < count; ++l) {
    if (!(ok & (1 << l))) {
      blend.set_source(4 * g + l, redone[l].pose, redone[l].velocity, redone[l].angular_velocity);
    }
  }
}

// The switch during a blend: every group in the lanes, the last one's outgoing joints
// completed with joints at rest.
void blend_switch(DeadBlend& blend, const PoseMotion& outgoing, Weight w) {
  const size_t n = static_cast<size_t>(blend.joints);
  const auto vectors = [](std::span<const glm::vec3> v, size_t first, size_t count) {
    glm::vec3 four[4] = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
    if (!v.empty()) std::copy_n(&v[first], count, four);
    return load_vec3s(four);
  };
  for (size_t g = 0; g < blend.groups.size(); ++g) {
    const size_t first = 4 * g;
    const size_t count = std::min<size_t>(4, n - first);
    Transform local[4];
    std::copy_n(&outgoing.local[first], count, local);
    blend_switch_x4(blend, g,
                    {local, vectors(outgoing.velocities, first, count),
                     vectors(outgoing.angular_velocities, first, count)},
                    outgoing, w, count);
  }
}

// The blended pose alone, every group in the lanes; the last group's incoming joints are
// completed with joints at rest.
void blend_pose(const DeadBlend& blend, const PoseMotion& incoming, Weight w,
                std::span<Transform> out) {
  const size_t n = static_cast<size_t>(blend.joints);
  for (size_t g = 0; g < blend.groups.size(); ++g) {
    const size_t first = 4 * g;
    const size_t count = std::min<size_t>(4, n - first);
    if (count == 4) {
      blend_x4(blend, g, &incoming.local[first], incoming, w, 4, &out[first]);
      continue;
    }
    Transform in[4];
    std::copy_n(&incoming.local[first], count, in);
    blend_x4(blend, g, in, incoming, w, count, &out[first]);
  }
}
#endif

}  // namespace

void DeadBlend::resize(int joint_count) {
  MM_ASSERT(joint_count >= 0);
  joints = joint_count;
  groups.assign((static_cast<size_t>(joint_count) + 3) / 4, DeadBlendSourceGroup{});
  clear();
}

Transform DeadBlend::source(size_t j) const {
  const DeadBlendSourceGroup& g = groups[j / 4];
  const size_t l = j % 4;
  Transform t;
  t.rotation = glm::quat(g.rotation[0][l], g.rotation[1][l], g.rotation[2][l], g.rotation[3][l]);
  t.translation = glm::vec3(g.translation[0][l], g.translation[1][l], g.translation[2][l]);
  return t;
}

glm::vec3 DeadBlend::source_velocity(size_t j) const {
  const DeadBlendSourceGroup& g = groups[j / 4];
  const size_t l = j % 4;
  return glm::vec3(g.velocity[0][l], g.velocity[1][l], g.velocity[2][l]);
}

glm::vec3 DeadBlend::source_angular_velocity(size_t j) const {
  const DeadBlendSourceGroup& g = groups[j / 4];
  const size_t l = j % 4;
  return glm::vec3(g.angular_velocity[0][l], g.angular_velocity[1][l], g.angular_velocity[2][l]);
}

void DeadBlend::set_source(size_t j, const Transform& pose, const glm::vec3& velocity,
                           const glm::vec3& angular_velocity) {
  DeadBlendSourceGroup& g = groups[j / 4];
  const size_t l = j % 4;
  g.rotation[0][l] = pose.rotation.w;
  g.rotation[1][l] = pose.rotation.x;
  g.rotation[2][l] = pose.rotation.y;
  g.rotation[3][l] = pose.rotation.z;
  for (int k = 0; k < 3; ++k) {
    g.translation[k][l] = pose.translation[k];
    g.velocity[k][l] = velocity[k];
    g.angular_velocity[k][l] = angular_velocity[k];
  }
}

void DeadBlend::clear() {
  time = 0.0f;
  active = false;
}

void dead_blend_transition(DeadBlend& blend, const PoseMotion& outgoing, float blend_time) {
  const size_t n = static_cast<size_t>(blend.joints);
  MM_ASSERT(outgoing.local.size() == n);
  MM_ASSERT(outgoing.velocities.empty() || outgoing.velocities.size() == n);
  MM_ASSERT(outgoing.angular_velocities.empty() || outgoing.angular_velocities.size() == n);
  const Weight w = blend.active ? weight_at(blend.time, usable_length(blend_time)) : Weight{};
#if defined(__SSE2__)
  // During a blend the shown joints, four at a time, each lane equal to blend_joint's to the bit.
  if (w.value < 1.0f) {
    blend_switch(blend, outgoing, w);
    blend.time = 0.0f;
    blend.active = true;
    return;
  }
#endif
  for (size_t i = 0; i < n; ++i) {
    if (w.value < 1.0f) {
      const JointBlend shown = blend_joint(blend, i, outgoing, w, true);
      blend.set_source(i, shown.pose, shown.velocity, shown.angular_velocity);
    } else {
      blend.set_source(i, outgoing.local[i], at_or_zero(outgoing.velocities, i),
                       at_or_zero(outgoing.angular_velocities, i));
    }
  }
  blend.time = 0.0f;
  blend.active = true;
}

void dead_blend_update(DeadBlend& blend, const PoseMotion& incoming, float blend_time,
                       float decay_halflife, float dt, std::span<Transform> out_local,
                       std::span<glm::vec3> out_velocities,
                       std::span<glm::vec3> out_angular_velocities) {
  const size_t n = static_cast<size_t>(blend.joints);
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
  if (!blend.active) {
    // No blend: the incoming motion as it is, copied whole rather than joint by joint.
    std::copy_n(incoming.local.begin(), n, out_local.begin());
    for (size_t i = 0; i < out_velocities.size(); ++i)
      out_velocities[i] = at_or_zero(incoming.velocities, i);
    for (size_t i = 0; i < out_angular_velocities.size(); ++i)
      out_angular_velocities[i] = at_or_zero(incoming.angular_velocities, i);
    return;
  }
#if defined(__SSE2__)
  // The pose alone: four joints at a time, each lane equal to blend_joint's to the bit.
  if (!with_velocities) {
    blend_pose(blend, incoming, w, out_local);
    return;
  }
#endif
  for (size_t i = 0; i < n; ++i) {
    const JointBlend out = blend_joint(blend, i, incoming, w, with_velocities);
    out_local[i] = out.pose;
    if (!out_velocities.empty()) out_velocities[i] = out.velocity;
    if (!out_angular_velocities.empty()) out_angular_velocities[i] = out.angular_velocity;
  }
}

}  // namespace mm
