#include "skinned_body.hpp"

#include <utility>
#include "mm/runtime/assert.hpp"

namespace mm::viewer {

std::string_view skinning_method_name(SkinningMethod method) {
  return method == SkinningMethod::LinearBlend ? "lbs" : "dqs";
}

bool parse_skinning_method(std::string_view name, SkinningMethod& method) {
  if (name == "lbs") {
    method = SkinningMethod::LinearBlend;
  } else if (name == "dqs") {
    method = SkinningMethod::DualQuaternion;
  } else {
    return false;
  }
  return true;
}

SkinnedBody::SkinnedBody(SkinnedMesh mesh) : mesh_(std::move(mesh)) {
  const size_t joints = mesh_.bind_global.size();
  inverse_bind_.resize(joints);
  inverse_bind_transforms(mesh_.bind_global, inverse_bind_);
  matrices_.resize(joints);
  dual_quats_.resize(joints);
  positions_ = mesh_.mesh.positions;
  normals_ = mesh_.mesh.normals;
  normals_.resize(positions_.size(), glm::vec3(0.0f, 1.0f, 0.0f));
}

void SkinnedBody::set_influences(std::vector<VertexInfluences> influences) {
  MM_ASSERT(influences.size() == mesh_.mesh.positions.size());
  mesh_.influences = std::move(influences);
}

void SkinnedBody::pose(std::span<const Transform> global, SkinningMethod method) {
  MM_ASSERT(global.size() == inverse_bind_.size());
  const std::span<const glm::vec3> rest_normals =
      mesh_.mesh.normals.size() == mesh_.mesh.positions.size()
          ? std::span<const glm::vec3>(mesh_.mesh.normals)
          : std::span<const glm::vec3>();
  std::span<glm::vec3> out_normals = rest_normals.empty() ? std::span<glm::vec3>() : normals_;
  if (method == SkinningMethod::LinearBlend) {
    skinning_matrices(global, inverse_bind_, matrices_);
    skin_linear_blend(matrices_, mesh_.mesh.positions, rest_normals, mesh_.influences, positions_,
                      out_normals);
  } else {
    skinning_dual_quats(global, inverse_bind_, dual_quats_);
    skin_dual_quaternion(dual_quats_, mesh_.mesh.positions, rest_normals, mesh_.influences,
                         positions_, out_normals);
  }
}

}  // namespace mm::viewer
