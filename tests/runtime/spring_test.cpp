#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/spring.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;
using test::same_rotation;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
const glm::vec3 kUp{0.0f, 1.0f, 0.0f};

// ---- independent reference: fine-step RK4 of the ODE --------------------------------------------

// x'' = -c*x' - k*(x - goal), integrated with classical RK4 in double with a tiny step.
struct Rk4Spring {
  double c, k;  // damping and stiffness

  void advance(double& x, double& v, double goal, double duration, double h = 1e-4) const {
    auto acc = [&](double px, double pv) { return -c * pv - k * (px - goal); };
    const int steps = static_cast<int>(std::ceil(duration / h));
    h = duration / steps;
    for (int i = 0; i < steps; ++i) {
      const double k1x = v, k1v = acc(x, v);
      const double k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
      const double k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
      const double k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
      x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
  }
};

Rk4Spring reference_for(float halflife) {
  return {halflife_to_damping(halflife), halflife_to_stiffness(halflife)};
}

// The spring character as an ODE in (x, v, a): x' = v, v' = a, a' = -c*a - k*(v - desired).
struct Rk4Character {
  double c, k;

  void advance(std::array<double, 3>& s, double desired, double duration, double h = 1e-4) const {
    auto f = [&](const std::array<double, 3>& y) {
      return std::array<double, 3>{y[1], y[2], -c * y[2] - k * (y[1] - desired)};
    };
    auto add = [](const std::array<double, 3>& y, const std::array<double, 3>& d, double scale) {
      return std::array<double, 3>{y[0] + scale * d[0], y[1] + scale * d[1], y[2] + scale * d[2]};
    };
    const int steps = static_cast<int>(std::ceil(duration / h));
    h = duration / steps;
    for (int i = 0; i < steps; ++i) {
      const auto k1 = f(s);
      const auto k2 = f(add(s, k1, 0.5 * h));
      const auto k3 = f(add(s, k2, 0.5 * h));
      const auto k4 = f(add(s, k3, h));
      for (int j = 0; j < 3; ++j) s[j] += h / 6.0 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
    }
  }
};

// ---- conversions
// ----------------------------------------------------------------------------------

TEST(SpringConversions, CriticalDampingAndRoundTrips) {
  for (float h : {0.05f, 0.2f, 1.0f, 3.0f}) {
    const float w = halflife_to_angular_frequency(h);
    EXPECT_NEAR(w * h, 1.6783469900166608f, 1e-5f);
    EXPECT_NEAR(halflife_to_damping(h), 2.0f * w, 1e-4f * w);
    EXPECT_NEAR(halflife_to_stiffness(h), w * w, 1e-4f * w * w);
    // Critical damping: c^2 == 4k, i.e. zeta = c / (2 sqrt(k)) == 1.
    const float zeta = halflife_to_damping(h) / (2.0f * std::sqrt(halflife_to_stiffness(h)));
    EXPECT_NEAR(zeta, 1.0f, 1e-6f);
    EXPECT_NEAR(damping_to_halflife(halflife_to_damping(h)), h, 1e-6f * h);
    EXPECT_NEAR(angular_frequency_to_halflife(w), h, 1e-6f * h);
  }
  // The factor solves (1 + u) e^-u = 1/2.
  const double u = kHalflifeFrequencyFactor;
  EXPECT_NEAR((1.0 + u) * std::exp(-u), 0.5, 1e-7);
}

// ---- scalar and vec3 springs
// ----------------------------------------------------------------------

TEST(CriticalSpring, ScalarMatchesRk4OfTheOde) {
  struct Case {
    float x, v, goal, halflife;
  };
  for (const Case c : {Case{0.0f, 0.0f, 1.0f, 0.2f}, Case{2.0f, -5.0f, -1.0f, 0.1f},
                       Case{-3.0f, 10.0f, 0.5f, 0.5f}, Case{1.0f, 0.0f, 1.0f, 1.0f}}) {
    const Rk4Spring ref = reference_for(c.halflife);
    float x = c.x, v = c.v;
    double rx = c.x, rv = c.v;
    const float dt = 1.0f / 60.0f;
    for (int frame = 0; frame < 90; ++frame) {
      critical_spring_update(x, v, c.goal, c.halflife, dt);
      ref.advance(rx, rv, c.goal, dt);
      ASSERT_NEAR(x, rx, 1e-5) << frame;
      ASSERT_NEAR(v, rv, 1e-4 * (1.0 + std::abs(rv))) << frame;
    }
  }
}

TEST(CriticalSpring, Vec3MatchesRk4PerAxis) {
  const float h = 0.15f;
  const Rk4Spring ref = reference_for(h);
  glm::vec3 x(1.0f, -2.0f, 0.5f), v(0.0f, 3.0f, -4.0f);
  const glm::vec3 goal(0.2f, 0.4f, -0.6f);
  std::array<double, 3> rx{1.0, -2.0, 0.5}, rv{0.0, 3.0, -4.0};
  for (int frame = 0; frame < 60; ++frame) {
    const float dt = 0.01f + 0.005f * (frame % 3);  // uneven frame times
    critical_spring_update(x, v, goal, h, dt);
    for (int i = 0; i < 3; ++i) {
      ref.advance(rx[i], rv[i], goal[i], dt);
      ASSERT_NEAR(x[i], rx[i], 1e-5) << frame;
      ASSERT_NEAR(v[i], rv[i], 1e-4 * (1.0 + std::abs(rv[i]))) << frame;
    }
  }
}

TEST(CriticalSpring, HalflifeHalvesTheDistanceFromRest) {
  for (float h : {0.05f, 0.3f, 2.0f}) {
    // Closed form in one step, and in many small steps.
    float x = 10.0f, v = 0.0f;
    critical_spring_update(x, v, 4.0f, h, h);
    EXPECT_NEAR(x - 4.0f, 3.0f, 1e-5f) << h;
    float xs = 10.0f, vs = 0.0f;
    for (int i = 0; i < 100; ++i) critical_spring_update(xs, vs, 4.0f, h, h / 100.0f);
    EXPECT_NEAR(xs - 4.0f, 3.0f, 1e-4f) << h;
    // The ODE itself agrees, so the halflife meaning does not rest on the closed form.
    double rx = 10.0, rv = 0.0;
    reference_for(h).advance(rx, rv, 4.0, h);
    EXPECT_NEAR(rx - 4.0, 3.0, 1e-6) << h;
    // Two halflives from rest leave less than a quarter: critical damping never overshoots.
    critical_spring_update(x, v, 4.0f, h, h);
    EXPECT_GT(x - 4.0f, 0.0f);
    EXPECT_LT(x - 4.0f, 6.0f / 4.0f);
  }
}

TEST(CriticalSpring, ZeroAndNegativeDtLeaveStateUnchanged) {
  float x = 1.5f, v = -2.0f;
  critical_spring_update(x, v, 10.0f, 0.2f, 0.0f);
  EXPECT_EQ(x, 1.5f);
  EXPECT_EQ(v, -2.0f);
  critical_spring_update(x, v, 10.0f, 0.2f, -0.1f);
  EXPECT_EQ(x, 1.5f);
  EXPECT_EQ(v, -2.0f);
  glm::vec3 p(1, 2, 3), pv(4, 5, 6);
  critical_spring_update(p, pv, glm::vec3(0.0f), 0.2f, 0.0f);
  EXPECT_EQ(p, glm::vec3(1, 2, 3));
  EXPECT_EQ(pv, glm::vec3(4, 5, 6));
}

TEST(CriticalSpring, HugeDtConvergesExactly) {
  for (float dt : {100.0f, 1e6f, 1e30f, 3e38f}) {
    float x = 1.5f, v = 40.0f;
    critical_spring_update(x, v, -7.0f, 0.2f, dt);
    EXPECT_EQ(x, -7.0f) << dt;
    EXPECT_EQ(v, 0.0f) << dt;
    glm::vec3 p(1, 2, 3), pv(4, 5, 6);
    critical_spring_update(p, pv, glm::vec3(9.0f), 0.2f, dt);
    EXPECT_EQ(p, glm::vec3(9.0f));
    EXPECT_EQ(pv, glm::vec3(0.0f));
  }
}

TEST(CriticalSpring, NonFiniteInputIsIgnored) {
  float x = 1.0f, v = 2.0f;
  critical_spring_update(x, v, kNaN, 0.2f, 0.1f);
  critical_spring_update(x, v, kInf, 0.2f, 0.1f);
  critical_spring_update(x, v, 0.0f, kNaN, 0.1f);
  critical_spring_update(x, v, 0.0f, 0.2f, kNaN);
  critical_spring_update(x, v, 0.0f, 0.2f, kInf);
  EXPECT_EQ(x, 1.0f);
  EXPECT_EQ(v, 2.0f);
  glm::vec3 p(1.0f), pv(0.0f);
  critical_spring_update(p, pv, glm::vec3(0.0f, kNaN, 0.0f), 0.2f, 0.1f);
  EXPECT_EQ(p, glm::vec3(1.0f));
  EXPECT_EQ(pv, glm::vec3(0.0f));
  // The spring still works afterwards.
  critical_spring_update(x, v, 0.0f, 0.2f, 10.0f);
  EXPECT_NEAR(x, 0.0f, 1e-6f);
}

TEST(CriticalSpring, ZeroHalflifeArrivesAtOnce) {
  float x = 1.0f, v = 3.0f;
  critical_spring_update(x, v, 5.0f, 0.0f, 1.0f / 60.0f);
  EXPECT_EQ(x, 5.0f);
  EXPECT_EQ(v, 0.0f);
  float y = 1.0f, w = 3.0f;
  critical_spring_update(y, w, 5.0f, -1.0f, 1.0f / 60.0f);
  EXPECT_EQ(y, 5.0f);
}

// ---- rotation spring ---------------------------------------------------------------------------

TEST(RotationSpring, SingleAxisEqualsScalarSpringOnTheShortestAngle) {
  // Facing 0 toward a goal of 300 degrees about +Y: the short way is -60 degrees.
  const float h = 0.25f;
  const Rk4Spring ref = reference_for(h);
  glm::quat q(1.0f, 0.0f, 0.0f, 0.0f);
  glm::vec3 w(0.0f, 0.5f, 0.0f);
  const glm::quat goal = glm::angleAxis(glm::radians(300.0f), kUp);
  double angle = 0.0, rate = 0.5;
  const double goal_angle = glm::radians(-60.0);
  for (int frame = 0; frame < 60; ++frame) {
    critical_spring_update(q, w, goal, h, 1.0f / 60.0f);
    ref.advance(angle, rate, goal_angle, 1.0 / 60.0);
    ASSERT_TRUE(same_rotation(q, glm::angleAxis(static_cast<float>(angle), kUp), 1e-5f)) << frame;
    ASSERT_TRUE(near_vec3(w, glm::vec3(0.0f, static_cast<float>(rate), 0.0f), 1e-4f)) << frame;
  }
  // It went the short way: the angle was always between -60 and +small, never near +300.
  EXPECT_LT(angle, 0.0);
}

TEST(RotationSpring, HalflifeHalvesTheAngleAndConverges) {
  for (int i = 0; i < 20; ++i) {
    const glm::quat start = test::random_rotation();
    const glm::quat goal = test::random_rotation();
    const double angle0 = test::rotation_angle_between(start, goal);
    glm::quat q = start;
    glm::vec3 w(0.0f);
    critical_spring_update(q, w, goal, 0.3f, 0.3f);
    EXPECT_NEAR(test::rotation_angle_between(q, goal), 0.5 * angle0, 1e-5);
    critical_spring_update(q, w, goal, 0.3f, 100.0f);
    EXPECT_TRUE(same_rotation(q, goal, 1e-6f));
    EXPECT_NEAR(glm::length(q), 1.0f, 1e-6f);
  }
}

TEST(RotationSpring, NonFiniteGoalAndZeroDtAreIgnored) {
  const glm::quat start = glm::angleAxis(0.4f, kUp);
  glm::quat q = start;
  glm::vec3 w(0.1f, 0.2f, 0.3f);
  critical_spring_update(q, w, glm::quat(kNaN, 0.0f, 0.0f, 0.0f), 0.2f, 0.1f);
  critical_spring_update(q, w, glm::quat(1.0f, 0.0f, 0.0f, 0.0f), 0.2f, 0.0f);
  EXPECT_EQ(q, start);
  EXPECT_EQ(w, glm::vec3(0.1f, 0.2f, 0.3f));
}

// ---- predictions
// ---------------------------------------------------------------------------------

TEST(SpringPredict, MatchesRk4AndRepeatedUpdates) {
  const float h = 0.2f;
  const glm::vec3 x(1.0f, 0.0f, -1.0f), v(2.0f, 0.0f, 1.0f), goal(0.0f, 0.0f, 3.0f);
  const std::array<float, 4> times{0.0f, 0.33f, 0.67f, 1.0f};
  std::array<glm::vec3, 4> positions, velocities;
  critical_spring_predict(positions, velocities, x, v, goal, h, times);
  const Rk4Spring ref = reference_for(h);
  for (size_t i = 0; i < times.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      double rx = x[axis], rv = v[axis];
      if (times[i] > 0.0f) ref.advance(rx, rv, goal[axis], times[i]);
      EXPECT_NEAR(positions[i][axis], rx, 1e-5) << i;
      EXPECT_NEAR(velocities[i][axis], rv, 1e-4) << i;
    }
  }
  // Predicting 1 s ahead equals stepping 60 frames of 1/60 s.
  glm::vec3 sx = x, sv = v;
  for (int f = 0; f < 60; ++f) critical_spring_update(sx, sv, goal, h, 1.0f / 60.0f);
  EXPECT_TRUE(near_vec3(positions[3], sx, 1e-5f));
  EXPECT_TRUE(near_vec3(velocities[3], sv, 1e-4f));
  // Empty outputs are allowed; a negative time predicts "now".
  const std::array<float, 1> past{-1.0f};
  std::array<glm::vec3, 1> now;
  critical_spring_predict(now, {}, x, v, goal, h, past);
  EXPECT_EQ(now[0], x);
}

