#pragma once
// The pieces the generated courses share (course.cpp, course2.cpp): meshes built in double in a
// part's own frame, the node that places each, the .glb written from them and the table's number
// format. Internal to world/.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace mm::course_mesh {

double radians(double degrees);

// "3", "16.34", "0.08": at most two decimals, no trailing zeros.
std::string metres(double v);

struct Mesh {
  std::vector<glm::dvec3> positions;
  std::vector<uint32_t> indices;

  uint32_t vertex(const glm::dvec3& p);

  // A triangle wound counter-clockwise seen from `outside` (a direction its normal should face).
  void triangle(uint32_t a, uint32_t b, uint32_t c, const glm::dvec3& outside);

  // A convex prism: `profile` (z, y) points in order around a convex polygon, extruded along x
  // from x0 to x1. Every face wound outward.
  void prism(const std::vector<glm::dvec2>& profile, double x0, double x1);

  void box(const glm::dvec3& low, const glm::dvec3& high);
};

// A patch of bumps: `field(u, v)` (metres into the patch) sampled every `cell` over `columns`
// by `rows` cells. Its mesh splits every cell along the diagonal from its (low u, low v) corner
// to its (high u, high v) corner; height() is that mesh's surface exactly.
struct HeightField {
  double (*field)(double u, double v);
  double cell;
  int columns;
  int rows;

  // The field at a grid vertex, as the mesh stores it (rounded to float).
  double vertex(int column, int row) const;
  double height(double u, double v) const;
  double top() const;
  // The patch's mesh, its (0, 0) corner at the origin, u along x and v along z.
  Mesh mesh() const;
};

// A part's node: its mesh in its own frame, where the node puts it.
struct Placed {
  std::string name;
  Mesh mesh;
  glm::dvec3 translation{0.0};
  double yaw_degrees = 0.0;
};

// The .glb of the parts, each a node (and a mesh) under one root node named `root_name`, the
// scene named the same: the same bytes on every run and machine (tinygltf's writer, positions
// rounded to float once).
std::vector<unsigned char> write_glb(const std::vector<Placed>& parts, const std::string& root_name,
                                     const std::string& generator);

}  // namespace mm::course_mesh
