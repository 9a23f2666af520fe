#pragma once
// Triangle meshes and the bone segments they are built around and skinned to.
// Units as everywhere in the project: metres, Y up, right-handed. Triangles wind
// counter-clockwise seen from outside, so normals point out.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "mm/runtime/skinning.hpp"

namespace mm {

// An indexed triangle mesh: three indices per triangle into positions (and normals, which are
// either empty or one per position).
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<uint32_t> indices;

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
};

// One bone as a tapered capsule in bind space: the segment head -> tail with a radius at each
// end, owned by `joint` (the skeleton joint whose transform moves it; several segments may
// share a joint, e.g. the hips' segments to the spine and to both legs). A zero-length segment
// is a sphere.
struct BoneSegment {
  glm::vec3 head{0.0f};
  glm::vec3 tail{0.0f};
  float head_radius = 0.0f;
  float tail_radius = 0.0f;
  int joint = -1;
};

// A mesh bound to a skeleton: the mesh in bind pose, up to four influences per vertex, and the
// bind-pose global transform of every joint (inverse_bind_transforms() of it gives what the
// skinning functions need).
struct SkinnedMesh {
  TriangleMesh mesh;
  std::vector<VertexInfluences> influences;  // one per vertex
  std::vector<Transform> bind_global;        // one per skeleton joint
};

}  // namespace mm
