// The courses' shared pieces (course_mesh.hpp): meshes built in double, their .glb.

#include "course_mesh.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <utility>

namespace mm::course_mesh {
namespace {

// Appends arrays to the model's one buffer, each in its own 4-byte aligned buffer view.
int add_accessor(tinygltf::Model& model, std::vector<unsigned char>& buffer, const void* data,
                 size_t bytes, int component_type, int type, size_t count, int target,
                 std::vector<double> min = {}, std::vector<double> max = {}) {
  while (buffer.size() % 4 != 0) buffer.push_back(0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), p, p + bytes);
  model.bufferViews.push_back(std::move(view));
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size() - 1);
  accessor.byteOffset = 0;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  accessor.minValues = std::move(min);
  accessor.maxValues = std::move(max);
  model.accessors.push_back(std::move(accessor));
  return static_cast<int>(model.accessors.size() - 1);
}

}  // namespace

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
std::vector<unsigned char> write_glb(const std::vector<Placed>& parts, const std::string& root_name,
                                     const std::string& generator) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = generator;
  std::vector<unsigned char> buffer;
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
    const int position_accessor =
        add_accessor(model, buffer, positions.data(), positions.size() * sizeof(float),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, part.mesh.positions.size(),
                     TINYGLTF_TARGET_ARRAY_BUFFER, low, high);
    const int index_accessor = add_accessor(
        model, buffer, part.mesh.indices.data(), part.mesh.indices.size() * sizeof(uint32_t),
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, part.mesh.indices.size(),
        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
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
  while (buffer.size() % 4 != 0) buffer.push_back(0);
  tinygltf::Buffer gltf_buffer;
  gltf_buffer.data = std::move(buffer);
  model.buffers.push_back(std::move(gltf_buffer));

  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/false, /*writeBinary=*/true);
  const std::string bytes = stream.str();
  return {bytes.begin(), bytes.end()};
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

}  // namespace mm::course_mesh
