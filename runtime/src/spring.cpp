#include "mm/runtime/spring.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/finite.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/transform_sse.hpp"

namespace mm {

namespace {

// Beyond this many time constants exp(-w*t) is below 1e-26: the spring has arrived (any state
// below 1e14 would decay under kSpringNegligible), and the float coefficients of a shorter step
// stay clear of the subnormal range.
constexpr double kArrivedExponent = 60.0;

// A state component smaller than kSpringNegligible is exactly zero (spring.hpp).
double settled(double value) {
  return std::abs(value) < static_cast<double>(kSpringNegligible) ? 0.0 : value;
}

glm::vec3 settled(const glm::vec3& v) {
  auto component = [](float c) { return std::abs(c) < kSpringNegligible ? 0.0f : c; };
  return {component(v.x), component(v.y), component(v.z)};
}

#if defined(__SSE2__)
// The same of each lane: +0 where the magnitude is below kSpringNegligible (a NaN is kept).
__m128 settled(__m128 v) {
  const __m128 magnitude = _mm_andnot_ps(_mm_set1_ps(-0.0f), v);
  return _mm_andnot_ps(_mm_cmplt_ps(magnitude, _mm_set1_ps(kSpringNegligible)), v);
}
#endif

double angular_frequency(float halflife) {
  return static_cast<double>(kHalflifeFrequencyFactor) /
         static_cast<double>(std::max(halflife, kMinSpringHalflife));
}

// The critically damped spring after t seconds is linear in the initial offset j0 = x0 - goal
// and velocity v0: x - goal = xx*j0 + xv*v0, v = vx*j0 + vv*v0. Computed in double.
struct SpringCoefficients {
  double xx = 1.0, xv = 0.0, vx = 0.0, vv = 1.0;
};

SpringCoefficients spring_coefficients(double w, double t) {
  SpringCoefficients c;
  const double u = w * t;
  if (u > kArrivedExponent) return {0.0, 0.0, 0.0, 0.0};
  const double e = std::exp(-u);
  c.xx = e * (1.0 + u);
  c.xv = e * t;
  c.vx = -e * w * w * t;
  c.vv = e * (1.0 - u);
  return c;
}

// The spring character after t seconds, with j0 = v0 - desired and j1 = a0 + w*j0:
//   x = x0 + desired*t + j0*t*f1(u) + j1*t*t*f2(u),  v = desired + e*(j0 + j1*t),
//   a = e*(a0 - w*j1*t),
// where f1(u) = (1 - e^-u)/u and f2(u) = (1 - e^-u (1 + u))/u^2 (series near u = 0, where
// the differences cancel).
struct CharacterCoefficients {
  double x_j0 = 0.0, x_j1 = 0.0, e = 1.0, t = 0.0, w = 0.0;
};

CharacterCoefficients character_coefficients(double w, double t) {
  CharacterCoefficients c;
  const double u = w * t;
  c.t = t;
  c.w = w;
  c.e = u > kArrivedExponent ? 0.0 : std::exp(-u);
  double f1 = 0.0;
  double f2 = 0.0;
  if (u < 1e-3) {
    f1 = 1.0 - u / 2.0 + u * u / 6.0 - u * u * u / 24.0;
    f2 = 0.5 - u / 3.0 + u * u / 8.0 - u * u * u / 30.0;
  } else {
    f1 = (1.0 - c.e) / u;
    f2 = (1.0 - c.e * (1.0 + u)) / (u * u);
  }
  c.x_j0 = t * f1;
  c.x_j1 = t * t * f2;
  return c;
}

glm::vec3 scaled(double s, const glm::vec3& v) {
  return static_cast<float>(s) * v;
}

void apply_spring(glm::vec3& x, glm::vec3& v, const glm::vec3& goal, const SpringCoefficients& c) {
  const glm::vec3 j0 = x - goal;
  const glm::vec3 v0 = v;
  x = goal + settled(scaled(c.xx, j0) + scaled(c.xv, v0));
  v = settled(scaled(c.vx, j0) + scaled(c.vv, v0));
}

void apply_character(glm::vec3& x, glm::vec3& v, glm::vec3& a, const glm::vec3& desired,
                     const CharacterCoefficients& c) {
  const glm::vec3 j0 = v - desired;
  const glm::vec3 j1 = a + scaled(c.w, j0);
  x = x + scaled(c.t, desired) + scaled(c.x_j0, j0) + scaled(c.x_j1, j1);
  v = desired + settled(scaled(c.e, j0) + scaled(c.e * c.t, j1));
  a = settled(scaled(c.e, a) - scaled(c.e * c.w * c.t, j1));
}

// critical_spring_update's step of a scalar spring, in double.
void apply_scalar(float& x, float& v, float goal, const SpringCoefficients& c) {
  const double j0 = static_cast<double>(x) - goal;
  const double v0 = v;
  x = static_cast<float>(goal + settled(c.xx * j0 + c.xv * v0));
  v = static_cast<float>(settled(c.vx * j0 + c.vv * v0));
}

bool usable(float halflife, float dt) {
  return std::isfinite(halflife) && std::isfinite(dt);
}

// A prediction time that is negative or non-finite predicts "now".
double prediction_time(float t) {
  return std::isfinite(t) && t > 0.0f ? t : 0.0;
}

}  // namespace

float halflife_to_angular_frequency(float halflife) {
  return static_cast<float>(angular_frequency(halflife));
}

float angular_frequency_to_halflife(float angular_frequency) {
  return kHalflifeFrequencyFactor / angular_frequency;
}

float halflife_to_damping(float halflife) {
  return 2.0f * halflife_to_angular_frequency(halflife);
}

float damping_to_halflife(float damping) {
  return angular_frequency_to_halflife(0.5f * damping);
}

float halflife_to_stiffness(float halflife) {
  const float w = halflife_to_angular_frequency(halflife);
  return w * w;
}

void critical_spring_update(float& x, float& v, float goal, float halflife, float dt) {
  if (!(dt > 0.0f) || !usable(halflife, dt) || !std::isfinite(goal)) return;
  apply_scalar(x, v, goal, spring_coefficients(angular_frequency(halflife), dt));
}

void CriticalSpringScalarCache::update(float& x, float& v, float goal, float halflife, float dt) {
  if (!(dt > 0.0f) || !usable(halflife, dt) || !std::isfinite(goal)) return;
  // At rest on its goal the step's arithmetic is all zeros, settled to +0: the result is the
  // goal (goal + 0 makes a -0 goal +0, as apply_scalar's double sum does) and no velocity. Held
  // feet and settled lifts sit there most updates.
  if (x == goal && v == 0.0f) {
    x = goal + 0.0f;
    v = 0.0f;
    return;
  }
  if (key_.changed(halflife, dt)) {
    const SpringCoefficients c = spring_coefficients(angular_frequency(halflife), dt);
    xx_ = c.xx;
    xv_ = c.xv;
    vx_ = c.vx;
    vv_ = c.vv;
  }
  apply_scalar(x, v, goal, {xx_, xv_, vx_, vv_});
}

void critical_spring_update(glm::vec3& x, glm::vec3& v, const glm::vec3& goal, float halflife,
                            float dt) {
  critical_spring_apply(x, v, goal, critical_spring_step(halflife, dt));
}

CriticalSpringStep critical_spring_step(float halflife, float dt) {
  CriticalSpringStep step;
  if (!(dt > 0.0f) || !usable(halflife, dt)) return step;
  const SpringCoefficients c = spring_coefficients(angular_frequency(halflife), dt);
  step.xx = static_cast<float>(c.xx);
  step.xv = static_cast<float>(c.xv);
  step.vx = static_cast<float>(c.vx);
  step.vv = static_cast<float>(c.vv);
  step.moves = true;
  return step;
}

void critical_spring_apply(glm::vec3& x, glm::vec3& v, const glm::vec3& goal,
                           const CriticalSpringStep& step) {
  if (!step.moves || !finite(goal)) return;
  // At rest on its goal: settled zeros, so the goal (a -0 component made +0) and no velocity,
  // without the arithmetic (a released foot's offset sits there once it has decayed, a held
  // foot's always).
  if (x == goal && v == glm::vec3(0.0f)) {
    x = goal + glm::vec3(0.0f);
    v = glm::vec3(0.0f);
    return;
  }
#if defined(__SSE2__)
  // The same in SSE registers, lane by lane in GLM's order (transform_sse.hpp).
  const __m128 g = sse::load(goal), v0 = sse::load(v);
  const __m128 j0 = _mm_sub_ps(sse::load(x), g);
  const __m128 moved =
      _mm_add_ps(_mm_mul_ps(_mm_set1_ps(step.xx), j0), _mm_mul_ps(_mm_set1_ps(step.xv), v0));
  const __m128 rate =
      _mm_add_ps(_mm_mul_ps(_mm_set1_ps(step.vx), j0), _mm_mul_ps(_mm_set1_ps(step.vv), v0));
  x = sse::to_vec3(_mm_add_ps(g, settled(moved)));
  v = sse::to_vec3(settled(rate));
#else
  const glm::vec3 j0 = x - goal;
  const glm::vec3 v0 = v;
  x = goal + settled(step.xx * j0 + step.xv * v0);
  v = settled(step.vx * j0 + step.vv * v0);
#endif
}

void critical_spring_update(glm::quat& rotation, glm::vec3& angular_velocity, const glm::quat& goal,
                            float halflife, float dt) {
  if (!(dt > 0.0f) || !usable(halflife, dt)) return;
  critical_spring_update(rotation, angular_velocity, goal, critical_spring_step(halflife, dt));
}

void critical_spring_update(glm::quat& rotation, glm::vec3& angular_velocity, const glm::quat& goal,
                            const CriticalSpringStep& step) {
  if (!step.moves || !finite(goal)) return;
  glm::vec3 error = quat_to_scaled_angle_axis(rotation * glm::conjugate(goal));
  critical_spring_apply(error, angular_velocity, glm::vec3(0.0f), step);
  rotation = glm::normalize(quat_from_scaled_angle_axis(error) * goal);
}

const CriticalSpringStep& CriticalSpringStepCache::step(float halflife, float dt) {
  if (key_.changed(halflife, dt)) step_ = critical_spring_step(halflife, dt);
  return step_;
}

void critical_spring_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                             const glm::vec3& x, const glm::vec3& v, const glm::vec3& goal,
                             float halflife, std::span<const float> times) {
  MM_ASSERT(positions.empty() || positions.size() == times.size());
  MM_ASSERT(velocities.empty() || velocities.size() == times.size());
  const bool frozen = !std::isfinite(halflife) || !finite(goal);
  const double w = angular_frequency(halflife);
  for (size_t i = 0; i < times.size(); ++i) {
    glm::vec3 xi = x;
    glm::vec3 vi = v;
    if (!frozen) apply_spring(xi, vi, goal, spring_coefficients(w, prediction_time(times[i])));
    if (!positions.empty()) positions[i] = xi;
    if (!velocities.empty()) velocities[i] = vi;
  }
}

