#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/inertialization.hpp"
#include "mm/runtime/spring.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;
using test::same_rotation;

constexpr int kJoints = 4;

glm::quat turn(const glm::vec3& scaled_axis) {
  const float angle = glm::length(scaled_axis);
  return angle > 0.0f ? glm::angleAxis(angle, scaled_axis / angle) : glm::quat(1, 0, 0, 0);
}

// One joint's analytic motion: rotation exp(t*w1) * exp(t*w2) * r0, whose parent-frame angular
// velocity is w1 + exp(t*w1) * w2, and position p0 + v*t + a*t^2/2.
struct JointMotion {
  glm::vec3 w1, w2;
  glm::quat r0;
  glm::vec3 p0, v, a;

  glm::quat rotation(float t) const { return turn(t * w1) * turn(t * w2) * r0; }
  glm::vec3 angular_velocity(float t) const { return w1 + turn(t * w1) * w2; }
  glm::vec3 position(float t) const { return p0 + v * t + 0.5f * a * t * t; }
  glm::vec3 velocity(float t) const { return v + a * t; }
};

JointMotion random_motion() {
  JointMotion m;
  m.w1 = test::random_vec3(-2.0f, 2.0f);
  m.w2 = test::random_vec3(-1.5f, 1.5f);
  m.r0 = test::random_rotation();
  m.p0 = test::random_vec3(-0.5f, 0.5f);
  m.v = test::random_vec3(-1.0f, 1.0f);
  m.a = test::random_vec3(-2.0f, 2.0f);
  return m;
}

// A whole animation (one motion per joint) sampled into arrays.
struct Animation {
  std::array<JointMotion, kJoints> joints;
  std::array<Transform, kJoints> local;
  std::array<glm::vec3, kJoints> velocities;
  std::array<glm::vec3, kJoints> angular_velocities;

  static Animation random() {
    Animation anim;
    for (JointMotion& m : anim.joints) m = random_motion();
    return anim;
  }

  // A different animation whose pose differs from `other` by at least 0.3 m and 0.5 rad on
  // every joint (the last joint by 170 degrees, near the antipodal limit).
  static Animation different_from(const Animation& other) {
    Animation anim = random();
    for (int j = 0; j < kJoints; ++j) {
      const float angle = j == kJoints - 1 ? glm::radians(170.0f) : test::uniform(0.5f, 2.5f);
      anim.joints[j].r0 = glm::angleAxis(angle, test::random_unit_vec3()) * other.joints[j].r0;
      anim.joints[j].p0 = other.joints[j].p0 + 0.3f * test::random_unit_vec3();
    }
    return anim;
  }

  PoseMotion at(float t) {
    for (int j = 0; j < kJoints; ++j) {
      local[j].rotation = joints[j].rotation(t);
      local[j].translation = joints[j].position(t);
      velocities[j] = joints[j].velocity(t);
      angular_velocities[j] = joints[j].angular_velocity(t);
    }
    return {local, velocities, angular_velocities};
  }
};

// The output of the inertializer dt seconds after `offsets`' time, on a copy of the offsets.
struct Output {
  std::array<Transform, kJoints> local;
  std::array<glm::vec3, kJoints> velocities;
  std::array<glm::vec3, kJoints> angular_velocities;
};

Output output_after(InertializationOffsets offsets, Animation& incoming, float time, float dt,
                    float halflife) {
  Output out;
  inertialize_update(offsets, incoming.at(time + dt), halflife, dt, out.local, out.velocities,
                     out.angular_velocities);
  return out;
}

// Parent-frame angular velocity taking q0 to q1 in h seconds: 2 * vec(q1 * q0^-1) / h, which is
// exact to second order for the small angles of a finite difference.
glm::vec3 finite_difference_angular_velocity(const glm::quat& q0, const glm::quat& q1, float h) {
  glm::quat d = q1 * glm::conjugate(q0);
  if (d.w < 0.0f) d = -d;
  return 2.0f * glm::vec3(d.x, d.y, d.z) / h;
}

constexpr float kHalflife = 0.2f;
constexpr float kDelta = 2e-3f;

// Richardson-extrapolated one-sided derivatives (2*D(h/2) - D(h)) cancel the first-order error
// of a one-sided difference, including the jump in acceleration a transition may introduce.
glm::vec3 richardson(const glm::vec3& d_h, const glm::vec3& d_half) {
  return 2.0f * d_half - d_h;
}

