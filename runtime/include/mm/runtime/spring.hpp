#pragma once
// Critically damped springs in exact closed form, parametrized by a halflife in seconds.
//
// The spring obeys x'' = -2*w*x' - w*w*(x - goal), the critically damped case (zeta = 1) of
// x'' = -c*x' - k*(x - goal) with damping c = 2*w and stiffness k = w*w. With j0 = x0 - goal
// and j1 = v0 + w*j0 its exact solution is
//   x(t) = goal + exp(-w*t) * (j0 + j1*t),   v(t) = exp(-w*t) * (v0 - w*j1*t),
// so one update of any length dt is exact: no integration error and no instability.
//
// Halflife (our definition): the time a spring starting AT REST takes to close exactly half of
// its distance to the goal, i.e. (1 + w*h) * exp(-w*h) = 1/2, which gives
// w = kHalflifeFrequencyFactor / h with kHalflifeFrequencyFactor = 1.67834699. (Some code uses
// w = 2*ln(2)/h instead, whose "halflife" leaves about 60 % of the distance; ours means what
// it says.) A spring that is already moving may close more or less than half in one halflife.
//
// Robustness, shared by every function here:
// - dt <= 0 leaves the state unchanged (springs never run backwards);
// - a non-finite goal, halflife or dt is ignored: the call leaves the state unchanged, so one
//   NaN from input cannot poison the state;
// - halflife is clamped below at kMinSpringHalflife (so 0 means "arrive at once");
// - a very long dt converges exactly to the goal with zero velocity;
// - each component of a spring's offset from the goal, of its velocity and (spring character)
//   of its acceleration is set to exactly 0 once smaller in magnitude than kSpringNegligible.
//   Left alone, an offset decaying toward a goal of zero (an inertialization offset, a
//   stopping character's velocity) would shrink into the subnormal floats (below about
//   1e-38), whose arithmetic is many times slower on x86, so a character standing for minutes
//   would cost more every frame; zero costs nothing. Toward a goal away from zero the offset
//   can only shrink to the float spacing at the goal (and a rotation's error to the rounding
//   of its quaternions), where it may stay: normal floats, with a velocity far below
//   anything visible;
// - predictions at a negative or non-finite time give the current state, and predictions
//   with a non-finite goal or halflife give the current state at every time.
// Nothing here allocates.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm {

// w * halflife for a critically damped spring: the root of (1 + u) * exp(-u) = 1/2.
inline constexpr float kHalflifeFrequencyFactor = 1.6783469900166608f;

// The shortest halflife used (seconds); shorter ones, including 0, are clamped to it.
inline constexpr float kMinSpringHalflife = 1e-5f;

// Below this magnitude a spring's state is exactly zero (see above), in the state's own units:
// metres or radians for an offset from the goal, m/s or rad/s for its velocity (m/s^2 for the
// spring character's acceleration, whose "offset" is a velocity). A picometre, far below
// anything visible, and far above the subnormal range.
inline constexpr float kSpringNegligible = 1e-12f;

// The natural angular frequency w (1/s) of a critically damped spring with this halflife (s).
float halflife_to_angular_frequency(float halflife);

// The halflife (s) of a critically damped spring with natural angular frequency w (1/s).
float angular_frequency_to_halflife(float angular_frequency);

// The damping coefficient c = 2*w of x'' = -c*x' - k*(x - goal) for this halflife.
float halflife_to_damping(float halflife);

// The halflife whose critically damped spring has damping coefficient c = 2*w.
float damping_to_halflife(float damping);

// The stiffness k = w*w of x'' = -c*x' - k*(x - goal) for this halflife (critical damping).
float halflife_to_stiffness(float halflife);

// The share of the remaining distance an exponential pull (no velocity of its own: a damper)
// with this halflife closes in dt seconds: half in one halflife.
inline float pull_fraction(float halflife, float dt) {
  return 1.0f - std::exp2(-dt / std::max(halflife, kMinSpringHalflife));
}

// Advances a scalar spring (position x, velocity v) toward goal by dt seconds, exactly.
void critical_spring_update(float& x, float& v, float goal, float halflife, float dt);

