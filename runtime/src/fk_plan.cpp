#include "mm/runtime/fk_plan.hpp"

#include <algorithm>

#include "mm/runtime/assert.hpp"
#include "quat_lanes.hpp"

namespace mm {

ForwardKinematicsPlan::ForwardKinematicsPlan(std::span<const int> parents)
    : parents_(parents.begin(), parents.end()) {
  const int n = static_cast<int>(parents.size());
  // Each joint's height: the joints on its longest chain down (itself included). Parents come
  // before their children, so one pass from the end finds them.
  std::vector<int> height(parents.size(), 1);
  for (int j = n - 1; j >= 0; --j) {
    MM_ASSERT(parents[static_cast<size_t>(j)] < j);
    const int p = parents[static_cast<size_t>(j)];
    if (p >= 0) {
      height[static_cast<size_t>(p)] =
          std::max(height[static_cast<size_t>(p)], height[static_cast<size_t>(j)] + 1);
    }
  }
  // Greedy blocks: of the joints whose parents are done, the four with the longest chains below.
  std::vector<char> done(parents.size(), 0);
  std::vector<int> ready;
  for (int placed = 0; placed < n;) {
    ready.clear();
    for (int j = 0; j < n; ++j) {
      const int p = parents[static_cast<size_t>(j)];
      if (!done[static_cast<size_t>(j)] && (p < 0 || done[static_cast<size_t>(p)])) {
        ready.push_back(j);
      }
    }
    std::stable_sort(ready.begin(), ready.end(), [&](int a, int b) {
      return height[static_cast<size_t>(a)] > height[static_cast<size_t>(b)];
    });
    Block block;
    block.count = std::min<int>(4, static_cast<int>(ready.size()));
    for (int l = 0; l < 4; ++l) {
      const int j = ready[static_cast<size_t>(std::min(l, block.count - 1))];
      block.joints[static_cast<size_t>(l)] = j;
      block.parents[static_cast<size_t>(l)] = parents[static_cast<size_t>(j)];
    }
    block.lanes = block.count > 1;
    for (int l = 0; l < block.count; ++l) {
      const int j = ready[static_cast<size_t>(l)];
      done[static_cast<size_t>(j)] = 1;
      // A root has no parent to gather.
      if (parents[static_cast<size_t>(j)] < 0) block.lanes = false;
    }
    placed += block.count;
    blocks_.push_back(block);
  }
}

namespace {

// compose(parent, child), GLM's way: the one joint form of the lanes below. With unit scales
// (both scales exactly one) the scale's products are the identity and left out.
template <bool kUnitScale>
void compose_joint(std::span<const int> parents, std::span<const Transform> local,
                   std::span<Transform> global, int j) {
  const size_t k = static_cast<size_t>(j);
  const int p = parents[k];
  if (p < 0) {
    global[k] = local[k];
  } else if (kUnitScale) {
    const Transform& parent = global[static_cast<size_t>(p)];
    Transform& out = global[k];
    out.rotation = parent.rotation * local[k].rotation;
    out.translation = parent.rotation * local[k].translation + parent.translation;
    out.scale = glm::vec3(1.0f);
  } else {
    global[k] = compose(global[static_cast<size_t>(p)], local[k]);
  }
}

#if defined(__SSE2__)
using namespace lanes;

// Four Transforms anywhere: rotation, translation and scale registers.
struct Transforms4 {
  Quat4 rotation;
  Vec4x3 translation, scale;
};

template <bool kUnitScale>
Transforms4 gather(const Transform* a, const Transform* b, const Transform* c, const Transform* d) {
  __m128 q0 = _mm_loadu_ps(&a->rotation.x), q1 = _mm_loadu_ps(&b->rotation.x);
  __m128 q2 = _mm_loadu_ps(&c->rotation.x), q3 = _mm_loadu_ps(&d->rotation.x);
  _MM_TRANSPOSE4_PS(q0, q1, q2, q3);
  // translation x y z and scale x, then (translation z) scale x y z: both inside a Transform.
  __m128 t0 = _mm_loadu_ps(&a->translation.x), t1 = _mm_loadu_ps(&b->translation.x);
  __m128 t2 = _mm_loadu_ps(&c->translation.x), t3 = _mm_loadu_ps(&d->translation.x);
  _MM_TRANSPOSE4_PS(t0, t1, t2, t3);
  if (kUnitScale) {
    const __m128 one = _mm_set1_ps(1.0f);
    return {{q3, q0, q1, q2}, {t0, t1, t2}, {one, one, one}};
  }
  __m128 s0 = _mm_loadu_ps(&a->translation.z), s1 = _mm_loadu_ps(&b->translation.z);
  __m128 s2 = _mm_loadu_ps(&c->translation.z), s3 = _mm_loadu_ps(&d->translation.z);
  _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
  return {{q3, q0, q1, q2}, {t0, t1, t2}, {s1, s2, s3}};
}

template <bool kUnitScale>
[[gnu::always_inline]] inline void compose_block(const std::array<int, 4>& parents,
                                                 std::span<const Transform> local,
                                                 std::span<Transform> global,
                                                 const std::array<int, 4>& joints) {
  const auto at = [](auto span, int j) { return &span[static_cast<size_t>(j)]; };
  const Transforms4 p = gather<kUnitScale>(at(global, parents[0]), at(global, parents[1]),
                                           at(global, parents[2]), at(global, parents[3]));
  const Transforms4 l = gather<kUnitScale>(at(local, joints[0]), at(local, joints[1]),
                                           at(local, joints[2]), at(local, joints[3]));
  const Quat4 rotation = multiply(p.rotation, l.rotation);
  const Vec4x3 translation =
      add(rotate(p.rotation, kUnitScale ? l.translation : times(p.scale, l.translation)),
          p.translation);
  const Vec4x3 s = kUnitScale ? p.scale : times(p.scale, l.scale);
  __m128 x = rotation.x, y = rotation.y, z = rotation.z, w = rotation.w;
  _MM_TRANSPOSE4_PS(x, y, z, w);
  __m128 tx = translation.x, ty = translation.y, tz = translation.z, sx = s.x;
  _MM_TRANSPOSE4_PS(tx, ty, tz, sx);
  alignas(16) float sy[4], sz[4];
  _mm_store_ps(sy, s.y);
  _mm_store_ps(sz, s.z);
  const __m128 rotations[4] = {x, y, z, w};
  const __m128 translations[4] = {tx, ty, tz, sx};
  // Lanes repeating a joint write the same values again.
  for (size_t i = 0; i < 4; ++i) {
    Transform& o = global[static_cast<size_t>(joints[i])];
    _mm_storeu_ps(&o.rotation.x, rotations[i]);
    _mm_storeu_ps(&o.translation.x, translations[i]);
    o.scale.y = sy[i];
    o.scale.z = sz[i];
  }
}
#endif

}  // namespace

template <bool kUnitScale>
void ForwardKinematicsPlan::run_blocks(std::span<const Transform> local,
                                       std::span<Transform> global) const {
  MM_ASSERT(local.size() == parents_.size() && global.size() == parents_.size());
  for (const Block& b : blocks_) {
#if defined(__SSE2__)
    if (b.lanes) {
      compose_block<kUnitScale>(b.parents, local, global, b.joints);
      continue;
    }
#endif
    for (int l = 0; l < b.count; ++l)
      compose_joint<kUnitScale>(parents_, local, global, b.joints[static_cast<size_t>(l)]);
  }
}

void ForwardKinematicsPlan::run(std::span<const Transform> local,
                                std::span<Transform> global) const {
  run_blocks<false>(local, global);
}

void ForwardKinematicsPlan::run_unit_scale(std::span<const Transform> local,
                                           std::span<Transform> global) const {
  run_blocks<true>(local, global);
}

}  // namespace mm
