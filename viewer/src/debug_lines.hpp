#pragma once
// A list of coloured line segments for the debug drawing, rebuilt every frame (cleared, not
// freed, so it stops allocating once it has grown to a frame's size).

#include <vector>

#include <glm/glm.hpp>

namespace mm::viewer {

struct LineVertex {
  glm::vec3 position;
  glm::vec3 colour;
};

class DebugLines {
 public:
  void clear() { vertices_.clear(); }
  void line(const glm::vec3& a, const glm::vec3& b, const glm::vec3& colour);
  // Three axis-aligned strokes of this half-size through p.
  void cross(const glm::vec3& p, float size, const glm::vec3& colour);
  // A circle on the horizontal plane through centre.
  void circle(const glm::vec3& centre, float radius, const glm::vec3& colour, int segments = 24);
  // A line from `from` along `direction` with a two-stroke head in the horizontal plane.
  void arrow(const glm::vec3& from, const glm::vec3& direction, const glm::vec3& colour);

  const std::vector<LineVertex>& vertices() const { return vertices_; }

 private:
  std::vector<LineVertex> vertices_;
};

}  // namespace mm::viewer