// Checks that the output just after `time` (offsets at `time`, incoming animation `incoming`)
// starts from `value` with derivative `velocity` / `angular_velocity`.
void expect_continuous(const InertializationOffsets& offsets, Animation& incoming, float time,
                       const std::array<Transform, kJoints>& value,
                       const std::array<glm::vec3, kJoints>& velocity,
                       const std::array<glm::vec3, kJoints>& angular_velocity) {
  const Output at = output_after(offsets, incoming, time, 0.0f, kHalflife);
  const Output half = output_after(offsets, incoming, time, 0.5f * kDelta, kHalflife);
  const Output full = output_after(offsets, incoming, time, kDelta, kHalflife);
  for (int j = 0; j < kJoints; ++j) {
    SCOPED_TRACE("joint " + std::to_string(j));
    // Value continuity.
    EXPECT_TRUE(same_rotation(at.local[j].rotation, value[j].rotation, 2e-6f));
    EXPECT_TRUE(near_vec3(at.local[j].translation, value[j].translation, 1e-5f));
    // The velocities the inertializer reports match.
    EXPECT_TRUE(near_vec3(at.velocities[j], velocity[j], 1e-5f));
    EXPECT_TRUE(near_vec3(at.angular_velocities[j], angular_velocity[j], 2e-5f));
    // And so does the actual motion of the output, by finite differences.
    const glm::vec3 v =
        richardson((full.local[j].translation - at.local[j].translation) / kDelta,
                   (half.local[j].translation - at.local[j].translation) / (0.5f * kDelta));
    EXPECT_TRUE(near_vec3(v, velocity[j], 2e-3f));
    const glm::vec3 w = richardson(
        finite_difference_angular_velocity(at.local[j].rotation, full.local[j].rotation, kDelta),
        finite_difference_angular_velocity(at.local[j].rotation, half.local[j].rotation,
                                           0.5f * kDelta));
    EXPECT_TRUE(near_vec3(w, angular_velocity[j], 3e-3f));
  }
}

TEST(Inertialization, ValueAndFirstDerivativeContinuousAtTheSwitch) {
  for (int trial = 0; trial < 5; ++trial) {
    Animation outgoing = Animation::random();
    Animation incoming = Animation::different_from(outgoing);
    const float switch_time = 0.4f;
    InertializationOffsets offsets;
    offsets.resize(kJoints);

    // Before the switch, the output is the outgoing animation itself.
    outgoing.at(switch_time);
    const auto shown = outgoing.local;
    const auto shown_velocity = outgoing.velocities;
    const auto shown_angular_velocity = outgoing.angular_velocities;
    // Without inertialization the derivative would jump: make sure the test would see it.
    incoming.at(switch_time);
    for (int j = 0; j < kJoints; ++j) {
      ASSERT_GT(glm::length(shown_angular_velocity[j] - incoming.angular_velocities[j]) +
                    glm::length(shown_velocity[j] - incoming.velocities[j]),
                0.1f);
    }

    inertialize_transition(offsets, outgoing.at(switch_time), incoming.at(switch_time));
    expect_continuous(offsets, incoming, switch_time, shown, shown_velocity,
                      shown_angular_velocity);
  }
}

TEST(Inertialization, RepeatedTransitionsStayContinuous) {
  Animation a = Animation::random();
  Animation b = Animation::different_from(a);
  Animation c = Animation::different_from(b);
  InertializationOffsets offsets;
  offsets.resize(kJoints);

  // a -> b at 0.3 s, then frames of 1/60 s until just before 0.45 s.
  const float t1 = 0.3f;
  const float t2 = 0.45f;
  inertialize_transition(offsets, a.at(t1), b.at(t1));
  const InertializationOffsets initial = offsets;
  float time = t1;
  std::array<Transform, kJoints> scratch;
  while (time + 1.0f / 60.0f < t2 - kDelta) {
    inertialize_update(offsets, b.at(time + 1.0f / 60.0f), kHalflife, 1.0f / 60.0f, scratch, {},
                       {});
    time += 1.0f / 60.0f;
  }
  const float last = (t2 - kDelta) - time;
  inertialize_update(offsets, b.at(t2 - kDelta), kHalflife, last, scratch, {}, {});
  time = t2 - kDelta;

  // The output approaching t2 from the left, and its Richardson derivative at t2.
  const Output before = output_after(offsets, b, time, 0.0f, kHalflife);
  const Output before_half = output_after(offsets, b, time, 0.5f * kDelta, kHalflife);
  const Output at_switch = output_after(offsets, b, time, kDelta, kHalflife);
  std::array<glm::vec3, kJoints> left_velocity, left_angular_velocity;
  for (int j = 0; j < kJoints; ++j) {
    left_velocity[j] = richardson(
        (at_switch.local[j].translation - before.local[j].translation) / kDelta,
        (at_switch.local[j].translation - before_half.local[j].translation) / (0.5f * kDelta));
    left_angular_velocity[j] =
        richardson(finite_difference_angular_velocity(before.local[j].rotation,
                                                      at_switch.local[j].rotation, kDelta),
                   finite_difference_angular_velocity(before_half.local[j].rotation,
                                                      at_switch.local[j].rotation, 0.5f * kDelta));
    // The left-hand finite difference agrees with what the inertializer reports at t2.
    EXPECT_TRUE(near_vec3(left_velocity[j], at_switch.velocities[j], 2e-3f)) << j;
    EXPECT_TRUE(near_vec3(left_angular_velocity[j], at_switch.angular_velocities[j], 3e-3f)) << j;
  }

  // Advance the offsets to t2: the first transition is still well under way.
  inertialize_update(offsets, b.at(t2), kHalflife, kDelta, scratch, {}, {});
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_GT(glm::length(offsets.rotations[j]), 0.05f * glm::length(initial.rotations[j])) << j;
  }

  // b -> c at t2, mid-decay: value and derivative continue from the left-hand ones.
  inertialize_transition(offsets, b.at(t2), c.at(t2));
  expect_continuous(offsets, c, t2, at_switch.local, at_switch.velocities,
                    at_switch.angular_velocities);
}

