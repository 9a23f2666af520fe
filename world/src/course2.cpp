// The second test course (mm/world/course.hpp, course2_*): the shapes of the first with other
// numbers everywhere, and shapes the first lacks (a ramp and stairs met from their top, a corner,
// a corridor, a kerb, a slope walked across), so that what was tuned on one is measured on the
// other. Its parts, their meshes, the .glb and the table.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "course_mesh.hpp"
#include "mm/world/course.hpp"

namespace mm {
namespace {

using course_mesh::HeightField;
using course_mesh::metres;
using course_mesh::Placed;
using course_mesh::radians;
using course_mesh::RampProfile;
using course_mesh::StairsProfile;
using course_mesh::TurnedWall;
using course_mesh::walk;

// ---------------------------------------------------------------------------------------------
// The layout (metres, degrees). Lanes run along +Z from kLaneStart, side by side along +X, each
// part a metre or more from the next.

constexpr double kLaneStart = 2.0;

const glm::dvec2 kGroundLow{-2.0, -2.0};  // x, z
const glm::dvec2 kGroundHigh{45.0, 16.0};

constexpr double kLaneWidth = 1.6;  // ramps and the rough patch's neighbours
constexpr double kStairsWidth = 1.8;

// Ramps up 0.8 m, across a 1.5 m plateau, and down.
struct Ramp {
  const char* name;
  RampProfile profile;
  double x;  // the lane's low x
};
constexpr Ramp kRamps[] = {{"ramp_15", {15.0, 0.8, 1.5}, 0.0}, {"ramp_25", {25.0, 0.8, 1.5}, 2.6}};

// A platform the walk starts on, then a ramp or stairs down from its edge.
constexpr double kPlatformStart = 0.5;  // z; the lane starts on it
constexpr double kPlatformEdge = 4.0;   // z of its edge
constexpr double kRampDownX = 5.2;
constexpr double kRampDownDegrees = 20.0;
constexpr double kRampDownTop = 0.7;
constexpr double kStairsDownX = 13.4;
constexpr int kStairsDownSteps = 4;
constexpr double kStairsDownRiser = 0.16;
constexpr double kStairsDownTread = 0.28;

// Stairs up to a landing and down again.
struct Stairs {
  const char* name;
  double x;
  StairsProfile profile;
};
constexpr Stairs kStairs[] = {{"stairs_12_35", 7.8, {5, 0.12, 0.35, 1.2}},
                              {"stairs_20_25", 10.6, {4, 0.20, 0.25, 1.0}}};

// The rough patch: a smooth height field sampled every kRoughCell.
constexpr double kRoughX = 16.2;
constexpr double kRoughWidth = 2.5;
constexpr double kRoughLength = 5.0;
constexpr double kRoughCell = 0.125;
constexpr int kRoughColumns = 20;  // kRoughWidth / kRoughCell
constexpr int kRoughRows = 40;     // kRoughLength / kRoughCell

// Walls turned from +Z toward +X, met by a walk along +Z.
constexpr double kWallHeight = 2.0;
constexpr double kTurnedThickness = 0.3;
struct Turned {
  const char* name;
  TurnedWall wall;
  double walk_x;  // a walk along +Z here meets its face
};
constexpr Turned kTurnedWalls[] = {{"wall_45", {20.2, 4.0, 5.0, 45.0, kTurnedThickness}, 21.2},
                                   {"wall_60", {24.8, 4.0, 4.0, 60.0, kTurnedThickness}, 25.8}};

// The corner: a wall across the lane and one along its +X side, meeting at kCornerAt (concave,
// seen from the lane). The corridor: two walls kCorridorWidth apart.
constexpr double kCornerThickness = 0.25;
constexpr double kCornerAt[2] = {31.8, 7.0};  // x of the side wall's face, z of the far wall's
constexpr double kCornerFarLowX = 29.3;
constexpr double kCornerSideStartZ = 3.0;
constexpr double kCornerWalkX = 31.3;
constexpr double kCorridorX = 33.25;  // its -X wall's face
constexpr double kCorridorWidth = 1.0;
constexpr double kCorridorThickness = 0.2;
constexpr double kCorridorZ[2] = {3.0, 9.0};

// Boxes across the lane.
struct Box {
  const char* name;
  double x[2];
  double z[2];
  double top;
  const char* what;
};
constexpr Box kBoxes[] = {{"kerb", {35.45, 37.45}, {5.0, 5.3}, 0.15, "kerb"},
                          {"box_35", {38.45, 39.65}, {5.0, 6.2}, 0.35, "box"}};

// A plane rising toward +X, walked along +Z (across its slope).
constexpr double kSlopeX = 40.65;
constexpr double kSlopeWidth = 3.0;
constexpr double kSlopeZ[2] = {1.0, 9.0};
constexpr double kSlopeDegrees = 12.0;

// ---------------------------------------------------------------------------------------------
// Profiles

double ramp_down_run() {
  return kRampDownTop / std::tan(radians(kRampDownDegrees));
}

double ramp_down_height(double z) {
  if (z < kPlatformStart || z >= kPlatformEdge + ramp_down_run()) return 0.0;
  if (z <= kPlatformEdge) return kRampDownTop;
  return kRampDownTop * (1.0 - (z - kPlatformEdge) / ramp_down_run());
}

double stairs_down_top() {
  return kStairsDownRiser * kStairsDownSteps;
}

double stairs_down_end() {
  return kPlatformEdge + (kStairsDownSteps - 1) * kStairsDownTread;
}

double stairs_down_height(double z) {
  if (z < kPlatformStart || z > stairs_down_end()) return 0.0;
  if (z < kPlatformEdge) return stairs_down_top();
  return kStairsDownRiser *
         (kStairsDownSteps - 1 - std::floor((z - kPlatformEdge) / kStairsDownTread));
}

// Bumps of other wavelengths and amplitude than the first course's, on a window that brings them
// smoothly down to the ground within 0.4 m of the patch's edges.
double rough_field(double u, double v) {
  const double bumps = 0.06 + 0.035 * std::sin(2.0 * std::numbers::pi * u / 1.1) +
                       0.025 * std::sin(2.0 * std::numbers::pi * v / 0.7 + 1.3);
  return course_mesh::edge_window(u, kRoughWidth, 0.4) *
         course_mesh::edge_window(v, kRoughLength, 0.4) * bumps;
}

constexpr HeightField kRough{rough_field, kRoughCell, kRoughColumns, kRoughRows};

double slope_top() {
  return kSlopeWidth * std::tan(radians(kSlopeDegrees));
}

struct Rect {
  double x0, x1, z0, z1;
};

// The corner's and the corridor's walls, as boxes on the ground.
std::vector<Rect> corner_walls() {
  return {{kCornerFarLowX, kCornerAt[0] + kCornerThickness, kCornerAt[1],
           kCornerAt[1] + kCornerThickness},
          {kCornerAt[0], kCornerAt[0] + kCornerThickness, kCornerSideStartZ, kCornerAt[1]}};
}
std::vector<Rect> corridor_walls() {
  return {{kCorridorX - kCorridorThickness, kCorridorX, kCorridorZ[0], kCorridorZ[1]},
          {kCorridorX + kCorridorWidth, kCorridorX + kCorridorWidth + kCorridorThickness,
           kCorridorZ[0], kCorridorZ[1]}};
}

// ---------------------------------------------------------------------------------------------
// Meshes, in each part's own frame

Placed rough_patch() {
  return Placed{"rough", kRough.mesh(), {kRoughX, 0.0, kLaneStart}, 0.0};
}

Placed boxes(const char* name, const std::vector<Rect>& rects, double height) {
  Placed placed{name, {}, {0.0, 0.0, 0.0}, 0.0};
  for (const Rect& r : rects) placed.mesh.box({r.x0, 0.0, r.z0}, {r.x1, height, r.z1});
  return placed;
}

void add_ramps_and_stairs(std::vector<Placed>& parts) {
  for (const Ramp& ramp : kRamps) {
    parts.push_back(
        Placed{ramp.name, ramp.profile.mesh(kLaneWidth), {ramp.x, 0.0, kLaneStart}, 0.0});
  }
  {
    Placed placed{"ramp_down_20", {}, {kRampDownX, 0.0, 0.0}, 0.0};
    placed.mesh.prism({{kPlatformStart, 0.0},
                       {kPlatformStart, kRampDownTop},
                       {kPlatformEdge, kRampDownTop},
                       {kPlatformEdge + ramp_down_run(), 0.0}},
                      0.0, kLaneWidth);
    parts.push_back(std::move(placed));
  }
  for (const Stairs& stairs : kStairs) {
    parts.push_back(
        Placed{stairs.name, stairs.profile.mesh(kStairsWidth), {stairs.x, 0.0, kLaneStart}, 0.0});
  }
  {
    // The platform, then one box per tread down.
    Placed placed{"stairs_down", {}, {kStairsDownX, 0.0, 0.0}, 0.0};
    placed.mesh.box({0.0, 0.0, kPlatformStart}, {kStairsWidth, stairs_down_top(), kPlatformEdge});
    for (int tread = 0; tread + 1 < kStairsDownSteps; ++tread) {
      const double z = kPlatformEdge + tread * kStairsDownTread;
      placed.mesh.box({0.0, 0.0, z}, {kStairsWidth, stairs_down_height(z + 0.5 * kStairsDownTread),
                                      z + kStairsDownTread});
    }
    parts.push_back(std::move(placed));
  }
}

std::vector<Placed> course2_meshes() {
  std::vector<Placed> parts;
  parts.push_back(course_mesh::flat_ground(kGroundLow, kGroundHigh));
  add_ramps_and_stairs(parts);
  parts.push_back(rough_patch());
  for (const Turned& t : kTurnedWalls) {
    parts.push_back(Placed{
        t.name, t.wall.mesh(kWallHeight), {t.wall.start_x, 0.0, t.wall.start_z}, t.wall.degrees});
  }
  parts.push_back(boxes("corner", corner_walls(), kWallHeight));
  parts.push_back(boxes("corridor", corridor_walls(), kWallHeight));
  for (const Box& box : kBoxes) {
    parts.push_back(boxes(box.name, {{box.x[0], box.x[1], box.z[0], box.z[1]}}, box.top));
  }
  {
    // Its profile (x across the slope, y) extruded along its own x; the node's quarter turn about
    // +Y takes its own z to world +x and its own x to world -z.
    Placed placed{"slope_across", {}, {kSlopeX, 0.0, 0.0}, 90.0};
    placed.mesh.prism({{0.0, 0.0}, {kSlopeWidth, 0.0}, {kSlopeWidth, slope_top()}}, -kSlopeZ[1],
                      -kSlopeZ[0]);
    parts.push_back(std::move(placed));
  }
  return parts;
}

// ---------------------------------------------------------------------------------------------
// The table's rows

void add_ramp_rows(std::vector<CoursePart>& parts) {
  for (const Ramp& ramp : kRamps) {
    parts.push_back(ramp.profile.row(ramp.name, ramp.x, kLaneWidth, kLaneStart));
  }
  parts.push_back({"ramp_down_20",
                   {kRampDownX, kRampDownX + kLaneWidth},
                   {kPlatformStart, kPlatformEdge + ramp_down_run()},
                   kRampDownTop,
                   "platform " + metres(kRampDownTop) + " m high (z " + metres(kPlatformStart) +
                       " to " + metres(kPlatformEdge) + "), " + metres(kRampDownDegrees) +
                       "° down from its edge (to " + metres(kPlatformEdge + ramp_down_run()) + ")" +
                       walk(kRampDownX + 0.5 * kLaneWidth) + " from its top"});
}

void add_stairs_rows(std::vector<CoursePart>& parts) {
  for (const Stairs& s : kStairs) {
    parts.push_back(s.profile.row(s.name, s.x, kStairsWidth, kLaneStart));
  }
  parts.push_back({"stairs_down",
                   {kStairsDownX, kStairsDownX + kStairsWidth},
                   {kPlatformStart, stairs_down_end()},
                   stairs_down_top(),
                   "platform " + metres(stairs_down_top()) + " m high (z " +
                       metres(kPlatformStart) + " to " + metres(kPlatformEdge) + "), " +
                       std::to_string(kStairsDownSteps) + " risers of " + metres(kStairsDownRiser) +
                       " m down (treads " + metres(kStairsDownTread) + " m, to " +
                       metres(stairs_down_end()) + ")" + walk(kStairsDownX + 0.5 * kStairsWidth) +
                       " from its top"});
}

void add_wall_rows(std::vector<CoursePart>& parts) {
  for (const Turned& t : kTurnedWalls) parts.push_back(t.wall.row(t.name, kWallHeight, t.walk_x));
  parts.push_back({"corner",
                   {kCornerFarLowX, kCornerAt[0] + kCornerThickness},
                   {kCornerSideStartZ, kCornerAt[1] + kCornerThickness},
                   kWallHeight,
                   "a wall across (face z = " + metres(kCornerAt[1]) +
                       ") meeting one along the +X " + "side (face x = " + metres(kCornerAt[0]) +
                       ", from z = " + metres(kCornerSideStartZ) + "), concave" +
                       walk(kCornerWalkX) + " into the corner"});
  parts.push_back(
      {"corridor",
       {kCorridorX - kCorridorThickness, kCorridorX + kCorridorWidth + kCorridorThickness},
       {kCorridorZ[0], kCorridorZ[1]},
       kWallHeight,
       "two walls " + metres(kCorridorWidth) + " m apart (faces x = " + metres(kCorridorX) +
           " and " + metres(kCorridorX + kCorridorWidth) + ")" +
           walk(kCorridorX + 0.5 * kCorridorWidth) + " along it"});
}

}  // namespace

std::vector<CoursePart> course2_parts() {
  std::vector<CoursePart> parts;
  parts.push_back(course_mesh::ground_row(kGroundLow, kGroundHigh));
  add_ramp_rows(parts);
  add_stairs_rows(parts);
  parts.push_back(kRough.row("rough", kRoughX, kLaneStart));
  add_wall_rows(parts);
  for (const Box& box : kBoxes) {
    parts.push_back(course_mesh::box_row(box.name, box.what, {box.x[0], box.x[1]},
                                         {box.z[0], box.z[1]}, box.top));
  }
  parts.push_back({"slope_across",
                   {kSlopeX, kSlopeX + kSlopeWidth},
                   {kSlopeZ[0], kSlopeZ[1]},
                   slope_top(),
                   "a plane rising " + metres(kSlopeDegrees) + "° toward +X" +
                       walk(kSlopeX + 0.5 * kSlopeWidth) + " across its slope"});
  return parts;
}

std::string course2_table() {
  return course_table_of(course2_parts());
}

double course2_height(double x, double z) {
  auto inside = [](double v, double low, double high) { return v >= low && v <= high; };
  auto in_rect = [&](const Rect& r) { return inside(x, r.x0, r.x1) && inside(z, r.z0, r.z1); };
  for (const Ramp& ramp : kRamps) {
    if (inside(x, ramp.x, ramp.x + kLaneWidth) &&
        inside(z, kLaneStart, kLaneStart + ramp.profile.length())) {
      return ramp.profile.height(z - kLaneStart);
    }
  }
  if (inside(x, kRampDownX, kRampDownX + kLaneWidth)) return ramp_down_height(z);
  for (const Stairs& stairs : kStairs) {
    if (inside(x, stairs.x, stairs.x + kStairsWidth)) return stairs.profile.height(z - kLaneStart);
  }
  if (inside(x, kStairsDownX, kStairsDownX + kStairsWidth)) return stairs_down_height(z);
  if (inside(x, kRoughX, kRoughX + kRoughWidth) &&
      inside(z, kLaneStart, kLaneStart + kRoughLength)) {
    return kRough.height(x - kRoughX, z - kLaneStart);
  }
  for (const Turned& t : kTurnedWalls) {
    if (t.wall.contains(x, z)) return kWallHeight;
  }
  for (const Rect& r : corner_walls()) {
    if (in_rect(r)) return kWallHeight;
  }
  for (const Rect& r : corridor_walls()) {
    if (in_rect(r)) return kWallHeight;
  }
  for (const Box& box : kBoxes) {
    if (in_rect({box.x[0], box.x[1], box.z[0], box.z[1]})) return box.top;
  }
  if (inside(x, kSlopeX, kSlopeX + kSlopeWidth) && inside(z, kSlopeZ[0], kSlopeZ[1])) {
    return (x - kSlopeX) / kSlopeWidth * slope_top();
  }
  return 0.0;
}

std::vector<unsigned char> course2_glb() {
  return course_mesh::write_glb(course2_meshes(), "course2",
                                "mm-make-course --course 2 (world/src/course2.cpp)");
}

}  // namespace mm
