#pragma once
// Skinning: deforming a mesh bound to a skeleton. A vertex is bound in the bind pose; a joint's
// skinning transform takes it from the bind pose to the current pose:
//   skin = global * inverse_bind,  with inverse_bind = inverse(bind-pose global transform).
// Each vertex has up to four influences (joint, weight). Two blends are offered:
// - linear blend skinning (LBS): the vertex is transformed by the weighted sum of the skinning
//   matrices. Cheap and supports scale, but at a bent joint the blended matrix is no longer a
//   rotation and the limb collapses (by cos(angle / 2) in the bend plane: 71 % at 90 degrees);
// - dual-quaternion skinning (DQS): the weighted sum of the skinning dual quaternions (each
//   sign-aligned with the vertex's heaviest influence, since q and -q are one motion),
//   normalized, is a rigid motion, so a bent joint keeps its radius. Rigid only: scale ignored.
// Weights should be non-negative and sum to 1; negative weights count as zero and the rest
// are divided by their sum; a vertex whose weights sum to zero keeps its rest position.
// Influence slots with weight 0 are never read, so unused joint indices may be anything.
// Per-frame functions write into caller-owned spans and never allocate.

#include <span>

#include <glm/glm.hpp>

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// Up to four joints influencing one vertex, with their weights.
struct VertexInfluences {
  glm::ivec4 joints{0};     // joint (skinning transform) indices
  glm::vec4 weights{0.0f};  // non-negative weights, ideally summing to 1
};

// inverse_bind[i] = inverse(bind_global[i]): from model space into joint i's bind-pose frame.
void inverse_bind_transforms(std::span<const Transform> bind_global,
                             std::span<Transform> inverse_bind);

// skin[i] = to_matrix(global[i]) * to_matrix(inverse_bind[i]) (keeps scale).
void skinning_matrices(std::span<const Transform> global, std::span<const Transform> inverse_bind,
                       std::span<glm::mat4> skin);

// skin[i] = to_matrix(global[i]) * inverse_bind_matrices[i], for matrices from a file (glTF).
void skinning_matrices(std::span<const Transform> global,
                       std::span<const glm::mat4> inverse_bind_matrices, std::span<glm::mat4> skin);

// skin[i] = dual quaternion of the rigid part of global[i] * inverse_bind[i] (scale ignored).
void skinning_dual_quats(std::span<const Transform> global, std::span<const Transform> inverse_bind,
                         std::span<DualQuat> skin);

// Linear blend skinning of rest (bind-pose) positions, and normals when `rest_normals` is
// non-empty (then `out_normals` must have the same size; normals use the blended matrix's
// cofactor, i.e. its inverse transpose up to scale, and come out unit length).
void skin_linear_blend(std::span<const glm::mat4> skin, std::span<const glm::vec3> rest_positions,
                       std::span<const glm::vec3> rest_normals,
                       std::span<const VertexInfluences> influences,
                       std::span<glm::vec3> out_positions, std::span<glm::vec3> out_normals);

// Dual-quaternion skinning of rest positions, and normals when `rest_normals` is non-empty
// (rotated by the blended rotation).
void skin_dual_quaternion(std::span<const DualQuat> skin, std::span<const glm::vec3> rest_positions,
                          std::span<const glm::vec3> rest_normals,
                          std::span<const VertexInfluences> influences,
                          std::span<glm::vec3> out_positions, std::span<glm::vec3> out_normals);

}  // namespace mm
