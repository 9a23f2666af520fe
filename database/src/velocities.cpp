#include "mm/database/velocities.hpp"

#include <algorithm>
#include <cstdint>

#if defined(__SSE2__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include <glm/gtc/type_ptr.hpp>

#include "cpu_features.hpp"
#include "mm/runtime/assert.hpp"
#include "mm/runtime/interpolation.hpp"
#include "validation.hpp"

namespace mm {

namespace {

// The rotation vector of a unit quaternion like quat_to_scaled_angle_axis, faster for the
// small rotations between neighbouring frames: for |angle| < ~29 degrees a series for atan
// (error below 1e-9 relative) replaces atan2; larger rotations take the exact path.
glm::vec3 small_rotation_vector(const glm::quat& rotation) {
  const glm::quat q = rotation.w < 0.0f ? -rotation : rotation;
  const glm::vec3 v(q.x, q.y, q.z);
  const float s2 = glm::dot(v, v);
  if (s2 < 0.0625f * q.w * q.w) {
    // 2 atan(s / w) / s = (2 / w) (1 - x/3 + x^2/5 - ...), x = s^2 / w^2 <= 1/16.
    const float x = s2 / (q.w * q.w);
    const float series =
        1.0f + x * (-1.0f / 3 +
                    x * (1.0f / 5 +
                         x * (-1.0f / 7 + x * (1.0f / 9 + x * (-1.0f / 11 + x * (1.0f / 13))))));
    return v * (2.0f * series / q.w);
  }
  return quat_to_scaled_angle_axis(q);
}

#if defined(__SSE2__) && defined(__GNUC__)
// Several joints at once: the same float operations as angular_velocity_between, in the same
// order, so every value has the scalar bits (without FMA there is nothing to contract). A lane
// whose rotation is too large for the series takes the scalar path.
using Floats4 = float __attribute__((vector_size(16)));
using Floats8 = float __attribute__((vector_size(32)));

// Quaternions lane by lane (one vector per component).
template <class V>
struct QuatLanes {
  V x, y, z, w;
};

// small_rotation_vector(to * conjugate(from)) * inv_dt for every lane into rate; returns the bit
// mask of the lanes whose rotation the series covers (the others need the scalar path).
template <class V>
[[gnu::always_inline]] inline unsigned series_rates(const QuatLanes<V>& from,
                                                    const QuatLanes<V>& to, float inv_dt,
                                                    QuatLanes<V>& rate) {
  // p * q with p = to and q = conjugate(from), as glm writes the quaternion product.
  const V qx = -from.x, qy = -from.y, qz = -from.z, qw = from.w;
  V w = to.w * qw - to.x * qx - to.y * qy - to.z * qz;
  V x = to.w * qx + to.x * qw + to.y * qz - to.z * qy;
  V y = to.w * qy + to.y * qw + to.z * qx - to.x * qz;
  V z = to.w * qz + to.z * qw + to.x * qy - to.y * qx;
  const auto flip = w < 0.0f;  // the shorter way round
  w = flip ? -w : w;
  x = flip ? -x : x;
  y = flip ? -y : y;
  z = flip ? -z : z;
  const V s2 = x * x + y * y + z * z;
  const auto small = s2 < 0.0625f * w * w;
  const V t = s2 / (w * w);
  const V series =
      1.0f +
      t * (-1.0f / 3 +
           t * (1.0f / 5 + t * (-1.0f / 7 + t * (1.0f / 9 + t * (-1.0f / 11 + t * (1.0f / 13))))));
  const V k = 2.0f * series / w;
  rate.x = x * k * inv_dt;
  rate.y = y * k * inv_dt;
  rate.z = z * k * inv_dt;
  unsigned bits = 0;
  for (size_t lane = 0; lane < sizeof(V) / sizeof(float); ++lane) {
    bits |= static_cast<unsigned>(small[lane] != 0) << lane;
  }
  return bits;
}

// Four vec3 from the lanes of x, y and z: rows of a transpose stored 16 bytes at a time, each
// one's spare float overwritten by the next row, the last row 12 bytes.
inline void store_vec3_x4(Floats4 x, Floats4 y, Floats4 z, glm::vec3* out) {
  __m128 r0 = x, r1 = y, r2 = z, r3 = _mm_setzero_ps();
  _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
  _mm_storeu_ps(&out[0].x, r0);
  _mm_storeu_ps(&out[1].x, r1);
  _mm_storeu_ps(&out[2].x, r2);
  alignas(16) float last[4];
  _mm_store_ps(last, r3);
  std::memcpy(&out[3].x, last, sizeof(glm::vec3));
}

inline void store_vec3(const QuatLanes<Floats4>& v, glm::vec3* out) {
  store_vec3_x4(v.x, v.y, v.z, out);
}

inline void store_vec3(const QuatLanes<Floats8>& v, glm::vec3* out) {
  // By reference: a vector argument by value outside an AVX function would change the ABI.
  const auto low = [](const Floats8& f) {
    return Floats4(__builtin_shufflevector(f, f, 0, 1, 2, 3));
  };
  const auto high = [](const Floats8& f) {
    return Floats4(__builtin_shufflevector(f, f, 4, 5, 6, 7));
  };
  store_vec3_x4(low(v.x), low(v.y), low(v.z), out);
  store_vec3_x4(high(v.x), high(v.y), high(v.z), out + 4);
}

// The rates into out: all lanes at once when the series covered them all (the common case),
// else lane by lane with the scalar path for the others. Returns whether all are finite.
template <class V>
[[gnu::always_inline]] inline bool store_rates(const QuatLanes<V>& rate, unsigned series,
                                               const glm::quat* from, const glm::quat* to,
                                               float inv_dt, glm::vec3* out) {
  constexpr size_t kLanes = sizeof(V) / sizeof(float);
  if (series == (1u << kLanes) - 1) {
    store_vec3(rate, out);
    // x - x is 0 for a finite x and NaN otherwise.
    const auto finite =
        (rate.x - rate.x == 0.0f) & (rate.y - rate.y == 0.0f) & (rate.z - rate.z == 0.0f);
    bool all = true;
    for (size_t lane = 0; lane < kLanes; ++lane) all &= finite[lane] != 0;
    return all;
  }
  bool all = true;
  for (size_t lane = 0; lane < kLanes; ++lane) {
    out[lane] = (series >> lane & 1) != 0 ? glm::vec3(rate.x[lane], rate.y[lane], rate.z[lane])
                                          : angular_velocity_between(from[lane], to[lane], inv_dt);
    all &= detail::finite3(out[lane]);
  }
  return all;
}

// Four quaternions (x, y, z, w in memory) transposed into one vector per component.
QuatLanes<Floats4> load_quats_x4(const glm::quat* q) {
  __m128 x = _mm_loadu_ps(&q[0].x), y = _mm_loadu_ps(&q[1].x);
  __m128 z = _mm_loadu_ps(&q[2].x), w = _mm_loadu_ps(&q[3].x);
  _MM_TRANSPOSE4_PS(x, y, z, w);
  return {x, y, z, w};
}

// angular_velocity_between for samples [0, count), a vector's lanes at a time, the quaternions
// read by `load`; returns how many it did and clears `finite` if one of them is not.
template <class V, class Load>
[[gnu::always_inline]] inline size_t angular_velocity_run(Load load, const glm::quat* from,
                                                          const glm::quat* to, size_t count,
                                                          float inv_dt, glm::vec3* out,
                                                          bool& finite) {
  constexpr size_t kLanes = sizeof(V) / sizeof(float);
  size_t i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    QuatLanes<V> rate;
    const unsigned series = series_rates(load(from + i), load(to + i), inv_dt, rate);
    finite &= store_rates(rate, series, from + i, to + i, inv_dt, out + i);
  }
  return i;
}

size_t angular_velocities_x4(const glm::quat* from, const glm::quat* to, size_t count, float inv_dt,
                             glm::vec3* out, bool& finite) {
  return angular_velocity_run<Floats4>(load_quats_x4, from, to, count, inv_dt, out, finite);
}

// Two quaternions in the two halves of one vector.
__attribute__((target("avx"))) __m256 load_quat_pair(const glm::quat& low, const glm::quat& high) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(&low.x)), _mm_loadu_ps(&high.x),
                              1);
}