TEST(Inertialization, OffsetsDecayBelowOnePercentAfterFiveHalflives) {
  Animation outgoing = Animation::random();
  Animation incoming = Animation::different_from(outgoing);
  const float halflife = 0.1f;
  InertializationOffsets offsets;
  offsets.resize(kJoints);
  inertialize_transition(offsets, outgoing.at(0.0f), incoming.at(0.0f));
  const InertializationOffsets initial = offsets;

  std::array<Transform, kJoints> out;
  float time = 0.0f;
  for (int frame = 0; frame < 30; ++frame) {  // 30 frames of 1/60 s = five halflives
    time += 1.0f / 60.0f;
    inertialize_update(offsets, incoming.at(time), halflife, 1.0f / 60.0f, out, {}, {});
  }
  incoming.at(time);
  for (int j = 0; j < kJoints; ++j) {
    const float angle0 = glm::length(initial.rotations[j]);
    const float distance0 = glm::length(initial.positions[j]);
    EXPECT_LT(glm::length(offsets.rotations[j]), 0.01f * angle0) << j;
    EXPECT_LT(glm::length(offsets.positions[j]), 0.01f * distance0) << j;
    // The output is within 1 % of the initial offsets from the incoming animation.
    EXPECT_LT(test::rotation_angle_between(out[j].rotation, incoming.local[j].rotation),
              0.01 * angle0)
        << j;
    EXPECT_LT(glm::distance(out[j].translation, incoming.local[j].translation), 0.01f * distance0)
        << j;
  }
}

// After a long time the offsets are exactly zero (the output is exactly the incoming
// animation), and on the way they follow the spring's exact decay and never become subnormal
// floats, whose arithmetic would slow every later update.
TEST(Inertialization, OffsetsComeToRestExactlyWithoutSubnormals) {
  Animation outgoing = Animation::random();
  Animation incoming = Animation::different_from(outgoing);
  InertializationOffsets offsets;
  offsets.resize(kJoints);
  inertialize_transition(offsets, outgoing.at(0.0f), incoming.at(0.0f));
  const InertializationOffsets initial = offsets;
  // spring.hpp's closed form for an offset decaying toward zero, in double.
  const double w = 1.6783469900166608 / kHalflife;
  auto exact = [&](float x0, float v0, double t) {
    return std::exp(-w * t) * (x0 + (v0 + w * x0) * t);
  };
  std::array<Transform, kJoints> out;
  const float dt = 1.0f / 60.0f;
  for (int frame = 1; frame <= 120 * 60; ++frame) {  // two minutes at 60 Hz
    const double t = frame * static_cast<double>(dt);
    inertialize_update(offsets, incoming.at(static_cast<float>(t)), kHalflife, dt, out, {}, {});
    for (int j = 0; j < kJoints; ++j) {
      ASSERT_TRUE(
          test::no_subnormal(offsets.positions[j]) && test::no_subnormal(offsets.velocities[j]) &&
          test::no_subnormal(offsets.rotations[j]) && test::no_subnormal(offsets.rotation_rates[j]))
          << "frame " << frame << ", joint " << j;
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_NEAR(offsets.positions[j][axis],
                    exact(initial.positions[j][axis], initial.velocities[j][axis], t), 1e-6)
            << "frame " << frame << ", joint " << j;
        ASSERT_NEAR(offsets.rotations[j][axis],
                    exact(initial.rotations[j][axis], initial.rotation_rates[j][axis], t), 1e-6)
            << "frame " << frame << ", joint " << j;
      }
    }
  }
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_EQ(offsets.positions[j], glm::vec3(0.0f)) << j;
    EXPECT_EQ(offsets.velocities[j], glm::vec3(0.0f)) << j;
    EXPECT_EQ(offsets.rotations[j], glm::vec3(0.0f)) << j;
    EXPECT_EQ(offsets.rotation_rates[j], glm::vec3(0.0f)) << j;
    EXPECT_EQ(out[j].translation, incoming.local[j].translation) << j;
  }
}

