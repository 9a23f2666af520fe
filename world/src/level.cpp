// Level::validate and the glTF level reader (mm/world/level.hpp).

#include "mm/world/level.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>

#include <glm/gtc/quaternion.hpp>

// offline/src/gltf_files.hpp: the glTF importer's rules for the files a buffer may name, shared
// rather than copied (world/CMakeLists.txt says why this library may include it).
#include "gltf_files.hpp"
#include "mm/database/files.hpp"

namespace mm {
namespace {

using gltf_files::component_name;
using gltf_files::component_size;
using gltf_files::components_in_type;
using gltf_files::type_name;

// Accessor data is little-endian; reading it with memcpy is only right on a little-endian host.
static_assert(std::endian::native == std::endian::little, "the level reader assumes little-endian");

// Primitive instances (a primitive times the nodes using its mesh) visited before giving up: a
// small file can list a mesh of thousands of point primitives under thousands of nodes, which
// adds no triangle but would take minutes to walk.
constexpr uint64_t kMaxPrimitiveInstances = 1'000'000;
// Names are cut to this many characters in messages (a hostile file can make them huge).
constexpr size_t kShownNameLength = 100;

constexpr int kModeTriangles = 4;

// A number as a person would write it ("2.5", "1e+09"), not std::to_string's "2.500000".
std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// A point, to a tenth of a millimetre 100 km out.
std::string point(const glm::dvec3& p) {
  std::ostringstream out;
  out.precision(10);
  out << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return out.str();
}

std::string quoted(const std::string& name) {
  if (name.empty()) return "";
  if (name.size() > kShownNameLength) return " '" + name.substr(0, kShownNameLength) + "...'";
  return " '" + name + "'";
}

bool within_range(const glm::dvec3& world) {
  return std::abs(world.x) <= kMaxLevelCoordinate && std::abs(world.y) <= kMaxLevelCoordinate &&
         std::abs(world.z) <= kMaxLevelCoordinate;
}

bool finite3(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Why the triangle (a, b, c) is degenerate, or "" when it is not. Computed in double on the
// float corners Bullet will be given, so what passes here is what it sees.
std::string degenerate_reason(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::dvec3 A(a), B(b), C(c);
  const glm::dvec3 ab = B - A;
  const glm::dvec3 ac = C - A;
  const glm::dvec3 bc = C - B;
  const double longest_squared = std::max({glm::dot(ab, ab), glm::dot(ac, ac), glm::dot(bc, bc)});
  const double twice_area = glm::length(glm::cross(ab, ac));
  if (!(twice_area > 0.0)) return "zero area";
  // Height over the longest side, as a fraction of that side: twice the area over its square.
  const double aspect = twice_area / longest_squared;
  if (aspect < kMinTriangleAspect) {
    return "a sliver: its height is " + number(aspect) + " of its longest side (at least " +
           number(kMinTriangleAspect) + ")";
  }
  return "";
}

// ---------------------------------------------------------------------------------------------
// Accessors

// Where an accessor's elements lie, once its type, component type and bounds are checked: every
// byte read lies inside its buffer, so a declared count is backed by the file's own bytes.
struct Located {
  const unsigned char* base = nullptr;
  size_t stride = 0;
  size_t count = 0;
  int component_type = 0;
};

// `what` names the accessor for messages ("mesh 0, primitive 1: POSITION").
Result<Located> locate(const tinygltf::Model& model, int index, int expected_type,
                       std::initializer_list<int> component_types, const std::string& expected,
                       const std::string& what) {
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
    return Error{what + " is accessor " + std::to_string(index) + ", out of range (the file has " +
                 std::to_string(model.accessors.size()) + " accessors)"};
  }
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  const tinygltf::Accessor& accessor = model.accessors[static_cast<size_t>(index)];
  if (accessor.sparse.isSparse) return Error{where + " is sparse, which is not supported"};
  if (accessor.type != expected_type) {
    return Error{where + " has type " + type_name(accessor.type) + ", expected " +
                 type_name(expected_type)};
  }
  const int ct = accessor.componentType;
  if (accessor.normalized ||
      std::find(component_types.begin(), component_types.end(), ct) == component_types.end()) {
    return Error{where + " has component type " + component_name(ct) +
                 (accessor.normalized ? " (normalized)" : "") + ", expected " + expected};
  }
  if (accessor.count == 0) return Error{where + " has no elements (count is 0)"};
  // Without a buffer view an accessor is all zeros (glTF 2.0, 3.6.2.3): positions all at one
  // point, or every index naming vertex 0, so every triangle would be degenerate. Refused here,
  // before its count (backed by no bytes of the file) can make anything allocate.
  if (accessor.bufferView < 0) {
    return Error{where + " has no buffer view (all zeros: every triangle would be degenerate)"};
  }
  const size_t element_size = static_cast<size_t>(components_in_type(accessor.type)) *
                              static_cast<size_t>(component_size(ct));
  if (static_cast<size_t>(accessor.bufferView) >= model.bufferViews.size()) {
    return Error{where + " refers to buffer view " + std::to_string(accessor.bufferView) +
                 ", out of range (the file has " + std::to_string(model.bufferViews.size()) +
                 " buffer views)"};
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(accessor.bufferView)];
  const std::string view_label = "buffer view " + std::to_string(accessor.bufferView);
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    return Error{where + ": " + view_label + " refers to buffer " + std::to_string(view.buffer) +
                 ", out of range (the file has " + std::to_string(model.buffers.size()) +
                 " buffers)"};
  }
  const std::vector<unsigned char>& data = model.buffers[static_cast<size_t>(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
    return Error{where + ": " + view_label + " spans bytes [" + std::to_string(view.byteOffset) +
                 ", +" + std::to_string(view.byteLength) + ") but buffer " +
                 std::to_string(view.buffer) + " holds " + std::to_string(data.size()) + " bytes"};
  }
  if (view.byteStride != 0 && view.byteStride < element_size) {
    return Error{where + ": " + view_label + " has byte stride " + std::to_string(view.byteStride) +
                 ", smaller than its " + std::to_string(element_size) + "-byte elements"};
  }
  const size_t stride = view.byteStride != 0 ? view.byteStride : element_size;
  const size_t length = view.byteLength;
  const size_t count = accessor.count;
  if (accessor.byteOffset > length || element_size > length - accessor.byteOffset ||
      (count - 1) > (length - accessor.byteOffset - element_size) / stride) {
    return Error{where + ": " + std::to_string(count) + " elements of " +
                 std::to_string(element_size) + " bytes (stride " + std::to_string(stride) +
                 ") from byte offset " + std::to_string(accessor.byteOffset) + " do not fit in " +
                 view_label + " (" + std::to_string(length) + " bytes)"};
  }
  return Located{data.data() + view.byteOffset + accessor.byteOffset, stride, count, ct};
}

glm::vec3 read_position(const Located& a, size_t i) {
  float v[3];
  std::memcpy(v, a.base + i * a.stride, sizeof v);
  return {v[0], v[1], v[2]};
}

uint32_t read_index(const Located& a, size_t i) {
  const unsigned char* p = a.base + i * a.stride;
  switch (a.component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    default: {
      uint32_t v;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The scene's nodes

std::string node_label(const tinygltf::Model& model, int node) {
  return "node " + std::to_string(node) + quoted(model.nodes[static_cast<size_t>(node)].name);
}

// A node's transform relative to its parent: its matrix, or translation * rotation * scale.
Result<glm::dmat4> local_matrix(const tinygltf::Model& model, int index) {
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(index)];
  const std::string where = node_label(model, index);
  auto all_finite = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) {
      return Error{where + ": matrix has " + std::to_string(node.matrix.size()) +
                   " numbers, expected 16"};
    }
    if (!all_finite(node.matrix)) return Error{where + ": matrix is not finite"};
    glm::dmat4 m(1.0);
    for (int column = 0; column < 4; ++column) {
      for (int row = 0; row < 4; ++row) {
        m[column][row] = node.matrix[static_cast<size_t>(column * 4 + row)];
      }
    }
    return m;
  }
  auto check = [&](const std::vector<double>& values, size_t size,
                   const char* what) -> std::string {
    if (!values.empty() && values.size() != size) {
      return where + ": " + what + " has " + std::to_string(values.size()) + " numbers, expected " +
             std::to_string(size);
    }
    if (!all_finite(values)) return where + ": " + what + " is not finite";
    return "";
  };
  for (const auto& [values, size, what] : {std::tuple{&node.translation, size_t{3}, "translation"},
                                           std::tuple{&node.rotation, size_t{4}, "rotation"},
                                           std::tuple{&node.scale, size_t{3}, "scale"}}) {
    if (std::string problem = check(*values, size, what); !problem.empty()) return Error{problem};
  }
  glm::dmat4 m(1.0);
  if (!node.translation.empty()) {
    m[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
  }
  if (!node.rotation.empty()) {
    // glTF stores x, y, z, w.
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    const double length = glm::length(q);
    if (!(length > 1e-12) || !std::isfinite(length)) {
      return Error{where + ": rotation has zero length"};
    }
    m = m * glm::dmat4(glm::mat3_cast(q / length));
  }
  if (!node.scale.empty()) {
    m = m * glm::dmat4(glm::dmat3(glm::dvec3(node.scale[0], 0, 0), glm::dvec3(0, node.scale[1], 0),
                                  glm::dvec3(0, 0, node.scale[2])));
  }
  return m;
}

// One node of the scene that holds a mesh, with its global transform.
struct MeshInstance {
  int node = 0;
  int mesh = 0;
  glm::dmat4 global{1.0};
};

// The scene's nodes that hold a mesh, after checking that the hierarchy is a tree.
Result<std::vector<MeshInstance>> mesh_instances(const tinygltf::Model& model) {
  const size_t node_count = model.nodes.size();
  std::vector<int> parent(node_count, -1);
  for (size_t n = 0; n < node_count; ++n) {
    for (int child : model.nodes[n].children) {
      if (child < 0 || static_cast<size_t>(child) >= node_count) {
        return Error{node_label(model, static_cast<int>(n)) + " lists child " +
                     std::to_string(child) + ", out of range (the file has " +
                     std::to_string(node_count) + " nodes)"};
      }
      if (parent[static_cast<size_t>(child)] != -1 || static_cast<size_t>(child) == n) {
        return Error{node_label(model, child) + " has more than one parent (or is its own child)"};
      }
      parent[static_cast<size_t>(child)] = static_cast<int>(n);
    }
  }
  std::vector<int> roots;
  std::string scene_label = "the nodes that are no node's child (the file has no scene)";
  if (!model.scenes.empty()) {
    const int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<size_t>(scene) >= model.scenes.size()) {
      return Error{"scene " + std::to_string(scene) + " is the default but the file has " +
                   std::to_string(model.scenes.size()) + " scenes"};
    }
    scene_label = "scene " + std::to_string(scene);
    for (int root : model.scenes[static_cast<size_t>(scene)].nodes) {
      if (root < 0 || static_cast<size_t>(root) >= node_count) {
        return Error{scene_label + " lists node " + std::to_string(root) +
                     ", out of range (the file has " + std::to_string(node_count) + " nodes)"};
      }
      roots.push_back(root);
    }
  } else {
    for (size_t n = 0; n < node_count; ++n) {
      if (parent[n] == -1) roots.push_back(static_cast<int>(n));
    }
  }

  std::vector<MeshInstance> instances;
  std::vector<char> visited(node_count, 0);
  std::vector<std::pair<int, glm::dmat4>> pending;  // node, its parent's global transform
  for (auto root = roots.rbegin(); root != roots.rend(); ++root) {
    pending.emplace_back(*root, glm::dmat4(1.0));
  }
  while (!pending.empty()) {
    const auto [n, parent_global] = pending.back();
    pending.pop_back();
    if (visited[static_cast<size_t>(n)]) {
      return Error{scene_label + " reaches " + node_label(model, n) +
                   " twice (it is listed twice, or is both a root and a child)"};
    }
    visited[static_cast<size_t>(n)] = 1;
    auto local = local_matrix(model, n);
    if (!local) return local.error();
    const glm::dmat4 global = parent_global * *local;
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(n)];
    if (node.mesh >= 0) {
      if (static_cast<size_t>(node.mesh) >= model.meshes.size()) {
        return Error{node_label(model, n) + " refers to mesh " + std::to_string(node.mesh) +
                     ", out of range (the file has " + std::to_string(model.meshes.size()) +
                     " meshes)"};
      }
      instances.push_back({n, node.mesh, global});
    } else if (node.mesh != -1) {
      return Error{node_label(model, n) + " refers to mesh " + std::to_string(node.mesh) +
                   ", out of range"};
    }
    for (auto child = node.children.rbegin(); child != node.children.rend(); ++child) {
      pending.emplace_back(*child, global);
    }
  }
  return instances;
}

// ---------------------------------------------------------------------------------------------
// Primitives

const char* mode_name(int mode) {
  switch (mode) {
    case 0:
      return "POINTS";
    case 1:
      return "LINES";
    case 2:
      return "LINE_LOOP";
    case 3:
      return "LINE_STRIP";
    case 4:
      return "TRIANGLES";
    case 5:
      return "TRIANGLE_STRIP";
    case 6:
      return "TRIANGLE_FAN";
    default:
      return "unknown";
  }
}

// One triangle primitive of one mesh instance, its accessors located.
struct TrianglePrimitive {
  std::string label;  // "node 2 'stairs', mesh 1 'steps', primitive 0"
  const glm::dmat4* global = nullptr;
  Located positions;
  std::optional<Located> indices;
  size_t triangles = 0;
};

// Calls visit(const TrianglePrimitive&) -> Status for every triangle primitive of every instance,
// after checking its mode and accessors; skips points and lines.
template <class Visit>
Status for_each_triangle_primitive(const tinygltf::Model& model,
                                   const std::vector<MeshInstance>& instances, Visit&& visit) {
  uint64_t primitive_instances = 0;
  for (const MeshInstance& instance : instances) {
    const tinygltf::Mesh& mesh = model.meshes[static_cast<size_t>(instance.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      if (++primitive_instances > kMaxPrimitiveInstances) {
        return Error{"has more than " + std::to_string(kMaxPrimitiveInstances) +
                     " mesh primitives in its scene (each primitive counted once per node using "
                     "its mesh)"};
      }
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      TrianglePrimitive triangles;
      triangles.label = node_label(model, instance.node) + ", mesh " +
                        std::to_string(instance.mesh) + quoted(mesh.name) + ", primitive " +
                        std::to_string(p);
      triangles.global = &instance.global;
      // tinygltf fills in TRIANGLES when the file gives no mode.
      const int mode = primitive.mode;
      if (mode >= 0 && mode <= 3) continue;  // points and lines have no surface
      if (mode != kModeTriangles) {
        return Error{triangles.label + " has mode " + std::to_string(mode) + " (" +
                     mode_name(mode) +
                     "); only TRIANGLES (4) is read (export triangulated meshes)"};
      }
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) {
        return Error{triangles.label + " has no POSITION attribute"};
      }
      auto positions =
          locate(model, position->second, TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT},
                 "FLOAT", triangles.label + ": POSITION");
      if (!positions) return positions.error();
      triangles.positions = *positions;
      size_t corners = positions->count;
      if (primitive.indices != -1) {  // -1: tinygltf's "no indices"
        auto indices =
            locate(model, primitive.indices, TINYGLTF_TYPE_SCALAR,
                   {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                   "UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT", triangles.label + ": indices");
        if (!indices) return indices.error();
        triangles.indices = *indices;
        corners = indices->count;
      }
      if (corners % 3 != 0) {
        return Error{triangles.label + " has " + std::to_string(corners) +
                     (triangles.indices ? " indices" : " vertices and no indices") +
                     ", not a multiple of 3"};
      }
      triangles.triangles = corners / 3;
      if (Status s = visit(triangles); !s) return s;
    }
  }
  return Status::success();
}

Result<Level> read_level(const tinygltf::Model& model) {
  if (!model.extensionsRequired.empty()) {
    std::string names;
    for (const std::string& name : model.extensionsRequired) {
      names += (names.empty() ? "" : ", ") + name.substr(0, kShownNameLength);
    }
    return Error{"requires the extensions " + names + ", which the level reader does not read"};
  }
  auto instances = mesh_instances(model);
  if (!instances) return instances.error();

  // 1. Count, from the accessors' declared counts, before reading or allocating anything.
  uint64_t triangle_total = 0;
  uint64_t vertex_total = 0;
  Status counted = for_each_triangle_primitive(
      model, *instances, [&](const TrianglePrimitive& primitive) -> Status {
        triangle_total += primitive.triangles;
        vertex_total += primitive.positions.count;
        if (triangle_total > kMaxLevelTriangles) {
          return Error{"declares more than " + std::to_string(kMaxLevelTriangles) +
                       " triangles (the most a level may have; counted from the accessors, "
                       "once per node using a mesh, up to " +
                       primitive.label + ")"};
        }
        if (vertex_total > kMaxLevelVertices) {
          return Error{"declares more than " + std::to_string(kMaxLevelVertices) +
                       " vertices (the most a level may have; counted from the accessors, once "
                       "per node using a mesh, up to " +
                       primitive.label + ")"};
        }
        return Status::success();
      });
  if (!counted) return Error{counted.message()};
  if (triangle_total == 0) {
    return Error{"has no triangles (no mesh primitive of mode TRIANGLES on the scene's nodes)"};
  }

  // 2. The bounds of the world positions, which place the level's origin.
  glm::dvec3 low(std::numeric_limits<double>::infinity());
  glm::dvec3 high(-std::numeric_limits<double>::infinity());
  Status bounded = for_each_triangle_primitive(
      model, *instances, [&](const TrianglePrimitive& primitive) -> Status {
        for (size_t i = 0; i < primitive.positions.count; ++i) {
          const glm::vec3 p = read_position(primitive.positions, i);
          if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            return Error{primitive.label + ": POSITION element " + std::to_string(i) +
                         " is not finite"};
          }
          const glm::dvec3 world(*primitive.global * glm::dvec4(glm::dvec3(p), 1.0));
          if (!finite3(world)) {
            return Error{primitive.label + ": vertex " + std::to_string(i) +
                         " is not finite once the node transforms are applied"};
          }
          if (!within_range(world)) {
            return Error{primitive.label + ": vertex " + std::to_string(i) + " lies at " +
                         point(world) + " in the world, beyond ±" + number(kMaxLevelCoordinate) +
                         " m"};
          }
          low = glm::min(low, world);
          high = glm::max(high, world);
        }
        return Status::success();
      });
  if (!bounded) return Error{bounded.message()};

