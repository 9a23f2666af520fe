#include "mm/offline/bone_weights.hpp"
#include "mm/runtime/finite.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include <Eigen/SparseCholesky>

namespace mm {

namespace {

constexpr size_t kMaxInfluences = 4;
// Short lengths count as this fraction of the mean edge length, and never less than
// kMinLength (see the header): they would otherwise divide by zero.
constexpr float kLengthFloorFraction = 1e-3f;
constexpr float kMinLength = 1e-6f;
// Weights within this of a vertex's largest weight tie with it for "dominant".
constexpr float kDominanceTolerance = 1e-6f;

std::string str(size_t n) {
  return std::to_string(n);
}

// ---------------------------------------------------------------------------------------------
// Input validation.

Status validate_mesh_indices(const TriangleMesh& mesh) {
  const size_t n = mesh.vertex_count();
  if (mesh.indices.size() % 3 != 0) {
    return Error{"bone weights: the mesh has " + str(mesh.indices.size()) +
                 " triangle indices, not a multiple of 3"};
  }
  for (size_t k = 0; k < mesh.indices.size(); ++k) {
    if (mesh.indices[k] >= n) {
      return Error{"bone weights: triangle " + str(k / 3) + " has vertex index " +
                   str(mesh.indices[k]) + ", out of range for " + str(n) + " vertices"};
    }
  }
  return Status::success();
}

Status validate_mesh(const TriangleMesh& mesh) {
  const size_t n = mesh.vertex_count();
  if (n == 0) return Error{"bone weights: the mesh has no vertices"};
  if (!mesh.normals.empty() && mesh.normals.size() != n) {
    return Error{"bone weights: the mesh has " + str(mesh.normals.size()) + " normals for " +
                 str(n) + " vertices (normals must be empty or one per vertex)"};
  }
  for (size_t v = 0; v < n; ++v) {
    if (!finite(mesh.positions[v])) {
      return Error{"bone weights: vertex " + str(v) + " has a non-finite position"};
    }
    if (!mesh.normals.empty() && !finite(mesh.normals[v])) {
      return Error{"bone weights: vertex " + str(v) + " has a non-finite normal"};
    }
  }
  return validate_mesh_indices(mesh);
}

Status validate_bones(std::span<const BoneSegment> bones) {
  if (bones.empty()) return Error{"bone weights: no bones"};
  for (size_t b = 0; b < bones.size(); ++b) {
    const BoneSegment& bone = bones[b];
    const std::string name = "bone weights: bone " + str(b);
    if (bone.joint < 0) {
      return Error{name + " has joint " + std::to_string(bone.joint) + " (must be >= 0)"};
    }
    if (!finite(bone.head) || !finite(bone.tail)) {
      return Error{name + " has a non-finite head or tail"};
    }
    if (!std::isfinite(bone.head_radius) || !std::isfinite(bone.tail_radius)) {
      return Error{name + " has a non-finite radius"};
    }
    if (bone.head_radius < 0.0f || bone.tail_radius < 0.0f) {
      return Error{name + " has a negative radius (head " + std::to_string(bone.head_radius) +
                   ", tail " + std::to_string(bone.tail_radius) + ")"};
    }
  }
  return Status::success();
}

// `value` must be finite and > 0 (an error message naming the option otherwise).
Status require_positive(float value, const char* name) {
  if (std::isfinite(value) && value > 0.0f) return Status::success();
  return Error{std::string("bone weights: option ") + name + " must be finite and > 0 (got " +
               std::to_string(value) + ")"};
}

Status validate_options(const BoneWeightOptions& o) {
  const std::pair<float, const char*> positives[] = {{o.distance_power, "distance_power"},
                                                     {o.distance_softness, "distance_softness"},
                                                     {o.envelope_falloff, "envelope_falloff"},
                                                     {o.heat_constant, "heat_constant"},
                                                     {o.geodesic_falloff, "geodesic_falloff"}};
  for (const auto& [value, name] : positives) {
    if (Status s = require_positive(value, name); !s) return s;
  }
  // Below 1/4 the largest of four normalized weights (>= 1/4) is never dropped.
  if (!(o.min_weight >= 0.0f && o.min_weight < 0.25f)) {
    return Error{"bone weights: option min_weight must be in [0, 0.25) (got " +
                 std::to_string(o.min_weight) + ")"};
  }
  return Status::success();
}

Status validate_input(const TriangleMesh& mesh, std::span<const BoneSegment> bones) {
  if (Status s = validate_mesh(mesh); !s) return s;
  return validate_bones(bones);
}

// ---------------------------------------------------------------------------------------------
// Joints and distances.

// The distinct joints of the bones, ascending, and each bone's index among them.
struct JointTable {
  std::vector<int> ids;
  std::vector<size_t> of_bone;
};

JointTable collect_joints(std::span<const BoneSegment> bones) {
  JointTable table;
  for (const BoneSegment& bone : bones) table.ids.push_back(bone.joint);
  std::sort(table.ids.begin(), table.ids.end());
  table.ids.erase(std::unique(table.ids.begin(), table.ids.end()), table.ids.end());
  for (const BoneSegment& bone : bones) {
    const auto it = std::lower_bound(table.ids.begin(), table.ids.end(), bone.joint);
    table.of_bone.push_back(static_cast<size_t>(it - table.ids.begin()));
  }
  return table;
}

struct BoneDistance {
  float axis = 0.0f;     // to the closest point of the segment
  float surface = 0.0f;  // axis minus the radius there: negative inside the capsule
};

BoneDistance bone_distance(const glm::vec3& p, const BoneSegment& bone) {
  const glm::vec3 d = bone.tail - bone.head;
  const float length2 = glm::dot(d, d);
  const float t =
      length2 > 0.0f ? std::clamp(glm::dot(p - bone.head, d) / length2, 0.0f, 1.0f) : 0.0f;
  const float axis = glm::length(p - (bone.head + t * d));
  return {axis, axis - glm::mix(bone.head_radius, bone.tail_radius, t)};
}

// Every vertex measured against every joint (row-major, one row of joint_count per vertex).
struct Proximity {
  size_t joint_count = 0;
  std::vector<float> surface;       // smallest surface distance over the joint's bones
  std::vector<size_t> nearest;      // the joint (index into JointTable::ids) of the nearest bone
  std::vector<float> nearest_axis;  // axis distance to the nearest bone
};

Proximity measure_proximity(const TriangleMesh& mesh, std::span<const BoneSegment> bones,
                            const JointTable& joints) {
  const size_t n = mesh.vertex_count();
  const size_t jc = joints.ids.size();
  Proximity px;
  px.joint_count = jc;
  px.surface.assign(n * jc, std::numeric_limits<float>::infinity());
  px.nearest.assign(n, 0);
  px.nearest_axis.assign(n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    float best = std::numeric_limits<float>::infinity();
    for (size_t b = 0; b < bones.size(); ++b) {
      const BoneDistance d = bone_distance(mesh.positions[v], bones[b]);
      float& slot = px.surface[v * jc + joints.of_bone[b]];
      slot = std::min(slot, d.surface);
      if (d.surface < best) {  // strict: the lower bone index wins a tie
        best = d.surface;
        px.nearest[v] = joints.of_bone[b];
        px.nearest_axis[v] = d.axis;
      }
    }
  }
  return px;
}

// ---------------------------------------------------------------------------------------------
// The mesh's edges as a graph.

// Undirected edges in compressed rows: vertex v's neighbours are
// neighbors[offsets[v] .. offsets[v + 1]), ascending, with the edge lengths beside them.
struct EdgeGraph {
  std::vector<uint32_t> offsets;
  std::vector<uint32_t> neighbors;
  std::vector<float> lengths;  // floored (see length_floor)
  float length_floor = kMinLength;
};

// The distinct edges of the triangles as (lower, higher) vertex pairs, ascending.
std::vector<std::pair<uint32_t, uint32_t>> unique_edges(const TriangleMesh& mesh) {
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  edges.reserve(mesh.indices.size());
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t a = mesh.indices[t + k];
      const uint32_t b = mesh.indices[t + (k + 1) % 3];
      if (a != b) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

EdgeGraph build_edge_graph(const TriangleMesh& mesh) {
  const std::vector<std::pair<uint32_t, uint32_t>> edges = unique_edges(mesh);
  const auto& p = mesh.positions;
  EdgeGraph graph;
  double total = 0.0;
  for (const auto& [a, b] : edges) total += glm::distance(p[a], p[b]);
  if (!edges.empty()) {
    const float mean = static_cast<float>(total / static_cast<double>(edges.size()));
    graph.length_floor = std::max(kLengthFloorFraction * mean, kMinLength);
  }
  graph.offsets.assign(mesh.vertex_count() + 1, 0);
  for (const auto& [a, b] : edges) {
    ++graph.offsets[a + 1];
    ++graph.offsets[b + 1];
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) graph.offsets[v + 1] += graph.offsets[v];
  graph.neighbors.resize(edges.size() * 2);
  graph.lengths.resize(edges.size() * 2);
  std::vector<uint32_t> fill(graph.offsets.begin(), graph.offsets.end() - 1);
  // Edges are sorted by lower vertex, so every row fills in ascending order.
  for (const auto& [a, b] : edges) {
    const float length = std::max(glm::distance(p[a], p[b]), graph.length_floor);
    graph.neighbors[fill[a]] = b;
    graph.lengths[fill[a]++] = length;
    graph.neighbors[fill[b]] = a;
    graph.lengths[fill[b]++] = length;
  }
  return graph;
}

// ---------------------------------------------------------------------------------------------
// Raw weights: one row of joint_count per vertex, any non-negative scale.

using RawWeights = std::vector<float>;

// 1 at or below 0, 0 at or beyond `width`, a smoothstep between (continuous slope).
float smooth_falloff(float x, float width) {
  if (x <= 0.0f) return 1.0f;
  if (x >= width) return 0.0f;
  const float t = x / width;
  return 1.0f - t * t * (3.0f - 2.0f * t);
}

RawWeights distance_weights(const Proximity& px, const BoneWeightOptions& options) {
  const size_t jc = px.joint_count;
  RawWeights raw(px.surface.size());
  for (size_t v = 0; v < px.nearest.size(); ++v) {
    const float nearest = px.surface[v * jc + px.nearest[v]];
    for (size_t j = 0; j < jc; ++j) {
      // Relative to the nearest bone's weight, so no power of a short length overflows.
      const float gap = px.surface[v * jc + j] - nearest;
      const float ratio = options.distance_softness / (gap + options.distance_softness);
      raw[v * jc + j] = std::pow(ratio, options.distance_power);
    }
  }
  return raw;
}

RawWeights envelope_weights(const Proximity& px, const BoneWeightOptions& options) {
  const size_t jc = px.joint_count;
  RawWeights raw(px.surface.size());
  for (size_t v = 0; v < px.nearest.size(); ++v) {
    bool any = false;
    for (size_t j = 0; j < jc; ++j) {
      const float w = smooth_falloff(px.surface[v * jc + j], options.envelope_falloff);
      raw[v * jc + j] = w;
      any = any || w > 0.0f;
    }
    if (!any) raw[v * jc + px.nearest[v]] = 1.0f;  // outside every envelope
  }
  return raw;
}

// Geodesic distances from the seeds (distance 0), over edges, up to `cutoff`; farther or
// unreachable vertices stay at infinity.
std::vector<float> geodesic_distances(const EdgeGraph& graph, std::span<const uint32_t> seeds,
                                      float cutoff) {
  std::vector<float> dist(graph.offsets.size() - 1, std::numeric_limits<float>::infinity());
  using Entry = std::pair<float, uint32_t>;  // ties pop the lower vertex first: deterministic
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  for (uint32_t s : seeds) {
    dist[s] = 0.0f;
    queue.emplace(0.0f, s);
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;  // a stale entry
    for (uint32_t e = graph.offsets[v]; e < graph.offsets[v + 1]; ++e) {
      const float candidate = d + graph.lengths[e];
      const uint32_t w = graph.neighbors[e];
      if (candidate < dist[w] && candidate < cutoff) {
        dist[w] = candidate;
        queue.emplace(candidate, w);
      }
    }
  }
  return dist;
}

RawWeights geodesic_weights(const Proximity& px, const EdgeGraph& graph,
                            const BoneWeightOptions& options) {
  const size_t jc = px.joint_count;
  const size_t n = px.nearest.size();
  std::vector<std::vector<uint32_t>> seeds(jc);
  for (size_t v = 0; v < n; ++v) seeds[px.nearest[v]].push_back(static_cast<uint32_t>(v));
  RawWeights raw(n * jc, 0.0f);
  for (size_t j = 0; j < jc; ++j) {
    if (seeds[j].empty()) continue;
    const std::vector<float> dist = geodesic_distances(graph, seeds[j], options.geodesic_falloff);
    for (size_t v = 0; v < n; ++v) {
      raw[v * jc + j] = smooth_falloff(dist[v], options.geodesic_falloff);
    }
  }
  return raw;
}

// ---------------------------------------------------------------------------------------------
// Heat diffusion.

// The symmetric positive definite matrix L + H on the edge graph (off-diagonal entries
// -1 / length^2, the diagonal their negated sum plus H), and H.
struct HeatSystem {
  Eigen::SparseMatrix<double> matrix;
  std::vector<double> heat;  // H
};

HeatSystem build_heat_system(const EdgeGraph& graph, const Proximity& px,
                             const BoneWeightOptions& options) {
  const size_t n = px.nearest.size();
  HeatSystem sys;
  sys.heat.resize(n);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(n + graph.neighbors.size());
  for (size_t v = 0; v < n; ++v) {
    const double axis = std::max(px.nearest_axis[v], graph.length_floor);
    sys.heat[v] = static_cast<double>(options.heat_constant) / (axis * axis);
    double diagonal = sys.heat[v];
    const int row = static_cast<int>(v);
    for (uint32_t e = graph.offsets[v]; e < graph.offsets[v + 1]; ++e) {
      const double length = graph.lengths[e];
      entries.emplace_back(row, static_cast<int>(graph.neighbors[e]), -1.0 / (length * length));
      diagonal += 1.0 / (length * length);
    }
    entries.emplace_back(row, row, diagonal);
  }
  sys.matrix.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  sys.matrix.setFromTriplets(entries.begin(), entries.end());
  return sys;
}

// Every joint's system at once: L + H is factored once (sparse Cholesky, LDL^T) and solved for
// the right-hand sides of all the joints that own a vertex together.
Result<RawWeights> heat_weights(const Proximity& px, const EdgeGraph& graph,
                                const JointTable& joints, const BoneWeightOptions& options) {
  const size_t jc = px.joint_count;
  const size_t n = px.nearest.size();
  const HeatSystem sys = build_heat_system(graph, px, options);
  // Columns only for joints nearest to some vertex: the others' weights are exactly 0.
  std::vector<int> column(jc, -1);
  int columns = 0;
  for (size_t v = 0; v < n; ++v) {
    int& c = column[px.nearest[v]];
    if (c < 0) c = columns++;
  }
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), columns);
  for (size_t v = 0; v < n; ++v) {
    rhs(static_cast<Eigen::Index>(v), column[px.nearest[v]]) = sys.heat[v];
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(sys.matrix);
  if (solver.info() != Eigen::Success) {
    return Error{"bone weights: the heat diffusion system (L + H, " + std::to_string(n) +
                 " vertices) could not be factored"};
  }
  const Eigen::MatrixXd solution = solver.solve(rhs);
  RawWeights raw(n * jc, 0.0f);
  for (size_t j = 0; j < jc; ++j) {
    if (column[j] < 0) continue;
    for (size_t v = 0; v < n; ++v) {
      const double w = solution(static_cast<Eigen::Index>(v), column[j]);
      if (!std::isfinite(w)) {
        return Error{"bone weights: heat diffusion for joint " + std::to_string(joints.ids[j]) +
                     " gave a non-finite weight"};
      }
      raw[v * jc + j] = static_cast<float>(std::max(w, 0.0));
    }
  }
  return raw;
}

// ---------------------------------------------------------------------------------------------
// Pruning to four influences.

// The four largest positive raw weights of one vertex, normalized, small ones dropped.
VertexInfluences top_influences(std::span<const float> row, const JointTable& joints,
                                size_t nearest, float min_weight) {
  std::array<std::pair<float, size_t>, kMaxInfluences> best{};
  size_t count = 0;
  for (size_t j = 0; j < row.size(); ++j) {
    const float w = row[j];
    if (!(w > 0.0f) || !std::isfinite(w)) continue;
    size_t at = count;  // insert after equal weights, so the lower joint keeps a tie
    while (at > 0 && best[at - 1].first < w) --at;
    if (at >= kMaxInfluences) continue;
    for (size_t k = std::min(count, kMaxInfluences - 1); k > at; --k) best[k] = best[k - 1];
    best[at] = {w, j};
    count = std::min(count + 1, kMaxInfluences);
  }
  if (count == 0) best[count++] = {1.0f, nearest};  // cannot happen; never leave it weightless
  for (int pass = 0; pass < 2; ++pass) {            // normalize, drop the small, normalize again
    float sum = 0.0f;
    for (size_t k = 0; k < count; ++k) sum += best[k].first;
    for (size_t k = 0; k < count; ++k) best[k].first /= sum;
    while (count > 1 && best[count - 1].first < min_weight) --count;
  }
  VertexInfluences out;
  for (size_t k = 0; k < count; ++k) {
    out.joints[static_cast<int>(k)] = joints.ids[best[k].second];
    out.weights[static_cast<int>(k)] = best[k].first;
  }
  return out;
}

std::vector<VertexInfluences> prune(const RawWeights& raw, const Proximity& px,
                                    const JointTable& joints, float min_weight) {
  const size_t jc = px.joint_count;
  std::vector<VertexInfluences> out(px.nearest.size());
  for (size_t v = 0; v < out.size(); ++v) {
    out[v] = top_influences(std::span(raw).subspan(v * jc, jc), joints, px.nearest[v], min_weight);
  }
  return out;
}

Result<RawWeights> raw_weights(const TriangleMesh& mesh, const Proximity& px,
                               const JointTable& joints, const BoneWeightOptions& options) {
  switch (options.method) {
    case WeightMethod::Distance:
      return distance_weights(px, options);
    case WeightMethod::Envelope:
      return envelope_weights(px, options);
    case WeightMethod::HeatDiffusion:
      return heat_weights(px, build_edge_graph(mesh), joints, options);
    case WeightMethod::Geodesic:
      return geodesic_weights(px, build_edge_graph(mesh), options);
  }
  return Error{"bone weights: unknown method " + std::to_string(static_cast<int>(options.method))};
}

// ---------------------------------------------------------------------------------------------
// Quality checks.

// The total weight of `joint` in the vertex's slots (a joint may appear in several slots).
float joint_weight(const VertexInfluences& inf, int joint) {
  float sum = 0.0f;
  for (int k = 0; k < 4; ++k) {
    if (inf.joints[k] == joint) sum += inf.weights[k];
  }
  return sum;
}

// The joint with the largest total weight > 0 (the lowest slot on a tie), or -1.
int dominant_joint(const VertexInfluences& inf) {
  int best = -1;
  float best_weight = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const float w = joint_weight(inf, inf.joints[k]);
    if (w > best_weight) {
      best_weight = w;
      best = inf.joints[k];
    }
  }
  return best;
}

// True when `joint` has (within kDominanceTolerance) the vertex's largest total weight.
bool dominates(const VertexInfluences& inf, int joint) {
  const int top = dominant_joint(inf);
  if (top < 0) return false;
  return joint_weight(inf, joint) >= joint_weight(inf, top) - kDominanceTolerance;
}

void check_vertex_rules(std::span<const VertexInfluences> influences, const JointTable& joints,
                        float sum_tolerance, WeightQualityReport& report) {
  for (size_t v = 0; v < influences.size(); ++v) {
    const VertexInfluences& inf = influences[v];
    bool negative = false, positive = false, bad_joint = false;
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const float w = inf.weights[k];
      negative = negative || !(w >= 0.0f) || !std::isfinite(w);
      positive = positive || w > 0.0f;
      sum += w;
      const bool known = std::binary_search(joints.ids.begin(), joints.ids.end(), inf.joints[k]);
      bad_joint = bad_joint || (w > 0.0f && !known);
    }
    if (negative) report.negative_weight_vertices.push_back(v);
    if (!(std::abs(sum - 1.0f) <= sum_tolerance)) report.unnormalized_vertices.push_back(v);
    if (!positive) report.weightless_vertices.push_back(v);
    if (bad_joint) report.bad_joint_vertices.push_back(v);
  }
}

