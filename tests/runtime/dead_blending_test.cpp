#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "mm/runtime/dead_blending.hpp"
#include "mm/runtime/inertialization.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/spring.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;
using test::same_rotation;

constexpr int kJoints = 4;
constexpr float kBlendTime = 0.5f;
constexpr float kDecay = 0.1f;

glm::quat turn(const glm::vec3& scaled_axis) {
  const float angle = glm::length(scaled_axis);
  return angle > 0.0f ? glm::angleAxis(angle, scaled_axis / angle) : glm::quat(1, 0, 0, 0);
}

// An animation with analytic motion per joint: rotation exp(t * w) * r0 (parent-frame angular
// velocity w) and position p0 + v t + a t^2 / 2.
struct Animation {
  std::array<glm::vec3, kJoints> w, p0, v, a;
  std::array<glm::quat, kJoints> r0;
  std::array<Transform, kJoints> local;
  std::array<glm::vec3, kJoints> velocities, angular_velocities;

  static Animation random() {
    Animation anim;
    for (int j = 0; j < kJoints; ++j) {
      anim.w[j] = test::random_vec3(-3.0f, 3.0f);
      anim.r0[j] = test::random_rotation();
      anim.p0[j] = test::random_vec3(-0.5f, 0.5f);
      anim.v[j] = test::random_vec3(-2.0f, 2.0f);
      anim.a[j] = test::random_vec3(-3.0f, 3.0f);
    }
    return anim;
  }

  PoseMotion at(float t) {
    for (int j = 0; j < kJoints; ++j) {
      local[j].rotation = turn(t * w[j]) * r0[j];
      local[j].translation = p0[j] + v[j] * t + 0.5f * a[j] * t * t;
      velocities[j] = v[j] + a[j] * t;
      angular_velocities[j] = w[j];
    }
    return {local, velocities, angular_velocities};
  }
};

struct Output {
  std::array<Transform, kJoints> local;
  std::array<glm::vec3, kJoints> velocities, angular_velocities;
};

// The blend's output dt seconds after its time, on a copy of the state.
Output output_after(DeadBlend blend, Animation& incoming, float time, float dt) {
  Output out;
  dead_blend_update(blend, incoming.at(time + dt), kBlendTime, kDecay, dt, out.local,
                    out.velocities, out.angular_velocities);
  return out;
}

// Parent-frame angular velocity taking q0 to q1 in h seconds (second-order accurate).
glm::vec3 finite_difference_angular_velocity(const glm::quat& q0, const glm::quat& q1, float h) {
  glm::quat d = q1 * glm::conjugate(q0);
  if (d.w < 0.0f) d = -d;
  return 2.0f * glm::vec3(d.x, d.y, d.z) / h;
}

constexpr float kDelta = 2e-3f;

// Richardson-extrapolated one-sided derivative at 0 from differences over h and h/2.
glm::vec3 richardson(const glm::vec3& d_h, const glm::vec3& d_half) {
  return 2.0f * d_half - d_h;
}

// The output right after `time` starts from `shown` with `shown`'s velocities, both as reported
// and as the output actually moves.
void expect_continuous(const DeadBlend& blend, Animation& incoming, float time,
                       const Output& shown) {
  const Output at = output_after(blend, incoming, time, 0.0f);
  const Output half = output_after(blend, incoming, time, 0.5f * kDelta);
  const Output full = output_after(blend, incoming, time, kDelta);
  for (int j = 0; j < kJoints; ++j) {
    SCOPED_TRACE("joint " + std::to_string(j));
    EXPECT_TRUE(same_rotation(at.local[j].rotation, shown.local[j].rotation, 2e-6f));
    EXPECT_TRUE(near_vec3(at.local[j].translation, shown.local[j].translation, 1e-5f));
    EXPECT_TRUE(near_vec3(at.velocities[j], shown.velocities[j], 1e-4f));
    EXPECT_TRUE(near_vec3(at.angular_velocities[j], shown.angular_velocities[j], 1e-4f));
    const glm::vec3 v =
        richardson((full.local[j].translation - at.local[j].translation) / kDelta,
                   (half.local[j].translation - at.local[j].translation) / (0.5f * kDelta));
    EXPECT_TRUE(near_vec3(v, shown.velocities[j], 5e-3f));
    const glm::vec3 w = richardson(
        finite_difference_angular_velocity(at.local[j].rotation, full.local[j].rotation, kDelta),
        finite_difference_angular_velocity(at.local[j].rotation, half.local[j].rotation,
                                           0.5f * kDelta));
    EXPECT_TRUE(near_vec3(w, shown.angular_velocities[j], 5e-3f));
  }
}