// The halflife and dt a cached spring step was computed for, compared bit for bit: the caches
// below recompute only when either changes, so their result is the uncached one to the bit.
class SpringStepKey {
 public:
  // Whether (halflife, dt) differs from the last call's (always on the first); remembers it.
  bool changed(float halflife, float dt) {
    const std::uint32_t h = std::bit_cast<std::uint32_t>(halflife);
    const std::uint32_t t = std::bit_cast<std::uint32_t>(dt);
    if (known_ && h == halflife_bits_ && t == dt_bits_) return false;
    halflife_bits_ = h;
    dt_bits_ = t;
    known_ = true;
    return true;
  }

 private:
  std::uint32_t halflife_bits_ = 0, dt_bits_ = 0;
  bool known_ = false;
};

// critical_spring_update of a scalar spring, to the bit, with the step's coefficients kept: at
// a fixed update rate and halflife every update takes the same step, whose exponential is then
// computed once. They are computed again whenever the halflife or dt differs from the last
// call's (bit for bit). One cache per spring that has its own halflife.
class CriticalSpringScalarCache {
 public:
  void update(float& x, float& v, float goal, float halflife, float dt);

 private:
  SpringStepKey key_;
  double xx_ = 1.0, xv_ = 0.0, vx_ = 0.0, vv_ = 1.0;  // as critical_spring_update computes them
};

// Advances a 3D spring toward goal by dt seconds, exactly (each axis is independent).
void critical_spring_update(glm::vec3& x, glm::vec3& v, const glm::vec3& goal, float halflife,
                            float dt);

// One step of dt seconds of every critically damped spring with this halflife, computed once:
// springs that share a halflife and a dt (the inertialization offsets of every joint) advance
// with one exponential between them. A step with dt <= 0 or a non-finite halflife or dt is a
// no-op, as for critical_spring_update.
struct CriticalSpringStep {
  float xx = 1.0f, xv = 0.0f, vx = 0.0f, vv = 1.0f;  // x' - goal = xx*(x - goal) + xv*v, ...
  bool moves = false;                                // false: the step leaves springs as they are
};
CriticalSpringStep critical_spring_step(float halflife, float dt);

// Advances a 3D spring by a precomputed step; the same result as critical_spring_update with
// the step's halflife and dt.
void critical_spring_apply(glm::vec3& x, glm::vec3& v, const glm::vec3& goal,
                           const CriticalSpringStep& step);

// The last step asked for, kept: at a fixed update rate and halflife every update takes the
// same step, whose exponential is then computed once instead of in every update. The step is
// computed again whenever the halflife or dt differs from the last call's (bit for bit, so a
// change of settings or rate is never missed); the result is critical_spring_step's.
class CriticalSpringStepCache {
 public:
  const CriticalSpringStep& step(float halflife, float dt);

 private:
  SpringStepKey key_;
  CriticalSpringStep step_;
};

// Advances a rotation spring toward goal by dt seconds along the shortest path. The state is
// the rotation error e = angle*axis of rotation * inverse(goal) (world frame, |e| <= pi) and
// angular_velocity = de/dt (rad/s, axis times rate), which is the true angular velocity
// whenever the rotation stays about one axis (a facing about +Y, for instance).
void critical_spring_update(glm::quat& rotation, glm::vec3& angular_velocity, const glm::quat& goal,
                            float halflife, float dt);
// The same with a precomputed step (critical_spring_step of the halflife and dt).
void critical_spring_update(glm::quat& rotation, glm::vec3& angular_velocity, const glm::quat& goal,
                            const CriticalSpringStep& step);

// Predicts a 3D spring at future times (seconds from now, each >= 0) without changing it:
// positions[i] and velocities[i] are the state after times[i]. Either output may be empty;
// a non-empty output must have times.size() entries.
void critical_spring_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                             const glm::vec3& x, const glm::vec3& v, const glm::vec3& goal,
                             float halflife, std::span<const float> times);

