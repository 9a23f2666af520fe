// The test course (mm/world/course.hpp): its parts, their meshes, the .glb and the table.

#include "mm/world/course.hpp"

#include "course_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace mm {
namespace {

using course_mesh::HeightField;
using course_mesh::metres;
using course_mesh::Placed;
using course_mesh::RampProfile;
using course_mesh::StairsProfile;
using course_mesh::TurnedWall;

// ---------------------------------------------------------------------------------------------
// The layout (metres, degrees). Lanes run along +Z from kLaneStart, side by side along +X, each
// part a metre or more from the next so that a walk across one never touches another.

constexpr double kLaneStart = 3.0;

const glm::dvec2 kGroundLow{-3.0, -3.0};  // x, z
const glm::dvec2 kGroundHigh{35.0, 20.0};

// Ramps: up 1 m, a 2 m plateau, down, all kRampWidth wide.
struct Ramp {
  const char* name;
  RampProfile profile;
  double x;  // the lane's low x
};
constexpr Ramp kRamps[] = {{"ramp_10", {10.0, 1.0, 2.0}, 0.0},
                           {"ramp_20", {20.0, 1.0, 2.0}, 3.0},
                           {"ramp_30", {30.0, 1.0, 2.0}, 6.0}};
constexpr double kRampWidth = 2.0;

// Stairs: 6 risers up to a landing, as many down.
constexpr double kStairsX = 9.0;
constexpr double kStairsWidth = 2.0;
constexpr StairsProfile kStairs{6, 0.17, 0.30, 1.5};

// The rough patch: a smooth height field sampled every kRoughCell.
constexpr double kRoughX = 12.0;
constexpr double kRoughWidth = 3.0;
constexpr double kRoughLength = 6.0;
constexpr double kRoughCell = 0.1;
constexpr int kRoughColumns = 30;  // kRoughWidth / kRoughCell
constexpr int kRoughRows = 60;     // kRoughLength / kRoughCell

// Walls and boxes.
constexpr double kWallHeight = 2.0;
constexpr double kWallThickness = 0.3;
constexpr double kHeadOnX[2] = {16.0, 19.0};
constexpr double kHeadOnZ = 8.0;  // its face
// Turned 30° from +Z toward +X, one end of its face at (20.5, 5).
constexpr TurnedWall kTurned{20.5, 5.0, 6.0, 30.0, kWallThickness};
constexpr double kTurnedWalkX = 22.0;  // a walk along +Z here meets its face mid-length
constexpr double kBoxSide = 1.0;
struct Box {
  const char* name;
  double x;  // low x
  double top;
};
constexpr Box kBoxes[] = {{"box_low", 27.5, 0.3}, {"box_high", 30.5, 1.2}};
constexpr double kBoxZ = 6.0;

// The rough patch's height field at (u, v) metres into it: bumps on a window that brings it
// smoothly down to the ground within 0.3 m of its edges.
double rough_field(double u, double v) {
  const double bumps = 0.04 + 0.02 * std::sin(2.0 * std::numbers::pi * u / 0.9) +
                       0.02 * std::sin(2.0 * std::numbers::pi * v / 1.3 + 0.7);
  return course_mesh::edge_window(u, kRoughWidth, 0.3) *
         course_mesh::edge_window(v, kRoughLength, 0.3) * bumps;
}

constexpr HeightField kRough{rough_field, kRoughCell, kRoughColumns, kRoughRows};

std::vector<Placed> course_meshes() {
  std::vector<Placed> parts;
  parts.push_back(course_mesh::flat_ground(kGroundLow, kGroundHigh));
  for (const Ramp& ramp : kRamps) {
    parts.push_back(
        Placed{ramp.name, ramp.profile.mesh(kRampWidth), {ramp.x, 0.0, kLaneStart}, 0.0});
  }
  parts.push_back(Placed{"stairs", kStairs.mesh(kStairsWidth), {kStairsX, 0.0, kLaneStart}, 0.0});
  parts.push_back(Placed{"rough", kRough.mesh(), {kRoughX, 0.0, kLaneStart}, 0.0});
  {
    Placed wall{"wall_head_on", {}, {kHeadOnX[0], 0.0, kHeadOnZ}, 0.0};
    wall.mesh.box({0.0, 0.0, 0.0}, {kHeadOnX[1] - kHeadOnX[0], kWallHeight, kWallThickness});
    parts.push_back(std::move(wall));
  }
  parts.push_back(Placed{"wall_30",
                         kTurned.mesh(kWallHeight),
                         {kTurned.start_x, 0.0, kTurned.start_z},
                         kTurned.degrees});
  for (const Box& box : kBoxes) {
    Placed placed{box.name, {}, {box.x, 0.0, kBoxZ}, 0.0};
    placed.mesh.box({0.0, 0.0, 0.0}, {kBoxSide, box.top, kBoxSide});
    parts.push_back(std::move(placed));
  }
  return parts;
}

}  // namespace

