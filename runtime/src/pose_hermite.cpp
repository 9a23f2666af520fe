#include "mm/runtime/pose_hermite.hpp"

#include <algorithm>
#include <cstddef>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/interpolation.hpp"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace mm {

namespace {

// One joint through transform_hermite itself: the reference, and what the lanes do.
Transform joint_hermite(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                        size_t j) {
  Transform ta, tb;
  ta.rotation = a.rotations[j];
  ta.translation = a.positions[j];
  tb.rotation = b.rotations[j];
  tb.translation = b.positions[j];
  return transform_hermite(ta, a.velocities[j], a.angular_velocities[j], tb, b.velocities[j],
                           b.angular_velocities[j], duration, t);
}

#if defined(__SSE2__)

// Four quaternions (GLM's memory order x, y, z, w) as one register per component.
struct Quat4 {
  __m128 w, x, y, z;
};

// Four vec3 as one register per component.
struct Vec4x3 {
  __m128 x, y, z;
};

static_assert(sizeof(glm::quat) == 16 && sizeof(glm::vec3) == 12);
static_assert(offsetof(glm::quat, x) == 0 && offsetof(glm::quat, w) == 12);

Quat4 load_quats(const glm::quat* q) {
  __m128 r0 = _mm_loadu_ps(&q[0].x), r1 = _mm_loadu_ps(&q[1].x);
  __m128 r2 = _mm_loadu_ps(&q[2].x), r3 = _mm_loadu_ps(&q[3].x);
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  return {r3, r0, r1, r2};
}

// Twelve consecutive floats x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3 to x, y and z registers.
Vec4x3 load_vec3s(const glm::vec3* v) {
  const float* f = &v[0].x;
  const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
  const __m128 x01 = _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 3, 0));  // x0 x1 x1 x1
  const __m128 x23 = _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2));  // x2 x2 x3 x3
  const __m128 y01 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1));  // y0 y0 y1 y1
  const __m128 y23 = _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3));  // y2 y2 y3 y3
  const __m128 z01 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2));  // z0 z0 z1 z1
  const __m128 z23 = _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0));  // z2 z2 z3 z3
  return {_mm_shuffle_ps(x01, x23, _MM_SHUFFLE(2, 0, 3, 0)),
          _mm_shuffle_ps(y01, y23, _MM_SHUFFLE(2, 0, 2, 0)),
          _mm_shuffle_ps(z01, z23, _MM_SHUFFLE(2, 0, 2, 0))};
}

// GLM's quaternion product p * q, component for component in its order.
Quat4 multiply(const Quat4& p, const Quat4& q) {
  const auto mul = _mm_mul_ps;
  const auto add = _mm_add_ps;
  const auto sub = _mm_sub_ps;
  return {sub(sub(sub(mul(p.w, q.w), mul(p.x, q.x)), mul(p.y, q.y)), mul(p.z, q.z)),
          sub(add(add(mul(p.w, q.x), mul(p.x, q.w)), mul(p.y, q.z)), mul(p.z, q.y)),
          sub(add(add(mul(p.w, q.y), mul(p.y, q.w)), mul(p.z, q.x)), mul(p.x, q.z)),
          sub(add(add(mul(p.w, q.z), mul(p.z, q.w)), mul(p.x, q.y)), mul(p.y, q.x))};
}

Quat4 scale(const Quat4& q, __m128 s) {
  return {_mm_mul_ps(q.w, s), _mm_mul_ps(q.x, s), _mm_mul_ps(q.y, s), _mm_mul_ps(q.z, s)};
}

Quat4 add(const Quat4& p, const Quat4& q) {
  return {_mm_add_ps(p.w, q.w), _mm_add_ps(p.x, q.x), _mm_add_ps(p.y, q.y), _mm_add_ps(p.z, q.z)};
}

// GLM's quaternion dot: (w w + x x) + (y y + z z).
__m128 dot(const Quat4& a, const Quat4& b) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.w, b.w), _mm_mul_ps(a.x, b.x)),
                    _mm_add_ps(_mm_mul_ps(a.y, b.y), _mm_mul_ps(a.z, b.z)));
}

