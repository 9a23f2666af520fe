#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/interpolation.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;
using test::rotation_angle_between;
using test::same_rotation;

constexpr float kPi = glm::pi<float>();
const glm::vec3 kUp{0.0f, 1.0f, 0.0f};
const glm::vec3 kZ{0.0f, 0.0f, 1.0f};

// ---- log / exp --------------------------------------------------------------------------------

TEST(QuatLogExp, ScaledAngleAxisMatchesAngleAndAxis) {
  for (int i = 0; i < 50; ++i) {
    const float angle = test::uniform(0.0f, 3.1f);
    const glm::vec3 axis = test::random_unit_vec3();
    const glm::vec3 v = quat_to_scaled_angle_axis(glm::angleAxis(angle, axis));
    EXPECT_TRUE(near_vec3(v, angle * axis, 2e-5f)) << "angle " << angle;
    EXPECT_TRUE(same_rotation(quat_from_scaled_angle_axis(angle * axis),
                              glm::angleAxis(angle, axis), 1e-6f));
  }
}

TEST(QuatLogExp, NearIdentityKeepsFirstOrderTerm) {
  // glm::exp/log drop vectors below epsilon; ours must keep a 1e-6 rad rotation exactly.
  for (float angle : {1e-3f, 1e-6f, 1e-9f, 1e-20f}) {
    const glm::quat q(std::cos(0.5f * angle), std::sin(0.5f * angle), 0.0f, 0.0f);
    const glm::vec3 v = quat_to_scaled_angle_axis(q);
    EXPECT_NEAR(v.x, angle, angle * 1e-5f) << angle;
    EXPECT_EQ(v.y, 0.0f);
    const glm::quat back = quat_from_scaled_angle_axis(glm::vec3(angle, 0.0f, 0.0f));
    EXPECT_NEAR(back.x, std::sin(0.5f * angle), angle * 1e-5f) << angle;
    EXPECT_NEAR(back.w, std::cos(0.5f * angle), 1e-7f);
  }
  EXPECT_EQ(quat_log(glm::quat(1.0f, 0.0f, 0.0f, 0.0f)), glm::vec3(0.0f));
  EXPECT_TRUE(same_rotation(quat_exp(glm::vec3(0.0f)), glm::quat(1.0f, 0.0f, 0.0f, 0.0f), 0.0f));
}

TEST(QuatLogExp, SeriesAndTrigonometryAgreeWithDoublePrecision) {
  // Small half angles take Taylor series, larger ones sin/cos/atan2: on both sides of the
  // switch, and across it, both agree with the double-precision functions to float rounding.
  for (int i = 0; i <= 400; ++i) {
    const double half = 1.2 * i / 400.0;
    const glm::vec3 axis = test::random_unit_vec3();
    const glm::vec3 v = static_cast<float>(half) * axis;
    const glm::quat e = quat_exp(v);
    EXPECT_NEAR(e.w, std::cos(half), 2e-7) << half;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(e[k], std::sin(half) * axis[k], 2e-7) << half;
    const glm::quat q(static_cast<float>(std::cos(half)),
                      static_cast<float>(std::sin(half)) * axis);
    const glm::vec3 l = quat_log(q);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(l[k], half * axis[k], 2e-7 + 2e-7 * half) << half;
  }
}

TEST(QuatLogExp, ShortestPathFlipsNegativeW) {
  // 350 degrees about +Y is -10 degrees about +Y.
  const glm::quat q = glm::angleAxis(glm::radians(350.0f), kUp);
  ASSERT_LT(q.w, 0.0f);
  const glm::vec3 v = quat_to_scaled_angle_axis(q);
  EXPECT_TRUE(near_vec3(v, glm::radians(-10.0f) * kUp, 1e-5f));
  EXPECT_GE(quat_abs(q).w, 0.0f);
  // The exact antipode of identity (-1) is identity.
  EXPECT_TRUE(near_vec3(quat_to_scaled_angle_axis(glm::quat(-1.0f, 0.0f, 0.0f, 0.0f)),
                        glm::vec3(0.0f), 0.0f));
}