// The outgoing animation shown as an Output.
Output shown_animation(Animation& anim, float time) {
  anim.at(time);
  return {anim.local, anim.velocities, anim.angular_velocities};
}

// A blend for the test's joints, started from `outgoing` at time t.
DeadBlend started_from(Animation& outgoing, float t, float blend_time = kBlendTime) {
  DeadBlend blend;
  blend.resize(kJoints);
  dead_blend_transition(blend, outgoing.at(t), blend_time);
  return blend;
}

TEST(DeadBlending, ValueAndVelocityContinuousAtTheSwitch) {
  for (int trial = 0; trial < 5; ++trial) {
    Animation outgoing = Animation::random();
    Animation incoming = Animation::random();
    const float t = 0.4f;
    const Output shown = shown_animation(outgoing, t);
    expect_continuous(started_from(outgoing, t), incoming, t, shown);
  }
}

TEST(DeadBlending, TheReportedVelocitiesAreTheOutputsOwnMidBlend) {
  Animation outgoing = Animation::random();
  Animation incoming = Animation::random();
  DeadBlend blend = started_from(outgoing, 0.0f);
  const float t = 0.2f;  // mid-blend, where the weight changes fastest
  std::array<Transform, kJoints> scratch;
  dead_blend_update(blend, incoming.at(t - kDelta), kBlendTime, kDecay, t - kDelta, scratch, {},
                    {});
  const Output before = output_after(blend, incoming, t - kDelta, 0.0f);
  const Output at = output_after(blend, incoming, t - kDelta, kDelta);
  const Output after = output_after(blend, incoming, t - kDelta, 2.0f * kDelta);
  for (int j = 0; j < kJoints; ++j) {
    SCOPED_TRACE("joint " + std::to_string(j));
    const glm::vec3 v = (after.local[j].translation - before.local[j].translation) / (2 * kDelta);
    EXPECT_TRUE(near_vec3(v, at.velocities[j], 1e-2f));
    const glm::vec3 w = finite_difference_angular_velocity(before.local[j].rotation,
                                                           after.local[j].rotation, 2 * kDelta);
    EXPECT_TRUE(near_vec3(w, at.angular_velocities[j], 1e-2f));
  }
}

TEST(DeadBlending, ASwitchDuringABlendStartsFromWhatIsShown) {
  Animation a = Animation::random();
  Animation b = Animation::random();
  Animation c = Animation::random();
  DeadBlend blend = started_from(a, 0.0f);
  std::array<Transform, kJoints> scratch;
  float t = 0.0f;
  for (int f = 0; f < 12; ++f) {  // 0.2 s into the blend a -> b
    t += 1.0f / 60.0f;
    dead_blend_update(blend, b.at(t), kBlendTime, kDecay, 1.0f / 60.0f, scratch, {}, {});
  }
  ASSERT_TRUE(blend.active);
  const Output shown = output_after(blend, b, t, 0.0f);
  dead_blend_transition(blend, b.at(t), kBlendTime);
  expect_continuous(blend, c, t, shown);
}