TEST(SpringPredict, RotationsMatchRepeatedUpdates) {
  const glm::quat q = test::random_rotation();
  const glm::quat goal = test::random_rotation();
  const glm::vec3 w(0.3f, -0.2f, 0.1f);
  const std::array<float, 3> times{0.25f, 0.5f, 1.0f};
  std::array<glm::quat, 3> rotations;
  std::array<glm::vec3, 3> rates;
  critical_spring_predict(rotations, rates, q, w, goal, 0.2f, times);
  glm::quat sq = q;
  glm::vec3 sw = w;
  for (int f = 1; f <= 60; ++f) {
    critical_spring_update(sq, sw, goal, 0.2f, 1.0f / 60.0f);
    if (f == 15 || f == 30 || f == 60) {
      const int i = f == 15 ? 0 : (f == 30 ? 1 : 2);
      EXPECT_TRUE(same_rotation(rotations[i], sq, 1e-5f)) << f;
      EXPECT_TRUE(near_vec3(rates[i], sw, 1e-4f)) << f;
    }
  }
}

// ---- spring character
// ----------------------------------------------------------------------------

TEST(SpringCharacter, MatchesRk4AcrossDesiredVelocityChanges) {
  const float h = 0.3f;
  const Rk4Character ref{halflife_to_damping(h), halflife_to_stiffness(h)};
  glm::vec3 x(0.0f), v(0.0f), a(0.0f);
  std::array<std::array<double, 3>, 3> rs{};  // per axis: x, v, a
  const float dt = 1.0f / 60.0f;
  for (int frame = 0; frame < 180; ++frame) {
    // Walk forward, then strafe, then stop.
    const glm::vec3 desired = frame < 60    ? glm::vec3(0, 0, 1.5f)
                              : frame < 120 ? glm::vec3(2.0f, 0, 0.5f)
                                            : glm::vec3(0.0f);
    spring_character_update(x, v, a, desired, h, dt);
    for (int i = 0; i < 3; ++i) {
      ref.advance(rs[i], desired[i], dt);
      ASSERT_NEAR(x[i], rs[i][0], 1e-5) << frame;
      ASSERT_NEAR(v[i], rs[i][1], 1e-5) << frame;
      ASSERT_NEAR(a[i], rs[i][2], 1e-4) << frame;
    }
  }
}

