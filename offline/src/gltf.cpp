#include "mm/offline/gltf.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>

#include <glm/gtc/quaternion.hpp>

#include "gltf_buffer_writer.hpp"
#include "gltf_files.hpp"
#include "mm/database/files.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {
namespace {

using gltf_export::BufferWriter;

using gltf_files::component_name;
using gltf_files::component_size;
using gltf_files::components_in_type;
using gltf_files::type_name;

// Accessor data is little-endian; reading it with memcpy is only right on a little-endian host.
static_assert(std::endian::native == std::endian::little, "the glTF reader assumes little-endian");

// Limits that keep a hostile file from making us allocate without bound. Sampled animations
// are capped at 16M joint transforms (640 MB): 6.7 hours of a 22-joint skeleton at 30 Hz.
constexpr double kMaxSampledTransforms = 16'000'000.0;
constexpr size_t kMaxZeroAccessorElements = 1'000'000;

// ---------------------------------------------------------------------------------------------
// Small helpers

// A number as a person would write it in a message ("2.5", "1e+09"), not std::to_string's
// "2.500000".
std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string quoted_name(const std::string& name) {
  return name.empty() ? "" : " '" + name + "'";
}

std::string node_label(const tinygltf::Model& model, int node) {
  return "node " + std::to_string(node) + quoted_name(model.nodes[static_cast<size_t>(node)].name);
}

// Decodes one component at p into a float; integer types use the glTF "normalized" mapping.
float read_component(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, sizeof v);
      return std::max(static_cast<float>(v) / 127.0f, -1.0f);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return static_cast<float>(*p) / 255.0f;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, sizeof v);
      return std::max(static_cast<float>(v) / 32767.0f, -1.0f);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, sizeof v);
      return static_cast<float>(v) / 65535.0f;
    }
    default:
      return 0.0f;
  }
}

// Where an accessor's elements lie, after checking the index, type, component type and that
// every byte read lies inside its buffer. `component_ok` says which component types (and
// normalized flags) the caller accepts, `expected` names them for the message; `what` says
// what the accessor is for.
struct AccessorData {
  const unsigned char* base = nullptr;  // first element; null when the accessor is all zeros
  size_t stride = 0;                    // bytes between elements
  size_t count = 0;
  size_t components = 0;
  int component_type = 0;
  std::string where;  // "<what>: accessor <index>", for messages about elements
};

template <class ComponentOk>
Result<AccessorData> locate_accessor(const tinygltf::Model& model, int index, int expected_type,
                                     ComponentOk component_ok, const std::string& expected,
                                     const std::string& what) {
  const std::string where = what + ": accessor " + std::to_string(index);
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size()) {
    return Error{what + ": accessor index " + std::to_string(index) +
                 " is out of range (the file has " + std::to_string(model.accessors.size()) +
                 " accessors)"};
  }
  const tinygltf::Accessor& accessor = model.accessors[static_cast<size_t>(index)];
  if (accessor.sparse.isSparse) return Error{where + " is sparse, which is not supported"};
  if (accessor.type != expected_type) {
    return Error{where + " has type " + type_name(accessor.type) + ", expected " +
                 type_name(expected_type)};
  }
  const int ct = accessor.componentType;
  if (component_size(ct) == 0 || !component_ok(ct, accessor.normalized)) {
    return Error{where + " has component type " + component_name(ct) +
                 (accessor.normalized ? " (normalized)" : "") + ", expected " + expected};
  }
  if (accessor.count == 0) return Error{where + " has no elements (count is 0)"};
  const size_t components = static_cast<size_t>(components_in_type(accessor.type));
  const size_t element_size = components * static_cast<size_t>(component_size(ct));
  const size_t count = accessor.count;
  // Without a buffer view an accessor is all zeros (glTF 2.0, 3.6.2.3); nothing bounds its
  // count but this limit.
  if (accessor.bufferView < 0) {
    if (count > kMaxZeroAccessorElements) {
      return Error{where + " has no buffer view and claims " + std::to_string(count) +
                   " elements, more than the " + std::to_string(kMaxZeroAccessorElements) +
                   " allowed"};
    }
    return AccessorData{nullptr, 0, count, components, ct, where};
  }

  if (static_cast<size_t>(accessor.bufferView) >= model.bufferViews.size()) {
    return Error{where + " refers to buffer view " + std::to_string(accessor.bufferView) +
                 ", out of range (the file has " + std::to_string(model.bufferViews.size()) +
                 " buffer views)"};
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(accessor.bufferView)];
  const std::string view_label = "buffer view " + std::to_string(accessor.bufferView);
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size()) {
    return Error{what + ": " + view_label + " refers to buffer " + std::to_string(view.buffer) +
                 ", out of range (the file has " + std::to_string(model.buffers.size()) +
                 " buffers)"};
  }
  const std::vector<unsigned char>& data = model.buffers[static_cast<size_t>(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
    return Error{what + ": " + view_label + " spans bytes [" + std::to_string(view.byteOffset) +
                 ", +" + std::to_string(view.byteLength) + ") but buffer " +
                 std::to_string(view.buffer) + " holds " + std::to_string(data.size()) + " bytes"};
  }
  if (view.byteStride != 0 && view.byteStride < element_size) {
    return Error{what + ": " + view_label + " has byte stride " + std::to_string(view.byteStride) +
                 ", smaller than the " + std::to_string(element_size) + "-byte elements of " +
                 where.substr(what.size() + 2)};
  }
  const size_t stride = view.byteStride != 0 ? view.byteStride : element_size;
  const size_t length = view.byteLength;
  if (accessor.byteOffset > length || element_size > length - accessor.byteOffset ||
      (count - 1) > (length - accessor.byteOffset - element_size) / stride) {
    return Error{where + ": " + std::to_string(count) + " elements of " +
                 std::to_string(element_size) + " bytes (stride " + std::to_string(stride) +
                 ") from byte offset " + std::to_string(accessor.byteOffset) + " do not fit in " +
                 view_label + " (" + std::to_string(length) + " bytes)"};
  }
  return AccessorData{
      data.data() + view.byteOffset + accessor.byteOffset, stride, count, components, ct, where};
}