TEST(DeadBlending, EndsOnTheIncomingAnimationAfterTheBlendTime) {
  Animation a = Animation::random();
  Animation b = Animation::random();
  DeadBlend blend = started_from(a, 0.0f);
  Output out;
  float t = 0.0f;
  bool differed_midway = false;
  for (int f = 0; f < 40; ++f) {  // 0.67 s at 60 Hz
    t += 1.0f / 60.0f;
    dead_blend_update(blend, b.at(t), kBlendTime, kDecay, 1.0f / 60.0f, out.local, out.velocities,
                      out.angular_velocities);
    if (t < kBlendTime) {
      differed_midway =
          differed_midway || glm::length(out.local[0].translation - b.local[0].translation) > 1e-3f;
    }
  }
  EXPECT_TRUE(differed_midway);
  EXPECT_FALSE(blend.active);
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_EQ(out.local[j].translation, b.local[j].translation);
    EXPECT_EQ(out.local[j].rotation, b.local[j].rotation);
    EXPECT_EQ(out.velocities[j], b.velocities[j]);
    EXPECT_EQ(out.angular_velocities[j], b.angular_velocities[j]);
  }
}

TEST(DeadBlending, TheSourceCoastsToRestWithItsVelocitiesExactlyZero) {
  Animation a = Animation::random();
  DeadBlend blend = started_from(a, 0.0f, 100.0f);  // a blend long enough to watch the source
  Animation still = Animation::random();
  std::array<Transform, kJoints> scratch;
  for (int f = 0; f < 600; ++f) {
    dead_blend_update(blend, still.at(0.0f), 100.0f, kDecay, 1.0f / 60.0f, scratch, {}, {});
  }
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_EQ(blend.source_velocity(static_cast<size_t>(j)), glm::vec3(0.0f));
    EXPECT_EQ(blend.source_angular_velocity(static_cast<size_t>(j)), glm::vec3(0.0f));
    // It went no farther than its speed times the decay's mean time (halflife / ln 2).
    EXPECT_LE(
        glm::length(blend.source(static_cast<size_t>(j)).translation - a.local[j].translation),
        glm::length(a.velocities[j]) * kDecay / std::log(2.0f) + 1e-4f);
  }
}

TEST(DeadBlending, TheSameSpanOfTimeGivesTheSamePoseHoweverItIsCut) {
  Animation a = Animation::random();
  Animation b = Animation::random();
  DeadBlend once = started_from(a, 0.0f);
  DeadBlend often = started_from(a, 0.0f);
  Output one, many;
  dead_blend_update(once, b.at(0.3f), kBlendTime, kDecay, 0.3f, one.local, {}, {});
  for (int f = 0; f < 30; ++f) {
    dead_blend_update(often, b.at(0.01f * static_cast<float>(f + 1)), kBlendTime, kDecay, 0.01f,
                      many.local, {}, {});
  }
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_TRUE(near_vec3(one.local[j].translation, many.local[j].translation, 1e-5f));
    EXPECT_TRUE(same_rotation(one.local[j].rotation, many.local[j].rotation, 1e-5f));
  }
}

// Without velocities asked for, the pose is computed four joints at a time; each joint equals the
// one computed with velocities (joint by joint) to the bit, through a whole blend, for joints near
// their incoming pose (the logarithm's and exponential's series) and far from it (their
// trigonometric forms), with a joint count that leaves a remainder after the blocks of four
// (its last group is completed with joints at rest in the lanes).
// The lanes (the pose alone) against blend_joint (the pose with its velocities) for n joints.
void expect_pose_alone_equals_pose_with_velocities(size_t n) {
  SCOPED_TRACE(std::to_string(n) + " joints");
  std::vector<Transform> outgoing(n), incoming(n), pose_alone(n), pose(n);
  std::vector<glm::vec3> out_v(n), out_w(n), in_v(n), in_w(n), v(n), w(n);
  for (size_t j = 0; j < n; ++j) {
    outgoing[j] = test::random_transform(0.5f);
    out_v[j] = test::random_vec3(-2.0f, 2.0f);
    out_w[j] = test::random_vec3(-6.0f, 6.0f);
    incoming[j].rotation = j % 3 == 0 ? test::random_rotation()
                                      : turn(test::random_vec3(-0.2f, 0.2f)) * outgoing[j].rotation;
    incoming[j].translation = test::random_vec3(-0.5f, 0.5f);
    in_v[j] = test::random_vec3(-2.0f, 2.0f);
    in_w[j] = test::random_vec3(-6.0f, 6.0f);
  }
  DeadBlend alone;
  alone.resize(static_cast<int>(n));
  dead_blend_transition(alone, {outgoing, out_v, out_w}, kBlendTime);
  DeadBlend with_velocities = alone;
  int blended = 0;
  for (int step = 0; step < 40; ++step) {
    dead_blend_update(alone, {incoming, in_v, in_w}, kBlendTime, kDecay, 1.0f / 60.0f, pose_alone,
                      {}, {});
    dead_blend_update(with_velocities, {incoming, in_v, in_w}, kBlendTime, kDecay, 1.0f / 60.0f,
                      pose, v, w);
    blended += alone.active ? 1 : 0;
    for (size_t j = 0; j < n; ++j) {
      EXPECT_EQ(pose_alone[j].rotation, pose[j].rotation) << "step " << step << ", joint " << j;
      EXPECT_EQ(pose_alone[j].translation, pose[j].translation)
          << "step " << step << ", joint " << j;
      EXPECT_EQ(pose_alone[j].scale, pose[j].scale);
    }
  }
  EXPECT_GT(blended, 20);
}