TEST(SpringCharacter, AccelerationIsContinuousWhenTheGoalJumps) {
  glm::vec3 x(0.0f), v(1.0f, 0.0f, 0.0f), a(0.5f, 0.0f, 0.0f);
  const glm::vec3 a_before = a;
  // A sudden 5 m/s change of desired velocity; a 10 microsecond step barely moves a.
  spring_character_update(x, v, a, glm::vec3(-4.0f, 0.0f, 0.0f), 0.2f, 1e-5f);
  // Jerk at the jump is bounded by w^2 * 5 m/s + 2 w |a|, about 370 m/s^3 here.
  EXPECT_LT(glm::length(a - a_before), 0.01f);
  EXPECT_LT(glm::length(v - glm::vec3(1.0f, 0.0f, 0.0f)), 1e-4f);
}

TEST(SpringCharacter, VelocityHalflifeAndConvergence) {
  glm::vec3 x(0.0f), v(0.0f), a(0.0f);
  spring_character_update(x, v, a, glm::vec3(0, 0, 4.0f), 0.25f, 0.25f);
  EXPECT_NEAR(v.z, 2.0f, 1e-5f);
  spring_character_update(x, v, a, glm::vec3(0, 0, 4.0f), 0.25f, 1e9f);
  EXPECT_TRUE(finite(x));
  EXPECT_EQ(v, glm::vec3(0, 0, 4.0f));
  EXPECT_EQ(a, glm::vec3(0.0f));
  // dt = 0 and a NaN desired velocity change nothing.
  const glm::vec3 x0 = x;
  spring_character_update(x, v, a, glm::vec3(0, 0, 1.0f), 0.25f, 0.0f);
  spring_character_update(x, v, a, glm::vec3(kNaN), 0.25f, 0.1f);
  EXPECT_EQ(x, x0);
  EXPECT_EQ(v, glm::vec3(0, 0, 4.0f));
}