// Reads every element of an accessor as floats (count * components values); integer
// components use the glTF "normalized" mapping. allow_normalized_integers admits the
// normalized BYTE/SHORT encodings glTF allows for rotations and weights.
Result<std::vector<float>> read_accessor(const tinygltf::Model& model, int index, int expected_type,
                                         bool allow_normalized_integers, const std::string& what) {
  auto ok = [&](int ct, bool normalized) {
    return ct == TINYGLTF_COMPONENT_TYPE_FLOAT ||
           (allow_normalized_integers && normalized && ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  };
  auto located = locate_accessor(
      model, index, expected_type, ok,
      allow_normalized_integers ? "FLOAT or normalized BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT"
                                : "FLOAT",
      what);
  if (!located) return located.error();
  const AccessorData& a = *located;
  std::vector<float> values(a.count * a.components, 0.0f);
  if (!a.base) return values;
  const size_t csize = static_cast<size_t>(component_size(a.component_type));
  for (size_t i = 0; i < a.count; ++i) {
    for (size_t c = 0; c < a.components; ++c) {
      const float v = read_component(a.base + i * a.stride + c * csize, a.component_type);
      if (!std::isfinite(v)) {
        return Error{a.where + ": element " + std::to_string(i) + " is not finite"};
      }
      values[i * a.components + c] = v;
    }
  }
  return values;
}

// Reads an accessor of unsigned integers (indices, joint numbers) as they are stored, not
// normalized; `component_types` lists the accepted ones and `expected` names them.
Result<std::vector<uint32_t>> read_integer_accessor(const tinygltf::Model& model, int index,
                                                    int expected_type,
                                                    std::initializer_list<int> component_types,
                                                    const std::string& expected,
                                                    const std::string& what) {
  auto ok = [&](int ct, bool normalized) {
    return !normalized &&
           std::find(component_types.begin(), component_types.end(), ct) != component_types.end();
  };
  auto located = locate_accessor(model, index, expected_type, ok, expected, what);
  if (!located) return located.error();
  const AccessorData& a = *located;
  std::vector<uint32_t> values(a.count * a.components, 0u);
  if (!a.base) return values;
  const size_t csize = static_cast<size_t>(component_size(a.component_type));
  for (size_t i = 0; i < a.count; ++i) {
    for (size_t c = 0; c < a.components; ++c) {
      const unsigned char* p = a.base + i * a.stride + c * csize;
      uint32_t v = 0;
      if (csize == 1) {
        v = *p;
      } else if (csize == 2) {
        uint16_t u;
        std::memcpy(&u, p, sizeof u);
        v = u;
      } else {
        std::memcpy(&v, p, sizeof v);
      }
      values[i * a.components + c] = v;
    }
  }
  return values;
}

// ---------------------------------------------------------------------------------------------
// Import

enum class Path { translation, rotation, scale };
enum class Interpolation { step, linear, cubic_spline };

const char* path_name(Path p) {
  switch (p) {
    case Path::translation:
      return "translation";
    case Path::rotation:
      return "rotation";
    case Path::scale:
      return "scale";
  }
  return "?";
}

// One animated property of one node: key times and values (for CUBICSPLINE, three elements
// per key: in-tangent, value, out-tangent).
struct Track {
  int slot = 0;  // index into the sampled nodes (skeleton joints, then root ancestors)
  Path path = Path::translation;
  Interpolation interpolation = Interpolation::linear;
  int components = 3;
  std::vector<float> times;
  std::vector<float> values;
};

glm::vec4 element(const Track& track, size_t index) {
  const float* v = track.values.data() + index * static_cast<size_t>(track.components);
  return track.components == 4 ? glm::vec4(v[0], v[1], v[2], v[3])
                               : glm::vec4(v[0], v[1], v[2], 0.0f);
}

glm::quat as_quat(const glm::vec4& v) {
  return glm::quat(v.w, v.x, v.y, v.z);
}

// The track's value at time t (clamped to its first and last key).
glm::vec4 sample(const Track& track, double t) {
  const bool cubic = track.interpolation == Interpolation::cubic_spline;
  const size_t stride = cubic ? 3 : 1;
  const size_t value_offset = cubic ? 1 : 0;
  const size_t keys = track.times.size();
  if (t <= track.times.front()) return element(track, value_offset);
  if (t >= track.times.back()) return element(track, (keys - 1) * stride + value_offset);
  // times[k] <= t < times[k + 1], so the interval is never empty.
  const size_t k = static_cast<size_t>(
      std::upper_bound(track.times.begin(), track.times.end(), t,
                       [](double a, float b) { return a < static_cast<double>(b); }) -
      track.times.begin() - 1);
  const glm::vec4 v0 = element(track, k * stride + value_offset);
  const glm::vec4 v1 = element(track, (k + 1) * stride + value_offset);
  const double t0 = track.times[k];
  const double t1 = track.times[k + 1];
  const double dt = t1 - t0;
  // Key times are floats, so a sample meant to land on a key can miss it by a few float ulps;
  // treat those as the key itself, or resampling at the keys' own rate would blend a sliver of
  // the neighbouring key (visible wherever the motion jumps between two keys).
  const float far = std::max(std::abs(track.times[k]), std::abs(track.times[k + 1]));
  const double snap = std::min(
      8.0 * static_cast<double>(std::nextafter(far, std::numeric_limits<float>::infinity()) - far),
      0.01 * dt);
  if (t - t0 <= snap) return v0;
  if (t1 - t <= snap) return v1;
  if (track.interpolation == Interpolation::step) return v0;
  const double s = (t - t0) / dt;
  if (track.interpolation == Interpolation::linear) {
    if (track.path == Path::rotation) {
      // glm::slerp flips one end when the dot product is negative: the shortest path.
      const glm::dquat q = glm::slerp(glm::dquat(as_quat(v0)), glm::dquat(as_quat(v1)), s);
      const glm::quat r(glm::normalize(q));
      return {r.x, r.y, r.z, r.w};
    }
    return glm::vec4(glm::mix(glm::dvec4(v0), glm::dvec4(v1), s));
  }
  // Cubic Hermite spline (glTF 2.0, Appendix C): tangents are per second, scaled by dt.
  const glm::dvec4 out_tangent(element(track, k * 3 + 2));
  const glm::dvec4 in_tangent(element(track, (k + 1) * 3));
  const double s2 = s * s;
  const double s3 = s2 * s;
  const glm::dvec4 p = (2 * s3 - 3 * s2 + 1) * glm::dvec4(v0) +
                       (s3 - 2 * s2 + s) * dt * out_tangent + (-2 * s3 + 3 * s2) * glm::dvec4(v1) +
                       (s3 - s2) * dt * in_tangent;
  if (track.path == Path::rotation) {
    const double n = glm::length(p);
    // Tangents can cancel the value; fall back to the start key rather than divide by zero.
    if (!(n > 1e-12) || !std::isfinite(n)) return v0;
    return glm::vec4(p / n);
  }
  return glm::vec4(p);
}

// A matrix split into translation, rotation and scale (a mirror keeps the rotation proper and
// makes the x scale negative); `where` names the matrix in the error.
Result<Transform> decompose(const glm::dmat4& m, const std::string& where) {
  glm::dmat3 basis(m);
  glm::dvec3 scale(glm::length(basis[0]), glm::length(basis[1]), glm::length(basis[2]));
  if (glm::determinant(basis) < 0.0) scale.x = -scale.x;  // a mirror: keep the rotation proper
  if (!(std::abs(scale.x) > 1e-12 && scale.y > 1e-12 && scale.z > 1e-12) ||
      !std::isfinite(glm::determinant(m))) {
    return Error{where +
                 ": matrix is degenerate or not finite; it cannot be split into "
                 "translation, rotation and scale"};
  }
  basis[0] /= scale.x;
  basis[1] /= scale.y;
  basis[2] /= scale.z;
  Transform t;
  t.translation = glm::vec3(m[3]);
  t.rotation = glm::normalize(glm::quat(glm::quat_cast(basis)));
  t.scale = glm::vec3(scale);
  return t;
}

// The node's rest transform from its TRS or its matrix (decomposed into TRS).
Result<Transform> node_rest(const tinygltf::Model& model, int index) {
  const tinygltf::Node& node = model.nodes[static_cast<size_t>(index)];
  const std::string where = node_label(model, index);
  Transform t;
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) {
      return Error{where + ": matrix has " + std::to_string(node.matrix.size()) +
                   " numbers, expected 16"};
    }
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[static_cast<size_t>(c * 4 + r)];
    }
    auto split = decompose(m, where);
    if (!split) return split.error();
    t = *split;
  } else {
    auto read = [&](const std::vector<double>& v, size_t n, const char* what,
                    float* out) -> Status {
      if (v.empty()) return Status::success();
      if (v.size() != n) {
        return Error{where + ": " + what + " has " + std::to_string(v.size()) +
                     " numbers, expected " + std::to_string(n)};
      }
      for (size_t i = 0; i < n; ++i) out[i] = static_cast<float>(v[i]);
      return Status::success();
    };
    float tr[3] = {0.0f, 0.0f, 0.0f};
    float q[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    float sc[3] = {1.0f, 1.0f, 1.0f};
    if (Status s = read(node.translation, 3, "translation", tr); !s) return Error{s.message()};
    if (Status s = read(node.rotation, 4, "rotation", q); !s) return Error{s.message()};
    if (Status s = read(node.scale, 3, "scale", sc); !s) return Error{s.message()};
    t.translation = glm::vec3(tr[0], tr[1], tr[2]);
    t.scale = glm::vec3(sc[0], sc[1], sc[2]);
    t.rotation = glm::quat(q[3], q[0], q[1], q[2]);
    const float n = glm::length(t.rotation);
    if (!(n > 1e-6f) || !std::isfinite(n)) {
      return Error{where + ": rotation is zero or not finite"};
    }
    t.rotation /= n;
  }
  if (!finite(t.translation) || !finite(t.scale) || !finite(t.rotation)) {
    return Error{where + ": transform is not finite"};
  }
  return t;
}