// Every count of joints in the last group (a short last group is blended as the four joints
// ending at the last one, straddling two groups of the source), and fewer than four joints.
TEST(DeadBlending, ThePoseAloneEqualsThePoseWithItsVelocitiesToTheBit) {
  for (const size_t n : {1, 2, 3, 4, 5, 6, 7, 8, 9, 22})
    expect_pose_alone_equals_pose_with_velocities(n);
}

// A switch's new source for joint j as blend_joint writes it with its velocities, from the
// blend's state before the switch (the reference the lanes are held to, operation for operation).
struct ShownJoint {
  Transform pose;
  glm::vec3 velocity, angular_velocity;
};

ShownJoint shown_joint(const DeadBlend& before, size_t j, const Transform& in, const glm::vec3& vi,
                       const glm::vec3& wi) {
  const float x = before.time / kBlendTime;
  const float value = x * x * (3.0f - 2.0f * x), rate = 6.0f * x * (1.0f - x) / kBlendTime;
  const Transform s = before.source(j);
  const glm::vec3 vs = before.source_velocity(j), ws = before.source_angular_velocity(j);
  const glm::vec3 d = quat_to_scaled_angle_axis(in.rotation * glm::conjugate(s.rotation));
  const glm::quat partial = quat_from_scaled_angle_axis(value * d);
  ShownJoint out;
  out.pose.rotation = glm::normalize(partial * s.rotation);
  out.pose.translation = glm::mix(s.translation, in.translation, value);
  out.velocity = glm::mix(vs, vi, value) + rate * (in.translation - s.translation);
  const glm::vec3 d_rate =
      angular_velocity_to_rotation_vector_rate(d, wi - quat_from_scaled_angle_axis(d) * ws);
  out.angular_velocity =
      rotation_vector_rate_to_angular_velocity(value * d, rate * d + value * d_rate) + partial * ws;
  return out;
}

