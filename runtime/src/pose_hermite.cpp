#include "mm/runtime/pose_hermite.hpp"

#include <algorithm>
#include <cstddef>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/interpolation.hpp"

#include "quat_lanes.hpp"

namespace mm {

namespace {

// The rows of a group in the lanes' layout (pose_lanes.hpp), each four floats.
enum LaneRow : size_t {
  kRotationW = kPoseLaneRotationW,
  kRotationX = kPoseLaneRotationX,
  kRotationY = kPoseLaneRotationY,
  kRotationZ = kPoseLaneRotationZ,
  kPositionX = kPoseLanePosition,
  kVelocityX = kPoseLaneVelocity,
  kAngularVelocityX = kPoseLaneAngularVelocity,
};

// One joint of a frame: its local transform (unit scale) and velocities.
struct JointSample {
  Transform pose;
  glm::vec3 velocity, angular_velocity;
};

JointSample joint_of(const PoseFrameView& f, size_t j) {
  JointSample s;
  s.pose.rotation = f.rotations[j];
  s.pose.translation = f.positions[j];
  s.velocity = f.velocities[j];
  s.angular_velocity = f.angular_velocities[j];
  return s;
}

JointSample joint_of(std::span<const float> f, size_t j) {
  const float* g = &f[(j / 4) * kPoseLaneGroupFloats + j % 4];
  const auto row = [&](size_t r) { return g[4 * r]; };
  const auto vec = [&](size_t r) { return glm::vec3(row(r), row(r + 1), row(r + 2)); };
  JointSample s;
  s.pose.rotation = glm::quat(row(kRotationW), row(kRotationX), row(kRotationY), row(kRotationZ));
  s.pose.translation = vec(kPositionX);
  s.velocity = vec(kVelocityX);
  s.angular_velocity = vec(kAngularVelocityX);
  return s;
}

// One joint through transform_hermite itself: the reference, and what the lanes do.
template <class Frame>
Transform joint_hermite(const Frame& a, const Frame& b, float duration, float t, size_t j) {
  const JointSample sa = joint_of(a, j), sb = joint_of(b, j);
  return transform_hermite(sa.pose, sa.velocity, sa.angular_velocity, sb.pose, sb.velocity,
                           sb.angular_velocity, duration, t);
}

#if defined(__SSE2__)

using namespace lanes;

// Four joints of one frame, one register per component.
struct Joints4 {
  Quat4 rotation;
  Vec4x3 position, velocity, angular_velocity;
};

// Joints first .. first + 3 as the frame's per-joint arrays store them (transposed).
Joints4 load_joints(const PoseFrameView& f, size_t first) {
  return {load_quats(&f.rotations[first]), load_vec3s(&f.positions[first]),
          load_vec3s(&f.velocities[first]), load_vec3s(&f.angular_velocities[first])};
}

// One group of the lanes' layout: the registers as stored.
Joints4 load_joints(const float* g) {
  const auto row = [&](size_t r) { return _mm_loadu_ps(g + 4 * r); };
  const auto vec = [&](size_t r) { return Vec4x3{row(r), row(r + 1), row(r + 2)}; };
  return {{row(kRotationW), row(kRotationX), row(kRotationY), row(kRotationZ)},
          vec(kPositionX),
          vec(kVelocityX),
          vec(kAngularVelocityX)};
}

// transform_hermite of four joints, lane by lane in its order of operations. `length` is the
// rotation curve's length before normalizing (a lane at or below 1e-6 needs the scalar fallback).
struct Hermite4 {
  Quat4 rotation;
  Vec4x3 translation;
  __m128 length;
};

[[gnu::always_inline]] inline Hermite4 hermite_x4(const Joints4& a, const Joints4& b,
                                                  float duration, float t) {
  // transform_hermite's basis and tangent scales, in its order of operations.
  const float t2 = t * t;
  const float t3 = t2 * t;
  const __m128 h00 = c(2.0f * t3 - 3.0f * t2 + 1.0f);
  const __m128 h10 = c(t3 - 2.0f * t2 + t);
  const __m128 h01 = c(-2.0f * t3 + 3.0f * t2);
  const __m128 h11 = c(t3 - t2);
  const __m128 h10d = c((t3 - 2.0f * t2 + t) * duration);
  const __m128 h11d = c((t3 - t2) * duration);
  const __m128 half_duration = c(0.5f * duration);

  // Translation: h00 a + (h10 d) va + h01 b + (h11 d) vb, summed left to right.
  const auto curve = [&](__m128 p0, __m128 v0, __m128 p1, __m128 v1) {
    return _mm_add_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(h00, p0), _mm_mul_ps(h10d, v0)), _mm_mul_ps(h01, p1)),
        _mm_mul_ps(h11d, v1));
  };
  Hermite4 out;
  out.translation = {curve(a.position.x, a.velocity.x, b.position.x, b.velocity.x),
                     curve(a.position.y, a.velocity.y, b.position.y, b.velocity.y),
                     curve(a.position.z, a.velocity.z, b.position.z, b.velocity.z)};

  // Rotation: b on a's side, the tangents 0.5 d (0, w) q, the curve, normalized.
  const Quat4& qa = a.rotation;
  const Quat4 qb = negate_where(b.rotation, _mm_cmplt_ps(dot(qa, b.rotation), _mm_setzero_ps()));
  const Vec4x3& wa = a.angular_velocity;
  const Vec4x3& wb = b.angular_velocity;
  const Quat4 ta = scale(multiply({_mm_setzero_ps(), wa.x, wa.y, wa.z}, qa), half_duration);
  const Quat4 tb = scale(multiply({_mm_setzero_ps(), wb.x, wb.y, wb.z}, qb), half_duration);
  const Quat4 q = add(add(add(scale(qa, h00), scale(ta, h10)), scale(qb, h01)), scale(tb, h11));
  out.length = _mm_sqrt_ps(dot(q, q));
  out.rotation = {_mm_div_ps(q.w, out.length), _mm_div_ps(q.x, out.length),
                  _mm_div_ps(q.y, out.length), _mm_div_ps(q.z, out.length)};
  return out;
}

