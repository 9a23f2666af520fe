#pragma once
// Draws the scene: a ground plane with a metre grid, or a level's static triangles (lit, each
// face flat), the character's skinned body (lit, with a shadow flattened onto the ground under
// it), and debug lines. OpenGL 3.3 core; every GL object is made
// in create() and reused, the body's and the lines' vertex buffers are refilled each frame.
// Needs a current context for its whole life.

#include <span>

#include <glm/glm.hpp>

#include "debug_lines.hpp"
#include "mm/runtime/mesh.hpp"
#include "mm/runtime/result.hpp"

namespace mm::viewer {

struct CameraMatrices {
  glm::mat4 view{1.0f};
  glm::mat4 projection{1.0f};
  glm::vec3 eye{0.0f};
};

class Renderer {
 public:
  // Compiles the shaders (the message holds the compiler's log) and makes the buffers.
  static Result<Renderer> create();
  Renderer(Renderer&& other) noexcept;
  Renderer& operator=(Renderer&& other) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;
  ~Renderer();

  // The body's triangles (indices into the vertices given to draw_body).
  void set_body_triangles(std::span<const uint32_t> indices);
  // A level's triangles (world positions, three indices a triangle), drawn by draw_level with a
  // flat normal per face; uploaded once.
  void set_level(std::span<const glm::vec3> positions, std::span<const uint32_t> indices);

  // Clears the framebuffer (the sky colour) and sets the viewport.
  void begin(unsigned framebuffer, int width, int height);
  // The ground around `focus` (its grid is fixed in the world, so motion over it shows).
  void draw_ground(const CameraMatrices& camera, const glm::vec3& focus);
  // The level given to set_level, if any.
  void draw_level(const CameraMatrices& camera);
  // The body in its current pose, and its shadow on the ground at `ground_height` (the plane
  // the shadow is flattened onto).
  void draw_body(const CameraMatrices& camera, std::span<const glm::vec3> positions,
                 std::span<const glm::vec3> normals, const glm::vec3& colour,
                 float ground_height = 0.0f);
  // Lines, depth-tested against the scene or drawn over it.
  void draw_lines(const CameraMatrices& camera, const DebugLines& lines, bool over_scene);

 private:
  Renderer() = default;
  void release();
  Status build();

  unsigned mesh_program_ = 0, ground_program_ = 0, line_program_ = 0;
  unsigned body_vao_ = 0, body_positions_ = 0, body_normals_ = 0, body_indices_ = 0;
  unsigned ground_vao_ = 0, ground_vbo_ = 0;
  unsigned line_vao_ = 0, line_vbo_ = 0;
  unsigned level_vao_ = 0, level_vbo_ = 0;
  int body_index_count_ = 0;
  int level_vertex_count_ = 0;
};

}  // namespace mm::viewer
