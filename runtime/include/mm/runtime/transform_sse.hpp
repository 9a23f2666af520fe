#pragma once
// One quaternion, vector or transform in SSE registers: GLM's formulas for a single joint (the
// legs' two-bone solve and the refreshes after it), written so that each lane does GLM's
// operations in GLM's order. Built for plain x86-64 (no fused multiply-add), the results equal
// the scalar GLM code's to the bit; the scalar code, compiled one float at a time, spends most of
// its instructions moving components between registers. Without SSE2 the functions are GLM's.
//
// Lanes hold GLM's memory order: a quaternion's x, y, z, w; a vector's x, y, z and a fourth lane
// whose value no result depends on.

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/transform.hpp"

#if defined(__SSE2__)
#include <cstddef>

#include <immintrin.h>
#endif

namespace mm::sse {

#if defined(__SSE2__)

static_assert(sizeof(glm::quat) == 16 && offsetof(glm::quat, x) == 0 &&
              offsetof(glm::quat, w) == 12);
static_assert(sizeof(Transform) == 40 && offsetof(Transform, translation) == 16 &&
              offsetof(Transform, scale) == 28);

inline __m128 load(const glm::quat& q) {
  return _mm_loadu_ps(&q.x);
}

inline void store(__m128 q, glm::quat& out) {
  _mm_storeu_ps(&out.x, q);
}

// A vector's three floats (twelve bytes read, no more). x and y are read as one 64-bit lane
// through __m128i, a type that may alias the floats (a double read would not be).
inline __m128 load(const glm::vec3& v) {
  const __m128 xy = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&v.x)));
  return _mm_movelh_ps(xy, _mm_load_ss(&v.z));
}

inline glm::vec3 to_vec3(__m128 v) {
  alignas(16) float f[4];
  _mm_store_ps(f, v);
  return glm::vec3(f[0], f[1], f[2]);
}

inline glm::quat to_quat(__m128 q) {
  glm::quat out;
  store(q, out);
  return out;
}

// The lanes a, b, c, d of v. pshufd writes a register other than its source, where shufps
// overwrites its first operand and so needs a copy first whenever v is used again.
template <int a, int b, int c, int d>
inline __m128 lanes(__m128 v) {
  return _mm_castsi128_ps(_mm_shuffle_epi32(_mm_castps_si128(v), _MM_SHUFFLE(d, c, b, a)));
}

inline __m128 broadcast_w(__m128 q) {
  return lanes<3, 3, 3, 3>(q);
}

// GLM's quaternion product p * q. Its w is p.w q.w - p.x q.x - p.y q.y - p.z q.z and its x
// p.w q.x + p.x q.w + p.y q.z - p.z q.y (y and z alike): the second and third terms are added
// in the x, y, z lanes and subtracted in w, as additions of the negated products (a - b is
// a + (-b) in IEEE arithmetic, and negating a product is exact).
inline __m128 product(__m128 p, __m128 q) {
  const __m128 minus_w = _mm_set_ps(-0.0f, 0.0f, 0.0f, 0.0f);
  const __m128 first = _mm_mul_ps(broadcast_w(p), q);
  const __m128 second = _mm_xor_ps(_mm_mul_ps(lanes<0, 1, 2, 0>(p), lanes<3, 3, 3, 0>(q)), minus_w);
  const __m128 third = _mm_xor_ps(_mm_mul_ps(lanes<1, 2, 0, 1>(p), lanes<2, 0, 1, 1>(q)), minus_w);
  const __m128 fourth = _mm_mul_ps(lanes<2, 0, 1, 2>(p), lanes<1, 2, 0, 2>(q));
  return _mm_sub_ps(_mm_add_ps(_mm_add_ps(first, second), third), fourth);
}

inline __m128 conjugate(__m128 q) {
  return _mm_xor_ps(q, _mm_set_ps(0.0f, -0.0f, -0.0f, -0.0f));
}

// GLM's cross product: (x.y y.z - y.y x.z, x.z y.x - y.z x.x, x.x y.y - y.x x.y).
inline __m128 cross(__m128 x, __m128 y) {
  return _mm_sub_ps(_mm_mul_ps(lanes<1, 2, 0, 3>(x), lanes<2, 0, 1, 3>(y)),
                    _mm_mul_ps(lanes<1, 2, 0, 3>(y), lanes<2, 0, 1, 3>(x)));
}

// GLM's quaternion times vector: v + ((uv w) + uuv) 2 with uv = q.xyz x v, uuv = q.xyz x uv.
inline __m128 rotate(__m128 q, __m128 v) {
  const __m128 uv = cross(q, v);
  const __m128 uuv = cross(q, uv);
  return _mm_add_ps(v,
                    _mm_mul_ps(_mm_add_ps(_mm_mul_ps(uv, broadcast_w(q)), uuv), _mm_set1_ps(2.0f)));
}

// glm::normalize of a quaternion: its length sqrt((w w + x x) + (y y + z z)), the identity where
// that is zero (not where it is NaN: GLM's test is `length <= 0`), else each component times one
// over the length.
inline __m128 normalize(__m128 q) {
  const __m128 squares = _mm_mul_ps(q, q);
  const __m128 pairs = _mm_add_ps(squares, lanes<3, 2, 1, 0>(squares));  // x x + w w, y y + z z
  const __m128 length = _mm_sqrt_ss(_mm_add_ss(pairs, lanes<1, 1, 1, 1>(pairs)));
  if (_mm_cvtss_f32(length) <= 0.0f) return _mm_set_ps(1.0f, 0.0f, 0.0f, 0.0f);
  const __m128 inverse = _mm_div_ss(_mm_set_ss(1.0f), length);
  return _mm_mul_ps(q, lanes<0, 0, 0, 0>(inverse));
}

// compose(parent, child) (transform.hpp), written into `out` (which may be either argument).
inline void compose_into(const Transform& parent, const Transform& child, Transform& out) {
  const __m128 parent_rotation = load(parent.rotation);
  // The translation and the scale's x, then the scale from the translation's z on (both reads
  // stay inside the Transform).
  const __m128 parent_translation = _mm_loadu_ps(&parent.translation.x);
  const __m128 parent_scale = lanes<1, 2, 3, 3>(_mm_loadu_ps(&parent.translation.z));
  const __m128 child_translation = _mm_loadu_ps(&child.translation.x);
  const __m128 child_scale = lanes<1, 2, 3, 3>(_mm_loadu_ps(&child.translation.z));
  const __m128 rotation = product(parent_rotation, load(child.rotation));
  const __m128 translation = _mm_add_ps(
      rotate(parent_rotation, _mm_mul_ps(parent_scale, child_translation)), parent_translation);
  const __m128 scale = _mm_mul_ps(parent_scale, child_scale);
  store(rotation, out.rotation);
  // translation x, y, z and scale x; then scale y, z.
  const __m128 z_and_scale_x = _mm_shuffle_ps(translation, scale, _MM_SHUFFLE(0, 0, 2, 2));
  _mm_storeu_ps(&out.translation.x,
                _mm_shuffle_ps(translation, z_and_scale_x, _MM_SHUFFLE(2, 0, 1, 0)));
  _mm_storel_pi(reinterpret_cast<__m64*>(&out.scale.y), lanes<1, 2, 3, 3>(scale));
}

#else

inline void compose_into(const Transform& parent, const Transform& child, Transform& out) {
  out = compose(parent, child);
}

#endif

}  // namespace mm::sse