TEST(QuatBetween, RotatesFromOntoToIncludingOppositeAndZero) {
  for (int i = 0; i < 50; ++i) {
    const glm::vec3 from = test::random_unit_vec3() * test::uniform(0.1f, 3.0f);
    const glm::vec3 to = test::random_unit_vec3() * test::uniform(0.1f, 3.0f);
    const glm::quat q = quat_between(from, to);
    EXPECT_TRUE(near_vec3(q * glm::normalize(from), glm::normalize(to), 1e-5f));
    // The shortest such rotation turns by exactly the angle between the two directions.
    const double angle = std::acos(std::clamp(
        static_cast<double>(glm::dot(glm::normalize(from), glm::normalize(to))), -1.0, 1.0));
    EXPECT_NEAR(rotation_angle_between(glm::quat(1, 0, 0, 0), q), angle, 1e-4);
  }
  const glm::vec3 x(1, 0, 0);
  const glm::quat half = quat_between(x, -x);
  EXPECT_TRUE(near_vec3(half * x, -x, 1e-6f));
  EXPECT_NEAR(glm::length(half), 1.0f, 1e-6f);
  EXPECT_TRUE(same_rotation(quat_between(x, x), glm::quat(1, 0, 0, 0), 0.0f));
  EXPECT_TRUE(same_rotation(quat_between(glm::vec3(0.0f), x), glm::quat(1, 0, 0, 0), 0.0f));
}

// ---- slerp / nlerp ------------------------------------------------------------------------------

TEST(QuatSlerp, ExactEndpoints) {
  for (int i = 0; i < 50; ++i) {
    const glm::quat a = test::random_rotation();
    const glm::quat b = test::random_rotation();
    EXPECT_TRUE(same_rotation(quat_slerp(a, b, 0.0f), a, 1e-6f));
    EXPECT_TRUE(same_rotation(quat_slerp(a, b, 1.0f), b, 2e-6f));
    EXPECT_TRUE(same_rotation(quat_nlerp(a, b, 0.0f), a, 1e-6f));
    EXPECT_TRUE(same_rotation(quat_nlerp(a, b, 1.0f), b, 1e-6f));
  }
}

TEST(QuatSlerp, ConstantAngularSpeedAlongOneGreatCircle) {
  for (int i = 0; i < 30; ++i) {
    const glm::quat a = test::random_rotation();
    const glm::quat b = test::random_rotation();
    const double total = rotation_angle_between(a, b);
    ASSERT_LE(total, kPi + 1e-6);
    const glm::vec3 axis = glm::normalize(quat_to_scaled_angle_axis(glm::conjugate(a) * b));
    glm::quat previous = a;
    for (int k = 1; k <= 10; ++k) {
      const float t = k / 10.0f;
      const glm::quat s = quat_slerp(a, b, t);
      // Equal steps in t give equal angles, and the angle from a grows linearly.
      EXPECT_NEAR(rotation_angle_between(previous, s), total / 10.0, 2e-5) << t;
      EXPECT_NEAR(rotation_angle_between(a, s), t * total, 2e-5) << t;
      // Every sample is a rotation about the same relative axis (one great circle).
      if (t * total > 1e-2) {
        const glm::vec3 step_axis =
            glm::normalize(quat_to_scaled_angle_axis(glm::conjugate(a) * s));
        EXPECT_TRUE(near_vec3(step_axis, axis, 1e-4f));
      }
      previous = s;
    }
  }
}

TEST(QuatSlerp, UnitNormThroughout) {
  for (int i = 0; i < 40; ++i) {
    const glm::quat a = test::random_rotation();
    const glm::quat b = test::random_rotation();
    for (int k = 0; k <= 20; ++k) {
      const float t = k / 20.0f;
      EXPECT_NEAR(glm::length(quat_slerp(a, b, t)), 1.0f, 1e-6f);
      EXPECT_NEAR(glm::length(quat_nlerp(a, b, t)), 1.0f, 1e-6f);
    }
  }
}

TEST(QuatSlerp, TakesTheShortestPath) {
  // Identity to 300 degrees about +Y: the short way is -60 degrees, so the midpoint is -30.
  const glm::quat a(1.0f, 0.0f, 0.0f, 0.0f);
  const glm::quat b = glm::angleAxis(glm::radians(300.0f), kUp);
  const glm::quat expected_mid = glm::angleAxis(glm::radians(-30.0f), kUp);
  EXPECT_TRUE(same_rotation(quat_slerp(a, b, 0.5f), expected_mid, 1e-6f));
  EXPECT_TRUE(same_rotation(quat_nlerp(a, b, 0.5f), expected_mid, 1e-6f));
  // b and -b are the same rotation and give the same path.
  for (int k = 0; k <= 10; ++k) {
    const float t = k / 10.0f;
    EXPECT_TRUE(same_rotation(quat_slerp(a, b, t), quat_slerp(a, -b, t), 1e-6f));
    EXPECT_TRUE(
        same_rotation(quat_slerp(a, b, t), glm::angleAxis(glm::radians(-60.0f * t), kUp), 1e-6f));
  }
}

