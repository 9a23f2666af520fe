#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/ik.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;

// A leg: pelvis (root of the pose, turned) -> hip -> knee -> ankle -> toe, as local transforms.
struct Leg {
  static constexpr int kPelvis = 0, kHip = 1, kKnee = 2, kAnkle = 3, kToe = 4;
  std::vector<int> parents{-1, 0, 1, 2, 3};
  std::vector<Transform> local;
  std::vector<Transform> global;

  Leg(float upper, float lower, bool randomize) : local(5), global(5) {
    local[kPelvis].translation = {0.0f, 1.0f, 0.0f};
    local[kHip].translation = {0.1f, -0.05f, 0.0f};
    local[kKnee].translation = {0.0f, -upper, 0.0f};
    local[kAnkle].translation = {0.0f, -lower, 0.0f};
    local[kToe].translation = {0.0f, -0.05f, 0.12f};
    if (randomize) {
      local[kPelvis].rotation = test::random_rotation(0.0f, 1.0f);
      local[kHip].rotation = test::random_rotation(0.0f, 1.0f);
      // A knee bent forward a little, about the knee's local x axis.
      local[kKnee].rotation = glm::angleAxis(test::uniform(-1.2f, -0.1f), glm::vec3(1, 0, 0));
    } else {
      local[kKnee].rotation = glm::angleAxis(-0.3f, glm::vec3(1, 0, 0));
    }
    forward_kinematics(parents, local, global);
  }

  TwoBoneIkInput input(const glm::vec3& target, const glm::vec3& pole) const {
    TwoBoneIkInput in;
    in.root = global[kHip];
    in.mid = global[kKnee];
    in.end = global[kAnkle];
    in.root_parent_rotation = global[kPelvis].rotation;
    in.target = target;
    in.pole = pole;
    return in;
  }

  // Applies a result's local rotations and runs FK again: what a caller would see.
  std::vector<Transform> posed(const TwoBoneIkResult& r) const {
    std::vector<Transform> l = local;
    l[kHip].rotation = r.root_local;
    l[kKnee].rotation = r.mid_local;
    std::vector<Transform> g(l.size());
    forward_kinematics(parents, l, g);
    return g;
  }
};

bool finite_result(const TwoBoneIkResult& r) {
  return finite(r.root_local) && finite(r.mid_local) && finite(r.root_global) &&
         finite(r.mid_global) && finite(r.mid_position) && finite(r.end_position);
}

// The distance of the knee from the plane through the hip spanned by `direction` and `pole`,
// and the side of the hip->target line it lies on (positive: the pole's side).
struct KneePlacement {
  float off_plane;
  float pole_side;
};

KneePlacement knee_placement(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& target,
                             const glm::vec3& pole) {
  const glm::vec3 d = glm::normalize(target - hip);
  const glm::vec3 normal = glm::normalize(glm::cross(d, pole));
  const glm::vec3 k = knee - hip;
  const glm::vec3 pole_across = glm::normalize(pole - glm::dot(pole, d) * d);
  return {std::abs(glm::dot(k, normal)), glm::dot(k, pole_across)};
}

TEST(TwoBoneIk, ReachesReachableTargetsAndKeepsLengths) {
  for (int trial = 0; trial < 200; ++trial) {
    const float upper = test::uniform(0.2f, 0.6f);
    const float lower = test::uniform(0.2f, 0.6f);
    const Leg leg(upper, lower, true);
    const glm::vec3 hip = leg.global[Leg::kHip].translation;
    // A target at a reachable distance in a random direction.
    const float lo = std::abs(upper - lower) + 0.01f;
    const float hi = (upper + lower) * 0.99f;
    const glm::vec3 target = hip + test::uniform(lo, hi) * test::random_unit_vec3();
    glm::vec3 pole = test::random_unit_vec3();
    const TwoBoneIkResult r = solve_two_bone_ik(leg.input(target, pole));
    ASSERT_TRUE(finite_result(r));
    EXPECT_TRUE(r.reached);
    EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f)) << trial;

    // Independently, FK of the new local rotations puts the ankle on the target.
    const std::vector<Transform> g = leg.posed(r);
    EXPECT_TRUE(near_vec3(g[Leg::kAnkle].translation, target, 1e-4f)) << trial;
    EXPECT_TRUE(near_vec3(g[Leg::kKnee].translation, r.mid_position, 1e-5f));
    EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kKnee].translation), upper, 1e-5f);
    EXPECT_NEAR(glm::distance(g[Leg::kKnee].translation, g[Leg::kAnkle].translation), lower, 1e-5f);
    // The rest of the leg is untouched: the hip stays, the toe keeps its offset from the ankle.
    EXPECT_TRUE(near_vec3(g[Leg::kHip].translation, hip, 1e-6f));
    EXPECT_NEAR(glm::distance(g[Leg::kAnkle].translation, g[Leg::kToe].translation),
                glm::length(leg.local[Leg::kToe].translation), 1e-5f);

    // The knee lies in the half-plane of the pole (when the pole is not along the limb line).
    const glm::vec3 d = glm::normalize(target - hip);
    if (glm::length(glm::cross(d, pole)) > 0.1f) {
      const KneePlacement k = knee_placement(hip, r.mid_position, target, pole);
      EXPECT_LT(k.off_plane, 1e-4f) << trial;
      EXPECT_GT(k.pole_side, 0.0f) << trial;
    }
  }
}