Interpolation parse_interpolation(const std::string& s, bool* ok) {
  *ok = true;
  if (s == "LINEAR" || s.empty()) return Interpolation::linear;
  if (s == "STEP") return Interpolation::step;
  if (s == "CUBICSPLINE") return Interpolation::cubic_spline;
  *ok = false;
  return Interpolation::linear;
}

// Everything about the skeleton the animation sampler needs.
struct SkeletonLayout {
  std::vector<int> joint_nodes;              // node index of each skeleton joint, in order
  std::vector<int> ancestor_nodes;           // nodes above the roots, sampled to fold them in
  std::vector<int> slot_of_node;             // node -> slot (joints first, then ancestors), or -1
  std::vector<std::vector<int>> root_chain;  // per joint: ancestor slots top-down (roots only)
  std::vector<Transform> slot_rest;          // rest local transform per slot
};

// Builds the parent array of every node, refusing out-of-range children, nodes with two
// parents and cycles.
Result<std::vector<int>> node_parents(const tinygltf::Model& model) {
  const size_t n = model.nodes.size();
  std::vector<int> parent(n, -1);
  for (size_t i = 0; i < n; ++i) {
    for (int c : model.nodes[i].children) {
      if (c < 0 || static_cast<size_t>(c) >= n) {
        return Error{node_label(model, static_cast<int>(i)) + " lists child " + std::to_string(c) +
                     ", out of range (the file has " + std::to_string(n) + " nodes)"};
      }
      if (parent[static_cast<size_t>(c)] != -1 || static_cast<size_t>(c) == i) {
        return Error{node_label(model, c) + " has more than one parent (or is its own child)"};
      }
      parent[static_cast<size_t>(c)] = static_cast<int>(i);
    }
  }
  // 0 = not visited, 1 = on the current upward walk, 2 = known to reach a root.
  std::vector<unsigned char> state(n, 0);
  std::vector<int> walk;
  for (size_t i = 0; i < n; ++i) {
    walk.clear();
    int j = static_cast<int>(i);
    while (j >= 0 && state[static_cast<size_t>(j)] == 0) {
      state[static_cast<size_t>(j)] = 1;
      walk.push_back(j);
      j = parent[static_cast<size_t>(j)];
    }
    if (j >= 0 && state[static_cast<size_t>(j)] == 1) {
      return Error{"the node hierarchy has a cycle through " + node_label(model, j)};
    }
    for (int w : walk) state[static_cast<size_t>(w)] = 2;
  }
  return parent;
}

struct SkeletonResult {
  Skeleton skeleton;
  SkeletonLayout layout;
  std::vector<glm::mat4> inverse_bind_matrices;
};

// Node -> its index in skin.joints (-1 for nodes that are not joints), refusing out-of-range
// and repeated joints.
Result<std::vector<int>> skin_slots(const tinygltf::Model& model, const tinygltf::Skin& skin,
                                    const std::string& skin_label) {
  const size_t n = model.nodes.size();
  std::vector<int> skin_slot(n, -1);
  for (size_t i = 0; i < skin.joints.size(); ++i) {
    const int j = skin.joints[i];
    if (j < 0 || static_cast<size_t>(j) >= n) {
      return Error{skin_label + ": joint " + std::to_string(i) + " is node " + std::to_string(j) +
                   ", out of range (the file has " + std::to_string(n) + " nodes)"};
    }
    if (skin_slot[static_cast<size_t>(j)] != -1) {
      return Error{skin_label + ": " + node_label(model, j) + " is listed twice as a joint"};
    }
    skin_slot[static_cast<size_t>(j)] = static_cast<int>(i);
  }
  return skin_slot;
}

// Which nodes become skeleton joints: the skin's, plus any non-joint node between two joints,
// or the hierarchy would break.
std::vector<bool> skeleton_nodes(const tinygltf::Skin& skin, const std::vector<int>& parent,
                                 const std::vector<int>& skin_slot) {
  std::vector<bool> in_skeleton(parent.size(), false);
  for (int j : skin.joints) in_skeleton[static_cast<size_t>(j)] = true;
  std::vector<int> between;
  for (int j : skin.joints) {
    between.clear();
    int p = parent[static_cast<size_t>(j)];
    while (p >= 0 && skin_slot[static_cast<size_t>(p)] < 0) {
      between.push_back(p);
      p = parent[static_cast<size_t>(p)];
    }
    if (p >= 0) {
      for (int b : between) in_skeleton[static_cast<size_t>(b)] = true;
    }
  }
  return in_skeleton;
}

// The joints in depth-first order, roots in the order their first joint appears in the skin.
void order_joints_depth_first(const tinygltf::Model& model, const tinygltf::Skin& skin,
                              const std::vector<int>& parent, const std::vector<bool>& in_skeleton,
                              SkeletonLayout& layout) {
  layout.slot_of_node.assign(parent.size(), -1);
  std::vector<int> stack;
  for (int j : skin.joints) {
    int root = j;
    while (parent[static_cast<size_t>(root)] >= 0 &&
           in_skeleton[static_cast<size_t>(parent[static_cast<size_t>(root)])]) {
      root = parent[static_cast<size_t>(root)];
    }
    if (layout.slot_of_node[static_cast<size_t>(root)] >= 0) continue;
    stack.assign(1, root);
    while (!stack.empty()) {
      const int node = stack.back();
      stack.pop_back();
      layout.slot_of_node[static_cast<size_t>(node)] = static_cast<int>(layout.joint_nodes.size());
      layout.joint_nodes.push_back(node);
      const std::vector<int>& children = model.nodes[static_cast<size_t>(node)].children;
      for (auto it = children.rbegin(); it != children.rend(); ++it) {
        if (in_skeleton[static_cast<size_t>(*it)]) stack.push_back(*it);
      }
    }
  }
}

// Ancestors of the roots get slots after the joints; each root remembers its chain, so its
// animation can fold theirs in.
void chain_root_ancestors(const std::vector<int>& parent, const std::vector<bool>& in_skeleton,
                          SkeletonLayout& layout) {
  const size_t joint_count = layout.joint_nodes.size();
  layout.root_chain.resize(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    const int p = parent[static_cast<size_t>(layout.joint_nodes[i])];
    if (p >= 0 && in_skeleton[static_cast<size_t>(p)]) continue;
    std::vector<int>& chain = layout.root_chain[i];
    for (int a = p; a >= 0; a = parent[static_cast<size_t>(a)]) {
      if (layout.slot_of_node[static_cast<size_t>(a)] < 0) {
        layout.slot_of_node[static_cast<size_t>(a)] =
            static_cast<int>(joint_count + layout.ancestor_nodes.size());
        layout.ancestor_nodes.push_back(a);
      }
      chain.push_back(layout.slot_of_node[static_cast<size_t>(a)]);
    }
    std::reverse(chain.begin(), chain.end());
  }
}

Status read_slot_rest(const tinygltf::Model& model, SkeletonLayout& layout) {
  const size_t joint_count = layout.joint_nodes.size();
  const size_t slot_count = joint_count + layout.ancestor_nodes.size();
  layout.slot_rest.resize(slot_count);
  for (size_t s = 0; s < slot_count; ++s) {
    const int node =
        s < joint_count ? layout.joint_nodes[s] : layout.ancestor_nodes[s - joint_count];
    auto rest = node_rest(model, node);
    if (!rest) return rest.error();
    layout.slot_rest[s] = *rest;
  }
  return {};
}