// Lanes 0 .. count - 1 into out[first + lane] as Transforms: the rotation's four floats, then the
// translation's three with the scale's first (1) in the fourth, then the scale's other two. A
// lane whose curve passes through zero (opposite tangents) takes transform_hermite's fallback.
template <class Frame>
[[gnu::always_inline]] inline void store_joints(const Hermite4& h, const Frame& a, const Frame& b,
                                                float duration, float t, size_t first, size_t count,
                                                std::span<Transform> out) {
  __m128 rx = h.rotation.x, ry = h.rotation.y, rz = h.rotation.z, rw = h.rotation.w;
  _MM_TRANSPOSE4_PS(rx, ry, rz, rw);
  __m128 x = h.translation.x, y = h.translation.y, z = h.translation.z, ones = c(1.0f);
  _MM_TRANSPOSE4_PS(x, y, z, ones);
  const __m128 rotations[4] = {rx, ry, rz, rw};
  const __m128 translations[4] = {x, y, z, ones};
  Transform* o = &out[first];
  const auto put = [&](size_t i) {
    _mm_storeu_ps(&o[i].rotation.x, rotations[i]);
    _mm_storeu_ps(&o[i].translation.x, translations[i]);
    o[i].scale.y = o[i].scale.z = 1.0f;
  };
  // A whole group written straight, without a loop or a test per joint.
  if (count == 4) {
    put(0);
    put(1);
    put(2);
    put(3);
  } else {
    for (size_t i = 0; i < count; ++i) put(i);
  }
  const int usable = _mm_movemask_ps(_mm_cmpgt_ps(h.length, c(1e-6f)));
  const int lanes = (1 << count) - 1;
  if ((usable & lanes) == lanes) return;
  for (size_t i = 0; i < count; ++i) {
    if (!(usable & (1 << i))) o[i] = joint_hermite(a, b, duration, t, first + i);
  }
}

#endif

}  // namespace

void pose_hermite(const PoseFrameView& a, const PoseFrameView& b, float duration, float t,
                  std::span<Transform> out) {
  const size_t n = out.size();
  MM_ASSERT(a.rotations.size() == n && a.positions.size() == n && a.velocities.size() == n &&
            a.angular_velocities.size() == n);
  MM_ASSERT(b.rotations.size() == n && b.positions.size() == n && b.velocities.size() == n &&
            b.angular_velocities.size() == n);
#if defined(__SSE2__)
  if (n >= 4) {
    // Blocks of four; the last one ends at the last joint (it may redo joints of the one before,
    // to the same values), so nothing is read past the frames' arrays.
    for (size_t block = 0; block < n; block += 4) {
      const size_t first = std::min(block, n - 4);
      const Hermite4 h = hermite_x4(load_joints(a, first), load_joints(b, first), duration, t);
      store_joints(h, a, b, duration, t, first, 4, out);
    }
    return;
  }
#endif
  for (size_t j = 0; j < n; ++j) out[j] = joint_hermite(a, b, duration, t, j);
}