TEST(TwoBoneIk, KneeFollowsThePole) {
  // The same target with a forward and then a backward pole bends the knee both ways.
  const Leg leg(0.45f, 0.45f, false);
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  const glm::vec3 target = hip + glm::vec3(0.0f, -0.7f, 0.0f);
  for (float side : {1.0f, -1.0f}) {
    const glm::vec3 pole(0.0f, 0.0f, side);
    const TwoBoneIkResult r = solve_two_bone_ik(leg.input(target, pole));
    ASSERT_TRUE(finite_result(r));
    EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f));
    // By hand: an isosceles triangle with legs 0.45 and base 0.7 has its apex
    // sqrt(0.45^2 - 0.35^2) = 0.2828 from the base's midpoint, toward the pole.
    const glm::vec3 expected_knee =
        hip + glm::vec3(0.0f, -0.35f, side * std::sqrt(0.45f * 0.45f - 0.35f * 0.35f));
    EXPECT_TRUE(near_vec3(r.mid_position, expected_knee, 1e-4f)) << side;
  }
}

TEST(TwoBoneIk, UnreachableTargetGivesAStraightLimbTowardIt) {
  for (int trial = 0; trial < 50; ++trial) {
    const float upper = 0.45f, lower = 0.4f;
    const Leg leg(upper, lower, true);
    const glm::vec3 hip = leg.global[Leg::kHip].translation;
    const glm::vec3 direction = test::random_unit_vec3();
    const glm::vec3 target = hip + test::uniform(1.0f, 5.0f) * direction;
    const glm::vec3 pole = test::random_unit_vec3();
    for (float epsilon : {1e-4f, 0.0f}) {
      TwoBoneIkInput in = leg.input(target, pole);
      in.extension_epsilon = epsilon;
      const TwoBoneIkResult r = solve_two_bone_ik(in);
      ASSERT_TRUE(finite_result(r));
      EXPECT_FALSE(r.reached);
      // The ankle is on the line toward the target at the clamped full reach.
      const float reach = (upper + lower) * (1.0f - epsilon);
      EXPECT_TRUE(near_vec3(r.end_position, hip + reach * direction, 1e-4f)) << trial;
      // The knee is (nearly) on that line: straight within the epsilon's small bend.
      const glm::vec3 k = r.mid_position - hip;
      const float off_line = glm::length(k - glm::dot(k, direction) * direction);
      // With epsilon e the apex height is about upper * sqrt(2 e (1 + lower/upper)) ~ 0.6 cm.
      EXPECT_LT(off_line, epsilon > 0.0f ? 0.01f : 1e-3f) << trial;
      const float knee_angle =
          std::acos(std::clamp(glm::dot(glm::normalize(hip - r.mid_position),
                                        glm::normalize(r.end_position - r.mid_position)),
                               -1.0f, 1.0f));
      EXPECT_GT(knee_angle, glm::radians(177.0f)) << trial;
      const std::vector<Transform> g = leg.posed(r);
      EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kKnee].translation), upper, 1e-5f);
      EXPECT_NEAR(glm::distance(g[Leg::kKnee].translation, g[Leg::kAnkle].translation), lower,
                  1e-5f);
    }
  }
}