TEST(SpringCharacter, PredictMatchesRk4AndRepeatedUpdates) {
  const float h = 0.27f;
  const glm::vec3 x(1.0f, 0.0f, 2.0f), v(0.5f, 0.0f, -1.0f), a(2.0f, 0.0f, 0.0f);
  const glm::vec3 desired(-1.0f, 0.0f, 3.0f);
  const std::array<float, 4> times{1e-6f, 0.33f, 0.67f, 1.0f};
  std::array<glm::vec3, 4> px, pv, pa;
  spring_character_predict(px, pv, pa, x, v, a, desired, h, times);
  const Rk4Character ref{halflife_to_damping(h), halflife_to_stiffness(h)};
  for (size_t i = 0; i < times.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      std::array<double, 3> s{x[axis], v[axis], a[axis]};
      ref.advance(s, desired[axis], times[i], 1e-4);
      EXPECT_NEAR(px[i][axis], s[0], 1e-5) << i;
      EXPECT_NEAR(pv[i][axis], s[1], 1e-5) << i;
      EXPECT_NEAR(pa[i][axis], s[2], 1e-4) << i;
    }
  }
  glm::vec3 sx = x, sv = v, sa = a;
  for (int f = 0; f < 60; ++f) spring_character_update(sx, sv, sa, desired, h, 1.0f / 60.0f);
  EXPECT_TRUE(near_vec3(px[3], sx, 1e-5f));
  EXPECT_TRUE(near_vec3(pv[3], sv, 1e-5f));
  EXPECT_TRUE(near_vec3(pa[3], sa, 1e-4f));
}

