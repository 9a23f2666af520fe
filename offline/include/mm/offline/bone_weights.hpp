#pragma once
// Skinning weights for a mesh around a skeleton's bones, and a check of their quality.
//
// Distances. Every method measures a vertex p against a bone (a tapered capsule, see
// BoneSegment) by its closest point c on the segment head -> tail, at parameter t in [0, 1]:
//   axis distance     a = |p - c|,
//   surface distance  s = a - mix(head_radius, tail_radius, t)  (negative inside the capsule).
// Zero radii make s the plain distance to the segment. A vertex's NEAREST bone is the one with
// the smallest s (the lowest bone index on a tie), so a thick torso beats a thin arm whose axis
// happens to be closer. Weights belong to joints, not segments: a joint's distance is the
// smallest over the segments it owns, and it is weighted once.
//
// The methods (raw weights per joint j, before pruning):
// - Distance:  w_j = 1 / (s_j - s_min + distance_softness)^distance_power, s_min the nearest
//   bone's s. The nearest bone always has the largest weight; a bone distance_softness farther
//   weighs 2^-distance_power as much. Continuous, since s_min is.
// - Envelope:  w_j = 1 inside joint j's capsule (s_j <= 0), falling smoothly (smoothstep) to 0
//   at s_j = envelope_falloff outside it. Overlapping capsules share a vertex equally. A vertex
//   outside every envelope is bound wholly to its nearest bone, so none is weightless (weights
//   jump where that fallback region meets an envelope: choose radii that enclose the mesh).
// - HeatDiffusion (after Baran & Popovic, "Automatic rigging and animation of 3D characters"):
//   per joint, solve (L + H) w_j = H p_j, where p_j(v) = 1 if v's nearest bone belongs to j,
//   H(v) = heat_constant / a(v)^2 with a(v) the axis distance to v's nearest bone, and L the
//   graph Laplacian with edge weights 1 / length^2. That L approximates -Laplacian in 1/m^2 on
//   an even tessellation, so it matches H's units, and it was chosen over the cotangent
//   Laplacian because its off-diagonal entries are never positive: L + H is then a symmetric
//   M-matrix, so the solution stays in [0, 1] and sums to 1 over the joints (up to the solver's
//   rounding, whose tiny negative residue is clipped to 0),
//   whereas cotangent weights turn negative on obtuse triangles (and need triangle areas, which
//   degenerate triangles lack). Every vertex is heated, so each connected component, even one
//   far from every bone or a lone vertex, has a unique solution. L + H is factored once by a
//   sparse Cholesky (LDL^T, Eigen's SimplicialLDLT) in double precision and solved for every
//   joint together.
// - Geodesic: per joint, multi-source Dijkstra over the mesh's edges (Euclidean edge lengths)
//   from every vertex whose nearest bone belongs to j (distance 0); w_j falls smoothly
//   (smoothstep) from 1 at geodesic distance 0 to 0 at geodesic_falloff. Weights do not leak
//   across a gap between body parts that are close in space but far along the surface. A
//   vertex that no seed reaches (its component has no vertex nearest to j) gets no weight
//   from j; it always has its own nearest bone's weight 1.
//
// Then, per vertex: the four largest raw weights are kept (ties go to the lower joint value)
// and normalized, weights below min_weight are dropped, and the rest are normalized again. The
// largest is never dropped, so every vertex has weight. Slots are sorted by decreasing weight;
// unused slots hold joint 0 with weight 0 (glTF's convention). The result is deterministic.
//
// Lengths are metres. Edge lengths and axis distances below a thousandth of the mesh's mean
// edge length (and below a micrometre) count as that floor, so duplicate vertices and vertices
// on a bone's axis do not divide by zero.

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "mm/runtime/mesh.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skinning.hpp"