TEST(TwoBoneIk, TooCloseTargetIsClamped) {
  const float upper = 0.5f, lower = 0.3f;
  const Leg leg(upper, lower, true);
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  const glm::vec3 direction = glm::normalize(glm::vec3(0.2f, -1.0f, 0.3f));
  const TwoBoneIkResult r = solve_two_bone_ik(leg.input(hip + 0.05f * direction, {0, 0, 1}));
  ASSERT_TRUE(finite_result(r));
  EXPECT_FALSE(r.reached);
  const float min_reach = (upper - lower) + 1e-4f * (upper + lower);
  EXPECT_TRUE(near_vec3(r.end_position, hip + min_reach * direction, 1e-4f));
  const std::vector<Transform> g = leg.posed(r);
  EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kKnee].translation), upper, 1e-5f);
  EXPECT_NEAR(glm::distance(g[Leg::kKnee].translation, g[Leg::kAnkle].translation), lower, 1e-5f);
}

TEST(TwoBoneIk, DegenerateInputsNeverGiveNaN) {
  const Leg leg(0.45f, 0.45f, true);
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  // Target exactly at the hip (equal bones: the limb folds almost completely).
  {
    const TwoBoneIkResult r = solve_two_bone_ik(leg.input(hip, {0, 0, 1}));
    ASSERT_TRUE(finite_result(r));
    const std::vector<Transform> g = leg.posed(r);
    EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kKnee].translation), 0.45f, 1e-5f);
    EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kAnkle].translation), 1e-4f * 0.9f,
                1e-4f);
  }
  // Pole along the hip->target line, and a zero pole.
  for (const glm::vec3& pole : {glm::vec3(0, -1, 0), glm::vec3(0.0f)}) {
    const glm::vec3 target = hip + glm::vec3(0.0f, -0.6f, 0.0f);
    const TwoBoneIkResult r = solve_two_bone_ik(leg.input(target, pole));
    ASSERT_TRUE(finite_result(r));
    EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f));
  }
  // Zero-length bones: the input comes back unchanged.
  {
    Leg flat(0.0f, 0.45f, true);
    const TwoBoneIkResult r =
        solve_two_bone_ik(flat.input(hip + glm::vec3(0, -0.3f, 0), {0, 0, 1}));
    ASSERT_TRUE(finite_result(r));
    EXPECT_FALSE(r.reached);
    EXPECT_TRUE(test::same_rotation(r.root_local, flat.local[Leg::kHip].rotation, 1e-6f));
    EXPECT_TRUE(test::same_rotation(r.mid_local, flat.local[Leg::kKnee].rotation, 1e-6f));
    Leg both(0.0f, 0.0f, false);
    ASSERT_TRUE(finite_result(solve_two_bone_ik(both.input(hip, {0, 0, 1}))));
  }
  // Non-finite target: unchanged.
  {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const TwoBoneIkResult r = solve_two_bone_ik(leg.input(glm::vec3(nan, 0, 0), {0, 0, 1}));
    ASSERT_TRUE(finite_result(r));
    EXPECT_TRUE(near_vec3(r.end_position, leg.global[Leg::kAnkle].translation, 0.0f));
  }
}

// Every component the solve reads, made NaN or infinite in turn, leaves the chain as it was; the
// end's rotation and the joints' scales, which it does not read, do not stop it.
TEST(TwoBoneIk, AnyNonFiniteInputComponentLeavesTheChain) {
  Leg leg(0.45f, 0.42f, true);
  const glm::vec3 target = leg.global[Leg::kHip].translation + glm::vec3(0.1f, -0.6f, 0.1f);
  const TwoBoneIkInput good = leg.input(target, {0, 0, 1});
  const auto components = [](TwoBoneIkInput& in) {
    std::vector<float*> c;
    for (glm::quat* q : {&in.root.rotation, &in.mid.rotation, &in.root_parent_rotation}) {
      for (int i = 0; i < 4; ++i) c.push_back(&(*q)[i]);
    }
    for (glm::vec3* v : {&in.root.translation, &in.mid.translation, &in.end.translation, &in.target,
                         &in.pole, &in.hinge}) {
      for (int i = 0; i < 3; ++i) c.push_back(&(*v)[i]);
    }
    c.push_back(&in.extension_epsilon);
    return c;
  };
  const size_t count = [&] {
    TwoBoneIkInput in = good;
    return components(in).size();
  }();
  for (size_t k = 0; k < count; ++k) {
    for (const float bad :
         {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
          -std::numeric_limits<float>::infinity()}) {
      SCOPED_TRACE(testing::Message() << "component " << k << " = " << bad);
      TwoBoneIkInput in = good;
      *components(in)[k] = bad;
      const TwoBoneIkResult r = solve_two_bone_ik(in);
      EXPECT_FALSE(r.reached);
      // The input's own bits (a NaN is not equal to itself).
      EXPECT_EQ(std::memcmp(&r.root_global, &in.root.rotation, sizeof(glm::quat)), 0);
      EXPECT_EQ(std::memcmp(&r.mid_global, &in.mid.rotation, sizeof(glm::quat)), 0);
    }
  }
  TwoBoneIkInput unread = good;
  unread.end.rotation.x = std::numeric_limits<float>::quiet_NaN();
  unread.root.scale.x = unread.mid.scale.x = unread.end.scale.x =
      std::numeric_limits<float>::infinity();
  const TwoBoneIkResult r = solve_two_bone_ik(unread);
  EXPECT_TRUE(r.reached);
  EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f));
}