// A switch during a blend (in SSE lanes) for n joints: every joint's new source equals
// blend_joint's to the bit, and the last group's lanes past the joints stay at rest.
void expect_switch_equals_blend_joint(size_t n, bool outgoing_velocities) {
  SCOPED_TRACE(std::to_string(n) + " joints");
  std::vector<Transform> first(n), incoming(n), outgoing(n), scratch(n);
  std::vector<glm::vec3> v(n), w(n), out_v(n), out_w(n);
  for (size_t j = 0; j < n; ++j) {
    first[j] = test::random_transform(0.5f);
    incoming[j] = test::random_transform(0.5f);
    // A third of the joints far from the source (the logarithm's general branch).
    outgoing[j].rotation = j % 3 == 0 ? test::random_rotation()
                                      : turn(test::random_vec3(-0.2f, 0.2f)) * incoming[j].rotation;
    outgoing[j].translation = test::random_vec3(-0.5f, 0.5f);
    v[j] = test::random_vec3(-2.0f, 2.0f);
    w[j] = test::random_vec3(-6.0f, 6.0f);
    out_v[j] = outgoing_velocities ? test::random_vec3(-2.0f, 2.0f) : glm::vec3(0.0f);
    out_w[j] = outgoing_velocities ? test::random_vec3(-6.0f, 6.0f) : glm::vec3(0.0f);
  }
  DeadBlend blend;
  blend.resize(static_cast<int>(n));
  dead_blend_transition(blend, {first, v, w}, kBlendTime);
  for (int step = 0; step < 9; ++step) {
    dead_blend_update(blend, {incoming, v, w}, kBlendTime, kDecay, 1.0f / 60.0f, scratch, {}, {});
  }
  ASSERT_TRUE(blend.active);
  const DeadBlend before = blend;
  const PoseMotion motion =
      outgoing_velocities ? PoseMotion{outgoing, out_v, out_w} : PoseMotion{outgoing, {}, {}};
  dead_blend_transition(blend, motion, kBlendTime);
  for (size_t j = 0; j < n; ++j) {
    SCOPED_TRACE("joint " + std::to_string(j));
    const ShownJoint expected = shown_joint(before, j, outgoing[j], out_v[j], out_w[j]);
    EXPECT_EQ(blend.source(j).rotation, expected.pose.rotation);
    EXPECT_EQ(blend.source(j).translation, expected.pose.translation);
    EXPECT_EQ(blend.source_velocity(j), expected.velocity);
    EXPECT_EQ(blend.source_angular_velocity(j), expected.angular_velocity);
  }
  for (size_t j = n; j < 4 * blend.groups.size(); ++j) {
    EXPECT_EQ(blend.source(j).rotation, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
    EXPECT_EQ(blend.source(j).translation, glm::vec3(0.0f));
    EXPECT_EQ(blend.source_velocity(j), glm::vec3(0.0f));
    EXPECT_EQ(blend.source_angular_velocity(j), glm::vec3(0.0f));
  }
}

TEST(DeadBlending, ASwitchDuringABlendEqualsBlendJointToTheBit) {
  for (const size_t n : {1, 3, 4, 5, 6, 7, 8, 22}) {
    expect_switch_equals_blend_joint(n, true);
    expect_switch_equals_blend_joint(n, false);
  }
}

TEST(DeadBlending, BadTimesNeverPoisonTheState) {
  Animation a = Animation::random();
  Animation b = Animation::random();
  DeadBlend blend = started_from(a, 0.0f);
  Output out;
  for (const float dt : {std::nanf(""), -1.0f, INFINITY}) {
    dead_blend_update(blend, b.at(0.0f), kBlendTime, kDecay, dt, out.local, out.velocities,
                      out.angular_velocities);
  }
  for (const float blend_time : {std::nanf(""), -1.0f, 0.0f}) {
    dead_blend_transition(blend, a.at(0.0f), blend_time);
    dead_blend_update(blend, b.at(0.1f), blend_time, kDecay, 0.1f, out.local, out.velocities,
                      out.angular_velocities);
    EXPECT_FALSE(blend.active);  // no length: the incoming pose at once
    EXPECT_EQ(out.local[1].translation, b.local[1].translation);
  }
  dead_blend_transition(blend, a.at(0.0f), kBlendTime);
  dead_blend_update(blend, b.at(0.1f), kBlendTime, std::nanf(""), 0.1f, out.local, out.velocities,
                    out.angular_velocities);
  for (int j = 0; j < kJoints; ++j) {
    EXPECT_TRUE(std::isfinite(glm::length(out.local[j].translation)));
    EXPECT_TRUE(
        std::isfinite(glm::length(glm::vec4(out.local[j].rotation.x, out.local[j].rotation.y,
                                            out.local[j].rotation.z, out.local[j].rotation.w))));
    EXPECT_TRUE(std::isfinite(glm::length(out.velocities[j])));
  }
}

}  // namespace
}  // namespace mm
