#pragma once
// Skinning weights for a mesh around a skeleton's bones (interface; see the implementation's
// header comment once it lands for the rules of each method).

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

struct BoneWeightOptions {
  WeightMethod method = WeightMethod::HeatDiffusion;
};

// One VertexInfluences per mesh vertex: at most four influences, every weight >= 0, the
// weights of a vertex sum to 1, no vertex without weight. Joint indices are the segments'
// `joint` values. Fails with a message on an empty mesh, no bones, a bad index or a
// non-finite position.
Result<std::vector<VertexInfluences>> compute_bone_weights(const TriangleMesh& mesh,
                                                           std::span<const BoneSegment> bones,
                                                           const BoneWeightOptions& options = {});

}  // namespace mm