TEST(CriticalSpring, PrecomputedStepEqualsTheUpdate) {
  for (float halflife : {0.0f, 0.05f, 0.3f, 2.0f}) {
    for (float dt : {1.0f / 144.0f, 1.0f / 30.0f, 0.5f}) {
      const CriticalSpringStep step = critical_spring_step(halflife, dt);
      glm::vec3 x1(0.3f, -1.0f, 2.0f), v1(4.0f, 0.5f, -0.2f), x2 = x1, v2 = v1;
      const glm::vec3 goal(1.0f, 0.0f, -1.0f);
      critical_spring_update(x1, v1, goal, halflife, dt);
      critical_spring_apply(x2, v2, goal, step);
      EXPECT_EQ(x1, x2) << halflife << " " << dt;
      EXPECT_EQ(v1, v2) << halflife << " " << dt;
      EXPECT_NE(x1, glm::vec3(0.3f, -1.0f, 2.0f));  // it did move
    }
  }
  // Steps that must not move: dt <= 0, non-finite dt or halflife; and a non-finite goal.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (const CriticalSpringStep& step :
       {critical_spring_step(0.1f, 0.0f), critical_spring_step(0.1f, -1.0f),
        critical_spring_step(nan, 0.1f), critical_spring_step(0.1f, nan)}) {
    EXPECT_FALSE(step.moves);
    glm::vec3 x(1.0f), v(2.0f);
    critical_spring_apply(x, v, glm::vec3(0.0f), step);
    EXPECT_EQ(x, glm::vec3(1.0f));
    EXPECT_EQ(v, glm::vec3(2.0f));
  }
  glm::vec3 x(1.0f), v(2.0f);
  critical_spring_apply(x, v, glm::vec3(nan), critical_spring_step(0.1f, 0.1f));
  EXPECT_EQ(x, glm::vec3(1.0f));
}

// ---- coming to rest
// -------------------------------------------------------------------------------

// The exact critically damped offset from the goal after t seconds (spring.hpp's closed form),
// in double.
double exact_offset(double x0, double v0, float halflife, double t) {
  const double w = 1.6783469900166608 / halflife;
  return std::exp(-w * t) * (x0 + (v0 + w * x0) * t);
}

bool subnormal(float value) {
  return std::fpclassify(value) == FP_SUBNORMAL;
}

// Two minutes at 60 Hz: long past the point where an offset of a metre would have decayed
// through the whole float range.
constexpr int kLongRunFrames = 120 * 60;
constexpr float kFrame = 1.0f / 60.0f;

// The decay follows the exact curve (to float rounding, and relatively far into the tail) and
// never passes through a subnormal float. Toward zero it ends on exactly zero offset and
// velocity; toward 2.5 within the float spacing there, nearly still.
TEST(CriticalSpring, DecayComesToRestExactlyWithoutSubnormals) {
  const float halflife = 0.1f;
  for (const float goal : {0.0f, 2.5f}) {
    float x = goal + 1.0f, v = -3.0f;                        // a scalar spring
    glm::vec3 x3(0.4f, -1.0f, 1e-3f), v3(2.0f, 0.5f, 0.0f);  // and a 3D one, in steps
    const glm::vec3 x3_0 = x3, v3_0 = v3, goal3(goal);
    const CriticalSpringStep step = critical_spring_step(halflife, kFrame);
    int rest_frame = -1;
    for (int f = 1; f <= kLongRunFrames; ++f) {
      critical_spring_update(x, v, goal, halflife, kFrame);
      critical_spring_apply(x3, v3, goal3, step);
      const double expected = exact_offset(1.0, -3.0, halflife, f * static_cast<double>(kFrame));
      ASSERT_NEAR(x - goal, expected, 3e-7 * (1.0 + goal)) << "frame " << f << ", goal " << goal;
      if (goal == 0.0f && std::abs(expected) > 1e-9) {
        ASSERT_NEAR(x, expected, 1e-3 * std::abs(expected)) << "frame " << f;
      }
      for (int axis = 0; axis < 3; ++axis) {
        const double e = exact_offset(x3_0[axis] - goal, v3_0[axis], halflife, f * kFrame);
        ASSERT_NEAR(x3[axis] - goal, e, 3e-7 * (1.0 + goal)) << "frame " << f << ", axis " << axis;
      }
      ASSERT_FALSE(subnormal(x) || subnormal(v)) << "frame " << f << ", goal " << goal;
      ASSERT_TRUE(test::no_subnormal(x3) && test::no_subnormal(v3)) << "frame " << f;
      if (rest_frame < 0 && x == goal && v == 0.0f && x3 == goal3 && v3 == glm::vec3(0.0f)) {
        rest_frame = f;
      }
    }
    if (goal == 0.0f) {
      // At rest within a few seconds (a metre decays below kSpringNegligible in about 20
      // halflives), and for good.
      EXPECT_GT(rest_frame, 0);
      EXPECT_LT(rest_frame, 5 * 60);
      EXPECT_EQ(x, goal);
      EXPECT_EQ(v, 0.0f);
      EXPECT_EQ(x3, goal3);
      EXPECT_EQ(v3, glm::vec3(0.0f));
    } else {
      const float spacing = std::nextafter(goal, 10.0f) - goal;
      EXPECT_LE(std::abs(x - goal), spacing);
      EXPECT_LT(std::abs(v), 1e-5f);
      EXPECT_TRUE(near_vec3(x3, goal3, 2.0f * spacing));  // one spacing per axis
      EXPECT_TRUE(near_vec3(v3, glm::vec3(0.0f), 1e-5f));
    }
  }
}

