#pragma once
// The pieces the generated courses share (course.cpp, course2.cpp): meshes built in double in a
// part's own frame, the node that places each, the .glb written from them and the table's number
// format. Internal to world/.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mm/world/course.hpp"

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

// 0 at a patch's edges, rising smoothly (smoothstep) to 1 at `margin` inside them: `s` metres
// into a patch `length` long. Bumps times it meet the flat ground without a step.
double edge_window(double s, double length, double margin);

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
  // Its row of the table, its (0, 0) corner at world (x, z), its lane along v through its middle.
  CoursePart row(const std::string& name, double x, double z) const;
};

// "; walk +Z at x = 1": how the table says where a part's lane is.
std::string walk(double x);

// A ramp along +Z: up at `degrees` to `rise`, a plateau `plateau` long, down at `degrees` again.
struct RampProfile {
  double degrees;
  double rise;
  double plateau;

  // Each slope's length along the lane, and the whole ramp's.
  double run() const;
  double length() const;
  // The surface's height `along` metres from its foot (0 off the ramp).
  double height(double along) const;
  // Its mesh: the profile (along = z, height = y) extruded along x over `width`.
  Mesh mesh(double width) const;
  // Its row of the table, its foot at z = `z` and its lane from x to x + width.
  CoursePart row(const std::string& name, double x, double width, double z) const;
};

// Stairs along +Z: `steps` risers up to a landing `landing` long, as many down.
struct StairsProfile {
  int steps;
  double riser;
  double tread;
  double landing;

  double length() const;
  double top() const;
  // The tread's height `along` metres from the first riser (0 off the stairs).
  double height(double along) const;
  // One box per tread (the landing is one): columns standing on y = 0, x over `width`.
  Mesh mesh(double width) const;
  CoursePart row(const std::string& name, double x, double width, double z) const;
};

// A wall turned about +Y: its face runs from (start_x, start_z) `length` metres along the
// direction `degrees` from +Z toward +X; `thickness` lies behind it (the side facing -X).
struct TurnedWall {
  double start_x;
  double start_z;
  double length;
  double degrees;
  double thickness;

  glm::dvec2 along() const;   // its face's direction (x, z)
  glm::dvec2 across() const;  // its own +x: out of its face
  // (x, z) in its own frame: the face along +z from 0 to length at x = 0, the thickness at
  // x in [-thickness, 0].
  glm::dvec2 frame(double x, double z) const;
  bool contains(double x, double z) const;
  // Its mesh in its own frame, `height` high; the node turns it by `degrees` at its start.
  Mesh mesh(double height) const;
  // Its row: bounds, and where a walk along +Z at walk_x meets its face.
  CoursePart row(const std::string& name, double height, double walk_x) const;
};

// A box's row: "what 1.2 by 1.2 m, 0.35 m high; walk +Z at x = ...", the lane through its middle.
CoursePart box_row(const std::string& name, const std::string& what, const glm::dvec2& x,
                   const glm::dvec2& z, double top);

// A part's node: its mesh in its own frame, where the node puts it.
struct Placed {
  std::string name;
  Mesh mesh;
  glm::dvec3 translation{0.0};
  double yaw_degrees = 0.0;
};

// The flat ground (y = 0) from low to high (x, z), as one quad, and its row.
Placed flat_ground(const glm::dvec2& low, const glm::dvec2& high);
CoursePart ground_row(const glm::dvec2& low, const glm::dvec2& high);

// The .glb of the parts, each a node (and a mesh) under one root node named `root_name`, the
// scene named the same: the same bytes on every run and machine (tinygltf's writer, positions
// rounded to float once).
std::vector<unsigned char> write_glb(const std::vector<Placed>& parts, const std::string& root_name,
                                     const std::string& generator);

}  // namespace mm::course_mesh