  // 3. The triangles, relative to the whole metre nearest the bounds' centre.
  Level level;
  level.origin = glm::round(0.5 * (low + high));
  level.positions.reserve(static_cast<size_t>(vertex_total));
  level.indices.reserve(static_cast<size_t>(triangle_total) * 3);
  Status read = for_each_triangle_primitive(
      model, *instances, [&](const TrianglePrimitive& primitive) -> Status {
        const size_t first = level.positions.size();
        const size_t count = primitive.positions.count;
        for (size_t i = 0; i < count; ++i) {
          const glm::dvec3 world(
              *primitive.global *
              glm::dvec4(glm::dvec3(read_position(primitive.positions, i)), 1.0));
          level.positions.emplace_back(world - level.origin);
        }
        for (size_t t = 0; t < primitive.triangles; ++t) {
          uint32_t corner[3];
          for (size_t k = 0; k < 3; ++k) {
            const size_t at = t * 3 + k;
            const uint32_t index =
                primitive.indices ? read_index(*primitive.indices, at) : static_cast<uint32_t>(at);
            if (index >= count) {
              return Error{primitive.label + ": index " + std::to_string(at) + " is vertex " +
                           std::to_string(index) + ", but POSITION has " + std::to_string(count) +
                           " vertices"};
            }
            corner[k] = static_cast<uint32_t>(first + index);
          }
          const std::string reason = degenerate_reason(
              level.positions[corner[0]], level.positions[corner[1]], level.positions[corner[2]]);
          if (!reason.empty()) {
            return Error{primitive.label + ", triangle " + std::to_string(t) +
                         " is degenerate: " + reason};
          }
          level.indices.insert(level.indices.end(), corner, corner + 3);
        }
        return Status::success();
      });
  if (!read) return Error{read.message()};
  return level;
}

}  // namespace