TEST(TwoBoneIk, StraightStartingLimbBendsTowardThePole) {
  Leg leg(0.45f, 0.45f, false);
  leg.local[Leg::kKnee].rotation = glm::quat(1, 0, 0, 0);  // perfectly straight: no bend plane
  forward_kinematics(leg.parents, leg.local, leg.global);
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  const glm::vec3 target = hip + glm::vec3(0.1f, -0.6f, 0.05f);
  const glm::vec3 pole(1.0f, 0.0f, 0.0f);
  const TwoBoneIkResult r = solve_two_bone_ik(leg.input(target, pole));
  ASSERT_TRUE(finite_result(r));
  EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f));
  const KneePlacement k = knee_placement(hip, r.mid_position, target, pole);
  EXPECT_LT(k.off_plane, 1e-4f);
  EXPECT_GT(k.pole_side, 0.0f);
}

// The angle (radians) of the rotation q.
float rotation_angle(const glm::quat& q) {
  return 2.0f * std::atan2(glm::length(glm::vec3(q.x, q.y, q.z)), std::abs(q.w));
}

// The Leg's knee bends (a negative turn about its local x axis) toward -z, its front here: its
// hinge, bending a positive turn about it, is -x in the knee's frame.
glm::vec3 leg_hinge(const Leg& leg) {
  return leg.global[Leg::kKnee].rotation * glm::vec3(-1.0f, 0.0f, 0.0f);
}

// The knee's offset from the hip-ankle line toward `forward` (positive: bent forward).
float knee_forward(const std::vector<Transform>& g, const glm::vec3& forward) {
  const glm::vec3 hip = g[Leg::kHip].translation;
  const glm::vec3 line = glm::normalize(g[Leg::kAnkle].translation - hip);
  const glm::vec3 k = g[Leg::kKnee].translation - hip;
  return glm::dot(k - glm::dot(k, line) * line, forward);
}

// With its hinge the knee turns about that axis alone, whatever the target: its new local
// rotation is the old one turned about the hinge, the knee stays bent forward, and the pole is
// not read (a pole would twist the leg to its side).
TEST(TwoBoneIk, WithAHingeTheKneeTurnsAboutItAlone) {
  for (int trial = 0; trial < 200; ++trial) {
    const float upper = test::uniform(0.3f, 0.5f);
    const float lower = test::uniform(0.3f, 0.5f);
    const Leg leg(upper, lower, true);
    const glm::vec3 hip = leg.global[Leg::kHip].translation;
    const float lo = std::abs(upper - lower) + 0.05f;
    const float hi = (upper + lower) * 0.99f;
    const glm::vec3 target = hip + test::uniform(lo, hi) * test::random_unit_vec3();
    TwoBoneIkInput in = leg.input(target, test::random_unit_vec3());
    in.hinge = leg_hinge(leg);
    const TwoBoneIkResult r = solve_two_bone_ik(in);
    ASSERT_TRUE(finite_result(r));
    EXPECT_TRUE(r.reached);
    EXPECT_TRUE(near_vec3(r.end_position, target, 1e-4f)) << trial;
    const std::vector<Transform> g = leg.posed(r);
    EXPECT_TRUE(near_vec3(g[Leg::kAnkle].translation, target, 1e-4f)) << trial;
    EXPECT_NEAR(glm::distance(g[Leg::kHip].translation, g[Leg::kKnee].translation), upper, 1e-5f);
    EXPECT_NEAR(glm::distance(g[Leg::kKnee].translation, g[Leg::kAnkle].translation), lower, 1e-5f);
    // The knee's turn, in its parent's frame, is about the local x axis (the hinge).
    const glm::quat turn = r.mid_local * glm::conjugate(leg.local[Leg::kKnee].rotation);
    const glm::vec3 axis(turn.x, turn.y, turn.z);
    EXPECT_LT(std::hypot(axis.y, axis.z), 1e-4f) << trial;
    // Still bent forward: a negative turn about x.
    const glm::quat knee = r.mid_local.w < 0.0f ? -r.mid_local : r.mid_local;
    EXPECT_LT(knee.x, 0.0f) << trial;
    in.pole = -in.pole;
    const TwoBoneIkResult other = solve_two_bone_ik(in);
    EXPECT_EQ(other.root_local, r.root_local) << trial;
    EXPECT_EQ(other.mid_local, r.mid_local) << trial;
  }
}