TEST(SpringCharacter, VelocityAndAccelerationComeToRestExactlyWithoutSubnormals) {
  glm::vec3 x(0.0f), v(1.5f, 0.0f, -2.0f), a(4.0f, 0.0f, 1.0f);
  const glm::vec3 stop(0.0f);
  for (int f = 1; f <= kLongRunFrames; ++f) {
    spring_character_update(x, v, a, stop, 0.3f, kFrame);
    ASSERT_TRUE(test::no_subnormal(x) && test::no_subnormal(v) && test::no_subnormal(a))
        << "frame " << f;
  }
  EXPECT_EQ(v, glm::vec3(0.0f));
  EXPECT_EQ(a, glm::vec3(0.0f));
  // Where it stopped: x0 + the integral of the velocity, (v0 + (v0 w + a0) / w) / w per axis.
  const double w = 1.6783469900166608 / 0.3;
  EXPECT_NEAR(x.x, (1.5 + (1.5 * w + 4.0) / w) / w, 1e-5);
  EXPECT_NEAR(x.z, (-2.0 + (-2.0 * w + 1.0) / w) / w, 1e-5);
}

TEST(RotationSpring, AngularVelocitySettlesWithoutSubnormals) {
  const glm::quat goal = glm::angleAxis(0.3f, kUp);
  glm::quat q = glm::angleAxis(-1.0f, kUp);
  glm::vec3 rate(0.0f, 2.0f, 0.0f);
  for (int f = 1; f <= kLongRunFrames; ++f) {
    critical_spring_update(q, rate, goal, 0.15f, kFrame);
    ASSERT_TRUE(test::no_subnormal(rate)) << "frame " << f;
    ASSERT_FALSE(subnormal(q.w) || subnormal(q.x) || subnormal(q.y) || subnormal(q.z)) << f;
  }
  // The error measured from quaternions stops at their rounding: nearly still, on the goal.
  EXPECT_TRUE(near_vec3(rate, glm::vec3(0.0f), 1e-5f));
  EXPECT_TRUE(same_rotation(q, goal, 1e-6f));
}

// A prepared table predicts the same numbers as the halflife and times do, to the bit, and a
// table prepared again for another halflife or other times gives that one's (never the stale
// coefficients).
TEST(SpringPredictionTable, EqualsThePredictionFromTheHalflifeAndFollowsChanges) {
  const std::array<float, 4> times{0.0f, 0.2f, 0.5f, 1.0f};
  const std::array<float, 4> later{0.1f, 0.3f, 0.6f, 1.2f};
  const glm::vec3 x(0.3f, 0.0f, -1.2f), v(1.1f, 0.0f, 0.4f), a(-2.0f, 0.0f, 0.7f);
  const glm::vec3 desired(0.0f, 0.0f, 1.5f);
  const glm::quat q = glm::angleAxis(0.4f, glm::vec3(0, 1, 0));
  const glm::quat goal = glm::angleAxis(-1.3f, glm::vec3(0, 1, 0));
  const glm::vec3 w(0.0f, 0.8f, 0.0f);
  SpringPredictionTable positions_table, rotations_table;
  // The same key twice in a row (kept), then another halflife, then other times.
  for (const std::array<float, 4>& at : {times, later}) {
    for (const float halflife : {0.3f, 0.3f, 0.12f}) {
      std::array<glm::vec3, 4> p{}, vel{}, acc{}, p_table{}, vel_table{}, acc_table{};
      spring_character_predict(p, vel, acc, x, v, a, desired, halflife, at);
      positions_table.prepare_character(halflife, at);
      spring_character_predict(p_table, vel_table, acc_table, x, v, a, desired, positions_table);
      std::array<glm::quat, 4> r{}, r_table{};
      std::array<glm::vec3, 4> rate{}, rate_table{};
      critical_spring_predict(r, rate, q, w, goal, halflife, at);
      rotations_table.prepare_critical(halflife, at);
      critical_spring_predict(r_table, rate_table, q, w, goal, rotations_table);
      for (size_t i = 0; i < at.size(); ++i) {
        EXPECT_EQ(p_table[i], p[i]) << halflife << " " << i;
        EXPECT_EQ(vel_table[i], vel[i]) << halflife << " " << i;
        EXPECT_EQ(acc_table[i], acc[i]) << halflife << " " << i;
        EXPECT_EQ(r_table[i], r[i]) << halflife << " " << i;
        EXPECT_EQ(rate_table[i], rate[i]) << halflife << " " << i;
      }
    }
  }
  // The two halflives predict differently, so following the change is tested above.
  std::array<glm::vec3, 4> slow{}, fast{};
  spring_character_predict(slow, {}, {}, x, v, a, desired, 0.3f, times);
  spring_character_predict(fast, {}, {}, x, v, a, desired, 0.12f, times);
  EXPECT_NE(slow[3], fast[3]);
}

