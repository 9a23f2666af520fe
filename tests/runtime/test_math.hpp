#pragma once
// Small helpers shared by the runtime tests: deterministic random rotations and transforms,
// and comparisons of rotations up to the sign of the quaternion.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/finite.hpp"
#include "mm/runtime/transform.hpp"

namespace mm::test {

// A fixed-seed generator so every run sees the same "random" cases.
inline std::mt19937& rng() {
  static std::mt19937 generator(12345u);
  return generator;
}

inline float uniform(float lo, float hi) {
  return std::uniform_real_distribution<float>(lo, hi)(rng());
}

inline glm::vec3 random_vec3(float lo, float hi) {
  return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)};
}

inline glm::vec3 random_unit_vec3() {
  for (;;) {
    const glm::vec3 v = random_vec3(-1.0f, 1.0f);
    const float len = glm::length(v);
    if (len > 0.1f && len <= 1.0f) return v / len;
  }
}

// A rotation of a random angle in [min_angle, max_angle] radians about a random axis.
inline glm::quat random_rotation(float min_angle = 0.0f, float max_angle = 3.1f) {
  return glm::angleAxis(uniform(min_angle, max_angle), random_unit_vec3());
}

inline Transform random_transform(float max_translation = 2.0f) {
  Transform t;
  t.rotation = random_rotation();
  t.translation = random_vec3(-max_translation, max_translation);
  return t;
}

// The angle (radians) of the rotation from a to b: conjugate(a) * b in double precision, then
// atan2 of its vector length and |w| (accurate for tiny angles too, unlike acos of a dot).
inline double rotation_angle_between(const glm::quat& a, const glm::quat& b) {
  const glm::dquat r =
      glm::conjugate(glm::dquat(a.w, a.x, a.y, a.z)) * glm::dquat(b.w, b.x, b.y, b.z);
  return 2.0 * std::atan2(std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z), std::abs(r.w));
}

// True when a and b are the same rotation (q or -q) within tol, component-wise.
inline ::testing::AssertionResult same_rotation(const glm::quat& a, const glm::quat& b, float tol) {
  const glm::quat bs = glm::dot(a, b) < 0.0f ? -b : b;
  const float err = std::max(std::max(std::abs(a.w - bs.w), std::abs(a.x - bs.x)),
                             std::max(std::abs(a.y - bs.y), std::abs(a.z - bs.z)));
  if (err <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "rotations differ by " << err << ": (" << a.w << ", " << a.x << ", " << a.y << ", "
         << a.z << ") vs (" << bs.w << ", " << bs.x << ", " << bs.y << ", " << bs.z << ")";
}

inline ::testing::AssertionResult near_vec3(const glm::vec3& a, const glm::vec3& b, float tol) {
  const float err = glm::length(a - b);
  if (err <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "vectors differ by " << err << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs ("
         << b.x << ", " << b.y << ", " << b.z << ")";
}

// Whether no component is a subnormal float (whose arithmetic is slow on x86).
inline bool no_subnormal(const glm::vec3& v) {
  return std::fpclassify(v.x) != FP_SUBNORMAL && std::fpclassify(v.y) != FP_SUBNORMAL &&
         std::fpclassify(v.z) != FP_SUBNORMAL;
}

}  // namespace mm::test