// The skeleton: names (the node's, made unique with the node index when empty or repeated),
// parents, and rest transforms, a root's folding in its ancestors' (scene space).
Result<Skeleton> skeleton_from_layout(const tinygltf::Model& model, const std::vector<int>& parent,
                                      const SkeletonLayout& layout, const std::string& skin_label) {
  const size_t joint_count = layout.joint_nodes.size();
  std::unordered_map<std::string, int> name_uses;
  for (int node : layout.joint_nodes) ++name_uses[model.nodes[static_cast<size_t>(node)].name];
  std::vector<std::string> names;
  std::vector<int> skeleton_parents;
  std::vector<Transform> rest;
  names.reserve(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    const int node = layout.joint_nodes[i];
    const std::string& name = model.nodes[static_cast<size_t>(node)].name;
    if (name.empty()) {
      names.push_back("node_" + std::to_string(node));
    } else if (name_uses[name] > 1) {
      names.push_back(name + "_" + std::to_string(node));
    } else {
      names.push_back(name);
    }
    const int p = parent[static_cast<size_t>(node)];
    skeleton_parents.push_back(p >= 0 ? layout.slot_of_node[static_cast<size_t>(p)] : -1);
    if (skeleton_parents.back() >= static_cast<int>(joint_count)) skeleton_parents.back() = -1;
    Transform local = layout.slot_rest[i];
    for (auto it = layout.root_chain[i].rbegin(); it != layout.root_chain[i].rend(); ++it) {
      local = compose(layout.slot_rest[static_cast<size_t>(*it)], local);
    }
    rest.push_back(local);
  }
  auto skeleton = Skeleton::create(std::move(names), std::move(skeleton_parents), rest);
  if (!skeleton) return Error{skin_label + ": " + skeleton.message()};
  return std::move(*skeleton);
}

// Inverse bind matrices: the skin's for its joints, the inverse rest global for joints the
// importer added.
Result<std::vector<glm::mat4>> inverse_bind_matrices(
    const tinygltf::Model& model, const tinygltf::Skin& skin, const std::vector<int>& skin_slot,
    const Skeleton& skeleton, const SkeletonLayout& layout, const std::string& skin_label) {
  const size_t joint_count = layout.joint_nodes.size();
  std::vector<Transform> globals(joint_count);
  forward_kinematics(skeleton.parents(), skeleton.rest(), globals);
  std::vector<float> matrices;
  if (skin.inverseBindMatrices >= 0) {
    auto read = read_accessor(model, skin.inverseBindMatrices, TINYGLTF_TYPE_MAT4, false,
                              skin_label + " inverseBindMatrices");
    if (!read) return read.error();
    matrices = std::move(*read);
    if (matrices.size() / 16 < skin.joints.size()) {
      return Error{skin_label + " has " + std::to_string(skin.joints.size()) + " joints but only " +
                   std::to_string(matrices.size() / 16) + " inverse bind matrices"};
    }
  }
  std::vector<glm::mat4> inverse_binds(joint_count);
  for (size_t i = 0; i < joint_count; ++i) {
    const int k = skin_slot[static_cast<size_t>(layout.joint_nodes[i])];
    if (k < 0) {
      inverse_binds[i] = glm::inverse(to_matrix(globals[i]));
    } else if (matrices.empty()) {
      inverse_binds[i] = glm::mat4(1.0f);
    } else {
      std::memcpy(&inverse_binds[i][0][0], matrices.data() + static_cast<size_t>(k) * 16,
                  sizeof(float) * 16);
    }
  }
  return inverse_binds;
}

Result<SkeletonResult> build_skeleton(const tinygltf::Model& model, int skin_index) {
  if (model.skins.empty()) {
    return Error{"the file has no skin, so no skeleton to import (glTF \"skins\" is empty)"};
  }
  if (skin_index < 0 || static_cast<size_t>(skin_index) >= model.skins.size()) {
    return Error{"skin " + std::to_string(skin_index) + " requested but the file has " +
                 std::to_string(model.skins.size()) + " skins"};
  }
  const tinygltf::Skin& skin = model.skins[static_cast<size_t>(skin_index)];
  const std::string skin_label = "skin " + std::to_string(skin_index) + quoted_name(skin.name);
  if (skin.joints.empty()) return Error{skin_label + " has no joints"};

  auto parent = node_parents(model);
  if (!parent) return parent.error();
  auto skin_slot = skin_slots(model, skin, skin_label);
  if (!skin_slot) return skin_slot.error();

  SkeletonResult result;
  const std::vector<bool> in_skeleton = skeleton_nodes(skin, *parent, *skin_slot);
  order_joints_depth_first(model, skin, *parent, in_skeleton, result.layout);
  chain_root_ancestors(*parent, in_skeleton, result.layout);
  if (Status rest = read_slot_rest(model, result.layout); !rest) return Error{rest.message()};

  auto skeleton = skeleton_from_layout(model, *parent, result.layout, skin_label);
  if (!skeleton) return skeleton.error();
  result.skeleton = std::move(*skeleton);
  auto inverse_binds =
      inverse_bind_matrices(model, skin, *skin_slot, result.skeleton, result.layout, skin_label);
  if (!inverse_binds) return inverse_binds.error();
  result.inverse_bind_matrices = std::move(*inverse_binds);
  return result;
}

// ---------------------------------------------------------------------------------------------
// Skinned mesh import

// The first node (in node order) that carries a mesh skinned with `skin_index`.
Result<int> skinned_mesh_node(const tinygltf::Model& model, int skin_index) {
  for (size_t n = 0; n < model.nodes.size(); ++n) {
    const tinygltf::Node& node = model.nodes[n];
    if (node.skin != skin_index || node.mesh < 0) continue;
    if (static_cast<size_t>(node.mesh) >= model.meshes.size()) {
      return Error{node_label(model, static_cast<int>(n)) + " refers to mesh " +
                   std::to_string(node.mesh) + ", out of range (the file has " +
                   std::to_string(model.meshes.size()) + " meshes)"};
    }
    return static_cast<int>(n);
  }
  return Error{"no mesh is skinned with skin " + std::to_string(skin_index) +
               " (no node has both \"skin\": " + std::to_string(skin_index) + " and a \"mesh\")"};
}

// The index of a primitive attribute, or an error naming it when it is required and absent.
Result<int> attribute(const tinygltf::Primitive& primitive, const std::string& name,
                      const std::string& label, bool required) {
  const auto it = primitive.attributes.find(name);
  if (it != primitive.attributes.end()) return it->second;
  if (required) return Error{label + " has no " + name + " attribute"};
  return -1;
}

std::vector<glm::vec3> as_vec3s(const std::vector<float>& values) {
  std::vector<glm::vec3> out(values.size() / 3);
  for (size_t i = 0; i < out.size(); ++i) {
    out[i] = {values[3 * i], values[3 * i + 1], values[3 * i + 2]};
  }
  return out;
}

// POSITION, NORMAL and the triangles of a primitive, every count and index checked.
Result<TriangleMesh> read_triangles(const tinygltf::Model& model,
                                    const tinygltf::Primitive& primitive,
                                    const std::string& label) {
  if (primitive.mode != -1 && primitive.mode != TINYGLTF_MODE_TRIANGLES) {
    return Error{label + " has mode " + std::to_string(primitive.mode) +
                 "; only triangles (mode 4) are read"};
  }
  auto position = attribute(primitive, "POSITION", label, true);
  if (!position) return position.error();
  auto positions = read_accessor(model, *position, TINYGLTF_TYPE_VEC3, false, label + " POSITION");
  if (!positions) return positions.error();
  TriangleMesh mesh;
  mesh.positions = as_vec3s(*positions);
  const size_t n = mesh.positions.size();
  auto normal = attribute(primitive, "NORMAL", label, false);
  if (*normal >= 0) {
    auto normals = read_accessor(model, *normal, TINYGLTF_TYPE_VEC3, false, label + " NORMAL");
    if (!normals) return normals.error();
    mesh.normals = as_vec3s(*normals);
    if (mesh.normals.size() != n) {
      return Error{label + " has " + std::to_string(n) + " positions but " +
                   std::to_string(mesh.normals.size()) + " normals"};
    }
  }
  if (primitive.indices >= 0) {
    auto indices = read_integer_accessor(
        model, primitive.indices, TINYGLTF_TYPE_SCALAR,
        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
        "UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT", label + " indices");
    if (!indices) return indices.error();
    mesh.indices = std::move(*indices);
  } else {
    mesh.indices.resize(n);
    for (size_t i = 0; i < n; ++i) mesh.indices[i] = static_cast<uint32_t>(i);
  }
  if (mesh.indices.size() % 3 != 0) {
    return Error{label + " has " + std::to_string(mesh.indices.size()) +
                 " indices, not a whole number of triangles"};
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= n) {
      return Error{label + " index " + std::to_string(i) + " is vertex " +
                   std::to_string(mesh.indices[i]) + ", out of range (" + std::to_string(n) +
                   " vertices)"};
    }
  }
  return mesh;
}