// A knee overstretched backward (as standing actors' knees are, a few degrees past straight in
// the Bandai data) asked for a slightly shorter leg: with its hinge it unbends through straight
// and bends forward; without one, toward a forward pole. Either way the knee comes forward by
// turning about its hinge, and the thigh turns by what the bend and the ankle's move need (half
// the knee's 37 degrees and the ankle's 2 here). Twisted half a turn about the hip-ankle line
// instead (as the pole's solve did), the thigh and shin turn their fronts backward: a skinned leg
// is wrung at the hip and the ankle.
TEST(TwoBoneIk, AnOverstretchedKneeUnbendsThroughStraight) {
  Leg leg(0.42f, 0.42f, false);
  leg.local[Leg::kKnee].rotation = glm::angleAxis(0.15f, glm::vec3(1, 0, 0));  // past straight
  forward_kinematics(leg.parents, leg.local, leg.global);
  const glm::vec3 forward(0.0f, 0.0f, -1.0f);
  ASSERT_LT(knee_forward(leg.global, forward), -0.03f);  // the knee 3.1 cm behind the line
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  const glm::vec3 ankle = leg.global[Leg::kAnkle].translation;
  const glm::vec3 target = hip + 0.97f * (ankle - hip) + glm::vec3(0.0f, 0.0f, -0.03f);
  for (const bool hinged : {true, false}) {
    SCOPED_TRACE(hinged ? "hinge" : "pole");
    TwoBoneIkInput in = leg.input(target, forward);
    if (hinged) in.hinge = leg_hinge(leg);
    const TwoBoneIkResult r = solve_two_bone_ik(in);
    ASSERT_TRUE(finite_result(r));
    const std::vector<Transform> g = leg.posed(r);
    EXPECT_TRUE(near_vec3(g[Leg::kAnkle].translation, target, 1e-4f));
    EXPECT_GT(knee_forward(g, forward), 0.02f);
    const glm::quat knee_turn = r.mid_local * glm::conjugate(leg.local[Leg::kKnee].rotation);
    EXPECT_LT(std::hypot(knee_turn.y, knee_turn.z), 1e-4f);
    EXPECT_LT(rotation_angle(r.root_local * glm::conjugate(leg.local[Leg::kHip].rotation)),
              glm::radians(25.0f));
  }
}

// The target drawn in from the overstretched knee's full length to a deep bend, 2 mm a step:
// the knee comes forward at the first solve and from there moves a little per step (no turning
// over of the bend on the way), and the thigh's turn grows smoothly.
TEST(TwoBoneIk, AHingedKneeDrawnInBendsContinuously) {
  Leg leg(0.42f, 0.42f, false);
  leg.local[Leg::kKnee].rotation = glm::angleAxis(0.15f, glm::vec3(1, 0, 0));
  forward_kinematics(leg.parents, leg.local, leg.global);
  const glm::vec3 hip = leg.global[Leg::kHip].translation;
  const glm::vec3 down = glm::normalize(leg.global[Leg::kAnkle].translation - hip);
  glm::vec3 previous_knee;
  glm::quat previous_hip;
  for (int step = 0; step <= 200; ++step) {
    const float reach = 0.838f - 0.002f * static_cast<float>(step);  // 83.8 cm to 43.8 cm
    TwoBoneIkInput in = leg.input(hip + reach * down, glm::vec3(0, 0, -1));
    in.hinge = leg_hinge(leg);
    const TwoBoneIkResult r = solve_two_bone_ik(in);
    ASSERT_TRUE(finite_result(r));
    EXPECT_GT(knee_forward(leg.posed(r), glm::vec3(0, 0, -1)), 0.02f) << step;
    if (step > 0) {
      // Near straight the triangle's apex moves 1.2 cm per 2 mm of reach, less after.
      EXPECT_LT(glm::distance(r.mid_position, previous_knee), 0.015f) << step;
      EXPECT_LT(rotation_angle(r.root_local * glm::conjugate(previous_hip)), glm::radians(2.0f))
          << step;
    }
    previous_knee = r.mid_position;
    previous_hip = r.root_local;
  }
}

