// The test course (mm/world/course.hpp): its parts, their meshes, the .glb and the table.

#include "mm/world/course.hpp"

#include "course_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace mm {
namespace {

using course_mesh::HeightField;
using course_mesh::Mesh;
using course_mesh::metres;
using course_mesh::Placed;
using course_mesh::radians;

// ---------------------------------------------------------------------------------------------
// The layout (metres, degrees). Lanes run along +Z from kLaneStart, side by side along +X, each
// part a metre or more from the next so that a walk across one never touches another.

constexpr double kLaneStart = 3.0;

constexpr double kGroundLow[2] = {-3.0, -3.0};  // x, z
constexpr double kGroundHigh[2] = {35.0, 20.0};

// Ramps: up, a plateau, down, all kRampWidth wide.
struct Ramp {
  const char* name;
  double degrees;
  double x;  // the lane's low x
};
constexpr Ramp kRamps[] = {{"ramp_10", 10.0, 0.0}, {"ramp_20", 20.0, 3.0}, {"ramp_30", 30.0, 6.0}};
constexpr double kRampWidth = 2.0;
constexpr double kRampRise = 1.0;
constexpr double kRampPlateau = 2.0;

// Stairs: kSteps risers up to a landing, as many down.
constexpr double kStairsX = 9.0;
constexpr double kStairsWidth = 2.0;
constexpr int kSteps = 6;
constexpr double kRiser = 0.17;
constexpr double kTread = 0.30;
constexpr double kLanding = 1.5;

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
constexpr double kHeadOnZ = 8.0;                 // its face
constexpr double kTurnedStart[2] = {20.5, 5.0};  // x, z: one end of its face
constexpr double kTurnedLength = 6.0;
constexpr double kTurnedDegrees = 30.0;  // from +Z toward +X
constexpr double kTurnedWalkX = 22.0;    // a walk along +Z here meets its face mid-length
constexpr double kBoxSide = 1.0;
struct Box {
  const char* name;
  double x;  // low x
  double top;
};
constexpr Box kBoxes[] = {{"box_low", 27.5, 0.3}, {"box_high", 30.5, 1.2}};
constexpr double kBoxZ = 6.0;

double ramp_run(const Ramp& ramp) {
  return kRampRise / std::tan(radians(ramp.degrees));
}

double ramp_length(const Ramp& ramp) {
  return 2.0 * ramp_run(ramp) + kRampPlateau;
}

// The height of a ramp's profile `along` metres from its start.
double ramp_height(const Ramp& ramp, double along) {
  const double run = ramp_run(ramp);
  if (along <= 0.0 || along >= ramp_length(ramp)) return 0.0;
  if (along < run) return kRampRise * along / run;
  if (along <= run + kRampPlateau) return kRampRise;
  return kRampRise * (ramp_length(ramp) - along) / run;
}

double stairs_length() {
  return 2.0 * (kSteps - 1) * kTread + kLanding;
}

// The height of the stairs `along` metres from the first riser.
double stairs_height(double along) {
  if (along < 0.0 || along > stairs_length()) return 0.0;
  const double up = (kSteps - 1) * kTread;
  if (along < up) return kRiser * (std::floor(along / kTread) + 1.0);
  if (along <= up + kLanding) return kRiser * kSteps;
  return kRiser * (kSteps - 1 - std::floor((along - up - kLanding) / kTread));
}

// The rough patch's height field at (u, v) metres into it: bumps on a window that brings it
// smoothly down to the ground within 0.3 m of its edges.
double rough_field(double u, double v) {
  auto window = [](double s, double length) {
    const double t = std::clamp(std::min(s, length - s) / 0.3, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
  };
  const double bumps = 0.04 + 0.02 * std::sin(2.0 * std::numbers::pi * u / 0.9) +
                       0.02 * std::sin(2.0 * std::numbers::pi * v / 1.3 + 0.7);
  return window(u, kRoughWidth) * window(v, kRoughLength) * bumps;
}

constexpr HeightField kRough{rough_field, kRoughCell, kRoughColumns, kRoughRows};

// (x, z) in the turned wall's own frame: its face runs along +z from 0 to kTurnedLength at x = 0,
// its thickness is x in [-kWallThickness, 0].
glm::dvec2 turned_wall_frame(double x, double z) {
  const double angle = radians(kTurnedDegrees);
  const double dx = x - kTurnedStart[0];
  const double dz = z - kTurnedStart[1];
  return {dx * std::cos(angle) - dz * std::sin(angle), dx * std::sin(angle) + dz * std::cos(angle)};
}

std::vector<Placed> course_meshes() {
  std::vector<Placed> parts;
  {
    Placed ground{"ground", {}, {0.0, 0.0, 0.0}, 0.0};
    Mesh& m = ground.mesh;
    const uint32_t a = m.vertex({kGroundLow[0], 0.0, kGroundLow[1]});
    const uint32_t b = m.vertex({kGroundHigh[0], 0.0, kGroundLow[1]});
    const uint32_t c = m.vertex({kGroundHigh[0], 0.0, kGroundHigh[1]});
    const uint32_t d = m.vertex({kGroundLow[0], 0.0, kGroundHigh[1]});
    m.triangle(a, b, c, {0.0, 1.0, 0.0});
    m.triangle(a, c, d, {0.0, 1.0, 0.0});
    parts.push_back(std::move(ground));
  }
  for (const Ramp& ramp : kRamps) {
    Placed placed{ramp.name, {}, {ramp.x, 0.0, kLaneStart}, 0.0};
    const double run = ramp_run(ramp);
    placed.mesh.prism(
        {{0.0, 0.0}, {run, kRampRise}, {run + kRampPlateau, kRampRise}, {ramp_length(ramp), 0.0}},
        0.0, kRampWidth);
    parts.push_back(std::move(placed));
  }
  {
    // One box per tread (the landing is one): columns standing on the ground.
    Placed stairs{"stairs", {}, {kStairsX, 0.0, kLaneStart}, 0.0};
    double along = 0.0;
    for (int step = 1; step <= 2 * kSteps - 1; ++step) {
      const double length = step == kSteps ? kLanding : kTread;
      const double height = stairs_height(along + 0.5 * length);
      stairs.mesh.box({0.0, 0.0, along}, {kStairsWidth, height, along + length});
      along += length;
    }
    parts.push_back(std::move(stairs));
  }
  parts.push_back(Placed{"rough", kRough.mesh(), {kRoughX, 0.0, kLaneStart}, 0.0});
  {
    Placed wall{"wall_head_on", {}, {kHeadOnX[0], 0.0, kHeadOnZ}, 0.0};
    wall.mesh.box({0.0, 0.0, 0.0}, {kHeadOnX[1] - kHeadOnX[0], kWallHeight, kWallThickness});
    parts.push_back(std::move(wall));
  }
  {
    Placed wall{"wall_30", {}, {kTurnedStart[0], 0.0, kTurnedStart[1]}, kTurnedDegrees};
    wall.mesh.box({-kWallThickness, 0.0, 0.0}, {0.0, kWallHeight, kTurnedLength});
    parts.push_back(std::move(wall));
  }
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
  parts.push_back({"ground",
                   {kGroundLow[0], kGroundHigh[0]},
                   {kGroundLow[1], kGroundHigh[1]},
                   0.0,
                   "flat ground (y = 0) under the whole course"});
  for (const Ramp& ramp : kRamps) {
    const double run = ramp_run(ramp);
    const double z = kLaneStart;
    parts.push_back({ramp.name,
                     {ramp.x, ramp.x + kRampWidth},
                     {z, z + ramp_length(ramp)},
                     kRampRise,
                     metres(ramp.degrees) + "° up (z " + metres(z) + " to " + metres(z + run) +
                         "), plateau " + metres(kRampRise) + " m high (to " +
                         metres(z + run + kRampPlateau) + "), " + metres(ramp.degrees) +
                         "° down (to " + metres(z + ramp_length(ramp)) +
                         "); walk +Z at x = " + metres(ramp.x + 0.5 * kRampWidth)});
  }
  const double up = (kSteps - 1) * kTread;
  parts.push_back(
      {"stairs",
       {kStairsX, kStairsX + kStairsWidth},
       {kLaneStart, kLaneStart + stairs_length()},
       kRiser * kSteps,
       std::to_string(kSteps) + " risers of " + metres(kRiser) + " m up (treads " + metres(kTread) +
           " m, z " + metres(kLaneStart) + " to " + metres(kLaneStart + up) + "), landing " +
           metres(kRiser * kSteps) + " m high (to " + metres(kLaneStart + up + kLanding) + "), " +
           std::to_string(kSteps) + " down (to " + metres(kLaneStart + stairs_length()) +
           "); walk +Z at x = " + metres(kStairsX + 0.5 * kStairsWidth)});
  parts.push_back({"rough",
                   {kRoughX, kRoughX + kRoughWidth},
                   {kLaneStart, kLaneStart + kRoughLength},
                   kRough.top(),
                   "bumps of 0 to " + metres(100.0 * kRough.top()) +
                       " cm (a smooth height field on a " + metres(100.0 * kRoughCell) +
                       " cm grid); walk +Z at x = " + metres(kRoughX + 0.5 * kRoughWidth)});
  parts.push_back({"wall_head_on",
                   {kHeadOnX[0], kHeadOnX[1]},
                   {kHeadOnZ, kHeadOnZ + kWallThickness},
                   kWallHeight,
                   "wall across the lane, its face at z = " + metres(kHeadOnZ) +
                       "; walk +Z at x = " + metres(0.5 * (kHeadOnX[0] + kHeadOnX[1])) +
                       " into it"});
  {
    // The turned wall's bounds: its four footprint corners, turned.
    const double angle = radians(kTurnedDegrees);
    const glm::dvec2 along(std::sin(angle), std::cos(angle));    // its face's direction (x, z)
    const glm::dvec2 across(std::cos(angle), -std::sin(angle));  // its local +x
    const glm::dvec2 start(kTurnedStart[0], kTurnedStart[1]);
    glm::dvec2 low(1e9), high(-1e9);
    for (double a : {0.0, kTurnedLength}) {
      for (double t : {-kWallThickness, 0.0}) {
        const glm::dvec2 corner = start + a * along + t * across;
        low = glm::min(low, corner);
        high = glm::max(high, corner);
      }
    }
    const glm::dvec2 end = start + kTurnedLength * along;
    const double meet_z = start.y + (kTurnedWalkX - start.x) / along.x * along.y;
    parts.push_back({"wall_30",
                     {low.x, high.x},
                     {low.y, high.y},
                     kWallHeight,
                     "wall " + metres(kTurnedLength) + " m long turned " + metres(kTurnedDegrees) +
                         "° from +Z, its face from (" + metres(start.x) + ", " + metres(start.y) +
                         ") to (" + metres(end.x) + ", " + metres(end.y) +
                         "); walk +Z at x = " + metres(kTurnedWalkX) +
                         " to meet it at z = " + metres(meet_z) + " and slide along it"});
  }
  for (const Box& box : kBoxes) {
    parts.push_back({box.name,
                     {box.x, box.x + kBoxSide},
                     {kBoxZ, kBoxZ + kBoxSide},
                     box.top,
                     "box " + metres(kBoxSide) + " by " + metres(kBoxSide) + " m, " +
                         metres(box.top) +
                         " m high; walk +Z at x = " + metres(box.x + 0.5 * kBoxSide)});
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
        inside(z, kLaneStart, kLaneStart + ramp_length(ramp))) {
      return ramp_height(ramp, z - kLaneStart);
    }
  }
  if (inside(x, kStairsX, kStairsX + kStairsWidth) &&
      inside(z, kLaneStart, kLaneStart + stairs_length())) {
    return stairs_height(z - kLaneStart);
  }
  if (inside(x, kRoughX, kRoughX + kRoughWidth) &&
      inside(z, kLaneStart, kLaneStart + kRoughLength)) {
    return kRough.height(x - kRoughX, z - kLaneStart);
  }
  if (inside(x, kHeadOnX[0], kHeadOnX[1]) && inside(z, kHeadOnZ, kHeadOnZ + kWallThickness)) {
    return kWallHeight;
  }
  const glm::dvec2 turned = turned_wall_frame(x, z);
  if (inside(turned.x, -kWallThickness, 0.0) && inside(turned.y, 0.0, kTurnedLength)) {
    return kWallHeight;
  }
  for (const Box& box : kBoxes) {
    if (inside(x, box.x, box.x + kBoxSide) && inside(z, kBoxZ, kBoxZ + kBoxSide)) return box.top;
  }
  return 0.0;
}

std::vector<unsigned char> course_glb() {
  return course_mesh::write_glb(course_meshes(), "course", "mm-make-course (world/src/course.cpp)");
}

}  // namespace mm