// JOINTS_0 and WEIGHTS_0 as influences on skeleton joints: a skin joint number k becomes the
// skeleton joint of node skin.joints[k]. Weights are checked and normalized.
Result<std::vector<VertexInfluences>> read_influences(
    const tinygltf::Model& model, const tinygltf::Primitive& primitive, size_t vertex_count,
    const tinygltf::Skin& skin, const SkeletonLayout& layout, const std::string& label) {
  if (primitive.attributes.count("JOINTS_1") || primitive.attributes.count("WEIGHTS_1")) {
    return Error{label +
                 " has JOINTS_1/WEIGHTS_1: more than four influences per vertex are "
                 "not supported"};
  }
  auto joints_index = attribute(primitive, "JOINTS_0", label, true);
  if (!joints_index) return joints_index.error();
  auto weights_index = attribute(primitive, "WEIGHTS_0", label, true);
  if (!weights_index) return weights_index.error();
  auto joints = read_integer_accessor(
      model, *joints_index, TINYGLTF_TYPE_VEC4,
      {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
      "UNSIGNED_BYTE or UNSIGNED_SHORT", label + " JOINTS_0");
  if (!joints) return joints.error();
  auto weights =
      read_accessor(model, *weights_index, TINYGLTF_TYPE_VEC4, true, label + " WEIGHTS_0");
  if (!weights) return weights.error();
  if (joints->size() != vertex_count * 4 || weights->size() != vertex_count * 4) {
    return Error{label + " has " + std::to_string(vertex_count) + " positions but " +
                 std::to_string(joints->size() / 4) + " JOINTS_0 and " +
                 std::to_string(weights->size() / 4) + " WEIGHTS_0 elements"};
  }
  std::vector<VertexInfluences> influences(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) {
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const size_t i = v * 4 + static_cast<size_t>(k);
      const float w = (*weights)[i];
      if (w < 0.0f) {
        return Error{label + " vertex " + std::to_string(v) + " has negative weight " + number(w)};
      }
      if (w == 0.0f) continue;
      const uint32_t joint = (*joints)[i];
      if (joint >= skin.joints.size()) {
        return Error{label + " vertex " + std::to_string(v) + " is weighted to joint " +
                     std::to_string(joint) + ", out of range (the skin has " +
                     std::to_string(skin.joints.size()) + " joints)"};
      }
      influences[v].joints[k] = layout.slot_of_node[static_cast<size_t>(skin.joints[joint])];
      influences[v].weights[k] = w;
      sum += w;
    }
    if (!(sum > 0.0f)) return Error{label + " vertex " + std::to_string(v) + " has no weight"};
    influences[v].weights /= sum;
  }
  return influences;
}

Result<SkinnedMesh> read_skinned_mesh(const tinygltf::Model& model, int skin_index,
                                      const SkeletonResult& skeleton) {
  auto node = skinned_mesh_node(model, skin_index);
  if (!node) return node.error();
  const int mesh_index = model.nodes[static_cast<size_t>(*node)].mesh;
  const tinygltf::Mesh& gltf_mesh = model.meshes[static_cast<size_t>(mesh_index)];
  const std::string label =
      "mesh " + std::to_string(mesh_index) + quoted_name(gltf_mesh.name) + " primitive 0";
  if (gltf_mesh.primitives.empty()) {
    return Error{"mesh " + std::to_string(mesh_index) + quoted_name(gltf_mesh.name) +
                 " has no primitives"};
  }
  const tinygltf::Primitive& primitive = gltf_mesh.primitives[0];
  SkinnedMesh out;
  auto mesh = read_triangles(model, primitive, label);
  if (!mesh) return mesh.error();
  out.mesh = std::move(*mesh);
  auto influences =
      read_influences(model, primitive, out.mesh.positions.size(),
                      model.skins[static_cast<size_t>(skin_index)], skeleton.layout, label);
  if (!influences) return influences.error();
  out.influences = std::move(*influences);
  for (size_t j = 0; j < skeleton.inverse_bind_matrices.size(); ++j) {
    auto bind = decompose(
        glm::inverse(glm::dmat4(skeleton.inverse_bind_matrices[j])),
        "inverse bind matrix of joint '" + skeleton.skeleton.name(static_cast<int>(j)) + "'");
    if (!bind) return bind.error();
    out.bind_global.push_back(*bind);
  }
  return out;
}

// Reads one channel's sampler into a track, validating types, counts and key times.
Result<Track> read_track(const tinygltf::Model& model, const tinygltf::AnimationSampler& sampler,
                         Path path, const std::string& what) {
  Track track;
  track.path = path;
  track.components = path == Path::rotation ? 4 : 3;
  bool known = false;
  track.interpolation = parse_interpolation(sampler.interpolation, &known);
  if (!known) {
    return Error{what + ": unknown interpolation '" + sampler.interpolation +
                 "' (expected LINEAR, STEP or CUBICSPLINE)"};
  }
  auto times = read_accessor(model, sampler.input, TINYGLTF_TYPE_SCALAR, false, what + " input");
  if (!times) return times.error();
  track.times = std::move(*times);
  for (size_t k = 1; k < track.times.size(); ++k) {
    if (!(track.times[k] > track.times[k - 1])) {
      return Error{what + " input: key times must increase, but key " + std::to_string(k) + " (" +
                   number(track.times[k]) + " s) follows " + number(track.times[k - 1]) + " s"};
    }
  }
  auto values = read_accessor(model, sampler.output,
                              path == Path::rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                              path == Path::rotation, what + " output");
  if (!values) return values.error();
  track.values = std::move(*values);
  const bool cubic = track.interpolation == Interpolation::cubic_spline;
  const size_t expected = track.times.size() * (cubic ? 3 : 1);
  const size_t found = track.values.size() / static_cast<size_t>(track.components);
  if (found != expected) {
    return Error{what + ": " + std::to_string(track.times.size()) + " key times but " +
                 std::to_string(found) + " output values (expected " + std::to_string(expected) +
                 (cubic ? ": in-tangent, value, out-tangent per key" : "") + ")"};
  }
  if (path == Path::rotation) {
    // Key rotations must be usable unit quaternions; tangents stay as they are.
    for (size_t k = 0; k < track.times.size(); ++k) {
      float* q = track.values.data() + (cubic ? 3 * k + 1 : k) * 4;
      const float len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(len > 1e-6f)) {
        return Error{what + " output: rotation key " + std::to_string(k) + " has zero length"};
      }
      for (int c = 0; c < 4; ++c) q[c] /= len;
    }
  }
  return track;
}

