#pragma once
// Four quaternions or vectors, one SSE register per component: the runtime's pose loops that do
// the same arithmetic for every joint do it four joints at a time. Each operation is GLM's in its
// order of operations (no fused multiply-add: the build targets plain x86-64), so a lane's result
// equals the scalar GLM code's to the bit. Internal to the runtime's sources.

#if defined(__SSE2__)

#include <cstddef>

#include <immintrin.h>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/transform.hpp"

namespace mm::lanes {

inline __m128 c(float k) {
  return _mm_set1_ps(k);
}
inline __m128 mul(__m128 a, __m128 b) {
  return _mm_mul_ps(a, b);
}
inline __m128 add(__m128 a, __m128 b) {
  return _mm_add_ps(a, b);
}
inline __m128 sub(__m128 a, __m128 b) {
  return _mm_sub_ps(a, b);
}

struct Quat4 {
  __m128 w, x, y, z;
};

struct Vec4x3 {
  __m128 x, y, z;
};

static_assert(sizeof(glm::quat) == 16 && sizeof(glm::vec3) == 12);
static_assert(offsetof(glm::quat, x) == 0 && offsetof(glm::quat, w) == 12);
static_assert(offsetof(Transform, translation) + 16 <= sizeof(Transform));

// Four quaternions `stride` bytes apart (GLM's memory order x, y, z, w).
inline Quat4 load_quats(const glm::quat* q, size_t stride = sizeof(glm::quat)) {
  const char* p = reinterpret_cast<const char*>(q);
  __m128 r0 = _mm_loadu_ps(reinterpret_cast<const float*>(p));
  __m128 r1 = _mm_loadu_ps(reinterpret_cast<const float*>(p + stride));
  __m128 r2 = _mm_loadu_ps(reinterpret_cast<const float*>(p + 2 * stride));
  __m128 r3 = _mm_loadu_ps(reinterpret_cast<const float*>(p + 3 * stride));
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  return {r3, r0, r1, r2};
}

inline void store_quats(const Quat4& q, glm::quat* out, size_t stride = sizeof(glm::quat)) {
  __m128 x = q.x, y = q.y, z = q.z, w = q.w;
  _MM_TRANSPOSE4_PS(x, y, z, w);
  char* p = reinterpret_cast<char*>(out);
  _mm_storeu_ps(reinterpret_cast<float*>(p), x);
  _mm_storeu_ps(reinterpret_cast<float*>(p + stride), y);
  _mm_storeu_ps(reinterpret_cast<float*>(p + 2 * stride), z);
  _mm_storeu_ps(reinterpret_cast<float*>(p + 3 * stride), w);
}

// Twelve consecutive floats x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3 as x, y and z registers.
inline Vec4x3 load_vec3s(const glm::vec3* v) {
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

inline void store_vec3s(const Vec4x3& v, glm::vec3* out) {
  alignas(16) float x[4], y[4], z[4];
  _mm_store_ps(x, v.x);
  _mm_store_ps(y, v.y);
  _mm_store_ps(z, v.z);
  for (int i = 0; i < 4; ++i) out[i] = glm::vec3(x[i], y[i], z[i]);
}

// Four Transforms' translations (x, y, z) and, as the fourth register, their scales' x: the
// translation is followed by the scale in a Transform.
struct Translations4 {
  Vec4x3 t;
  __m128 scale_x;
};

inline Translations4 load_translations(const Transform* t) {
  __m128 r0 = _mm_loadu_ps(&t[0].translation.x), r1 = _mm_loadu_ps(&t[1].translation.x);
  __m128 r2 = _mm_loadu_ps(&t[2].translation.x), r3 = _mm_loadu_ps(&t[3].translation.x);
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  return {{r0, r1, r2}, r3};
}

// Writes the translations and the scales' x (the rest of each Transform is left alone).
inline void store_translations(const Vec4x3& v, __m128 scale_x, Transform* t) {
  __m128 x = v.x, y = v.y, z = v.z, s = scale_x;
  _MM_TRANSPOSE4_PS(x, y, z, s);
  _mm_storeu_ps(&t[0].translation.x, x);
  _mm_storeu_ps(&t[1].translation.x, y);
  _mm_storeu_ps(&t[2].translation.x, z);
  _mm_storeu_ps(&t[3].translation.x, s);
}

inline Quat4 transform_rotations(const Transform* t) {
  return load_quats(&t[0].rotation, sizeof(Transform));
}

// GLM's quaternion product p * q, component for component in its order.
inline Quat4 multiply(const Quat4& p, const Quat4& q) {
  return {sub(sub(sub(mul(p.w, q.w), mul(p.x, q.x)), mul(p.y, q.y)), mul(p.z, q.z)),
          sub(add(add(mul(p.w, q.x), mul(p.x, q.w)), mul(p.y, q.z)), mul(p.z, q.y)),
          sub(add(add(mul(p.w, q.y), mul(p.y, q.w)), mul(p.z, q.x)), mul(p.x, q.z)),
          sub(add(add(mul(p.w, q.z), mul(p.z, q.w)), mul(p.x, q.y)), mul(p.y, q.x))};
}

inline Quat4 scale(const Quat4& q, __m128 s) {
  return {_mm_mul_ps(q.w, s), _mm_mul_ps(q.x, s), _mm_mul_ps(q.y, s), _mm_mul_ps(q.z, s)};
}

inline Vec4x3 scale(const Vec4x3& v, __m128 s) {
  return {_mm_mul_ps(v.x, s), _mm_mul_ps(v.y, s), _mm_mul_ps(v.z, s)};
}

inline Quat4 add(const Quat4& p, const Quat4& q) {
  return {_mm_add_ps(p.w, q.w), _mm_add_ps(p.x, q.x), _mm_add_ps(p.y, q.y), _mm_add_ps(p.z, q.z)};
}

inline Vec4x3 add(const Vec4x3& a, const Vec4x3& b) {
  return {_mm_add_ps(a.x, b.x), _mm_add_ps(a.y, b.y), _mm_add_ps(a.z, b.z)};
}

// GLM's cross product.
inline Vec4x3 cross(const Vec4x3& x, const Vec4x3& y) {
  return {sub(mul(x.y, y.z), mul(y.y, x.z)), sub(mul(x.z, y.x), mul(y.z, x.x)),
          sub(mul(x.x, y.y), mul(y.x, x.y))};
}

// Component by component.
inline Vec4x3 times(const Vec4x3& a, const Vec4x3& b) {
  return {mul(a.x, b.x), mul(a.y, b.y), mul(a.z, b.z)};
}

// GLM's quaternion times vector: v + ((uv w) + uuv) 2 with uv = q.xyz x v, uuv = q.xyz x uv.
inline Vec4x3 rotate(const Quat4& q, const Vec4x3& v) {
  const Vec4x3 u{q.x, q.y, q.z};
  const Vec4x3 uv = cross(u, v);
  const Vec4x3 uuv = cross(u, uv);
  return add(v, scale(add(scale(uv, q.w), uuv), c(2.0f)));
}

// The sign bits of the lanes in `mask` flipped: -q there (exact), q elsewhere.
inline Quat4 negate_where(const Quat4& q, __m128 mask) {
  const __m128 flip = _mm_and_ps(mask, _mm_set1_ps(-0.0f));
  return {_mm_xor_ps(q.w, flip), _mm_xor_ps(q.x, flip), _mm_xor_ps(q.y, flip),
          _mm_xor_ps(q.z, flip)};
}

inline Quat4 conjugate(const Quat4& q) {
  const __m128 flip = _mm_set1_ps(-0.0f);
  return {q.w, _mm_xor_ps(q.x, flip), _mm_xor_ps(q.y, flip), _mm_xor_ps(q.z, flip)};
}

// GLM's quaternion dot: (w w + x x) + (y y + z z).
inline __m128 dot(const Quat4& a, const Quat4& b) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.w, b.w), _mm_mul_ps(a.x, b.x)),
                    _mm_add_ps(_mm_mul_ps(a.y, b.y), _mm_mul_ps(a.z, b.z)));
}

// GLM's vec3 dot: (x x + y y) + z z.
inline __m128 dot(const Vec4x3& a, const Vec4x3& b) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}

// glm::normalize of quaternions whose length is positive (the caller checks `length` > 0:
// GLM returns the identity otherwise).
inline Quat4 normalize(const Quat4& q, __m128& length) {
  length = _mm_sqrt_ps(dot(q, q));
  return scale(q, _mm_div_ps(_mm_set1_ps(1.0f), length));
}

}  // namespace mm::lanes

#endif
