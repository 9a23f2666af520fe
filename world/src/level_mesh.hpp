#pragma once
// A level's triangles as Bullet's static triangle mesh: what BulletWorld (bullet_world.cpp)
// queries and BulletCharacters (bullet_character.cpp) walks capsules on. Internal to world/.

#include <BulletCollision/CollisionShapes/btBvhTriangleMeshShape.h>
#include <BulletCollision/CollisionShapes/btTriangleIndexVertexArray.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "mm/world/level.hpp"

namespace mm {

inline bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Every coordinate within `reach` of zero.
inline bool within(const glm::dvec3& v, double reach) {
  return std::abs(v.x) <= reach && std::abs(v.y) <= reach && std::abs(v.z) <= reach;
}

inline btVector3 to_bullet(const glm::dvec3& v) {
  return {static_cast<btScalar>(v.x), static_cast<btScalar>(v.y), static_cast<btScalar>(v.z)};
}

// Triangles per part of Bullet's mesh: its quantized tree keeps a triangle's index in 21 bits
// of a node (and the part in the 10 above them), so one part holds at most 2^21 triangles;
// kMaxLevelTriangles takes five parts of this size.
inline constexpr size_t kTrianglesPerPart = size_t{1} << 20;
static_assert(kMaxLevelTriangles / kTrianglesPerPart < 1024, "Bullet's mesh has 10 bits of parts");

// The triangles, owned here: Bullet's mesh interface points into them. Held on the heap by its
// owner and never moved, so the pointers stay valid.
struct LevelMesh {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
  std::unique_ptr<btBvhTriangleMeshShape> shape;  // null for a level without triangles

  // Copies the level's (validated) triangles and builds the shape over them, in the level's
  // frame (positions relative to level.origin).
  void build(const Level& level) {
    positions = level.positions;
    indices = level.indices;
    const size_t triangles = level.triangle_count();
    if (triangles == 0) return;
    mesh_interface = std::make_unique<btTriangleIndexVertexArray>();
    for (size_t first = 0; first < triangles; first += kTrianglesPerPart) {
      btIndexedMesh part;
      part.m_numTriangles = static_cast<int>(std::min(kTrianglesPerPart, triangles - first));
      part.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(indices.data() + first * 3);
      part.m_triangleIndexStride = 3 * sizeof(uint32_t);
      part.m_indexType = PHY_INTEGER;
      // Every part sees every vertex: the indices are the level's own.
      part.m_numVertices = static_cast<int>(positions.size());
      part.m_vertexBase = reinterpret_cast<const unsigned char*>(positions.data());
      part.m_vertexStride = sizeof(glm::vec3);
      part.m_vertexType = PHY_FLOAT;
      mesh_interface->addIndexedMesh(part, PHY_INTEGER);
    }
    shape = std::make_unique<btBvhTriangleMeshShape>(
        mesh_interface.get(), /*useQuantizedAabbCompression=*/true, /*buildBvh=*/true);
  }
};

}  // namespace mm
