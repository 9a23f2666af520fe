// The courses' shared pieces (course_mesh.hpp): meshes built in double, their .glb.

#include "course_mesh.hpp"

#include <tiny_gltf.h>

// offline/src (world/'s private include path): the glTF exporter's buffer writer.
#include "gltf_buffer_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <utility>

namespace mm::course_mesh {

double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

// "3", "16.34", "0.08": at most two decimals, no trailing zeros.
std::string metres(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", v);
  std::string s(text);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

uint32_t Mesh::vertex(const glm::dvec3& p) {
  positions.push_back(p);
  return static_cast<uint32_t>(positions.size() - 1);
}

void Mesh::triangle(uint32_t a, uint32_t b, uint32_t c, const glm::dvec3& outside) {
  const glm::dvec3 normal = glm::cross(positions[b] - positions[a], positions[c] - positions[a]);
  if (glm::dot(normal, outside) < 0.0) std::swap(b, c);
  indices.insert(indices.end(), {a, b, c});
}

void Mesh::prism(const std::vector<glm::dvec2>& profile, double x0, double x1) {
  glm::dvec2 centre(0.0);
  for (const glm::dvec2& p : profile) centre += p / static_cast<double>(profile.size());
  const glm::dvec3 middle(0.5 * (x0 + x1), centre.y, centre.x);
  const uint32_t first = static_cast<uint32_t>(positions.size());
  const uint32_t n = static_cast<uint32_t>(profile.size());
  for (const glm::dvec2& p : profile) vertex({x0, p.y, p.x});
  for (const glm::dvec2& p : profile) vertex({x1, p.y, p.x});
  for (uint32_t k = 1; k + 1 < n; ++k) {
    triangle(first, first + k, first + k + 1, {-1.0, 0.0, 0.0});
    triangle(first + n, first + n + k, first + n + k + 1, {1.0, 0.0, 0.0});
  }
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t next = (k + 1) % n;
    const glm::dvec3 side = 0.5 * (positions[first + k] + positions[first + n + next]) - middle;
    triangle(first + k, first + next, first + n + next, side);
    triangle(first + k, first + n + next, first + n + k, side);
  }
}

void Mesh::box(const glm::dvec3& low, const glm::dvec3& high) {
  prism({{low.z, low.y}, {high.z, low.y}, {high.z, high.y}, {low.z, high.y}}, low.x, high.x);
}
std::string walk(double x) {
  return "; walk +Z at x = " + metres(x);
}

double RampProfile::run() const {
  return rise / std::tan(radians(degrees));
}

double RampProfile::length() const {
  return 2.0 * run() + plateau;
}

double RampProfile::height(double along) const {
  const double slope = run();
  if (along <= 0.0 || along >= length()) return 0.0;
  if (along < slope) return rise * along / slope;
  if (along <= slope + plateau) return rise;
  return rise * (length() - along) / slope;
}

Mesh RampProfile::mesh(double width) const {
  Mesh m;
  const double slope = run();
  m.prism({{0.0, 0.0}, {slope, rise}, {slope + plateau, rise}, {length(), 0.0}}, 0.0, width);
  return m;
}

CoursePart RampProfile::row(const std::string& name, double x, double width, double z) const {
  const double slope = run();
  return {name,
          {x, x + width},
          {z, z + length()},
          rise,
          metres(degrees) + "° up (z " + metres(z) + " to " + metres(z + slope) + "), plateau " +
              metres(rise) + " m high (to " + metres(z + slope + plateau) + "), " +
              metres(degrees) + "° down (to " + metres(z + length()) + ")" + walk(x + 0.5 * width)};
}

double StairsProfile::length() const {
  return 2.0 * (steps - 1) * tread + landing;
}

double StairsProfile::top() const {
  return riser * steps;
}

double StairsProfile::height(double along) const {
  if (along < 0.0 || along > length()) return 0.0;
  const double up = (steps - 1) * tread;
  if (along < up) return riser * (std::floor(along / tread) + 1.0);
  if (along <= up + landing) return riser * steps;
  return riser * (steps - 1 - std::floor((along - up - landing) / tread));
}

Mesh StairsProfile::mesh(double width) const {
  Mesh m;
  double along = 0.0;
  for (int step = 1; step <= 2 * steps - 1; ++step) {
    const double depth = step == steps ? landing : tread;
    m.box({0.0, 0.0, along}, {width, height(along + 0.5 * depth), along + depth});
    along += depth;
  }
  return m;
}

CoursePart StairsProfile::row(const std::string& name, double x, double width, double z) const {
  const double up = (steps - 1) * tread;
  return {name,
          {x, x + width},
          {z, z + length()},
          top(),
          std::to_string(steps) + " risers of " + metres(riser) + " m up (treads " + metres(tread) +
              " m, z " + metres(z) + " to " + metres(z + up) + "), landing " + metres(top()) +
              " m high (to " + metres(z + up + landing) + "), " + std::to_string(steps) +
              " down (to " + metres(z + length()) + ")" + walk(x + 0.5 * width)};
}

glm::dvec2 TurnedWall::along() const {
  return {std::sin(radians(degrees)), std::cos(radians(degrees))};
}

glm::dvec2 TurnedWall::across() const {
  return {std::cos(radians(degrees)), -std::sin(radians(degrees))};
}

glm::dvec2 TurnedWall::frame(double x, double z) const {
  const glm::dvec2 d(x - start_x, z - start_z);
  return {glm::dot(d, across()), glm::dot(d, along())};
}

bool TurnedWall::contains(double x, double z) const {
  const glm::dvec2 local = frame(x, z);
  return local.x >= -thickness && local.x <= 0.0 && local.y >= 0.0 && local.y <= length;
}

Mesh TurnedWall::mesh(double height) const {
  Mesh m;
  m.box({-thickness, 0.0, 0.0}, {0.0, height, length});
  return m;
}

CoursePart TurnedWall::row(const std::string& name, double height, double walk_x) const {
  const glm::dvec2 start(start_x, start_z);
  glm::dvec2 low(1e9), high(-1e9);
  for (double a : {0.0, length}) {
    for (double t : {-thickness, 0.0}) {
      const glm::dvec2 corner = start + a * along() + t * across();
      low = glm::min(low, corner);
      high = glm::max(high, corner);
    }
  }
  const glm::dvec2 end = start + length * along();
  const double meet_z = start.y + (walk_x - start.x) / along().x * along().y;
  return {name,
          {low.x, high.x},
          {low.y, high.y},
          height,
          "wall " + metres(length) + " m long turned " + metres(degrees) +
              "° from +Z, its face from (" + metres(start.x) + ", " + metres(start.y) + ") to (" +
              metres(end.x) + ", " + metres(end.y) + ")" + walk(walk_x) +
              " to meet it at z = " + metres(meet_z)};
}

CoursePart box_row(const std::string& name, const std::string& what, const glm::dvec2& x,
                   const glm::dvec2& z, double top) {
  return {name, x, z, top,
          what + " " + metres(x.y - x.x) + " by " + metres(z.y - z.x) + " m, " + metres(top) +
              " m high" + walk(0.5 * (x.x + x.y))};
}

Placed flat_ground(const glm::dvec2& low, const glm::dvec2& high) {
  Placed ground{"ground", {}, {0.0, 0.0, 0.0}, 0.0};
  Mesh& m = ground.mesh;
  const uint32_t a = m.vertex({low.x, 0.0, low.y});
  const uint32_t b = m.vertex({high.x, 0.0, low.y});
  const uint32_t c = m.vertex({high.x, 0.0, high.y});
  const uint32_t d = m.vertex({low.x, 0.0, high.y});
  m.triangle(a, b, c, {0.0, 1.0, 0.0});
  m.triangle(a, c, d, {0.0, 1.0, 0.0});
  return ground;
}

CoursePart ground_row(const glm::dvec2& low, const glm::dvec2& high) {
  return {"ground",
          {low.x, high.x},
          {low.y, high.y},
          0.0,
          "flat ground (y = 0) under the whole course"};
}

std::vector<unsigned char> write_glb(const std::vector<Placed>& parts, const std::string& root_name,
                                     const std::string& generator) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = generator;
  gltf_export::BufferWriter buffer(model);
  tinygltf::Node root;
  root.name = root_name;
  for (const Placed& part : parts) {
    std::vector<float> positions;
    std::vector<double> low(3, 1e300), high(3, -1e300);
    for (const glm::dvec3& p : part.mesh.positions) {
      for (int k = 0; k < 3; ++k) {
        const float v = static_cast<float>(p[k]);
        positions.push_back(v);
        low[static_cast<size_t>(k)] = std::min(low[static_cast<size_t>(k)], double{v});
        high[static_cast<size_t>(k)] = std::max(high[static_cast<size_t>(k)], double{v});
      }
    }
    const int position_accessor = buffer.add(
        positions.data(), positions.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
        TINYGLTF_TYPE_VEC3, part.mesh.positions.size(), TINYGLTF_TARGET_ARRAY_BUFFER, low, high);
    const int index_accessor =
        buffer.add(part.mesh.indices.data(), part.mesh.indices.size() * sizeof(uint32_t),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                   part.mesh.indices.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] = position_accessor;
    primitive.indices = index_accessor;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = part.name;
    mesh.primitives.push_back(std::move(primitive));
    model.meshes.push_back(std::move(mesh));

    tinygltf::Node node;
    node.name = part.name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    if (part.translation != glm::dvec3(0.0)) {
      node.translation = {part.translation.x, part.translation.y, part.translation.z};
    }
    if (part.yaw_degrees != 0.0) {
      const double half = 0.5 * radians(part.yaw_degrees);
      node.rotation = {0.0, std::sin(half), 0.0, std::cos(half)};  // x, y, z, w
    }
    model.nodes.push_back(std::move(node));
    root.children.push_back(static_cast<int>(model.nodes.size() - 1));
  }
  model.nodes.push_back(std::move(root));
  tinygltf::Scene scene;
  scene.name = root_name;
  scene.nodes = {static_cast<int>(model.nodes.size() - 1)};
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;
  buffer.finish();

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false, /*writeBinary=*/true);
  const std::string bytes = stream.str();
  return {bytes.begin(), bytes.end()};
}

