#pragma once
// Draws a crowd's bones with instancing: one unit box mesh, one instance per bone of every
// character (crowd_view.hpp's BoneInstance: a model matrix and a colour, streamed into one
// buffer per frame), so all characters are one draw call for their shadows on the ground and
// one for their lit bodies (glDrawArraysInstanced, OpenGL 3.3 core). Needs a current context for
// its whole life.

#include <span>

#include "crowd_view.hpp"
#include "mm/runtime/result.hpp"
#include "renderer.hpp"

namespace mm::viewer {

class CrowdRenderer {
 public:
  static Result<CrowdRenderer> create();
  CrowdRenderer(CrowdRenderer&& other) noexcept;
  CrowdRenderer& operator=(CrowdRenderer&& other) noexcept;
  CrowdRenderer(const CrowdRenderer&) = delete;
  CrowdRenderer& operator=(const CrowdRenderer&) = delete;
  ~CrowdRenderer();

  // Every bone: their shadows flattened onto the ground (y = 0), then the lit boxes.
  void draw(const CameraMatrices& camera, std::span<const BoneInstance> bones);

 private:
  CrowdRenderer() = default;
  Status build();
  void release();

  unsigned program_ = 0, vao_ = 0, mesh_ = 0, instances_ = 0;
  int vertex_count_ = 0;
};

}  // namespace mm::viewer