Result<Clip> sample_animation(const tinygltf::Model& model, size_t animation_index,
                              const SkeletonResult& skel, float sample_rate,
                              const std::string& stem, const std::string& source_path,
                              bool* animates_skeleton) {
  *animates_skeleton = false;
  const tinygltf::Animation& animation = model.animations[animation_index];
  const std::string label =
      "animation " + std::to_string(animation_index) + quoted_name(animation.name);
  if (animation.channels.empty()) return Error{label + " has no channels"};

  const SkeletonLayout& layout = skel.layout;
  std::vector<Track> tracks;
  std::vector<int> used_by_channel(layout.slot_rest.size() * 3, -1);
  for (size_t c = 0; c < animation.channels.size(); ++c) {
    const tinygltf::AnimationChannel& channel = animation.channels[c];
    const std::string what = label + " channel " + std::to_string(c);
    if (channel.sampler < 0 || static_cast<size_t>(channel.sampler) >= animation.samplers.size()) {
      return Error{what + ": sampler " + std::to_string(channel.sampler) +
                   " is out of range (the animation has " +
                   std::to_string(animation.samplers.size()) + " samplers)"};
    }
    if (channel.target_node < 0 || static_cast<size_t>(channel.target_node) >= model.nodes.size()) {
      return Error{what + ": target node " + std::to_string(channel.target_node) +
                   " is out of range (the file has " + std::to_string(model.nodes.size()) +
                   " nodes)"};
    }
    Path path;
    if (channel.target_path == "translation") {
      path = Path::translation;
    } else if (channel.target_path == "rotation") {
      path = Path::rotation;
    } else if (channel.target_path == "scale") {
      path = Path::scale;
    } else if (channel.target_path == "weights") {
      continue;  // morph target weights do not move joints
    } else {
      return Error{what + ": unknown target path '" + channel.target_path + "'"};
    }
    const int slot = layout.slot_of_node[static_cast<size_t>(channel.target_node)];
    if (slot < 0) continue;  // a node that does not move the skeleton (documented)
    int& previous = used_by_channel[static_cast<size_t>(slot) * 3 + static_cast<size_t>(path)];
    if (previous >= 0) {
      return Error{what + " and channel " + std::to_string(previous) + " both animate the " +
                   path_name(path) + " of " + node_label(model, channel.target_node)};
    }
    previous = static_cast<int>(c);
    auto track =
        read_track(model, animation.samplers[static_cast<size_t>(channel.sampler)], path,
                   what + " (sampler " + std::to_string(channel.sampler) + ", " + path_name(path) +
                       " of " + node_label(model, channel.target_node) + ")");
    if (!track) return track.error();
    track->slot = slot;
    tracks.push_back(std::move(*track));
  }
  if (tracks.empty()) return Clip{};
  *animates_skeleton = true;

  double t_begin = std::numeric_limits<double>::infinity();
  double t_end = -std::numeric_limits<double>::infinity();
  for (const Track& t : tracks) {
    t_begin = std::min(t_begin, static_cast<double>(t.times.front()));
    t_end = std::max(t_end, static_cast<double>(t.times.back()));
  }
  const double rate = sample_rate;
  const double intervals = (t_end - t_begin) * rate;
  const size_t joint_count = layout.joint_nodes.size();
  if (!((std::floor(intervals) + 1.0) * static_cast<double>(joint_count) <=
        kMaxSampledTransforms)) {
    return Error{label + " lasts " + number(t_end - t_begin) + " s: sampling " +
                 std::to_string(joint_count) + " joints at " + number(sample_rate) +
                 " Hz would exceed the limit of " +
                 std::to_string(static_cast<long>(kMaxSampledTransforms)) + " joint transforms"};
  }
  // The small tolerance keeps the last key when (end - begin) * rate is an integer up to
  // rounding.
  const int frame_count = clamped_integer<int>(std::floor(intervals + 1e-3)) + 1;

  Clip clip;
  clip.name = !animation.name.empty()        ? animation.name
              : model.animations.size() == 1 ? stem
                                             : stem + "_" + std::to_string(animation_index);
  clip.source_path = source_path;
  clip.skeleton = skel.skeleton;
  clip.frame_time = 1.0f / sample_rate;
  clip.frame_count = frame_count;
  clip.local.resize(static_cast<size_t>(frame_count) * joint_count);

  std::vector<Transform> slots(layout.slot_rest.size());
  for (int f = 0; f < frame_count; ++f) {
    const double t = t_begin + static_cast<double>(f) / rate;
    std::copy(layout.slot_rest.begin(), layout.slot_rest.end(), slots.begin());
    for (const Track& track : tracks) {
      const glm::vec4 v = sample(track, t);
      Transform& target = slots[static_cast<size_t>(track.slot)];
      switch (track.path) {
        case Path::translation:
          target.translation = glm::vec3(v);
          break;
        case Path::rotation:
          target.rotation = as_quat(v);
          break;
        case Path::scale:
          target.scale = glm::vec3(v);
          break;
      }
    }
    std::span<Transform> pose = clip.pose(f);
    for (size_t j = 0; j < joint_count; ++j) {
      Transform local = slots[j];
      const std::vector<int>& chain = layout.root_chain[j];
      for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        local = compose(slots[static_cast<size_t>(*it)], local);
      }
      pose[j] = local;
    }
  }
  if (Status s = clip.validate(); !s) return Error{label + ": " + s.message()};
  return clip;
}

Result<GltfAsset> parse_model(std::span<const unsigned char> bytes,
                              const std::filesystem::path& path, const GltfImportOptions& options) {
  if (!(options.sample_rate > 0.0f) || !std::isfinite(options.sample_rate)) {
    return Error{"sample rate must be a positive finite number of Hz, got " +
                 number(options.sample_rate)};
  }
  auto loaded = gltf_files::load_model(bytes, path, options.allow_external_files);
  if (!loaded) return loaded.error();
  const tinygltf::Model& model = *loaded;

  auto skeleton = build_skeleton(model, options.skin);
  if (!skeleton) return skeleton.error();

  GltfAsset asset;
  const std::string stem = path.stem().string();
  for (size_t a = 0; a < model.animations.size(); ++a) {
    bool animates = false;
    auto clip =
        sample_animation(model, a, *skeleton, options.sample_rate, stem, path.string(), &animates);
    if (!clip) return clip.error();
    if (animates) asset.clips.push_back(std::move(*clip));
  }
  if (options.read_skinned_mesh) {
    auto mesh = read_skinned_mesh(model, options.skin, *skeleton);
    if (!mesh) return mesh.error();
    asset.skinned_mesh = std::move(*mesh);
  }
  asset.skeleton = std::move(skeleton->skeleton);
  asset.inverse_bind_matrices = std::move(skeleton->inverse_bind_matrices);
  return asset;
}

// ---------------------------------------------------------------------------------------------
// Export

Status write_file(const std::filesystem::path& out, const std::string& content) {
  std::ofstream file(out, std::ios::binary | std::ios::trunc);
  if (!file) return Error{out.string() + ": cannot open for writing"};
  file.write(content.data(), static_cast<std::streamsize>(content.size()));
  file.close();
  if (!file) return Error{out.string() + ": writing failed (disk full or no permission?)"};
  return Status::success();
}

// The body's consistency with the skeleton, before anything is written.
Status check_body(const SkinnedMesh& body, size_t joints) {
  const TriangleMesh& mesh = body.mesh;
  const size_t vertices = mesh.positions.size();
  if (body.bind_global.size() != joints) {
    return Error{"the body has " + std::to_string(body.bind_global.size()) +
                 " bind transforms for " + std::to_string(joints) + " joints"};
  }
  if (joints > 65536)
    return Error{"JOINTS_0 as UNSIGNED_SHORT cannot address " + std::to_string(joints) + " joints"};
  if (vertices == 0 || mesh.indices.empty()) return Error{"the body mesh is empty"};
  if (body.influences.size() != vertices ||
      (!mesh.normals.empty() && mesh.normals.size() != vertices)) {
    return Error{"the body has " + std::to_string(vertices) + " vertices but " +
                 std::to_string(body.influences.size()) + " influences and " +
                 std::to_string(mesh.normals.size()) + " normals"};
  }
  if (mesh.indices.size() % 3 != 0) return Error{"the body's index count is not a multiple of 3"};
  for (uint32_t i : mesh.indices) {
    if (i >= vertices) return Error{"the body's index " + std::to_string(i) + " is out of range"};
  }
  for (size_t v = 0; v < vertices; ++v) {
    const VertexInfluences& in = body.influences[v];
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const float w = in.weights[k];
      if (!(w >= 0.0f) || !std::isfinite(w)) {
        return Error{"body vertex " + std::to_string(v) + " has weight " + number(w)};
      }
      if (w > 0.0f && (in.joints[k] < 0 || static_cast<size_t>(in.joints[k]) >= joints)) {
        return Error{"body vertex " + std::to_string(v) + " is weighted to joint " +
                     std::to_string(in.joints[k]) + ", out of range"};
      }
      sum += w;
    }
    if (!(sum > 0.0f)) return Error{"body vertex " + std::to_string(v) + " has no weight"};
    if (!finite(mesh.positions[v]) || (!mesh.normals.empty() && !finite(mesh.normals[v]))) {
      return Error{"body vertex " + std::to_string(v) + " is not finite"};
    }
  }
  return Status::success();
}