TEST(QuatSlerp, NearIdentityDoesNotDivideByZero) {
  const glm::quat a(1.0f, 0.0f, 0.0f, 0.0f);
  for (float angle : {1e-4f, 1e-6f, 1e-8f, 0.0f}) {
    const glm::quat b = glm::angleAxis(angle, kZ);
    for (float t : {0.0f, 0.25f, 0.5f, 1.0f}) {
      const glm::quat s = quat_slerp(a, b, t);
      ASSERT_TRUE(finite(s)) << angle << " " << t;
      EXPECT_NEAR(glm::length(s), 1.0f, 1e-6f);
      // The angle still grows linearly: the z component is sin(t * angle / 2).
      EXPECT_NEAR(s.z, std::sin(0.5f * t * angle), 1e-6f * angle + 1e-30f);
    }
  }
  // Two equal, non-trivial rotations.
  const glm::quat q = test::random_rotation();
  EXPECT_TRUE(same_rotation(quat_slerp(q, q, 0.3f), q, 1e-6f));
}

TEST(QuatSlerp, AntipodalInputs) {
  // q and -q are one rotation: every t gives q.
  for (int i = 0; i < 20; ++i) {
    const glm::quat q = test::random_rotation();
    for (float t : {0.0f, 0.3f, 0.5f, 1.0f}) {
      EXPECT_TRUE(same_rotation(quat_slerp(q, -q, t), q, 1e-6f));
      EXPECT_TRUE(same_rotation(quat_nlerp(q, -q, t), q, 1e-6f));
    }
  }
  // Rotations 180 degrees apart: either way is shortest; the path is finite, unit, and the
  // midpoint is 90 degrees from both ends.
  for (int i = 0; i < 20; ++i) {
    const glm::quat a = test::random_rotation();
    const glm::quat b = a * glm::angleAxis(kPi, test::random_unit_vec3());
    for (int k = 0; k <= 10; ++k) {
      const float t = k / 10.0f;
      const glm::quat s = quat_slerp(a, b, t);
      ASSERT_TRUE(finite(s));
      EXPECT_NEAR(glm::length(s), 1.0f, 1e-6f);
      EXPECT_NEAR(rotation_angle_between(a, s), t * kPi, 1e-4) << t;
    }
    const glm::quat n = quat_nlerp(a, b, 0.5f);
    EXPECT_NEAR(rotation_angle_between(a, n), 0.5 * kPi, 1e-4);
    EXPECT_NEAR(rotation_angle_between(b, n), 0.5 * kPi, 1e-4);
  }
}

TEST(QuatNlerp, MatchesClosedFormAndIsNotConstantSpeed) {
  // About one axis, nlerp's angle is 2*atan2(t*sin(d/2), (1-t) + t*cos(d/2)) for a turn d.
  const float d = glm::radians(150.0f);
  const glm::quat a(1.0f, 0.0f, 0.0f, 0.0f);
  const glm::quat b = glm::angleAxis(d, kUp);
  for (int k = 0; k <= 8; ++k) {
    const float t = k / 8.0f;
    const double expected =
        2.0 * std::atan2(t * std::sin(0.5 * d), (1.0 - t) + t * std::cos(0.5 * d));
    EXPECT_NEAR(rotation_angle_between(a, quat_nlerp(a, b, t)), expected, 1e-5) << t;
  }
  // The midpoint bisects, but a quarter of the way is visibly not a quarter of the angle.
  EXPECT_NEAR(rotation_angle_between(a, quat_nlerp(a, b, 0.5f)), 0.5 * d, 1e-5);
  EXPECT_GT(std::abs(rotation_angle_between(a, quat_nlerp(a, b, 0.25f)) - 0.25 * d), 0.05);
}

// ---- dual quaternions ---------------------------------------------------------------------------