size_t nearest_vertex(const TriangleMesh& mesh, const glm::vec3& point) {
  size_t best = 0;
  float best_distance = std::numeric_limits<float>::infinity();
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const float d = glm::distance(mesh.positions[v], point);
    if (d < best_distance) {
      best_distance = d;
      best = v;
    }
  }
  return best;
}

void check_mid_bones(const TriangleMesh& mesh, std::span<const BoneSegment> bones,
                     std::span<const VertexInfluences> influences, WeightQualityReport& report) {
  for (size_t b = 0; b < bones.size(); ++b) {
    const size_t v = nearest_vertex(mesh, 0.5f * (bones[b].head + bones[b].tail));
    if (dominates(influences[v], bones[b].joint)) continue;
    report.mid_bone_failures.push_back({b, v, bones[b].joint, dominant_joint(influences[v])});
  }
}

void check_jumps(const EdgeGraph& graph, std::span<const VertexInfluences> influences,
                 WeightQualityReport& report) {
  for (size_t a = 0; a + 1 < graph.offsets.size(); ++a) {
    for (uint32_t e = graph.offsets[a]; e < graph.offsets[a + 1]; ++e) {
      const size_t b = graph.neighbors[e];
      if (b < a) continue;  // each edge once
      const VertexInfluences* ends[2] = {&influences[a], &influences[b]};
      for (const VertexInfluences* end : ends) {
        for (int k = 0; k < 4; ++k) {
          const int joint = end->joints[k];
          const float jump =
              std::abs(joint_weight(influences[a], joint) - joint_weight(influences[b], joint));
          if (jump > report.max_neighbor_jump || report.jump_joint < 0) {
            report.max_neighbor_jump = jump;
            report.jump_vertex_a = a;
            report.jump_vertex_b = b;
            report.jump_joint = joint;
          }
        }
      }
    }
  }
}