// Eight quaternions: lanes 0-3 in the low half of each vector, 4-7 in the high half.
__attribute__((target("avx"))) QuatLanes<Floats8> load_quats_x8(const glm::quat* q) {
  const __m256 r0 = load_quat_pair(q[0], q[4]), r1 = load_quat_pair(q[1], q[5]);
  const __m256 r2 = load_quat_pair(q[2], q[6]), r3 = load_quat_pair(q[3], q[7]);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpacklo_ps(r2, r3);
  const __m256 t2 = _mm256_unpackhi_ps(r0, r1), t3 = _mm256_unpackhi_ps(r2, r3);
  return {_mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0)),
          _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2)),
          _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0)),
          _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(3, 2, 3, 2))};
}

// The same eight at a time, with AVX.
__attribute__((target("avx"))) size_t angular_velocities_x8(const glm::quat* from,
                                                            const glm::quat* to, size_t count,
                                                            float inv_dt, glm::vec3* out,
                                                            bool& finite) {
  return angular_velocity_run<Floats8>(load_quats_x8, from, to, count, inv_dt, out, finite);
}

#endif

// Finite differences over runs of samples (frame-major joint values) of one clip.
struct FrameDifferences {
  std::span<const glm::vec3> positions;
  std::span<const glm::quat> rotations;
  std::span<glm::vec3> velocities;
  std::span<glm::vec3> angular_velocities;

