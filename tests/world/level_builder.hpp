#pragma once
// Levels made by hand for the world's tests (bullet_world_test.cpp, step_height_test.cpp):
// triangles, quads, floors and boxes in the level's own frame.

#include <cstdint>

#include <glm/glm.hpp>

#include "mm/world/level.hpp"

namespace mm::test {

// Levels made by hand, in the level's own frame.
struct LevelBuilder {
  Level level;

  void triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const uint32_t first = static_cast<uint32_t>(level.positions.size());
    level.positions.insert(level.positions.end(), {a, b, c});
    level.indices.insert(level.indices.end(), {first, first + 1, first + 2});
  }
  void quad(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  // A flat square at height y, x and z in [-half, half].
  void floor(float half, float y = 0.0f) {
    quad({-half, y, -half}, {half, y, -half}, {half, y, half}, {-half, y, half});
  }
  // An axis-aligned box, all six faces.
  void box(const glm::vec3& lo, const glm::vec3& hi) {
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                            {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                            {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    quad(c[0], c[1], c[2], c[3]);
    quad(c[5], c[4], c[7], c[6]);
    quad(c[4], c[0], c[3], c[7]);
    quad(c[1], c[5], c[6], c[2]);
    quad(c[3], c[2], c[6], c[7]);
    quad(c[4], c[5], c[1], c[0]);
  }
};

}  // namespace mm::test