namespace {

// One predicted time of a rotation spring from its initial error (not frozen).
void predict_rotation(glm::quat& rotation, glm::vec3& rate, const glm::vec3& error0,
                      const glm::quat& goal, const SpringCoefficients& c) {
  glm::vec3 error = error0;
  apply_spring(error, rate, glm::vec3(0.0f), c);
  rotation = glm::normalize(quat_from_scaled_angle_axis(error) * goal);
}

}  // namespace

void critical_spring_predict(std::span<glm::quat> rotations,
                             std::span<glm::vec3> angular_velocities, const glm::quat& rotation,
                             const glm::vec3& angular_velocity, const glm::quat& goal,
                             float halflife, std::span<const float> times) {
  MM_ASSERT(rotations.empty() || rotations.size() == times.size());
  MM_ASSERT(angular_velocities.empty() || angular_velocities.size() == times.size());
  const bool frozen = !std::isfinite(halflife) || !finite(goal);
  const double w = angular_frequency(halflife);
  const glm::vec3 error0 =
      frozen ? glm::vec3(0.0f) : quat_to_scaled_angle_axis(rotation * glm::conjugate(goal));
  for (size_t i = 0; i < times.size(); ++i) {
    glm::quat q = rotation;
    glm::vec3 rate = angular_velocity;
    if (!frozen) {
      predict_rotation(q, rate, error0, goal, spring_coefficients(w, prediction_time(times[i])));
    }
    if (!rotations.empty()) rotations[i] = q;
    if (!angular_velocities.empty()) angular_velocities[i] = rate;
  }
}