Status Level::validate() const {
  if (!finite3(origin) || !within_range(origin)) {
    return Error{"the level's origin " + point(origin) + " is not finite or lies beyond ±" +
                 number(kMaxLevelCoordinate) + " m"};
  }
  if (indices.size() % 3 != 0) {
    return Error{"the level has " + std::to_string(indices.size()) +
                 " indices, not a multiple of 3"};
  }
  if (triangle_count() > kMaxLevelTriangles) {
    return Error{"the level has " + std::to_string(triangle_count()) + " triangles, more than " +
                 std::to_string(kMaxLevelTriangles)};
  }
  if (positions.size() > kMaxLevelVertices) {
    return Error{"the level has " + std::to_string(positions.size()) + " vertices, more than " +
                 std::to_string(kMaxLevelVertices)};
  }
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::dvec3 world = origin + glm::dvec3(positions[i]);
    if (!finite3(glm::dvec3(positions[i])) || !within_range(world)) {
      return Error{"vertex " + std::to_string(i) + " lies at " + point(world) +
                   " in the world: not finite or beyond ±" + number(kMaxLevelCoordinate) + " m"};
    }
  }
  for (size_t t = 0; t < triangle_count(); ++t) {
    for (size_t k = 0; k < 3; ++k) {
      if (indices[t * 3 + k] >= positions.size()) {
        return Error{"triangle " + std::to_string(t) + " names vertex " +
                     std::to_string(indices[t * 3 + k]) + ", but the level has " +
                     std::to_string(positions.size()) + " vertices"};
      }
    }
    const std::string reason = degenerate_reason(
        positions[indices[t * 3]], positions[indices[t * 3 + 1]], positions[indices[t * 3 + 2]]);
    if (!reason.empty())
      return Error{"triangle " + std::to_string(t) + " is degenerate: " + reason};
  }
  return Status::success();
}

Result<Level> parse_level(std::span<const unsigned char> bytes,
                          const std::filesystem::path& path_for_messages,
                          const LevelLoadOptions& options) {
  const std::string where = path_for_messages.string() + ": ";
  try {
    auto model = gltf_files::load_model(bytes, path_for_messages, options.allow_external_files);
    if (!model) return Error{where + model.message()};
    auto level = read_level(*model);
    if (!level) return Error{where + level.message()};
    return level;
  } catch (const std::exception& e) {
    // tinygltf and allocation can throw on hostile input; never let it escape.
    return Error{where + "failed to read glTF: " + e.what()};
  }
}

Result<Level> load_level(const std::filesystem::path& path, const LevelLoadOptions& options) {
  auto contents = read_whole_file(path, "level file");
  if (!contents) return contents.error();
  return parse_level(
      std::span(reinterpret_cast<const unsigned char*>(contents->data.get()), contents->size), path,
      options);
}

}  // namespace mm