// Joints first .. first + 3 into out.
void hermite_x4(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                size_t first, std::span<Transform> out) {
  // transform_hermite's basis and tangent scales, in its order of operations.
  const float t2 = t * t;
  const float t3 = t2 * t;
  const __m128 h00 = _mm_set1_ps(2.0f * t3 - 3.0f * t2 + 1.0f);
  const __m128 h10 = _mm_set1_ps(t3 - 2.0f * t2 + t);
  const __m128 h01 = _mm_set1_ps(-2.0f * t3 + 3.0f * t2);
  const __m128 h11 = _mm_set1_ps(t3 - t2);
  const __m128 h10d = _mm_set1_ps((t3 - 2.0f * t2 + t) * duration);
  const __m128 h11d = _mm_set1_ps((t3 - t2) * duration);
  const __m128 half_duration = _mm_set1_ps(0.5f * duration);

  // Translation: h00 a + (h10 d) va + h01 b + (h11 d) vb, summed left to right.
  const Vec4x3 pa = load_vec3s(&a.positions[first]);
  const Vec4x3 pb = load_vec3s(&b.positions[first]);
  const Vec4x3 va = load_vec3s(&a.velocities[first]);
  const Vec4x3 vb = load_vec3s(&b.velocities[first]);
  const auto curve = [&](__m128 p0, __m128 v0, __m128 p1, __m128 v1) {
    return _mm_add_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(h00, p0), _mm_mul_ps(h10d, v0)), _mm_mul_ps(h01, p1)),
        _mm_mul_ps(h11d, v1));
  };
  __m128 x = curve(pa.x, va.x, pb.x, vb.x);
  __m128 y = curve(pa.y, va.y, pb.y, vb.y);
  __m128 z = curve(pa.z, va.z, pb.z, vb.z);

  // Rotation: b on a's side, the tangents 0.5 d (0, w) q, the curve, normalized.
  const Quat4 qa = load_quats(&a.rotations[first]);
  Quat4 qb = load_quats(&b.rotations[first]);
  const __m128 flip = _mm_and_ps(_mm_cmplt_ps(dot(qa, qb), _mm_setzero_ps()), _mm_set1_ps(-0.0f));
  qb = {_mm_xor_ps(qb.w, flip), _mm_xor_ps(qb.x, flip), _mm_xor_ps(qb.y, flip),
        _mm_xor_ps(qb.z, flip)};
  const Vec4x3 wa = load_vec3s(&a.angular_velocities[first]);
  const Vec4x3 wb = load_vec3s(&b.angular_velocities[first]);
  const Quat4 ta = scale(multiply({_mm_setzero_ps(), wa.x, wa.y, wa.z}, qa), half_duration);
  const Quat4 tb = scale(multiply({_mm_setzero_ps(), wb.x, wb.y, wb.z}, qb), half_duration);
  const Quat4 q = add(add(add(scale(qa, h00), scale(ta, h10)), scale(qb, h01)), scale(tb, h11));
  const __m128 length = _mm_sqrt_ps(dot(q, q));
  __m128 rw = _mm_div_ps(q.w, length), rx = _mm_div_ps(q.x, length);
  __m128 ry = _mm_div_ps(q.y, length), rz = _mm_div_ps(q.z, length);

  // Back to one Transform per joint: the rotation's four floats, then the translation's three
  // with the scale's first (1) in the fourth, then the scale's other two.
  _MM_TRANSPOSE4_PS(rx, ry, rz, rw);
  __m128 ones = _mm_set1_ps(1.0f);
  _MM_TRANSPOSE4_PS(x, y, z, ones);
  const __m128 rotations[4] = {rx, ry, rz, rw};
  const __m128 translations[4] = {x, y, z, ones};
  const int usable = _mm_movemask_ps(_mm_cmpgt_ps(length, _mm_set1_ps(1e-6f)));
  for (size_t i = 0; i < 4; ++i) {
    Transform& o = out[first + i];
    _mm_storeu_ps(&o.rotation.x, rotations[i]);
    _mm_storeu_ps(&o.translation.x, translations[i]);
    o.scale.y = o.scale.z = 1.0f;
    // A curve through zero (opposite tangents): transform_hermite's fallback for this joint.
    if (!(usable & (1 << i))) o = joint_hermite(a, b, duration, t, first + i);
  }
}

#endif

}  // namespace

void pose_hermite(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                  std::span<Transform> out) {
  const size_t n = out.size();
  MM_ASSERT(a.rotations.size() == n && a.positions.size() == n && a.velocities.size() == n &&
            a.angular_velocities.size() == n);
  MM_ASSERT(b.rotations.size() == n && b.positions.size() == n && b.velocities.size() == n &&
            b.angular_velocities.size() == n);
#if defined(__SSE2__)
  if (n >= 4) {
    // Blocks of four; the last one ends at the last joint (it may redo joints of the one before,
    // to the same values), so nothing is read past the frames' arrays.
    for (size_t first = 0; first < n; first += 4)
      hermite_x4(a, b, duration, t, std::min(first, n - 4), out);
    return;
  }
#endif
  for (size_t j = 0; j < n; ++j) out[j] = joint_hermite(a, b, duration, t, j);
}

}  // namespace mm