void critical_spring_predict(std::span<glm::quat> rotations,
                             std::span<glm::vec3> angular_velocities, const glm::quat& rotation,
                             const glm::vec3& angular_velocity, const glm::quat& goal,
                             const SpringPredictionTable& table) {
  MM_ASSERT(table.prepared);
  MM_ASSERT(rotations.empty() || rotations.size() == table.count);
  MM_ASSERT(angular_velocities.empty() || angular_velocities.size() == table.count);
  const bool frozen = !std::isfinite(table.halflife) || !finite(goal);
  const glm::vec3 error0 =
      frozen ? glm::vec3(0.0f) : quat_to_scaled_angle_axis(rotation * glm::conjugate(goal));
  for (size_t i = 0; i < table.count; ++i) {
    glm::quat q = rotation;
    glm::vec3 rate = angular_velocity;
    if (!frozen) {
      const double* c = table.c[i];
      predict_rotation(q, rate, error0, goal, SpringCoefficients{c[0], c[1], c[2], c[3]});
    }
    if (!rotations.empty()) rotations[i] = q;
    if (!angular_velocities.empty()) angular_velocities[i] = rate;
  }
}

namespace {

// Whether a and b hold the same bits (a NaN equals itself, 0 and -0 differ).
template <typename T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

}  // namespace

