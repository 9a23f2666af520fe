#include "mm/runtime/pose_hermite.hpp"

#include <algorithm>
#include <cstddef>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/interpolation.hpp"

#include "quat_lanes.hpp"

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

using namespace lanes;

// Joints first .. first + 3 into out.
void hermite_x4(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                size_t first, std::span<Transform> out) {
  // transform_hermite's basis and tangent scales, in its order of operations.
  const float t2 = t * t;
  const float t3 = t2 * t;
  const __m128 h00 = c(2.0f * t3 - 3.0f * t2 + 1.0f);
  const __m128 h10 = c(t3 - 2.0f * t2 + t);
  const __m128 h01 = c(-2.0f * t3 + 3.0f * t2);
  const __m128 h11 = c(t3 - t2);
  const __m128 h10d = c((t3 - 2.0f * t2 + t) * duration);
  const __m128 h11d = c((t3 - t2) * duration);
  const __m128 half_duration = c(0.5f * duration);

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
  const __m128 flip = _mm_and_ps(_mm_cmplt_ps(dot(qa, qb), _mm_setzero_ps()), c(-0.0f));
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
  __m128 ones = c(1.0f);
  _MM_TRANSPOSE4_PS(x, y, z, ones);
  const __m128 rotations[4] = {rx, ry, rz, rw};
  const __m128 translations[4] = {x, y, z, ones};
  const int usable = _mm_movemask_ps(_mm_cmpgt_ps(length, c(1e-6f)));
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