TEST(DualQuat, RoundTripsAndTransformsPointsLikeTransform) {
  for (int i = 0; i < 30; ++i) {
    const Transform t = test::random_transform();
    const DualQuat q = dual_quat_from_transform(t);
    const Transform back = dual_quat_to_transform(q);
    EXPECT_TRUE(same_rotation(back.rotation, t.rotation, 1e-6f));
    EXPECT_TRUE(near_vec3(back.translation, t.translation, 1e-5f));
    const glm::vec3 p = test::random_vec3(-1.0f, 1.0f);
    EXPECT_TRUE(near_vec3(dual_quat_transform_point(q, p), transform_point(t, p), 1e-5f));
    // The sign of a dual quaternion does not change the motion.
    EXPECT_TRUE(near_vec3(dual_quat_transform_point(-1.0f * q, p), transform_point(t, p), 1e-5f));
  }
}

TEST(DualQuat, ProductComposesAndConjugateInverts) {
  for (int i = 0; i < 30; ++i) {
    const Transform a = test::random_transform();
    const Transform b = test::random_transform();
    const DualQuat ab = dual_quat_from_transform(a) * dual_quat_from_transform(b);
    const glm::vec3 p = test::random_vec3(-1.0f, 1.0f);
    EXPECT_TRUE(
        near_vec3(dual_quat_transform_point(ab, p), transform_point(compose(a, b), p), 1e-5f));
    const DualQuat identity = dual_quat_conjugate(ab) * ab;
    EXPECT_TRUE(near_vec3(dual_quat_transform_point(identity, p), p, 1e-5f));
  }
}

TEST(DualQuat, NormalizeRestoresUnitAndOrthogonality) {
  const DualQuat a = dual_quat_from_transform(test::random_transform());
  const DualQuat b = dual_quat_from_transform(test::random_transform());
  const DualQuat n = dual_quat_normalize(0.3f * a + 0.7f * b);
  EXPECT_NEAR(glm::length(n.real), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(n.real, n.dual), 0.0f, 1e-6f);
  const DualQuat zero = dual_quat_normalize(0.0f * a);
  EXPECT_TRUE(
      near_vec3(dual_quat_transform_point(zero, glm::vec3(1, 2, 3)), glm::vec3(1, 2, 3), 0.0f));
}

// A screw: turn `angle` about +Z through the point `center`, and slide `slide` along +Z.
Transform screw_motion(float angle, const glm::vec3& center, float slide) {
  Transform t;
  t.rotation = glm::angleAxis(angle, kZ);
  t.translation = center - t.rotation * center + slide * kZ;
  return t;
}

TEST(Sclerp, FollowsTheScrewHelix) {
  // From identity to a quarter turn about the vertical line through (1, 0, 0) with a slide of
  // 1 m: at t the motion is t times the turn and t times the slide, about the same line.
  const glm::vec3 center(1.0f, 0.0f, 0.0f);
  const Transform a;
  const Transform b = screw_motion(0.5f * kPi, center, 1.0f);
  for (int k = 0; k <= 10; ++k) {
    const float t = k / 10.0f;
    const Transform expected = screw_motion(t * 0.5f * kPi, center, t);
    const Transform s = transform_sclerp(a, b, t);
    EXPECT_TRUE(same_rotation(s.rotation, expected.rotation, 1e-6f)) << t;
    EXPECT_TRUE(near_vec3(s.translation, expected.translation, 1e-5f)) << t;
  }
  // The same screw started from an arbitrary frame: sclerp(c*a, c*b) == c * sclerp(a, b).
  const Transform c = test::random_transform();
  for (int k = 0; k <= 4; ++k) {
    const float t = k / 4.0f;
    const Transform lhs = transform_sclerp(compose(c, a), compose(c, b), t);
    const Transform rhs = compose(c, screw_motion(t * 0.5f * kPi, center, t));
    EXPECT_TRUE(same_rotation(lhs.rotation, rhs.rotation, 1e-5f));
    EXPECT_TRUE(near_vec3(lhs.translation, rhs.translation, 2e-5f));
  }
}

