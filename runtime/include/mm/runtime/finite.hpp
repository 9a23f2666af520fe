#pragma once
// Whether GLM values are finite: every component neither NaN nor infinite. The robustness rules
// of every module (sanitized input, validated imports, refused options) test values with these.

#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm {

inline bool finite(float v) {
  return std::isfinite(v);
}

inline bool finite(const glm::vec2& v) {
  return std::isfinite(v.x) && std::isfinite(v.y);
}

inline bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline bool finite(const glm::quat& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

}  // namespace mm
