#include "debug_lines.hpp"

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace mm::viewer {

void DebugLines::line(const glm::vec3& a, const glm::vec3& b, const glm::vec3& colour) {
  vertices_.push_back({a, colour});
  vertices_.push_back({b, colour});
}

void DebugLines::cross(const glm::vec3& p, float size, const glm::vec3& colour) {
  line(p - glm::vec3(size, 0, 0), p + glm::vec3(size, 0, 0), colour);
  line(p - glm::vec3(0, size, 0), p + glm::vec3(0, size, 0), colour);
  line(p - glm::vec3(0, 0, size), p + glm::vec3(0, 0, size), colour);
}

void DebugLines::circle(const glm::vec3& centre, float radius, const glm::vec3& colour,
                        int segments) {
  for (int i = 0; i < segments; ++i) {
    const float a0 = glm::two_pi<float>() * static_cast<float>(i) / static_cast<float>(segments);
    const float a1 =
        glm::two_pi<float>() * static_cast<float>(i + 1) / static_cast<float>(segments);
    line(centre + radius * glm::vec3(std::cos(a0), 0, std::sin(a0)),
         centre + radius * glm::vec3(std::cos(a1), 0, std::sin(a1)), colour);
  }
}

void DebugLines::arrow(const glm::vec3& from, const glm::vec3& direction, const glm::vec3& colour) {
  const glm::vec3 to = from + direction;
  line(from, to, colour);
  const glm::vec3 flat(direction.x, 0.0f, direction.z);
  const float length = glm::length(flat);
  if (length < 1e-4f) return;
  const glm::vec3 back = -flat / length * (0.25f * length);
  const glm::vec3 side = glm::vec3(-flat.z, 0.0f, flat.x) / length * (0.12f * length);
  line(to, to + back + side, colour);
  line(to, to + back - side, colour);
}

}  // namespace mm::viewer