TEST(Sclerp, ConstantAngularAndLinearSpeed) {
  for (int i = 0; i < 30; ++i) {
    const Transform a = test::random_transform();
    const Transform b = test::random_transform();
    const glm::vec3 p = test::random_vec3(-1.0f, 1.0f);  // any body point moves on a helix
    const double total_angle = rotation_angle_between(a.rotation, b.rotation);
    std::array<glm::vec3, 11> points;
    std::array<glm::quat, 11> rotations;
    for (int k = 0; k <= 10; ++k) {
      const Transform s = transform_sclerp(a, b, k / 10.0f);
      points[k] = transform_point(s, p);
      rotations[k] = s.rotation;
      EXPECT_NEAR(glm::length(s.rotation), 1.0f, 1e-6f);
    }
    EXPECT_TRUE(near_vec3(points[0], transform_point(a, p), 1e-5f));
    EXPECT_TRUE(near_vec3(points[10], transform_point(b, p), 2e-5f));
    const float chord = glm::distance(points[0], points[1]);
    for (int k = 1; k < 10; ++k) {
      EXPECT_NEAR(glm::distance(points[k], points[k + 1]), chord, 2e-5f + 1e-4f * chord) << k;
      EXPECT_NEAR(rotation_angle_between(rotations[k], rotations[k + 1]), total_angle / 10.0, 2e-5);
    }
  }
}

TEST(Sclerp, PureTranslationIsLinear) {
  Transform a;
  a.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3)));
  a.translation = {1.0f, 2.0f, 3.0f};
  Transform b = a;
  b.translation = {-2.0f, 0.5f, 4.0f};
  for (float tiny : {0.0f, 1e-7f}) {
    b.rotation = a.rotation * glm::angleAxis(tiny, kUp);
    for (int k = 0; k <= 10; ++k) {
      const float t = k / 10.0f;
      const Transform s = transform_sclerp(a, b, t);
      ASSERT_TRUE(finite(s.translation));
      EXPECT_TRUE(near_vec3(s.translation, glm::mix(a.translation, b.translation, t), 1e-5f));
      EXPECT_TRUE(same_rotation(s.rotation, a.rotation, 1e-6f));
    }
  }
}

TEST(Sclerp, AntipodalRotations) {
  // b's rotation is -a's rotation (the same rotation): the motion is a pure translation.
  Transform a;
  a.rotation = glm::angleAxis(1.0f, kUp);
  Transform b;
  b.rotation = -a.rotation;
  b.translation = {2.0f, 0.0f, 0.0f};
  EXPECT_TRUE(near_vec3(transform_sclerp(a, b, 0.5f).translation, glm::vec3(1, 0, 0), 1e-5f));
  EXPECT_TRUE(same_rotation(transform_sclerp(a, b, 0.5f).rotation, a.rotation, 1e-6f));
  // Half a turn about the vertical line through (1,0,0): the midpoint is a quarter turn.
  const glm::vec3 center(1.0f, 0.0f, 0.0f);
  const Transform half_turn = screw_motion(kPi, center, 0.0f);
  const Transform s = transform_sclerp(Transform{}, half_turn, 0.5f);
  ASSERT_TRUE(finite(s.rotation));
  EXPECT_NEAR(rotation_angle_between(glm::quat(1, 0, 0, 0), s.rotation), 0.5 * kPi, 1e-5);
  // Either quarter turn about that line is a valid midpoint; both keep the line fixed.
  EXPECT_TRUE(near_vec3(transform_point(s, center), center, 1e-5f));
}

TEST(TransformSlerp, TranslationAtConstantSpeedAndScaleLerped) {
  Transform a = test::random_transform();
  Transform b = test::random_transform();
  a.scale = glm::vec3(1.0f);
  b.scale = glm::vec3(3.0f);
  const float step = glm::distance(a.translation, b.translation) / 8.0f;
  glm::vec3 previous = a.translation;
  for (int k = 1; k <= 8; ++k) {
    const Transform s = transform_slerp(a, b, k / 8.0f);
    EXPECT_NEAR(glm::distance(previous, s.translation), step, 1e-5f);
    EXPECT_NEAR(s.scale.x, 1.0f + 2.0f * k / 8.0f, 1e-6f);
    previous = s.translation;
  }
  EXPECT_NEAR(transform_sclerp(a, b, 0.5f).scale.y, 2.0f, 1e-6f);
  EXPECT_NEAR(transform_nlerp(a, b, 0.25f).scale.z, 1.5f, 1e-6f);
}

// ---- clip sampling ------------------------------------------------------------------------------

// Three frames of two joints at 0.5 s per frame. Joint 0 turns about +Y by 0, 0.6 and 1.2 rad
// and moves along x to 0, 1 and 3 m; joint 1 turns about +Z by 0, -0.4, 2.0 rad.
struct SmallClip {
  static constexpr int kJoints = 2;
  static constexpr float kFrameTime = 0.5f;
  static constexpr std::array<float, 3> kYaw{0.0f, 0.6f, 1.2f};
  static constexpr std::array<float, 3> kX{0.0f, 1.0f, 3.0f};
  static constexpr std::array<float, 3> kRoll{0.0f, -0.4f, 2.0f};
  std::vector<Transform> frames;