// Predicts a rotation spring at future times (seconds from now), like critical_spring_update.
// Either output may be empty; a non-empty output must have times.size() entries.
void critical_spring_predict(std::span<glm::quat> rotations,
                             std::span<glm::vec3> angular_velocities, const glm::quat& rotation,
                             const glm::vec3& angular_velocity, const glm::quat& goal,
                             float halflife, std::span<const float> times);

// The "spring character": the velocity is a critically damped spring toward desired_velocity
// and the position is its exact integral, so position, velocity and acceleration all stay
// continuous when the desired velocity jumps. Advances the state by dt seconds.
void spring_character_update(glm::vec3& position, glm::vec3& velocity, glm::vec3& acceleration,
                             const glm::vec3& desired_velocity, float halflife, float dt);

// Predicts the spring character at future times (seconds from now) for a fixed desired
// velocity. Outputs may be empty; a non-empty output must have times.size() entries.
void spring_character_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> accelerations, const glm::vec3& position,
                              const glm::vec3& velocity, const glm::vec3& acceleration,
                              const glm::vec3& desired_velocity, float halflife,
                              std::span<const float> times);

// The coefficients of a prediction at fixed times for one halflife: they depend only on those
// (an exponential each), so a caller predicting every update at the same times (a trajectory)
// keeps them and computes them again only when the halflife or a time changes. prepare() checks
// that itself (exact comparison), so a stale table is never used, and the predictions from it
// equal the ones computed from the halflife and times to the bit.
struct SpringPredictionTable {
  static constexpr size_t kMaxTimes = 16;
  // Makes the table the one for halflife and times (times.size() <= kMaxTimes); recomputes only
  // when either differs from the last call's.
  void prepare_critical(float halflife, std::span<const float> times);
  void prepare_character(float halflife, std::span<const float> times);

  bool prepared = false;
  int kind = 0;  // 1: prepare_critical's coefficients, 2: prepare_character's
  float halflife = 0.0f;
  size_t count = 0;
  float times[kMaxTimes] = {};
  // Per time: the critical spring's xx, xv, vx, vv, or the character's x_j0, x_j1, e, t, and
  // the angular frequency w in w (spring.cpp).
  double c[kMaxTimes][4] = {};
  double w = 0.0;
};

// critical_spring_predict (rotations) with the table prepared (prepare_critical) for its
// halflife and times.
void critical_spring_predict(std::span<glm::quat> rotations,
                             std::span<glm::vec3> angular_velocities, const glm::quat& rotation,
                             const glm::vec3& angular_velocity, const glm::quat& goal,
                             const SpringPredictionTable& table);

// critical_spring_predict of the rotations alone from a prepared table, with its last result
// kept: a settled rotation spring (a facing held while walking straight or standing) predicts
// from the same rotation, rate and goal update after update. The prediction is made again
// whenever any of them, or the table's halflife or times, differs from the last call's bit for
// bit, so the result is always the function's to the bit.
class RotationPredictionCache {
 public:
  // rotations.size() must be table.count. Returns whether the prediction was made again (false:
  // the same rotations as the last call's).
  bool predict(std::span<glm::quat> rotations, const glm::quat& rotation,
               const glm::vec3& angular_velocity, const glm::quat& goal,
               const SpringPredictionTable& table);

 private:
  // The last call's arguments (compared bit for bit) and the table's key.
  bool known_ = false;
  glm::quat rotation_{1.0f, 0.0f, 0.0f, 0.0f}, goal_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 angular_velocity_{0.0f};
  int kind_ = 0;
  size_t count_ = 0;
  float halflife_ = 0.0f;
  float times_[SpringPredictionTable::kMaxTimes] = {};
  glm::quat rotations_[SpringPredictionTable::kMaxTimes] = {};
};

// spring_character_predict with the table prepared (prepare_character) for its halflife and
// times.
void spring_character_predict(std::span<glm::vec3> positions, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> accelerations, const glm::vec3& position,
                              const glm::vec3& velocity, const glm::vec3& acceleration,
                              const glm::vec3& desired_velocity,
                              const SpringPredictionTable& table);

}  // namespace mm