TEST(TwoBoneIk, ApplyOnAPoseUpdatesLocalsAndGlobals) {
  Leg leg(0.42f, 0.4f, true);
  const glm::vec3 target = leg.global[Leg::kHip].translation + glm::vec3(0.05f, -0.6f, 0.2f);
  std::vector<Transform> local = leg.local;
  std::vector<Transform> global = leg.global;
  const TwoBoneIkResult r = apply_two_bone_ik(leg.parents, local, global, Leg::kHip, Leg::kKnee,
                                              Leg::kAnkle, target, glm::vec3(0, 0, 1));
  EXPECT_TRUE(r.reached);
  EXPECT_TRUE(near_vec3(global[Leg::kAnkle].translation, target, 1e-4f));
  // The globals are exactly the FK of the updated locals.
  std::vector<Transform> fk(local.size());
  forward_kinematics(leg.parents, local, fk);
  for (size_t i = 0; i < fk.size(); ++i) {
    EXPECT_TRUE(near_vec3(global[i].translation, fk[i].translation, 1e-6f)) << i;
  }
  EXPECT_EQ(local[Leg::kPelvis].rotation, leg.local[Leg::kPelvis].rotation);
}

// The same solve as apply_two_bone_ik; every global outside the end's subtree equals its result
// to the bit, and the end's subtree keeps its globals for the caller to refresh. The knee has a
// second child after the ankle's subtree (a knee cap), so the skip has a joint after it.
TEST(TwoBoneIk, ApplyAboveEndRefreshesAllButTheEndsSubtree) {
  const std::vector<int> parents{-1, 0, 1, 2, 3, 2};
  const std::vector<int> subtree_sizes{6, 5, 4, 2, 1, 1};
  Leg leg(0.42f, 0.4f, true);
  std::vector<Transform> local = leg.local;
  local.push_back(Transform{});
  local[5].translation = {0.0f, 0.0f, 0.08f};
  local[5].rotation = test::random_rotation(0.0f, 1.0f);
  std::vector<Transform> before(local.size());
  forward_kinematics(parents, local, before);
  const glm::vec3 target = before[Leg::kHip].translation + glm::vec3(0.05f, -0.6f, 0.2f);
  std::vector<Transform> all_local = local, all = before;
  const TwoBoneIkResult expected = apply_two_bone_ik(parents, all_local, all, Leg::kHip, Leg::kKnee,
                                                     Leg::kAnkle, target, glm::vec3(0, 0, 1));
  std::vector<Transform> above = before;
  const TwoBoneIkResult r =
      apply_two_bone_ik_above_end(parents, subtree_sizes, local, above, Leg::kHip, Leg::kKnee,
                                  Leg::kAnkle, target, glm::vec3(0, 0, 1));
  EXPECT_EQ(r.root_local, expected.root_local);
  EXPECT_EQ(r.mid_local, expected.mid_local);
  for (int i : {Leg::kPelvis, Leg::kHip, Leg::kKnee, 5}) {
    EXPECT_EQ(above[i].translation, all[i].translation) << i;
    EXPECT_EQ(above[i].rotation, all[i].rotation) << i;
  }
  for (int i : {Leg::kAnkle, Leg::kToe}) {
    EXPECT_EQ(above[i].translation, before[i].translation) << i;
    EXPECT_EQ(above[i].rotation, before[i].rotation) << i;
  }
  // The end moved: a skip that refreshed it anyway would fail above.
  EXPECT_NE(all[Leg::kAnkle].translation, before[Leg::kAnkle].translation);
}

}  // namespace
}  // namespace mm