// The one-triangle primitive save_gltf writes without a body: 1 cm, weighted fully to joint
// 0, so importers that only build armatures for skinned meshes still see the skin.
tinygltf::Primitive anchor_primitive(BufferWriter& writer, const glm::vec3& anchor) {
  const float positions[9] = {anchor.x, anchor.y, anchor.z,         anchor.x + 0.01f, anchor.y,
                              anchor.z, anchor.x, anchor.y + 0.01f, anchor.z};
  const uint8_t joint_indices[12] = {};
  const float weights[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  std::vector<double> pmin(3), pmax(3);
  for (int c = 0; c < 3; ++c) {
    pmin[static_cast<size_t>(c)] = std::min({positions[c], positions[3 + c], positions[6 + c]});
    pmax[static_cast<size_t>(c)] = std::max({positions[c], positions[3 + c], positions[6 + c]});
  }
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.attributes["POSITION"] =
      writer.add(positions, sizeof positions, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3,
                 TINYGLTF_TARGET_ARRAY_BUFFER, pmin, pmax);
  primitive.attributes["JOINTS_0"] =
      writer.add(joint_indices, sizeof joint_indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                 TINYGLTF_TYPE_VEC4, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["WEIGHTS_0"] =
      writer.add(weights, sizeof weights, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, 3,
                 TINYGLTF_TARGET_ARRAY_BUFFER);
  return primitive;
}

// The body's primitive (check_body has accepted it): weights normalized, unused slots joint 0.
tinygltf::Primitive body_primitive(BufferWriter& writer, const SkinnedMesh& body) {
  const TriangleMesh& mesh = body.mesh;
  const size_t n = mesh.positions.size();
  std::vector<double> pmin(3, std::numeric_limits<double>::max());
  std::vector<double> pmax(3, -std::numeric_limits<double>::max());
  for (const glm::vec3& p : mesh.positions) {
    for (int c = 0; c < 3; ++c) {
      pmin[static_cast<size_t>(c)] = std::min(pmin[static_cast<size_t>(c)], double{p[c]});
      pmax[static_cast<size_t>(c)] = std::max(pmax[static_cast<size_t>(c)], double{p[c]});
    }
  }
  std::vector<uint16_t> joints(n * 4, 0);
  std::vector<float> weights(n * 4, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    const VertexInfluences& in = body.influences[v];
    const float sum = in.weights.x + in.weights.y + in.weights.z + in.weights.w;
    for (int k = 0; k < 4; ++k) {
      if (!(in.weights[k] > 0.0f)) continue;
      joints[v * 4 + static_cast<size_t>(k)] = static_cast<uint16_t>(in.joints[k]);
      weights[v * 4 + static_cast<size_t>(k)] = in.weights[k] / sum;
    }
  }
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.attributes["POSITION"] =
      writer.add(mesh.positions.data(), n * sizeof(glm::vec3), TINYGLTF_COMPONENT_TYPE_FLOAT,
                 TINYGLTF_TYPE_VEC3, n, TINYGLTF_TARGET_ARRAY_BUFFER, pmin, pmax);
  if (!mesh.normals.empty()) {
    primitive.attributes["NORMAL"] =
        writer.add(mesh.normals.data(), n * sizeof(glm::vec3), TINYGLTF_COMPONENT_TYPE_FLOAT,
                   TINYGLTF_TYPE_VEC3, n, TINYGLTF_TARGET_ARRAY_BUFFER);
  }
  primitive.attributes["JOINTS_0"] = writer.add(
      joints.data(), joints.size() * sizeof(uint16_t), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
      TINYGLTF_TYPE_VEC4, n, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["WEIGHTS_0"] =
      writer.add(weights.data(), weights.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
                 TINYGLTF_TYPE_VEC4, n, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.indices = writer.add(mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t),
                                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                 mesh.indices.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  return primitive;
}

// What save_model accepts: a known extension, frames matching the skeleton, finite transforms
// with usable rotations, a positive frame time, and a body consistent with the skeleton.
Status check_export(const Skeleton& skeleton, std::span<const Transform> frames, int frame_count,
                    float frame_time, const SkinnedMesh* body, const std::string& ext) {
  if (ext != ".glb" && ext != ".gltf") {
    return Error{"unknown extension '" + ext + "', expected .glb (binary) or .gltf (JSON)"};
  }
  const size_t joints = static_cast<size_t>(skeleton.joint_count());
  if (joints == 0) return Error{"the skeleton has no joints"};
  if (frame_count < 1)
    return Error{"nothing to write: frame count is " + std::to_string(frame_count)};
  if (!(frame_time > 0.0f) || !std::isfinite(frame_time)) {
    return Error{"frame time must be a positive finite number of seconds"};
  }
  const size_t frames_n = static_cast<size_t>(frame_count);
  if (frames.size() != frames_n * joints) {
    return Error{"expected " + std::to_string(frames_n * joints) + " transforms (" +
                 std::to_string(frame_count) + " frames x " + std::to_string(joints) +
                 " joints), got " + std::to_string(frames.size())};
  }
  if (body) {
    if (Status b = check_body(*body, joints); !b) return b;
  }
  auto usable = [](const Transform& t) {
    const float n = glm::length(t.rotation);
    return finite(t.translation) && finite(t.scale) && std::isfinite(n) && n > 1e-6f;
  };
  const std::string problem = ": non-finite transform or zero rotation";
  for (size_t j = 0; j < joints; ++j) {
    if (!usable(skeleton.rest(static_cast<int>(j)))) {
      return Error{"rest of joint '" + skeleton.name(static_cast<int>(j)) + "'" + problem};
    }
  }
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!usable(frames[i])) {
      return Error{"frame " + std::to_string(i / joints) + ", joint '" +
                   skeleton.name(static_cast<int>(i % joints)) + "'" + problem};
    }
  }
  return Status::success();
}

// The bind pose: the body's, else the rest pose; as globals and as the nodes' locals.
struct BindPose {
  std::vector<Transform> global;
  std::vector<Transform> local;
};

BindPose bind_pose(const Skeleton& skeleton, const SkinnedMesh* body) {
  const size_t joints = static_cast<size_t>(skeleton.joint_count());
  BindPose bind{std::vector<Transform>(joints), skeleton.rest()};
  if (body) {
    bind.global = body->bind_global;
    for (size_t j = 0; j < joints; ++j) {
      const int p = skeleton.parent(static_cast<int>(j));
      bind.local[j] = p < 0 ? bind.global[j]
                            : compose(inverse(bind.global[static_cast<size_t>(p)]), bind.global[j]);
    }
  } else {
    forward_kinematics(skeleton.parents(), skeleton.rest(), bind.global);
  }
  return bind;
}

// Joint nodes with their bind TRS, children listed by their parents. Returns the roots.
std::vector<int> add_joint_nodes(tinygltf::Model& model, const Skeleton& skeleton,
                                 const BindPose& bind) {
  const size_t joints = static_cast<size_t>(skeleton.joint_count());
  model.nodes.resize(joints);
  std::vector<int> roots;
  for (size_t j = 0; j < joints; ++j) {
    tinygltf::Node& node = model.nodes[j];
    const Transform& r = bind.local[j];
    const glm::quat q = glm::normalize(r.rotation);
    node.name = skeleton.name(static_cast<int>(j));
    node.translation = {r.translation.x, r.translation.y, r.translation.z};
    node.rotation = {q.x, q.y, q.z, q.w};
    if (r.scale != glm::vec3(1.0f)) node.scale = {r.scale.x, r.scale.y, r.scale.z};
    const int p = skeleton.parent(static_cast<int>(j));
    if (p >= 0) {
      model.nodes[static_cast<size_t>(p)].children.push_back(static_cast<int>(j));
    } else {
      roots.push_back(static_cast<int>(j));
    }
  }
  return roots;
}

// The skin (every joint, bound in the bind pose), the mesh it deforms (the body, or an anchor
// triangle), the node carrying both, and the scene.
void add_skin_mesh_and_scene(tinygltf::Model& model, BufferWriter& writer, const BindPose& bind,
                             const std::vector<int>& roots, const SkinnedMesh* body,
                             std::string_view name) {
  const size_t joints = bind.global.size();
  std::vector<float> inverse_binds(joints * 16);
  for (size_t j = 0; j < joints; ++j) {
    const glm::mat4 m = glm::inverse(to_matrix(bind.global[j]));
    std::memcpy(inverse_binds.data() + j * 16, &m[0][0], sizeof(float) * 16);
  }
  tinygltf::Skin skin;
  skin.name = std::string(name);
  for (size_t j = 0; j < joints; ++j) skin.joints.push_back(static_cast<int>(j));
  skin.inverseBindMatrices =
      writer.add(inverse_binds.data(), inverse_binds.size() * sizeof(float),
                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, joints, 0);
  if (roots.size() == 1) skin.skeleton = roots.front();
  model.skins.push_back(std::move(skin));

  tinygltf::Mesh mesh;
  mesh.name = std::string(name) + (body ? "_body" : "_skin_anchor");
  mesh.primitives.push_back(body ? body_primitive(writer, *body)
                                 : anchor_primitive(writer, bind.global[0].translation));
  model.meshes.push_back(std::move(mesh));
  tinygltf::Node mesh_node;
  mesh_node.name = model.meshes.back().name;
  mesh_node.mesh = 0;
  mesh_node.skin = 0;
  model.nodes.push_back(std::move(mesh_node));

  tinygltf::Scene scene;
  scene.name = std::string(name);
  scene.nodes = roots;
  scene.nodes.push_back(static_cast<int>(joints));
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;
}

// One joint's per-frame values of one TRS path, flattened.
template <class Value>
std::vector<float> joint_track(std::span<const Transform> frames, size_t joints, size_t joint,
                               Value value) {
  std::vector<float> values;
  for (size_t f = 0; f * joints < frames.size(); ++f) {
    const auto v = value(frames[f * joints + joint]);
    for (int c = 0; c < v.length(); ++c) values.push_back(v[c]);
  }
  return values;
}

// The animation: one key per frame, LINEAR, all samplers sharing the key times. Scale gets a
// channel only for joints whose scale leaves the bind pose's.
void add_animation(tinygltf::Model& model, BufferWriter& writer, std::span<const Transform> frames,
                   const BindPose& bind, float frame_time, std::string_view name) {
  const size_t joints = bind.local.size();
  const size_t frames_n = frames.size() / joints;
  std::vector<float> times(frames_n);
  for (size_t f = 0; f < frames_n; ++f) {
    times[f] = static_cast<float>(static_cast<double>(f) * frame_time);
  }
  const int time_accessor =
      writer.add(times.data(), times.size() * sizeof(float), TINYGLTF_COMPONENT_TYPE_FLOAT,
                 TINYGLTF_TYPE_SCALAR, frames_n, 0, {times.front()}, {times.back()});
  tinygltf::Animation animation;
  animation.name = std::string(name);
  auto add_channel = [&](size_t joint, const char* path, const std::vector<float>& values,
                         int type) {
    tinygltf::AnimationSampler sampler;
    sampler.input = time_accessor;
    sampler.output = writer.add(values.data(), values.size() * sizeof(float),
                                TINYGLTF_COMPONENT_TYPE_FLOAT, type, frames_n, 0);
    sampler.interpolation = "LINEAR";
    animation.samplers.push_back(std::move(sampler));
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(animation.samplers.size() - 1);
    channel.target_node = static_cast<int>(joint);
    channel.target_path = path;
    animation.channels.push_back(std::move(channel));
  };
  for (size_t j = 0; j < joints; ++j) {
    add_channel(j, "translation",
                joint_track(frames, joints, j, [](const Transform& t) { return t.translation; }),
                TINYGLTF_TYPE_VEC3);
    // Consecutive keys in one hemisphere, so importers that blend components see no flips.
    std::optional<glm::quat> previous;
    auto continuous_rotation = [&previous](const Transform& t) {
      glm::quat q = glm::normalize(t.rotation);
      if (previous && glm::dot(q, *previous) < 0.0f) q = -q;
      previous = q;
      return glm::vec4(q.x, q.y, q.z, q.w);
    };
    add_channel(j, "rotation", joint_track(frames, joints, j, continuous_rotation),
                TINYGLTF_TYPE_VEC4);
    bool scale_moves = false;
    for (size_t f = 0; f < frames_n && !scale_moves; ++f) {
      scale_moves = frames[f * joints + j].scale != bind.local[j].scale;
    }
    if (scale_moves) {
      add_channel(j, "scale",
                  joint_track(frames, joints, j, [](const Transform& t) { return t.scale; }),
                  TINYGLTF_TYPE_VEC3);
    }
  }
  model.animations.push_back(std::move(animation));
}

// `body` may be null: the skeleton's rest pose is the bind pose and an anchor triangle the mesh.
Status save_model(const Skeleton& skeleton, std::span<const Transform> frames, int frame_count,
                  float frame_time, std::string_view name, const SkinnedMesh* body,
                  const std::filesystem::path& out) {
  const std::string where = out.string() + ": ";
  const std::string ext = lower_extension(out);
  if (Status s = check_export(skeleton, frames, frame_count, frame_time, body, ext); !s) {
    return Error{where + s.message()};
  }
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "mm motion matching: mm::save_gltf";
  BufferWriter writer(model);
  const BindPose bind = bind_pose(skeleton, body);
  const std::vector<int> roots = add_joint_nodes(model, skeleton, bind);
  add_skin_mesh_and_scene(model, writer, bind, roots, body, name);
  add_animation(model, writer, frames, bind, frame_time, name);
  writer.finish();

  std::ostringstream stream;
  tinygltf::TinyGLTF serializer;
  if (!serializer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/true, ext == ".glb")) {
    return Error{where + "tinygltf could not serialize the model"};
  }
  return write_file(out, stream.str());
}

}  // namespace