  SmallClip() {
    for (int f = 0; f < 3; ++f) {
      Transform root;
      root.rotation = glm::angleAxis(kYaw[f], kUp);
      root.translation = {kX[f], 1.0f, 0.0f};
      Transform child;
      child.rotation = glm::angleAxis(kRoll[f], kZ);
      child.translation = {0.0f, 0.5f, 0.0f};
      frames.push_back(root);
      frames.push_back(child);
    }
  }

  std::array<Transform, 2> sample(float time, InterpolationMethod method, WrapMode wrap) const {
    std::array<Transform, 2> out;
    sample_pose(frames, kJoints, kFrameTime, time, method, wrap, out);
    return out;
  }
};

TEST(SamplePose, ExactlyOnKeyframesAndClampedOutside) {
  const SmallClip clip;
  for (InterpolationMethod m :
       {InterpolationMethod::Nlerp, InterpolationMethod::Slerp, InterpolationMethod::Sclerp}) {
    for (int f = 0; f < 3; ++f) {
      const auto out = clip.sample(f * SmallClip::kFrameTime, m, WrapMode::Clamp);
      EXPECT_EQ(out[0].rotation, clip.frames[2 * f].rotation);
      EXPECT_EQ(out[0].translation, clip.frames[2 * f].translation);
      EXPECT_EQ(out[1].rotation, clip.frames[2 * f + 1].rotation);
    }
    for (float t : {-0.01f, -100.0f}) {
      const auto out = clip.sample(t, m, WrapMode::Clamp);
      EXPECT_EQ(out[0].translation, clip.frames[0].translation);
      EXPECT_EQ(out[1].rotation, clip.frames[1].rotation);
    }
    for (float t : {1.0001f, 7.0f, 1e9f}) {
      const auto out = clip.sample(t, m, WrapMode::Clamp);
      EXPECT_EQ(out[0].translation, clip.frames[4].translation);
      EXPECT_EQ(out[1].rotation, clip.frames[5].rotation);
    }
    // A non-finite time samples frame 0 instead of producing NaN.
    const auto nan_out = clip.sample(std::numeric_limits<float>::quiet_NaN(), m, WrapMode::Loop);
    EXPECT_EQ(nan_out[0].translation, clip.frames[0].translation);
  }
}

TEST(SamplePose, SlerpBetweenKeyframes) {
  const SmallClip clip;
  // 0.7 s is 40 % of the way from frame 1 (0.5 s) to frame 2 (1.0 s).
  const auto out = clip.sample(0.7f, InterpolationMethod::Slerp, WrapMode::Clamp);
  EXPECT_TRUE(same_rotation(out[0].rotation, glm::angleAxis(0.6f + 0.4f * 0.6f, kUp), 1e-6f));
  EXPECT_TRUE(near_vec3(out[0].translation, glm::vec3(1.0f + 0.4f * 2.0f, 1.0f, 0.0f), 1e-5f));
  EXPECT_TRUE(same_rotation(out[1].rotation, glm::angleAxis(-0.4f + 0.4f * 2.4f, kZ), 1e-6f));
}

TEST(SamplePose, NlerpBetweenKeyframes) {
  const SmallClip clip;
  const float t = 0.4f;  // at 0.7 s
  const auto out = clip.sample(0.7f, InterpolationMethod::Nlerp, WrapMode::Clamp);
  // About one axis nlerp turns by 2*atan2(t*sin(d/2), (1-t) + t*cos(d/2)) from the start.
  const double d = 2.4;
  const double turned = 2.0 * std::atan2(t * std::sin(0.5 * d), (1.0 - t) + t * std::cos(0.5 * d));
  EXPECT_TRUE(same_rotation(out[1].rotation, glm::angleAxis(-0.4f + static_cast<float>(turned), kZ),
                            1e-6f));
  EXPECT_TRUE(near_vec3(out[0].translation, glm::vec3(1.8f, 1.0f, 0.0f), 1e-5f));
}