void pose_to_lanes(const PoseFrameView& frame, std::span<float> out) {
  const size_t n = frame.rotations.size();
  MM_ASSERT(frame.positions.size() == n && frame.velocities.size() == n &&
            frame.angular_velocities.size() == n && out.size() == pose_lane_floats(n));
  for (size_t j = 0; j < pose_lane_groups(n) * 4; ++j) {
    // Padding joints: at rest.
    const bool real = j < n;
    const glm::quat q = real ? frame.rotations[j] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    const glm::vec3 p = real ? frame.positions[j] : glm::vec3(0.0f);
    const glm::vec3 v = real ? frame.velocities[j] : glm::vec3(0.0f);
    const glm::vec3 w = real ? frame.angular_velocities[j] : glm::vec3(0.0f);
    float* g = &out[(j / 4) * kPoseLaneGroupFloats + j % 4];
    const auto put = [&](size_t row, float value) { g[4 * row] = value; };
    put(kRotationW, q.w);
    put(kRotationX, q.x);
    put(kRotationY, q.y);
    put(kRotationZ, q.z);
    for (int k = 0; k < 3; ++k) {
      put(kPositionX + static_cast<size_t>(k), p[k]);
      put(kVelocityX + static_cast<size_t>(k), v[k]);
      put(kAngularVelocityX + static_cast<size_t>(k), w[k]);
    }
  }
}

void pose_hermite(std::span<const float> a, std::span<const float> b, float duration, float t,
                  std::span<Transform> out) {
  const size_t n = out.size();
  MM_ASSERT(a.size() == pose_lane_floats(n) && b.size() == pose_lane_floats(n));
#if defined(__SSE2__)
  for (size_t group = 0; group < pose_lane_groups(n); ++group) {
    const size_t first = group * 4;
    const size_t at = group * kPoseLaneGroupFloats;
    const Hermite4 h = hermite_x4(load_joints(&a[at]), load_joints(&b[at]), duration, t);
    store_joints(h, a, b, duration, t, first, std::min<size_t>(4, n - first), out);
  }
#else
  for (size_t j = 0; j < n; ++j) out[j] = joint_hermite(a, b, duration, t, j);
#endif
}

void pose_velocity_mix(std::span<const float> a, std::span<const float> b, float weight,
                       size_t first, std::span<glm::vec3> velocities,
                       std::span<glm::vec3> angular_velocities) {
  const size_t n = velocities.size();
  MM_ASSERT(angular_velocities.size() == n && a.size() == pose_lane_floats(n) &&
            b.size() == pose_lane_floats(n));
#if defined(__SSE2__)
  // glm::mix: a (1 - w) + b w, lane by lane.
  static_assert(kAngularVelocityX == kVelocityX + 3);
  const __m128 keep = c(1.0f - weight), take = c(weight);
  for (size_t group = first / 4; group < pose_lane_groups(n); ++group) {
    const float* ga = &a[group * kPoseLaneGroupFloats];
    const float* gb = &b[group * kPoseLaneGroupFloats];
    alignas(16) float rows[6][4];
    for (size_t r = 0; r < 6; ++r) {
      const size_t row = kVelocityX + r;  // the angular velocity's rows follow the velocity's
      _mm_store_ps(rows[r], _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(ga + 4 * row), keep),
                                       _mm_mul_ps(_mm_loadu_ps(gb + 4 * row), take)));
    }
    for (size_t j = std::max(first, 4 * group); j < std::min(n, 4 * group + 4); ++j) {
      const size_t l = j % 4;
      velocities[j] = glm::vec3(rows[0][l], rows[1][l], rows[2][l]);
      angular_velocities[j] = glm::vec3(rows[3][l], rows[4][l], rows[5][l]);
    }
  }
#else
  for (size_t j = first; j < n; ++j) {
    velocities[j] = glm::mix(pose_lane_vec3(a.data(), j, kVelocityX),
                             pose_lane_vec3(b.data(), j, kVelocityX), weight);
    angular_velocities[j] = glm::mix(pose_lane_vec3(a.data(), j, kAngularVelocityX),
                                     pose_lane_vec3(b.data(), j, kAngularVelocityX), weight);
  }
#endif
}

}  // namespace mm
