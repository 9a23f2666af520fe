#include "mm/runtime/pose.hpp"

#include <cmath>
#include "mm/runtime/assert.hpp"
#include "mm/runtime/atan2_polynomial.hpp"
#include "mm/runtime/transform_sse.hpp"
#include "quat_lanes.hpp"

namespace mm {

void forward_kinematics(std::span<const int> parents, std::span<const Transform> local,
                        std::span<Transform> global) {
  MM_ASSERT(local.size() == parents.size() && global.size() == parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    const int p = parents[i];
    MM_ASSERT(p < static_cast<int>(i));
    global[i] = p < 0 ? local[i] : compose(global[p], local[i]);
  }
}

Transform forward_kinematics_joint(std::span<const int> parents, std::span<const Transform> local,
                                   int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
  Transform t = local[joint];
  for (int p = parents[joint]; p >= 0; p = parents[p]) t = compose(local[p], t);
  return t;
}

glm::vec3 forward_kinematics_position(std::span<const int> parents,
                                      std::span<const Transform> local, int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
  glm::vec3 position = local[joint].translation;
  // compose(parent, t).translation, step by step up the chain.
  for (int p = parents[joint]; p >= 0; p = parents[p]) {
    position = local[p].rotation * (local[p].scale * position) + local[p].translation;
  }
  return position;
}

namespace {

// One step of forward_kinematics_position's walk: up through joint p.
glm::vec3 position_step(const Transform& p, const glm::vec3& position) {
  return p.rotation * (p.scale * position) + p.translation;
}

}  // namespace

std::array<glm::vec3, 2> forward_kinematics_positions(std::span<const int> parents,
                                                      std::span<const Transform> local, int a,
                                                      int b) {
  MM_ASSERT(a >= 0 && static_cast<size_t>(a) < parents.size());
  MM_ASSERT(b >= 0 && static_cast<size_t>(b) < parents.size());
  std::array<glm::vec3, 2> out{local[a].translation, local[b].translation};
  int pa = parents[a], pb = parents[b];
  // Parents come before their children: the larger of the two next joints lies on its own
  // chain only, so it is stepped alone until both chains reach the same joint.
  while (pa != pb) {
    if (pa > pb) {
      out[0] = position_step(local[pa], out[0]);
      pa = parents[pa];
    } else {
      out[1] = position_step(local[pb], out[1]);
      pb = parents[pb];
    }
  }
#if defined(__SSE2__)
  using namespace lanes;
  Vec4x3 v{_mm_setr_ps(out[0].x, out[1].x, 0.0f, 0.0f), _mm_setr_ps(out[0].y, out[1].y, 0.0f, 0.0f),
           _mm_setr_ps(out[0].z, out[1].z, 0.0f, 0.0f)};
  for (int p = pa; p >= 0; p = parents[p]) {
    const Transform& t = local[p];
    const Quat4 q{c(t.rotation.w), c(t.rotation.x), c(t.rotation.y), c(t.rotation.z)};
    const Vec4x3 s{c(t.scale.x), c(t.scale.y), c(t.scale.z)};
    v = add(rotate(q, times(s, v)),
            Vec4x3{c(t.translation.x), c(t.translation.y), c(t.translation.z)});
  }
  alignas(16) float x[4], y[4], z[4];
  _mm_store_ps(x, v.x);
  _mm_store_ps(y, v.y);
  _mm_store_ps(z, v.z);
  return {glm::vec3(x[0], y[0], z[0]), glm::vec3(x[1], y[1], z[1])};
#else
  for (int p = pa; p >= 0; p = parents[p]) {
    out[0] = position_step(local[p], out[0]);
    out[1] = position_step(local[p], out[1]);
  }
  return out;
#endif
}

glm::quat forward_kinematics_rotation(std::span<const int> parents,
                                      std::span<const Transform> local, int joint) {
  MM_ASSERT(joint >= 0 && static_cast<size_t>(joint) < parents.size());
#if defined(__SSE2__)
  // GLM's products in registers (transform_sse.hpp: the same bits).
  __m128 rotation = sse::load(local[joint].rotation);
  for (int p = parents[joint]; p >= 0; p = parents[p]) {
    rotation = sse::product(sse::load(local[p].rotation), rotation);
  }
  return sse::to_quat(rotation);
#else
  glm::quat rotation = local[joint].rotation;
  for (int p = parents[joint]; p >= 0; p = parents[p]) rotation = local[p].rotation * rotation;
  return rotation;
#endif
}

void bone_lengths(std::span<const int> parents, std::span<const Transform> global,
                  std::span<float> lengths) {
  MM_ASSERT(global.size() == parents.size() && lengths.size() == parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    const int p = parents[i];
    lengths[i] = p < 0 ? glm::length(global[i].translation)
                       : glm::distance(global[i].translation, global[p].translation);
  }
}

float pair_yaw(const glm::vec3& left, const glm::vec3& right, float fallback) {
  const glm::vec3 across = left - right;
  // (left - right) x up = (-across.z, 0, across.x). Squared: a product underflowing to 0 or
  // overflowing to infinity lands on the same side of the threshold as the length would.
  if (across.x * across.x + across.z * across.z <= 1e-12f) return fallback;
  return atan2_polynomial(-across.z, across.x);
}

}  // namespace mm