double edge_window(double s, double length, double margin) {
  const double t = std::clamp(std::min(s, length - s) / margin, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

double HeightField::vertex(int column, int row) const {
  return static_cast<float>(field(column * cell, row * cell));
}

double HeightField::height(double u, double v) const {
  const int column = std::clamp(static_cast<int>(std::floor(u / cell)), 0, columns - 1);
  const int row = std::clamp(static_cast<int>(std::floor(v / cell)), 0, rows - 1);
  const double a = u / cell - column;
  const double b = v / cell - row;
  const double h00 = vertex(column, row);
  const double h10 = vertex(column + 1, row);
  const double h01 = vertex(column, row + 1);
  const double h11 = vertex(column + 1, row + 1);
  if (a >= b) return h00 + a * (h10 - h00) + b * (h11 - h10);
  return h00 + b * (h01 - h00) + a * (h11 - h01);
}

double HeightField::top() const {
  double highest = 0.0;
  for (int column = 0; column <= columns; ++column) {
    for (int row = 0; row <= rows; ++row) highest = std::max(highest, vertex(column, row));
  }
  return highest;
}

Mesh HeightField::mesh() const {
  Mesh m;
  for (int row = 0; row <= rows; ++row) {
    for (int column = 0; column <= columns; ++column) {
      m.vertex({column * cell, vertex(column, row), row * cell});
    }
  }
  const auto at = [this](int column, int row) {
    return static_cast<uint32_t>(row * (columns + 1) + column);
  };
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      // The diagonal height() assumes: (column, row) to (column + 1, row + 1).
      m.triangle(at(column, row), at(column + 1, row), at(column + 1, row + 1), {0, 1, 0});
      m.triangle(at(column, row), at(column + 1, row + 1), at(column, row + 1), {0, 1, 0});
    }
  }
  return m;
}

CoursePart HeightField::row(const std::string& name, double x, double z) const {
  const double width = columns * cell;
  return {name,
          {x, x + width},
          {z, z + rows * cell},
          top(),
          "bumps of 0 to " + metres(100.0 * top()) + " cm (a smooth height field on a " +
              metres(100.0 * cell) + " cm grid)" + walk(x + 0.5 * width)};
}

}  // namespace mm::course_mesh