std::vector<CoursePart> course_parts() {
  std::vector<CoursePart> parts;
  parts.push_back(course_mesh::ground_row(kGroundLow, kGroundHigh));
  for (const Ramp& ramp : kRamps) {
    parts.push_back(ramp.profile.row(ramp.name, ramp.x, kRampWidth, kLaneStart));
  }
  parts.push_back(kStairs.row("stairs", kStairsX, kStairsWidth, kLaneStart));
  parts.push_back(kRough.row("rough", kRoughX, kLaneStart));
  parts.push_back({"wall_head_on",
                   {kHeadOnX[0], kHeadOnX[1]},
                   {kHeadOnZ, kHeadOnZ + kWallThickness},
                   kWallHeight,
                   "wall across the lane, its face at z = " + metres(kHeadOnZ) +
                       course_mesh::walk(0.5 * (kHeadOnX[0] + kHeadOnX[1])) + " into it"});
  CoursePart turned = kTurned.row("wall_30", kWallHeight, kTurnedWalkX);
  turned.what += " and slide along it";
  parts.push_back(std::move(turned));
  for (const Box& box : kBoxes) {
    parts.push_back(course_mesh::box_row(box.name, "box", {box.x, box.x + kBoxSide},
                                         {kBoxZ, kBoxZ + kBoxSide}, box.top));
  }
  return parts;
}

std::string course_table_of(const std::vector<CoursePart>& parts) {
  std::string table = "| part | x (m) | z (m) | top (m) | what |\n|---|---|---|---|---|\n";
  for (const CoursePart& part : parts) {
    table += "| " + part.name + " | " + metres(part.x_range.x) + " to " + metres(part.x_range.y) +
             " | " + metres(part.z_range.x) + " to " + metres(part.z_range.y) + " | " +
             metres(part.top) + " | " + part.what + " |\n";
  }
  return table;
}

std::string course_table() {
  return course_table_of(course_parts());
}

double course_height(double x, double z) {
  auto inside = [](double v, double low, double high) { return v >= low && v <= high; };
  for (const Ramp& ramp : kRamps) {
    if (inside(x, ramp.x, ramp.x + kRampWidth) &&
        inside(z, kLaneStart, kLaneStart + ramp.profile.length())) {
      return ramp.profile.height(z - kLaneStart);
    }
  }
  if (inside(x, kStairsX, kStairsX + kStairsWidth) &&
      inside(z, kLaneStart, kLaneStart + kStairs.length())) {
    return kStairs.height(z - kLaneStart);
  }
  if (inside(x, kRoughX, kRoughX + kRoughWidth) &&
      inside(z, kLaneStart, kLaneStart + kRoughLength)) {
    return kRough.height(x - kRoughX, z - kLaneStart);
  }
  if (inside(x, kHeadOnX[0], kHeadOnX[1]) && inside(z, kHeadOnZ, kHeadOnZ + kWallThickness)) {
    return kWallHeight;
  }
  if (kTurned.contains(x, z)) return kWallHeight;
  for (const Box& box : kBoxes) {
    if (inside(x, box.x, box.x + kBoxSide) && inside(z, kBoxZ, kBoxZ + kBoxSide)) return box.top;
  }
  return 0.0;
}

std::vector<unsigned char> course_glb() {
  return course_mesh::write_glb(course_meshes(), "course", "mm-make-course (world/src/course.cpp)");
}

}  // namespace mm