bool RotationPredictionCache::predict(std::span<glm::quat> rotations, const glm::quat& rotation,
                                      const glm::vec3& angular_velocity, const glm::quat& goal,
                                      const SpringPredictionTable& table) {
  MM_ASSERT(table.prepared && table.count <= SpringPredictionTable::kMaxTimes);
  MM_ASSERT(rotations.size() == table.count);
  // The times past count are compared too (the table keeps them): stricter, never stale.
  const bool same = known_ && same_bits(rotation, rotation_) && same_bits(goal, goal_) &&
                    same_bits(angular_velocity, angular_velocity_) && table.kind == kind_ &&
                    table.count == count_ && same_bits(table.halflife, halflife_) &&
                    same_bits(table.times, times_);
  if (!same) {
    critical_spring_predict(std::span<glm::quat>(rotations_, table.count), {}, rotation,
                            angular_velocity, goal, table);
    known_ = true;
    rotation_ = rotation;
    goal_ = goal;
    angular_velocity_ = angular_velocity;
    kind_ = table.kind;
    count_ = table.count;
    halflife_ = table.halflife;
    std::memcpy(times_, table.times, sizeof(times_));
  }
  std::copy_n(rotations_, table.count, rotations.begin());
  return !same;
}

void spring_character_update(glm::vec3& position, glm::vec3& velocity, glm::vec3& acceleration,
                             const glm::vec3& desired_velocity, float halflife, float dt) {
  if (!(dt > 0.0f) || !usable(halflife, dt) || !finite(desired_velocity)) return;
  apply_character(position, velocity, acceleration, desired_velocity,
                  character_coefficients(angular_frequency(halflife), dt));
}