namespace mm {

enum class WeightMethod {
  Distance,       // distance to the bone segment
  Envelope,       // capsule envelope with falloff
  HeatDiffusion,  // heat diffusion over the mesh's graph Laplacian
  Geodesic,       // geodesic distance (Dijkstra over the mesh's edges)
};

// "distance", "envelope", "heat", "geodesic".
std::string_view weight_method_name(WeightMethod method);
std::optional<WeightMethod> parse_weight_method(std::string_view name);

// How to compute the weights; each field is used by the methods named in its comment.
struct BoneWeightOptions {
  WeightMethod method = WeightMethod::HeatDiffusion;
  float distance_power = 4.0f;      // Distance: > 0; larger makes blends between bones sharper
  float distance_softness = 0.05f;  // Distance: metres, > 0; how far apart two bones blend
  float envelope_falloff = 0.05f;   // Envelope: metres, > 0; width of the falloff outside
  float heat_constant = 1.0f;       // HeatDiffusion: > 0; larger holds weights nearer the bone
  float geodesic_falloff = 0.1f;    // Geodesic: metres, > 0; surface distance a weight reaches
  float min_weight = 0.01f;         // all: in [0, 0.25); smaller weights are dropped
};

// One VertexInfluences per mesh vertex: at most four influences, every weight >= 0, the
// weights of a vertex sum to 1, no vertex without weight. Joint indices are the segments'
// `joint` values. Fails with a message on an empty mesh, indices not a multiple of 3 or out of
// range, normals neither empty nor one per vertex, non-finite positions or normals, no bones,
// a bone with a negative joint, non-finite data or a negative radius, options out of range,
// or a heat solve that does not converge.
Result<std::vector<VertexInfluences>> compute_bone_weights(const TriangleMesh& mesh,
                                                           std::span<const BoneSegment> bones,
                                                           const BoneWeightOptions& options = {});

// A bone whose mid-point's nearest vertex is not dominated by the bone's joint.
struct MidBoneFailure {
  size_t bone = 0;          // index into the bones
  size_t vertex = 0;        // the vertex nearest the bone's mid-point
  int joint = -1;           // the bone's joint
  int dominant_joint = -1;  // the joint with the vertex's largest weight (-1: no weight at all)
};

// What check_bone_weights found. Vertex lists are ascending vertex indices.
struct WeightQualityReport {
  // The rules every vertex must obey.
  std::vector<size_t> negative_weight_vertices;  // a weight < 0 or not finite
  std::vector<size_t> unnormalized_vertices;     // weights sum off 1 by more than the tolerance
  std::vector<size_t> weightless_vertices;       // no weight > 0
  std::vector<size_t> bad_joint_vertices;        // a weight > 0 on a joint no bone has

  // Ownership: for every bone, the vertex nearest its mid-point should be dominated by the
  // bone's joint (a tie for the largest weight counts as dominated).
  std::vector<MidBoneFailure> mid_bone_failures;

  // Smoothness: the largest |w_j(a) - w_j(b)| over edges (a, b) and joints j, and where.
  float max_neighbor_jump = 0.0f;
  size_t jump_vertex_a = 0;  // the edge's lower vertex index
  size_t jump_vertex_b = 0;  // the edge's higher vertex index
  int jump_joint = -1;       // -1 when the mesh has no edges

  // Vertices whose nearest bone's joint has less weight than the vertex's largest weight.
  std::vector<size_t> not_nearest_vertices;

  // True when no vertex breaks a rule (the other findings are reports, not rules).
  bool rules_hold() const {
    return negative_weight_vertices.empty() && unnormalized_vertices.empty() &&
           weightless_vertices.empty() && bad_joint_vertices.empty();
  }
};

// Checks weights against the mesh and bones they were made for (any weights: computed here,
// loaded or painted). Fails with compute_bone_weights' messages on bad mesh or bones, and when
// there is not one VertexInfluences per vertex.
Result<WeightQualityReport> check_bone_weights(const TriangleMesh& mesh,
                                               std::span<const BoneSegment> bones,
                                               std::span<const VertexInfluences> influences,
                                               float sum_tolerance = 1e-5f);

}  // namespace mm