void check_nearest(const Proximity& px, const JointTable& joints,
                   std::span<const VertexInfluences> influences, WeightQualityReport& report) {
  for (size_t v = 0; v < influences.size(); ++v) {
    if (dominant_joint(influences[v]) < 0) continue;  // reported as weightless
    if (!dominates(influences[v], joints.ids[px.nearest[v]])) {
      report.not_nearest_vertices.push_back(v);
    }
  }
}

}  // namespace

std::string_view weight_method_name(WeightMethod method) {
  switch (method) {
    case WeightMethod::Distance:
      return "distance";
    case WeightMethod::Envelope:
      return "envelope";
    case WeightMethod::HeatDiffusion:
      return "heat";
    case WeightMethod::Geodesic:
      return "geodesic";
  }
  return "unknown";
}

std::optional<WeightMethod> parse_weight_method(std::string_view name) {
  for (WeightMethod m : {WeightMethod::Distance, WeightMethod::Envelope,
                         WeightMethod::HeatDiffusion, WeightMethod::Geodesic}) {
    if (weight_method_name(m) == name) return m;
  }
  return std::nullopt;
}

Result<std::vector<VertexInfluences>> compute_bone_weights(const TriangleMesh& mesh,
                                                           std::span<const BoneSegment> bones,
                                                           const BoneWeightOptions& options) {
  if (Status s = validate_input(mesh, bones); !s) return Error{s.message()};
  if (Status s = validate_options(options); !s) return Error{s.message()};
  const JointTable joints = collect_joints(bones);
  const Proximity px = measure_proximity(mesh, bones, joints);
  Result<RawWeights> raw = raw_weights(mesh, px, joints, options);
  if (!raw) return raw.error();
  return prune(*raw, px, joints, options.min_weight);
}

Result<WeightQualityReport> check_bone_weights(const TriangleMesh& mesh,
                                               std::span<const BoneSegment> bones,
                                               std::span<const VertexInfluences> influences,
                                               float sum_tolerance) {
  if (Status s = validate_input(mesh, bones); !s) return Error{s.message()};
  if (influences.size() != mesh.vertex_count()) {
    return Error{"bone weights: " + str(influences.size()) + " influences for " +
                 str(mesh.vertex_count()) + " vertices (one per vertex needed)"};
  }
  const JointTable joints = collect_joints(bones);
  WeightQualityReport report;
  check_vertex_rules(influences, joints, sum_tolerance, report);
  check_mid_bones(mesh, bones, influences, report);
  check_jumps(build_edge_graph(mesh), influences, report);
  check_nearest(measure_proximity(mesh, bones, joints), joints, influences, report);
  return report;
}

}  // namespace mm