TEST(Inertialization, FromRestDecayFollowsTheSpringHalflife) {
  // Static poses: the offset from rest halves in one halflife (spring.hpp's definition).
  std::array<Transform, 1> from{}, to{}, out{};
  from[0].rotation = glm::angleAxis(1.2f, glm::vec3(0, 1, 0));
  from[0].translation = {1.0f, 0.0f, 0.0f};
  InertializationOffsets offsets;
  offsets.resize(1);
  inertialize_transition(offsets, PoseMotion{from, {}, {}}, PoseMotion{to, {}, {}});
  inertialize_update(offsets, PoseMotion{to, {}, {}}, 0.25f, 0.25f, out, {}, {});
  EXPECT_NEAR(test::rotation_angle_between(out[0].rotation, to[0].rotation), 0.6, 1e-5);
  EXPECT_NEAR(out[0].translation.x, 0.5f, 1e-5f);
  // Four more halflives: (1 + u) e^-u with u = 5 * 1.678 is 0.21 %.
  inertialize_update(offsets, PoseMotion{to, {}, {}}, 0.25f, 1.0f, out, {}, {});
  EXPECT_LT(out[0].translation.x, 0.0022f);
  EXPECT_GT(out[0].translation.x, 0.0020f);
}

TEST(Inertialization, SameAnimationGivesZeroOffsetsAndClearResets) {
  Animation a = Animation::random();
  InertializationOffsets offsets;
  offsets.resize(kJoints);
  inertialize_transition(offsets, a.at(0.2f), a.at(0.2f));
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_LT(glm::length(offsets.rotations[j]), 1e-6f);
    EXPECT_LT(glm::length(offsets.rotation_rates[j]), 1e-5f);
    EXPECT_EQ(offsets.positions[j], glm::vec3(0.0f));
    EXPECT_EQ(offsets.velocities[j], glm::vec3(0.0f));
  }
  Animation b = Animation::different_from(a);
  inertialize_transition(offsets, a.at(0.2f), b.at(0.2f));
  offsets.clear();
  EXPECT_EQ(offsets.joint_count(), kJoints);
  std::array<Transform, kJoints> out;
  inertialize_update(offsets, b.at(0.2f), kHalflife, 0.0f, out, {}, {});
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_TRUE(same_rotation(out[j].rotation, b.local[j].rotation, 1e-6f));
    EXPECT_EQ(out[j].translation, b.local[j].translation);
  }
}

TEST(RotationVectorJacobian, MatchesFiniteDifferenceAndInverts) {
  for (int i = 0; i < 40; ++i) {
    const glm::vec3 e = test::uniform(0.0f, 3.1f) * test::random_unit_vec3();
    const glm::vec3 rate = test::random_vec3(-2.0f, 2.0f);
    const glm::vec3 w = rotation_vector_rate_to_angular_velocity(e, rate);
    // Angular velocity of exp(e + rate*t) at t = 0 by a central difference of axis-angle turns.
    const float h = 1e-3f;
    const glm::vec3 fd =
        finite_difference_angular_velocity(turn(e - h * rate), turn(e + h * rate), 2.0f * h);
    EXPECT_TRUE(near_vec3(w, fd, 2e-3f)) << i;
    EXPECT_TRUE(near_vec3(angular_velocity_to_rotation_vector_rate(e, w), rate, 1e-4f)) << i;
  }
  // Near zero both are the identity.
  const glm::vec3 r(0.3f, -0.2f, 0.1f);
  EXPECT_TRUE(near_vec3(rotation_vector_rate_to_angular_velocity(glm::vec3(0.0f), r), r, 0.0f));
  EXPECT_TRUE(near_vec3(angular_velocity_to_rotation_vector_rate(glm::vec3(1e-9f), r), r, 1e-7f));
  // At exactly pi the inverse is finite.
  const glm::vec3 at_pi =
      angular_velocity_to_rotation_vector_rate(glm::vec3(0.0f, glm::pi<float>(), 0.0f), r);
  EXPECT_TRUE(finite(at_pi));
}

}  // namespace
}  // namespace mm