void spring_character_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> accelerations, const glm::vec3& position,
                              const glm::vec3& velocity, const glm::vec3& acceleration,
                              const glm::vec3& desired_velocity, float halflife,
                              std::span<const float> times) {
  MM_ASSERT(positions.empty() || positions.size() == times.size());
  MM_ASSERT(velocities.empty() || velocities.size() == times.size());
  MM_ASSERT(accelerations.empty() || accelerations.size() == times.size());
  const bool frozen = !std::isfinite(halflife) || !finite(desired_velocity);
  const double w = angular_frequency(halflife);
  for (size_t i = 0; i < times.size(); ++i) {
    glm::vec3 x = position;
    glm::vec3 v = velocity;
    glm::vec3 a = acceleration;
    if (!frozen) {
      apply_character(x, v, a, desired_velocity,
                      character_coefficients(w, prediction_time(times[i])));
    }
    if (!positions.empty()) positions[i] = x;
    if (!velocities.empty()) velocities[i] = v;
    if (!accelerations.empty()) accelerations[i] = a;
  }
}

void spring_character_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> accelerations, const glm::vec3& position,
                              const glm::vec3& velocity, const glm::vec3& acceleration,
                              const glm::vec3& desired_velocity,
                              const SpringPredictionTable& table) {
  MM_ASSERT(table.prepared);
  MM_ASSERT(positions.empty() || positions.size() == table.count);
  MM_ASSERT(velocities.empty() || velocities.size() == table.count);
  MM_ASSERT(accelerations.empty() || accelerations.size() == table.count);
  const bool frozen = !std::isfinite(table.halflife) || !finite(desired_velocity);
  for (size_t i = 0; i < table.count; ++i) {
    glm::vec3 x = position;
    glm::vec3 v = velocity;
    glm::vec3 a = acceleration;
    if (!frozen) {
      const double* c = table.c[i];
      apply_character(x, v, a, desired_velocity,
                      CharacterCoefficients{c[0], c[1], c[2], c[3], table.w});
    }
    if (!positions.empty()) positions[i] = x;
    if (!velocities.empty()) velocities[i] = v;
    if (!accelerations.empty()) accelerations[i] = a;
  }
}

namespace {

// Whether the table was prepared (by the same kind of prepare) for this halflife and times.
bool same_key(const SpringPredictionTable& table, float halflife, std::span<const float> times) {
  if (!table.prepared || table.count != times.size()) return false;
  // Compared as bits: a NaN halflife or time is the same key as itself.
  if (std::memcmp(&table.halflife, &halflife, sizeof(float)) != 0) return false;
  return std::memcmp(table.times, times.data(), times.size() * sizeof(float)) == 0;
}

void set_key(SpringPredictionTable& table, float halflife, std::span<const float> times) {
  MM_ASSERT(times.size() <= SpringPredictionTable::kMaxTimes);
  table.prepared = true;
  table.halflife = halflife;
  table.count = times.size();
  std::copy(times.begin(), times.end(), table.times);
  table.w = angular_frequency(halflife);
}

}  // namespace

void SpringPredictionTable::prepare_critical(float new_halflife, std::span<const float> new_times) {
  if (same_key(*this, new_halflife, new_times) && kind == 1) return;
  set_key(*this, new_halflife, new_times);
  kind = 1;
  for (size_t i = 0; i < count; ++i) {
    const SpringCoefficients s = spring_coefficients(w, prediction_time(times[i]));
    c[i][0] = s.xx;
    c[i][1] = s.xv;
    c[i][2] = s.vx;
    c[i][3] = s.vv;
  }
}

void SpringPredictionTable::prepare_character(float new_halflife,
                                              std::span<const float> new_times) {
  if (same_key(*this, new_halflife, new_times) && kind == 2) return;
  set_key(*this, new_halflife, new_times);
  kind = 2;
  for (size_t i = 0; i < count; ++i) {
    const CharacterCoefficients s = character_coefficients(w, prediction_time(times[i]));
    c[i][0] = s.x_j0;
    c[i][1] = s.x_j1;
    c[i][2] = s.e;
    c[i][3] = s.t;
  }
}

}  // namespace mm