TEST(SamplePose, SclerpBetweenKeyframesFollowsTheScrew) {
  const SmallClip clip;
  // Joint 0 from frame 1 to frame 2 turns 0.6 rad about +Y while moving 2 m along x: a screw
  // about a vertical line. At 40 % the relative motion is the same screw at 40 % of its angle:
  // its fixed line c satisfies c = R c + p for the full motion, and the partial motion is
  // R(0.4*0.6) about c. Compute c by hand in the horizontal plane.
  const float angle = 0.6f;
  const glm::vec3 p(2.0f, 0.0f, 0.0f);  // relative translation expressed in frame 1
  const glm::quat r_inv = glm::angleAxis(-0.6f, kUp);
  const glm::vec3 rel_translation = r_inv * p;  // frame 1's inverse applied to the displacement
  // Solve (I - R) c = rel_translation for R a rotation by `angle` about +Y (2x2 system in x,z).
  const float cs = std::cos(angle);
  const float sn = std::sin(angle);
  // R about +Y: x' = cs*x + sn*z, z' = -sn*x + cs*z.
  const float a11 = 1.0f - cs, a12 = -sn, a21 = sn, a22 = 1.0f - cs;
  const float det = a11 * a22 - a12 * a21;
  const glm::vec3 c((a22 * rel_translation.x - a12 * rel_translation.z) / det, 0.0f,
                    (-a21 * rel_translation.x + a11 * rel_translation.z) / det);
  Transform partial;
  partial.rotation = glm::angleAxis(0.4f * angle, kUp);
  partial.translation = c - partial.rotation * c;
  const Transform expected = compose(clip.frames[2], partial);
  const auto out = clip.sample(0.7f, InterpolationMethod::Sclerp, WrapMode::Clamp);
  EXPECT_TRUE(same_rotation(out[0].rotation, expected.rotation, 1e-6f));
  EXPECT_TRUE(near_vec3(out[0].translation, expected.translation, 1e-5f));
  // Not a straight line: the screw bulges away from the chord between the two positions.
  EXPECT_GT(std::abs(out[0].translation.z), 1e-3f);
}

TEST(SamplePose, LoopWrapsFromLastFrameToFirst) {
  const SmallClip clip;
  // Period 1.5 s. 1.25 s is half way from frame 2 back to frame 0.
  for (float time : {1.25f, -0.25f, 1.25f + 3.0f, 1.25f - 30.0f}) {
    const auto out = clip.sample(time, InterpolationMethod::Slerp, WrapMode::Loop);
    EXPECT_TRUE(same_rotation(out[0].rotation, glm::angleAxis(0.6f, kUp), 1e-5f)) << time;
    EXPECT_TRUE(near_vec3(out[0].translation, glm::vec3(1.5f, 1.0f, 0.0f), 1e-4f)) << time;
    EXPECT_TRUE(same_rotation(out[1].rotation, glm::angleAxis(1.0f, kZ), 1e-5f)) << time;
  }
  // A whole number of periods lands exactly on frame 0; time 0.25 + 1.5 matches time 0.25.
  const auto at_period = clip.sample(3.0f, InterpolationMethod::Slerp, WrapMode::Loop);
  EXPECT_EQ(at_period[0].translation, clip.frames[0].translation);
  const auto a = clip.sample(0.25f, InterpolationMethod::Nlerp, WrapMode::Loop);
  const auto b = clip.sample(1.75f, InterpolationMethod::Nlerp, WrapMode::Loop);
  EXPECT_TRUE(same_rotation(a[0].rotation, b[0].rotation, 1e-6f));
  EXPECT_TRUE(near_vec3(a[0].translation, glm::vec3(0.5f, 1.0f, 0.0f), 1e-5f));
  // Clamping the same time holds the last frame instead.
  const auto clamped = clip.sample(1.25f, InterpolationMethod::Slerp, WrapMode::Clamp);
  EXPECT_EQ(clamped[0].translation, clip.frames[4].translation);
}

TEST(SamplePose, SingleFrameClip) {
  std::vector<Transform> one(1);
  one[0].translation = {1.0f, 2.0f, 3.0f};
  std::array<Transform, 1> out;
  for (WrapMode w : {WrapMode::Clamp, WrapMode::Loop}) {
    for (float t : {-1.0f, 0.0f, 0.3f, 99.0f}) {
      sample_pose(one, 1, 1.0f / 30.0f, t, InterpolationMethod::Slerp, w, out);
      EXPECT_EQ(out[0].translation, one[0].translation);
    }
  }
}

// ---- Heading -----------------------------------------------------------------------------