// The cached step is critical_spring_step's for the halflife and dt asked, also after either
// changes (a new rate, a new setting) and for steps that do not move.
TEST(CriticalSpringStepCache, EqualsTheStepOfTheHalflifeAndDtAskedAndFollowsChanges) {
  CriticalSpringStepCache cache;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::array<std::array<float, 2>, 9> asked = {{{0.1f, 1.0f / 60.0f},
                                                      {0.1f, 1.0f / 60.0f},
                                                      {0.1f, 1.0f / 30.0f},
                                                      {0.2f, 1.0f / 30.0f},
                                                      {0.2f, 1.0f / 30.0f},
                                                      {0.2f, 0.0f},
                                                      {nan, 1.0f / 30.0f},
                                                      {0.2f, 1.0f / 30.0f},
                                                      {0.0f, 1.0f / 144.0f}}};
  for (const auto& [halflife, dt] : asked) {
    SCOPED_TRACE(testing::Message() << "halflife " << halflife << ", dt " << dt);
    const CriticalSpringStep expected = critical_spring_step(halflife, dt);
    const CriticalSpringStep& got = cache.step(halflife, dt);
    EXPECT_EQ(got.moves, expected.moves);
    EXPECT_EQ(got.xx, expected.xx);
    EXPECT_EQ(got.xv, expected.xv);
    EXPECT_EQ(got.vx, expected.vx);
    EXPECT_EQ(got.vv, expected.vv);
  }
}

// A scalar spring through its cache moves as critical_spring_update moves it, to the bit, also
// when the halflife or dt changes between calls (or makes the step a no-op).
TEST(CriticalSpringScalarCache, EqualsCriticalSpringUpdateAndFollowsChanges) {
  CriticalSpringScalarCache cache;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::array<std::array<float, 3>, 10> asked = {{{0.1f, 1.0f / 60.0f, 1.0f},
                                                       {0.1f, 1.0f / 60.0f, 1.0f},
                                                       {0.1f, 1.0f / 30.0f, -2.0f},
                                                       {0.2f, 1.0f / 30.0f, -2.0f},
                                                       {0.2f, 1.0f / 30.0f, nan},
                                                       {0.2f, 0.0f, 0.5f},
                                                       {nan, 1.0f / 30.0f, 0.5f},
                                                       {0.2f, 1.0f / 30.0f, 0.5f},
                                                       {0.0f, 1.0f / 144.0f, 3.0f},
                                                       {0.0f, 1.0f / 144.0f, 3.0f}}};
  float x = 0.3f, v = -1.5f, expected_x = x, expected_v = v;
  for (const auto& [halflife, dt, goal] : asked) {
    SCOPED_TRACE(testing::Message() << "halflife " << halflife << ", dt " << dt);
    critical_spring_update(expected_x, expected_v, goal, halflife, dt);
    cache.update(x, v, goal, halflife, dt);
    EXPECT_EQ(std::bit_cast<uint32_t>(x), std::bit_cast<uint32_t>(expected_x));
    EXPECT_EQ(std::bit_cast<uint32_t>(v), std::bit_cast<uint32_t>(expected_v));
  }
}

// critical_spring_apply's result written out in GLM's scalar arithmetic: the step's formula,
// each component of the offset and the velocity below kSpringNegligible settled to zero.
struct SpringState {
  glm::vec3 x, v;
};
SpringState apply_by_formula(const CriticalSpringStep& step, const glm::vec3& x, const glm::vec3& v,
                             const glm::vec3& goal) {
  const auto settled = [](float c) { return std::abs(c) < kSpringNegligible ? 0.0f : c; };
  const glm::vec3 j0 = x - goal;
  const glm::vec3 moved = step.xx * j0 + step.xv * v;
  const glm::vec3 rate = step.vx * j0 + step.vv * v;
  return {goal + glm::vec3(settled(moved.x), settled(moved.y), settled(moved.z)),
          glm::vec3(settled(rate.x), settled(rate.y), settled(rate.z))};
}

// Both vectors' components equal to the bit (a NaN equals the same NaN; +0 is not -0).
void expect_same_bits(const glm::vec3& actual, const glm::vec3& expected) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(std::bit_cast<uint32_t>(actual[i]), std::bit_cast<uint32_t>(expected[i]))
        << "component " << i;
  }
}

// A spring at rest on its goal (its offset and velocity zero, either sign) takes a shortcut; its
// result is the full step's to the bit: the scalar one against the uncached update, the vector
// one against the step's formula written out here.
TEST(CriticalSpring, AtRestOnTheGoalEqualsTheFullStepToTheBit) {
  const float halflife = 0.1f, dt = 1.0f / 60.0f;
  const CriticalSpringStep step = critical_spring_step(halflife, dt);
  for (const float goal : {0.0f, -0.0f, 1.5f, -2.0f}) {
    for (const float x0 : {goal, goal == 0.0f ? -goal : goal}) {
      for (const float v0 : {0.0f, -0.0f}) {
        SCOPED_TRACE(testing::Message() << "goal " << goal << ", x " << x0 << ", v " << v0);
        CriticalSpringScalarCache cache;
        float x = x0, v = v0, expected_x = x0, expected_v = v0;
        critical_spring_update(expected_x, expected_v, goal, halflife, dt);
        cache.update(x, v, goal, halflife, dt);
        EXPECT_EQ(std::bit_cast<uint32_t>(x), std::bit_cast<uint32_t>(expected_x));
        EXPECT_EQ(std::bit_cast<uint32_t>(v), std::bit_cast<uint32_t>(expected_v));

        const glm::vec3 goal3(goal, 0.25f, goal), v3(v0, 0.0f, v0);
        glm::vec3 x3(x0, 0.25f, x0), velocity3 = v3;
        const SpringState expected3 = apply_by_formula(step, x3, v3, goal3);
        critical_spring_apply(x3, velocity3, goal3, step);
        expect_same_bits(x3, expected3.x);
        expect_same_bits(velocity3, expected3.v);
      }
    }
  }
}

