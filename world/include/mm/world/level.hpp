#pragma once
// A level: the static collision geometry of a game's world, as triangles, and its reader for
// glTF 2.0 files (.gltf, .glb). What BulletWorld (bullet_world.hpp) answers the controller's
// queries over. See docs/world-levels.md.
//
// Reading a glTF file (load_level, parse_level):
// - Every mesh primitive of mode TRIANGLES (4, the default) of every node of the file's scene
//   (its "scene", else scene 0; a file without scenes: every node that is no node's child)
//   becomes triangles, with the node's global transform applied (the hierarchy's matrices or
//   TRS composed in double). A mesh used by several nodes is placed once per node. Y up,
//   metres, as glTF says.
// - Skipped: primitives of mode POINTS, LINES, LINE_LOOP and LINE_STRIP (no surface: markers,
//   debug lines), skins and morph targets (a level is static: the node's own transform places
//   the mesh), materials, textures and images (never decoded, never opened), cameras, lights,
//   animations. Refused: TRIANGLE_STRIP (5) and TRIANGLE_FAN (6) (triangulate on export; strips
//   mark restarts with degenerate triangles, which are refused below), unknown modes, any
//   extension the file lists in extensionsRequired (quantized or compressed meshes).
// - POSITION is FLOAT VEC3; indices are UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT SCALAR,
//   each naming a vertex of the primitive, their count a multiple of 3; without indices the
//   vertices are taken three by three. Sparse accessors are refused.
// - Refused, with a message naming the file and what is wrong: a file that is not glTF 2.0; no
//   triangles; a coordinate that is not finite (in the file or after the node transforms) or
//   beyond ±kMaxLevelCoordinate metres; a degenerate triangle (zero area, or a sliver: see
//   kMinTriangleAspect), named by node, mesh, primitive and triangle index ("<file>: node 2
//   'stairs', mesh 1 'steps', primitive 0, triangle 17 is degenerate: zero area"); more than
//   kMaxLevelTriangles triangles or kMaxLevelVertices vertices, counted from the accessors'
//   declared counts (times the nodes using each mesh) before anything is read or allocated, so a
//   file declaring a billion triangles costs nothing; an index out of range; a node hierarchy that
//   is not a tree.
// - External buffers follow the glTF importer's rules (mm/offline/gltf.hpp, "External files",
//   the same code): data: URIs, the GLB binary chunk, or a relative path to a regular file
//   inside the glTF file's folder; no absolute path, no "..", no symbolic link out of it, each
//   checked before any file is opened. LevelLoadOptions::allow_external_files false (bytes not
//   from a file) refuses every buffer that names a file.
//
// Precision: positions are floats relative to Level::origin, a double: the whole metre nearest
// the centre of the level's bounds. A vertex d metres from that centre is stored to within
// d * 2^-24 (0.06 mm at 1 km), wherever the level lies in the world: a level 100 km out is as
// exact as one at the world origin.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mm/runtime/result.hpp"

namespace mm {

// At most this many triangles in a level (5 million: a large streamed region of a game; about
// 100 bytes each once BulletWorld holds them, with its bounding volume tree: 0.5 GB).
inline constexpr uint64_t kMaxLevelTriangles = 5'000'000;
// At most this many vertices (three per triangle: no level needs more).
inline constexpr uint64_t kMaxLevelVertices = 3 * kMaxLevelTriangles;
// Every world coordinate of a level (and of a box added to a BulletWorld) lies within this many
// metres of the world origin, on each axis (100 km).
inline constexpr double kMaxLevelCoordinate = 100'000.0;
// A triangle is degenerate when its height over its longest side is less than this fraction of
// that side (zero area included): 1 mm over 100 m. Bullet takes a hit's normal from the float
// cross product of two sides, whose rounding error is about 1e-7 of the sides' lengths squared;
// a flatter triangle's normal would be mostly rounding. Checked on the float positions Bullet
// is given.
inline constexpr double kMinTriangleAspect = 1e-5;

// Static collision triangles. World position of vertex i = origin + positions[i] (in double).
struct Level {
  // Where the positions are measured from (metres, world frame).
  glm::dvec3 origin{0.0};
  // Vertex positions relative to `origin` (metres, Y up).
  std::vector<glm::vec3> positions;
  // Three vertex indices per triangle.
  std::vector<uint32_t> indices;

  size_t triangle_count() const { return indices.size() / 3; }

  // Checks what BulletWorld relies on, for a level made by hand: a finite origin; a multiple of
  // 3 indices, each naming a vertex; finite positions whose world coordinates lie within
  // ±kMaxLevelCoordinate; no degenerate triangle (kMinTriangleAspect); at most kMaxLevelTriangles
  // triangles and kMaxLevelVertices vertices. An empty level is valid (boxes alone).
  Status validate() const;
};

struct LevelLoadOptions {
  // Whether buffers may name files beside the glTF file. Off (bytes that came from anywhere but
  // a file: fuzzing, the network), only data: URIs and the GLB binary chunk are read.
  bool allow_external_files = true;
};

// Reads a .gltf or .glb file (binary when it starts with "glTF"). Errors start with the path.
Result<Level> load_level(const std::filesystem::path& path, const LevelLoadOptions& options = {});

// The same from bytes in memory; path_for_messages names them in errors and its folder is where
// external buffers are looked for (when allowed).
Result<Level> parse_level(std::span<const unsigned char> bytes,
                          const std::filesystem::path& path_for_messages,
                          const LevelLoadOptions& options = {});

}  // namespace mm
