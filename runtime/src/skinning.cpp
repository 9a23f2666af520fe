#include "mm/runtime/skinning.hpp"

#include <cmath>
#include "mm/runtime/assert.hpp"

namespace mm {

namespace {

// The vertex's weights with negatives zeroed and divided by their sum; false if they sum to 0.
bool normalized_weights(const glm::vec4& raw, glm::vec4& weights) {
  weights = glm::max(raw, glm::vec4(0.0f));
  const float sum = weights.x + weights.y + weights.z + weights.w;
  if (!(sum > 0.0f) || !std::isfinite(sum)) return false;
  weights /= sum;
  return true;
}

// The loop both skinning methods share: sizes asserted (compiled out in release builds), each
// vertex's weights normalized, and a vertex without usable weights left at its rest place.
// `skin_vertex(v, weights)` writes vertex v's outputs.
template <class SkinVertex>
void for_each_skinned_vertex(std::span<const glm::vec3> rest_positions,
                             std::span<const glm::vec3> rest_normals,
                             std::span<const VertexInfluences> influences,
                             std::span<glm::vec3> out_positions, std::span<glm::vec3> out_normals,
                             SkinVertex skin_vertex) {
  MM_ASSERT(influences.size() == rest_positions.size());
  MM_ASSERT(out_positions.size() == rest_positions.size());
  MM_ASSERT(rest_normals.empty() || rest_normals.size() == rest_positions.size());
  MM_ASSERT(rest_normals.empty() || out_normals.size() == rest_positions.size());
  for (size_t v = 0; v < rest_positions.size(); ++v) {
    glm::vec4 w;
    if (normalized_weights(influences[v].weights, w)) {
      skin_vertex(v, w);
    } else {
      out_positions[v] = rest_positions[v];
      if (!rest_normals.empty()) out_normals[v] = rest_normals[v];
    }
  }
}

glm::vec3 unit_or(const glm::vec3& v, const glm::vec3& fallback) {
  const float len = glm::length(v);
  return len > 1e-20f ? v / len : fallback;
}

}  // namespace

void inverse_bind_transforms(std::span<const Transform> bind_global,
                             std::span<Transform> inverse_bind) {
  MM_ASSERT(bind_global.size() == inverse_bind.size());
  for (size_t i = 0; i < bind_global.size(); ++i) inverse_bind[i] = inverse(bind_global[i]);
}

void skinning_matrices(std::span<const Transform> global, std::span<const Transform> inverse_bind,
                       std::span<glm::mat4> skin) {
  MM_ASSERT(global.size() == inverse_bind.size() && global.size() == skin.size());
  for (size_t i = 0; i < global.size(); ++i) {
    skin[i] = to_matrix(global[i]) * to_matrix(inverse_bind[i]);
  }
}

void skinning_matrices(std::span<const Transform> global,
                       std::span<const glm::mat4> inverse_bind_matrices,
                       std::span<glm::mat4> skin) {
  MM_ASSERT(global.size() == inverse_bind_matrices.size() && global.size() == skin.size());
  for (size_t i = 0; i < global.size(); ++i) {
    skin[i] = to_matrix(global[i]) * inverse_bind_matrices[i];
  }
}

void skinning_dual_quats(std::span<const Transform> global, std::span<const Transform> inverse_bind,
                         std::span<DualQuat> skin) {
  MM_ASSERT(global.size() == inverse_bind.size() && global.size() == skin.size());
  for (size_t i = 0; i < global.size(); ++i) {
    skin[i] = dual_quat_normalize(dual_quat_from_transform(global[i]) *
                                  dual_quat_from_transform(inverse_bind[i]));
  }
}

void skin_linear_blend(std::span<const glm::mat4> skin, std::span<const glm::vec3> rest_positions,
                       std::span<const glm::vec3> rest_normals,
                       std::span<const VertexInfluences> influences,
                       std::span<glm::vec3> out_positions, std::span<glm::vec3> out_normals) {
  const bool with_normals = !rest_normals.empty();
  auto skin_vertex = [&](size_t v, const glm::vec4& w) {
    glm::mat4 m(0.0f);
    for (int k = 0; k < 4; ++k) {
      if (w[k] == 0.0f) continue;
      const int joint = influences[v].joints[k];
      MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < skin.size());
      m += w[k] * skin[joint];
    }
    out_positions[v] = glm::vec3(m * glm::vec4(rest_positions[v], 1.0f));
    if (with_normals) {
      // The cofactor matrix is det * inverse-transpose: right for normals under scale and
      // shear, and defined even where the blend made the matrix singular.
      const glm::vec3 c0(m[0]), c1(m[1]), c2(m[2]);
      const glm::mat3 cofactor(glm::cross(c1, c2), glm::cross(c2, c0), glm::cross(c0, c1));
      out_normals[v] = unit_or(cofactor * rest_normals[v], rest_normals[v]);
    }
  };
  for_each_skinned_vertex(rest_positions, rest_normals, influences, out_positions, out_normals,
                          skin_vertex);
}

void skin_dual_quaternion(std::span<const DualQuat> skin, std::span<const glm::vec3> rest_positions,
                          std::span<const glm::vec3> rest_normals,
                          std::span<const VertexInfluences> influences,
                          std::span<glm::vec3> out_positions, std::span<glm::vec3> out_normals) {
  const bool with_normals = !rest_normals.empty();
  auto skin_vertex = [&](size_t v, const glm::vec4& w) {
    // Align every influence's sign with the heaviest one so the blend takes the short way.
    int pivot = 0;
    for (int k = 1; k < 4; ++k) {
      if (w[k] > w[pivot]) pivot = k;
    }
    const glm::quat pivot_real = skin[influences[v].joints[pivot]].real;
    DualQuat blend;
    blend.real = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
    for (int k = 0; k < 4; ++k) {
      if (w[k] == 0.0f) continue;
      const int joint = influences[v].joints[k];
      MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < skin.size());
      const DualQuat& q = skin[joint];
      const float signed_weight = glm::dot(q.real, pivot_real) < 0.0f ? -w[k] : w[k];
      blend = blend + signed_weight * q;
    }
    const DualQuat unit = dual_quat_normalize(blend);
    out_positions[v] = dual_quat_transform_point(unit, rest_positions[v]);
    if (with_normals) out_normals[v] = unit_or(unit.real * rest_normals[v], rest_normals[v]);
  };
  for_each_skinned_vertex(rest_positions, rest_normals, influences, out_positions, out_normals,
                          skin_vertex);
}

}  // namespace mm