Result<GltfAsset> parse_gltf(std::span<const unsigned char> bytes,
                             const std::filesystem::path& path_for_messages,
                             const GltfImportOptions& options) {
  try {
    auto asset = parse_model(bytes, path_for_messages, options);
    if (!asset) return Error{path_for_messages.string() + ": " + asset.message()};
    return asset;
  } catch (const std::exception& e) {
    // tinygltf and allocation can throw on hostile input; never let it escape.
    return Error{path_for_messages.string() + ": failed to read glTF: " + e.what()};
  }
}

Result<GltfAsset> load_gltf(const std::filesystem::path& path, const GltfImportOptions& options) {
  auto contents = read_whole_file(path, "glTF file");
  if (!contents) return contents.error();
  return parse_gltf(
      std::span(reinterpret_cast<const unsigned char*>(contents->data.get()), contents->size), path,
      options);
}

Status save_gltf(const Skeleton& skeleton, std::span<const Transform> frames, int frame_count,
                 float frame_time, std::string_view name, const std::filesystem::path& out) {
  try {
    return save_model(skeleton, frames, frame_count, frame_time, name, nullptr, out);
  } catch (const std::exception& e) {
    return Error{out.string() + ": failed to write glTF: " + e.what()};
  }
}

Status save_skinned_gltf(const Skeleton& skeleton, const SkinnedMesh& body,
                         std::span<const Transform> frames, int frame_count, float frame_time,
                         std::string_view name, const std::filesystem::path& out) {
  try {
    return save_model(skeleton, frames, frame_count, frame_time, name, &body, out);
  } catch (const std::exception& e) {
    return Error{out.string() + ": failed to write glTF: " + e.what()};
  }
}

Status save_gltf(const Clip& clip, const std::filesystem::path& out) {
  if (Status s = clip.validate(); !s) return Error{out.string() + ": " + s.message()};
  return save_gltf(clip.skeleton, clip.local, clip.frame_count, clip.frame_time, clip.name, out);
}

}  // namespace mm