  // For samples i in [first, first + count): the rates from sample i - back to i + ahead.
  // Returns whether every rate is finite.
  bool differences(size_t first, size_t count, size_t back, size_t ahead, float inv_dt) const {
    if (count == 0) return true;
    // Linear: every float of a vec3 alike.
    const float* from = glm::value_ptr(positions[first - back]);
    const float* to = glm::value_ptr(positions[first + ahead]);
    float* velocity = glm::value_ptr(velocities[first]);
    uint32_t infinite = 0;
    for (size_t k = 0; k < 3 * count; ++k) {
      velocity[k] = (to[k] - from[k]) * inv_dt;
      infinite |= static_cast<uint32_t>(!detail::finite_bits(velocity[k]));
    }
    bool finite = infinite == 0;

    size_t i = first;
#if defined(__SSE2__) && defined(__GNUC__)
    const auto run = [&](auto kernel) {
      i += kernel(&rotations[i - back], &rotations[i + ahead], first + count - i, inv_dt,
                  &angular_velocities[i], finite);
    };
    if (detail::cpu_has_avx()) run(angular_velocities_x8);
    run(angular_velocities_x4);
#endif
    for (; i < first + count; ++i) {
      angular_velocities[i] =
          angular_velocity_between(rotations[i - back], rotations[i + ahead], inv_dt);
      finite &= detail::finite3(angular_velocities[i]);
    }
    return finite;
  }
};

}  // namespace

glm::vec3 angular_velocity_between(const glm::quat& from, const glm::quat& to, float inv_dt) {
  return small_rotation_vector(to * glm::conjugate(from)) * inv_dt;
}

bool compute_local_velocities(std::span<const glm::vec3> positions,
                              std::span<const glm::quat> rotations, int frame_count,
                              int joint_count, float frame_time, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> angular_velocities) {
  const size_t joints = static_cast<size_t>(joint_count);
  const size_t frames = frame_count > 0 ? static_cast<size_t>(frame_count) : 0;
  MM_ASSERT(positions.size() == frames * joints);
  MM_ASSERT(rotations.size() == positions.size() && velocities.size() == positions.size() &&
            angular_velocities.size() == positions.size());
  const FrameDifferences clip{positions, rotations, velocities, angular_velocities};
  if (frames < 2) {
    std::fill(velocities.begin(), velocities.end(), glm::vec3(0.0f));
    std::fill(angular_velocities.begin(), angular_velocities.end(), glm::vec3(0.0f));
    return true;
  }
  // Frame f differences frames a = max(0, f - 1) and b = min(last, f + 1) over (b - a) frames:
  // the first and last frames one-sided, all the others (one run of samples) central.
  const auto inv_dt = [&](int frame_steps) {
    return 1.0f / (static_cast<float>(frame_steps) * frame_time);
  };
  const bool first = clip.differences(0, joints, 0, joints, inv_dt(1));
  const bool inside = clip.differences(joints, (frames - 2) * joints, joints, joints, inv_dt(2));
  const bool last = clip.differences((frames - 1) * joints, joints, joints, 0, inv_dt(1));
  return first && inside && last;
}

}  // namespace mm