TEST(QuatYaw, HeadingOfYawRotationsAndWrapping) {
  for (float yaw : {0.0f, 0.5f, -1.2f, 3.0f, -3.0f}) {
    EXPECT_NEAR(quat_yaw(glm::angleAxis(yaw, kUp)), yaw, 1e-5f) << yaw;
  }
  // A pitch or roll on top of the yaw does not change where the forward axis points on the
  // ground, as long as it does not tip it past vertical.
  const glm::quat tilted = glm::angleAxis(0.7f, kUp) * glm::angleAxis(0.3f, glm::vec3(1, 0, 0));
  EXPECT_NEAR(quat_yaw(tilted), 0.7f, 1e-5f);
  EXPECT_NEAR(wrap_angle(2.0f * kPi + 0.25f), 0.25f, 1e-5f);
  EXPECT_NEAR(wrap_angle(-2.0f * kPi - 0.25f), -0.25f, 1e-5f);
  EXPECT_NEAR(wrap_angle(3.0f * kPi / 2.0f), -kPi / 2.0f, 1e-5f);
  for (float a : {-100.0f, -4.0f, 0.0f, 3.1f, 7.0f, 1e4f}) {
    const float w = wrap_angle(a);
    EXPECT_GE(w, -kPi);
    EXPECT_LT(w, kPi);
    EXPECT_NEAR(std::remainder(a - w, 2.0f * kPi), 0.0f, 1e-2f) << a;
  }
}

// ---- Cubic Hermite -----------------------------------------------------------------------

TEST(TransformHermite, ExactAtTheEndsAndFollowsTheDerivatives) {
  Transform a, b;
  a.rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 0)));
  a.translation = glm::vec3(0.1f, 0.9f, -0.2f);
  const glm::vec3 va(1.0f, 0.2f, 0.0f), wa(0.0f, 2.0f, 0.5f);
  const glm::vec3 wb(0.3f, -1.0f, 0.0f), vb(0.8f, -0.1f, 0.3f);
  const float duration = 1.0f / 30.0f;
  // b is where a moves in one interval at its own rates, so the curve is nearly that motion.
  b.rotation = glm::normalize(quat_from_scaled_angle_axis(wa * duration) * a.rotation);
  b.translation = a.translation + va * duration;
  // b's sign flipped must give the same curve (q and -q are one rotation).
  Transform b_flipped = b;
  b_flipped.rotation = -b.rotation;
  EXPECT_TRUE(same_rotation(transform_hermite(a, va, wa, b, vb, wb, duration, 0.0f).rotation,
                            a.rotation, 1e-6f));
  EXPECT_TRUE(same_rotation(transform_hermite(a, va, wa, b, vb, wb, duration, 1.0f).rotation,
                            b.rotation, 1e-6f));
  EXPECT_TRUE(near_vec3(transform_hermite(a, va, wa, b, vb, wb, duration, 1.0f).translation,
                        b.translation, 1e-6f));
  for (float t : {0.25f, 0.5f, 0.75f}) {
    EXPECT_TRUE(same_rotation(transform_hermite(a, va, wa, b, vb, wb, duration, t).rotation,
                              transform_hermite(a, va, wa, b_flipped, vb, wb, duration, t).rotation,
                              1e-6f));
  }
  // The translation's derivative at the start is the given velocity (not the chord's).
  const float h = 1e-3f;
  const glm::vec3 slope =
      (transform_hermite(a, va, wa, b, vb, wb, duration, h).translation - a.translation) /
      (h * duration);
  EXPECT_TRUE(near_vec3(slope, va, 2e-2f));
  // The rotation's rate at the start is the given angular velocity.
  const glm::quat early = transform_hermite(a, va, wa, b, vb, wb, duration, h).rotation;
  const glm::vec3 rate =
      quat_to_scaled_angle_axis(early * glm::conjugate(a.rotation)) / (h * duration);
  EXPECT_TRUE(near_vec3(rate, wa, 2e-2f));
  // Linear interpolation would have the chord's slope instead: the test tells them apart when
  // the velocity is not the chord's.
  Transform c = b;
  c.translation = a.translation + glm::vec3(0.0f, 0.0f, 0.05f);
  const glm::vec3 other =
      (transform_hermite(a, va, wa, c, vb, wb, duration, h).translation - a.translation) /
      (h * duration);
  EXPECT_TRUE(near_vec3(other, va, 2e-2f));
  EXPECT_FALSE(near_vec3(other, (c.translation - a.translation) / duration, 0.1f));
}

}  // namespace
}  // namespace mm