// critical_spring_apply (in SSE registers where built with SSE2) against the step's formula
// written out in GLM's scalar arithmetic, to the bit: random states, components that settle to
// zero (below kSpringNegligible after the step) and a NaN that must stay one.
TEST(CriticalSpring, ApplyEqualsTheStepFormulaToTheBit) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> value(-3.0f, 3.0f);
  for (int trial = 0; trial < 2000; ++trial) {
    const CriticalSpringStep step =
        critical_spring_step(0.02f + 0.001f * static_cast<float>(trial % 300), 1.0f / 60.0f);
    glm::vec3 x(value(random), value(random), value(random));
    glm::vec3 v(value(random), value(random), value(random));
    const glm::vec3 goal(value(random), value(random), value(random));
    if (trial % 5 == 1) x.y = goal.y + 1e-14f, v.y = -1e-14f;
    if (trial % 97 == 3) x.z = std::numeric_limits<float>::quiet_NaN();
    const SpringState expected = apply_by_formula(step, x, v, goal);
    critical_spring_apply(x, v, goal, step);
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    expect_same_bits(x, expected.x);
    expect_same_bits(v, expected.v);
  }
}

// The kept prediction is critical_spring_predict's from the table, to the bit: asked again with
// the same arguments, and after each of the rotation, the rate, the goal, the halflife and the
// times changes (and changes back).
TEST(RotationPredictionCache, EqualsThePredictionFromTheTableAndFollowsChanges) {
  const std::array<float, 3> times{0.2f, 0.4f, 0.6f};
  const std::array<float, 3> later{0.2f, 0.4f, 0.7f};
  const glm::quat q = glm::angleAxis(0.4f, glm::vec3(0, 1, 0));
  const glm::quat turned = glm::angleAxis(0.5f, glm::vec3(0, 1, 0));
  const glm::quat goal = glm::angleAxis(-1.3f, glm::vec3(0, 1, 0));
  const glm::quat other_goal = glm::angleAxis(1.1f, glm::vec3(1, 0, 0));
  const glm::vec3 w(0.0f, 0.8f, 0.0f), still(0.0f);
  struct Asked {
    glm::quat rotation;
    glm::vec3 rate;
    glm::quat goal;
    float halflife;
    const std::array<float, 3>* at;
  };
  const std::array<Asked, 9> asked = {{{q, w, goal, 0.3f, &times},
                                       {q, w, goal, 0.3f, &times},
                                       {turned, w, goal, 0.3f, &times},
                                       {turned, still, goal, 0.3f, &times},
                                       {turned, still, other_goal, 0.3f, &times},
                                       {turned, still, other_goal, 0.12f, &times},
                                       {turned, still, other_goal, 0.12f, &later},
                                       {q, w, goal, 0.3f, &times},
                                       {q, w, goal, 0.3f, &times}}};
  RotationPredictionCache cache;
  SpringPredictionTable table;
  std::array<glm::quat, 3> previous{};
  for (size_t k = 0; k < asked.size(); ++k) {
    const Asked& a = asked[k];
    table.prepare_critical(a.halflife, *a.at);
    std::array<glm::quat, 3> expected{}, kept{};
    critical_spring_predict(expected, {}, a.rotation, a.rate, a.goal, table);
    // Made again on every call but the repeats of the one before.
    EXPECT_EQ(cache.predict(kept, a.rotation, a.rate, a.goal, table), k != 1 && k != 8) << k;
    for (size_t i = 0; i < times.size(); ++i) {
      EXPECT_EQ(std::memcmp(&kept[i], &expected[i], sizeof(glm::quat)), 0) << k << " " << i;
    }
    // Every change of an argument changes the prediction, so a stale one would be seen.
    if (k > 0 && k != 1 && k != 8) {
      EXPECT_NE(kept, previous) << k;
    }
    previous = kept;
  }
}

// The rotation spring with a precomputed step is the one with the halflife and dt, to the bit.
TEST(RotationSpring, APrecomputedStepEqualsTheHalflifeAndDt) {
  for (int trial = 0; trial < 50; ++trial) {
    const glm::quat goal = test::random_rotation();
    glm::quat a = test::random_rotation(), b = a;
    glm::vec3 va = test::random_vec3(-3.0f, 3.0f), vb = va;
    const float halflife = test::uniform(0.05f, 0.5f);
    const CriticalSpringStep step = critical_spring_step(halflife, 1.0f / 60.0f);
    for (int i = 0; i < 10; ++i) {
      critical_spring_update(a, va, goal, halflife, 1.0f / 60.0f);
      critical_spring_update(b, vb, goal, step);
    }
    EXPECT_EQ(a, b);
    EXPECT_EQ(va, vb);
    EXPECT_NE(a, goal);  // the spring moved, and not all the way
  }
}

}  // namespace
}  // namespace mm
