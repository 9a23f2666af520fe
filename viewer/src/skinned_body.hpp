#pragma once
// The character's body on the CPU: a SkinnedMesh (generated or loaded) deformed every frame by
// the controller's global joint transforms, with linear-blend or dual-quaternion skinning
// (runtime/include/mm/runtime/skinning.hpp). Every buffer is sized when the mesh is set.

#include <span>
#include <string_view>
#include <vector>

#include "mm/runtime/mesh.hpp"
#include "mm/runtime/skinning.hpp"

namespace mm::viewer {

enum class SkinningMethod { LinearBlend, DualQuaternion };

// "lbs" or "dqs".
std::string_view skinning_method_name(SkinningMethod method);
bool parse_skinning_method(std::string_view name, SkinningMethod& method);

class SkinnedBody {
 public:
  explicit SkinnedBody(SkinnedMesh mesh);

  const SkinnedMesh& mesh() const { return mesh_; }
  // New weights for the same mesh (another weight method); one per vertex.
  void set_influences(std::vector<VertexInfluences> influences);
  // Deforms the bind-pose mesh into the pose of `global` (one transform per skeleton joint).
  void pose(std::span<const Transform> global, SkinningMethod method);

  std::span<const glm::vec3> positions() const { return positions_; }
  std::span<const glm::vec3> normals() const { return normals_; }

 private:
  SkinnedMesh mesh_;
  std::vector<Transform> inverse_bind_;
  std::vector<glm::mat4> matrices_;
  std::vector<DualQuat> dual_quats_;
  std::vector<glm::vec3> positions_;
  std::vector<glm::vec3> normals_;
};

}  // namespace mm::viewer
