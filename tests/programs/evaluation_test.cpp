// The evaluation's metrics on synthetic frame sequences whose answer is known by construction:
// a skeleton of a few joints with roles, posed frame by frame, fed to EvaluationAccumulator.

#include "mm/programs/evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <glm/glm.hpp>

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;

// Joint indices of the synthetic skeleton.
enum Joint : int {
  kRoot,
  kLeftUpperLeg,
  kRightUpperLeg,
  kLeftFoot,
  kRightFoot,
  kLeftToe,
  kRightToe,
  kLeftUpperArm,
  kRightUpperArm,
  kHead,
  kJointCount
};

JointRoleIndices synthetic_roles() {
  JointRoleIndices roles;
  roles.hips = kRoot;
  roles.left_upper_leg = kLeftUpperLeg;
  roles.right_upper_leg = kRightUpperLeg;
  roles.left_foot = kLeftFoot;
  roles.right_foot = kRightFoot;
  roles.left_toe = kLeftToe;
  roles.right_toe = kRightToe;
  roles.left_upper_arm = kLeftUpperArm;
  roles.right_upper_arm = kRightUpperArm;
  roles.head = kHead;
  return roles;
}

// The character's left for a body facing `yaw_deg` (yaw 0 faces +Z, whose left is +X).
glm::vec3 left_of(float yaw_deg) {
  const float yaw = glm::radians(yaw_deg);
  return {std::cos(yaw), 0.0f, -std::sin(yaw)};
}

glm::vec3 forward_of(float yaw_deg) {
  const float yaw = glm::radians(yaw_deg);
  return {std::sin(yaw), 0.0f, std::cos(yaw)};
}

// A pose described by what the metrics read.
struct Pose {
  float hips_yaw = 0.0f;   // degrees
  float chest_yaw = 0.0f;  // degrees
  glm::vec3 toe[2] = {{0.1f, 0.1f, 0.15f}, {-0.1f, 0.1f, 0.15f}};
  float foot_yaw[2] = {0.0f, 0.0f};  // degrees: the foot sits behind its toe along this yaw
  // Degrees: the foot-to-toe segment's pitch down from level (about 18 by default); past 90
  // the foot is ahead of its toe.
  float foot_pitch[2] = {18.43f, 18.43f};
  glm::vec3 head{0.0f, 1.6f, 0.0f};
};

std::vector<glm::vec3> joints_of(const Pose& p) {
  std::vector<glm::vec3> j(kJointCount, glm::vec3(0.0f, 1.0f, 0.0f));
  j[kLeftUpperLeg] = glm::vec3(0.0f, 0.9f, 0.0f) + 0.1f * left_of(p.hips_yaw);
  j[kRightUpperLeg] = glm::vec3(0.0f, 0.9f, 0.0f) - 0.1f * left_of(p.hips_yaw);
  j[kLeftUpperArm] = glm::vec3(0.0f, 1.4f, 0.0f) + 0.2f * left_of(p.chest_yaw);
  j[kRightUpperArm] = glm::vec3(0.0f, 1.4f, 0.0f) - 0.2f * left_of(p.chest_yaw);
  for (int side = 0; side < 2; ++side) {
    j[kLeftToe + side] = p.toe[side];
    const float pitch = glm::radians(p.foot_pitch[side]);
    j[kLeftFoot + side] = p.toe[side] - 0.158f * std::cos(pitch) * forward_of(p.foot_yaw[side]) +
                          glm::vec3(0.0f, 0.158f * std::sin(pitch), 0.0f);
  }
  j[kHead] = p.head;
  return j;
}

// Feeds frames to an accumulator over the synthetic skeleton.
struct FrameFeed {
  EvaluationAccumulator accumulator{synthetic_roles(), kJointCount, kDt};
  int frame = 0;

  // A frame with this pose and desired motion (desired velocity in m/s, facing in degrees).
  void add(const Pose& pose, glm::vec3 desired_velocity = glm::vec3(0.0f),
           float desired_yaw_deg = 0.0f) {
    const std::vector<glm::vec3> joints = joints_of(pose);
    EvaluationFrame f;
    f.t = static_cast<float>(frame + 1) * kDt;
    f.desired_velocity = desired_velocity;
    f.desired_yaw = glm::radians(desired_yaw_deg);
    f.joints = joints;
    accumulator.add(f);
    ++frame;
  }
  EvaluationMetrics metrics() const { return accumulator.metrics(); }
};

// Frames relative to a moving origin (a controller's local origin, rebased by whole metres)
// measure exactly as the same frames in world positions: the accumulator shifts its earlier
// frames into each new origin before comparing (rounding by at most a float step of a few
// metres, far below the tolerance; without the shift a rebase would read as a 1 m jump). The
// body moves at 1.4 m/s and the toes, in contact (what the skating metric counts), slide with it
// a little faster.
TEST(Evaluation, FramesRelativeToAMovingOriginMeasureAsWorldFrames) {
  EvaluationAccumulator world(synthetic_roles(), kJointCount, kDt);
  EvaluationAccumulator rebased(synthetic_roles(), kJointCount, kDt);
  glm::dvec3 origin(0.0);
  for (int f = 0; f < 240; ++f) {  // 4 s: the last 2 count as idle (the head's speed)
    const float x = static_cast<float>(f) / 128.0f;
    Pose pose;
    pose.toe[0] = {x, 0.0f, 0.25f};
    pose.toe[1] = {x, 0.0f, -0.25f};
    std::vector<glm::vec3> joints = joints_of(pose);
    for (glm::vec3& j : joints) j.x += 3.0f * x;
    EvaluationFrame frame;
    frame.t = static_cast<float>(f + 1) * kDt;
    frame.contact[0] = frame.contact[1] = true;
    frame.root_position = joints[kRoot];
    frame.sim_position = joints[kRoot] + glm::vec3(0.0f, 0.0f, 0.125f);
    frame.joints = joints;
    world.add(frame);
    // Every 7 frames the origin jumps to the whole metre nearest the root.
    if (f % 7 == 0) origin = glm::dvec3(std::round(frame.root_position.x), 0.0, 0.0);
    std::vector<glm::vec3> local = joints;
    for (glm::vec3& j : local) j -= glm::vec3(origin);
    frame.origin = origin;
    frame.root_position -= glm::vec3(origin);
    frame.sim_position -= glm::vec3(origin);
    frame.joints = local;
    rebased.add(frame);
  }
  const EvaluationMetrics a = world.metrics(), b = rebased.metrics();
  EXPECT_GT(a.foot_skate_cm_s_mean, 100.0);  // the slide is measured at all
  EXPECT_NEAR(b.foot_skate_cm_s_mean, a.foot_skate_cm_s_mean, 1e-3);
  EXPECT_NEAR(b.foot_skate_cm_s_p95, a.foot_skate_cm_s_p95, 1e-3);
  EXPECT_NEAR(b.root_sim_distance_cm_mean, a.root_sim_distance_cm_mean, 1e-3);
  EXPECT_NEAR(b.body_turn_rate_deg_s_max, a.body_turn_rate_deg_s_max, 1e-3);
  EXPECT_NEAR(b.idle_head_speed_cm_s_mean, a.idle_head_speed_cm_s_mean, 1e-3);
}

TEST(Evaluation, BodyTurningAtAConstantRateGivesThatRateAtP99AndMax) {
  // 120 deg/s for 4 s: the hips' yaw wraps past 180 degrees on the way.
  FrameFeed run;
  for (int f = 0; f < 240; ++f) {
    Pose pose;
    pose.hips_yaw = 120.0f * static_cast<float>(f) * kDt;
    run.add(pose);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_NEAR(m.body_turn_rate_deg_s_p99, 120.0, 0.05);
  EXPECT_NEAR(m.body_turn_rate_deg_s_max, 120.0, 0.05);
}

TEST(Evaluation, OneFastFrameIsTheMaximumButNotThe99thPercentile) {
  // 199 rates of 60 deg/s and one step of 10 degrees in a frame (600 deg/s).
  FrameFeed run;
  float yaw = 0.0f;
  for (int f = 0; f < 201; ++f) {
    if (f > 0) yaw += f == 100 ? 10.0f : 1.0f;
    Pose pose;
    pose.hips_yaw = yaw;
    run.add(pose);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_NEAR(m.body_turn_rate_deg_s_p99, 60.0, 0.05);
  EXPECT_NEAR(m.body_turn_rate_deg_s_max, 600.0, 0.1);
}

TEST(Evaluation, PercentilesOfASpreadOfValuesAreWithinTheDocumentedResolution) {
  // Hips' rates of 1, 2, ..., 1000 deg/s, one a frame: by nearest rank the 99th percentile of
  // the 1000 rates is the 990th smallest, 990 deg/s; the histogram is within 0.05 % of it
  // (plus the float error of the yaws, well under 0.01 deg/s).
  FrameFeed run;
  float yaw = 0.0f;
  for (int f = 0; f <= 1000; ++f) {
    // Kept in [-180, 180], where a float resolves the yaw finely enough.
    if (f > 0) yaw = std::remainder(yaw + static_cast<float>(f) * kDt, 360.0f);
    Pose pose;
    pose.hips_yaw = yaw;
    run.add(pose);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_NEAR(m.body_turn_rate_deg_s_p99, 990.0, 990.0 * 0.0005 + 0.01);
  EXPECT_NEAR(m.body_turn_rate_deg_s_max, 1000.0, 0.01);
}

TEST(Evaluation, FootPivotIsTheFootToToeYawRateOfALowSlowToe) {
  // Left: the toe planted at 3 cm while the foot swings around it at 30 deg/s (counted).
  // Right: the same swing at 90 deg/s, first with the toe at 10 cm (too high), then low but
  // sliding at 0.5 m/s (too fast), then low, in place, but bobbing up and down 2 cm a frame
  // (1.2 m/s: too fast, not planted): never counted.
  FrameFeed run;
  const int frames = 120;
  for (int f = 0; f < frames; ++f) {
    const float t = static_cast<float>(f) * kDt;
    Pose pose;
    pose.toe[0] = {0.1f, 0.03f, 0.2f};
    pose.foot_yaw[0] = 30.0f * t;
    pose.foot_yaw[1] = 90.0f * t;
    if (f < frames / 3) {
      pose.toe[1] = glm::vec3(-0.1f, 0.1f, 0.2f);
    } else if (f < 2 * frames / 3) {
      pose.toe[1] = glm::vec3(0.5f * t, 0.02f, 0.2f);
    } else {
      pose.toe[1] = glm::vec3(-0.1f, f % 2 == 0 ? 0.01f : 0.03f, 0.2f);
    }
    run.add(pose);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_NEAR(m.foot_pivot_deg_s_mean, 30.0, 0.05);
  // Low and slow on this and the previous frame: from the third frame on, left foot only.
  EXPECT_EQ(m.foot_pivot_frames, frames - 2);
}

// A foot rising through vertical over a still toe (the end of a push-off): its horizontal part
// shrinks to nothing and its yaw flips by half a turn, which is no pivot. Only the frames
// pitched at most kPivotMaxFootPitchDegrees count, and they do not turn.
TEST(Evaluation, AFootRisingThroughVerticalOverAStillToeIsNoPivot) {
  FrameFeed run;
  const int frames = 31;
  for (int f = 0; f < frames; ++f) {
    Pose pose;
    pose.toe[0] = {0.1f, 0.03f, 0.2f};
    pose.foot_pitch[0] = 20.0f + 3.0f * static_cast<float>(f);  // 20 to 110 degrees
    run.add(pose);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_NEAR(m.foot_pivot_deg_s_mean, 0.0, 1e-3);
  // Pitches 20, 23, ..., 59 are flat enough (frames 0 to 13), counted from the third frame on.
  EXPECT_EQ(m.foot_pivot_frames, 12);
}

TEST(Evaluation, LowestToeHeightIsTheLowestEitherToeReaches) {
  FrameFeed run;
  const float heights[][2] = {{0.05f, 0.04f}, {0.02f, -0.013f}, {0.0f, 0.01f}, {0.03f, 0.03f}};
  for (const auto& h : heights) {
    Pose pose;
    pose.toe[0].y = h[0];
    pose.toe[1].y = h[1];
    run.add(pose);
  }
  EXPECT_NEAR(run.metrics().toe_height_min_cm, -1.3, 1e-4);

  FrameFeed left_lowest;
  Pose pose;
  pose.toe[0].y = 0.007f;
  pose.toe[1].y = 0.02f;
  left_lowest.add(pose);
  EXPECT_NEAR(left_lowest.metrics().toe_height_min_cm, 0.7, 1e-4);
}

// Turns on the spot: the stick released, the desired facing stepped by the right stick.
TEST(Evaluation, AStandTurnThatSettlesGivesItsResponseTime) {
  FrameFeed run;
  Pose pose;
  for (int f = 0; f < 60; ++f) run.add(pose);  // standing, facing 0
  // The facing steps to 90 degrees; the hips follow at 3 degrees a frame (180 deg/s) and are
  // first within 10 degrees at 81 degrees, 27 frames after the step.
  for (int k = 0; k < 120; ++k) {
    pose.hips_yaw = std::min(90.0f, 3.0f * static_cast<float>(k));
    run.add(pose, glm::vec3(0.0f), 90.0f);
  }
  // Walking while the hips spin fast ends the event; its spin is no stand turn.
  for (int k = 0; k < 30; ++k) {
    pose.hips_yaw += 10.0f;
    run.add(pose, glm::vec3(0.0f, 0.0f, 1.0f), 90.0f);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.stand_turns, 1);
  EXPECT_EQ(m.stand_turn_unsettled, 0);
  EXPECT_NEAR(m.stand_turn_response_s, 27.0 * kDt, 1e-6);
  EXPECT_NEAR(m.stand_turn_final_error_deg_mean, 0.0, 1e-3);
  EXPECT_NEAR(m.stand_turn_peak_rate_deg_s_max, 180.0, 0.05);
  EXPECT_NEAR(m.body_turn_rate_deg_s_max, 600.0, 0.1);
}

TEST(Evaluation, AnUnsettledStandTurnCountsItsWholeLengthAndItsFinalError) {
  FrameFeed run;
  Pose pose;
  for (int f = 0; f < 60; ++f) run.add(pose);
  // First event: the facing steps to 50 while the hips face 0; they jump to 45 on the event's
  // 11th frame, 10 frames after its start, and settle there (5 degrees short).
  for (int k = 0; k < 40; ++k) {
    pose.hips_yaw = k >= 10 ? 45.0f : 0.0f;
    run.add(pose, glm::vec3(0.0f), 50.0f);
  }
  // Second event, 40 frames after the first: the facing to -130 (180 degrees away), the hips
  // stay at 45 for 50 frames, then the stick is pushed.
  for (int k = 0; k < 50; ++k) run.add(pose, glm::vec3(0.0f), -130.0f);
  run.add(pose, glm::vec3(0.5f, 0.0f, 0.0f), -130.0f);
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.stand_turns, 2);
  EXPECT_EQ(m.stand_turn_unsettled, 1);
  EXPECT_NEAR(m.stand_turn_response_s, (10.0 + 50.0) / 2.0 * kDt, 1e-6);
  // Errors on the last frames: 5 degrees, then 175.
  EXPECT_NEAR(m.stand_turn_final_error_deg_mean, (5.0 + 175.0) / 2.0, 1e-3);
  // Both lasted at least 40 frames (0.67 s): shorter than kStandTurnJudgeSeconds, so both were
  // cut short and neither is judged by where it ended.
  EXPECT_EQ(m.stand_turn_interrupted, 2);
  EXPECT_EQ(m.stand_turn_final_error_deg_max, 0.0);
  // The hips' one jump, 45 degrees in a frame, is the fastest rate inside an event.
  EXPECT_NEAR(m.stand_turn_peak_rate_deg_s_max, 45.0 / kDt, 0.1);
}

TEST(Evaluation, AStandTurnGivenTimeIsJudgedByWhereItEndedAndAShortOneIsInterrupted) {
  FrameFeed run;
  Pose pose;
  for (int f = 0; f < 60; ++f) run.add(pose);
  // A turn to 90 cut short after 0.5 s by a turn to -90; the hips follow to -82 and stay
  // there for 2 s: the first is interrupted, the second ends 8 degrees off.
  const int half_second = static_cast<int>(0.5f / kDt);
  for (int k = 0; k < half_second; ++k) run.add(pose, glm::vec3(0.0f), 90.0f);
  pose.hips_yaw = -82.0f;
  for (int k = 0; k < 4 * half_second; ++k) run.add(pose, glm::vec3(0.0f), -90.0f);
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.stand_turns, 2);
  EXPECT_EQ(m.stand_turn_interrupted, 1);
  EXPECT_NEAR(m.stand_turn_final_error_deg_max, 8.0, 1e-3);
}

TEST(Evaluation, NoStandTurnWithoutAStandOrForASmallTurn) {
  FrameFeed run;
  Pose pose;
  // Walking (the stick pushed) while the facing jumps: not on the spot.
  for (int f = 0; f < 30; ++f) run.add(pose, glm::vec3(0.0f, 0.0f, 1.0f), 0.0f);
  for (int f = 0; f < 30; ++f) run.add(pose, glm::vec3(1.0f, 0.0f, 0.0f), 90.0f);
  // The stick released at the moment of a turn: the speed 0.1 s earlier was not below 1 cm/s.
  for (int f = 0; f < 30; ++f) run.add(pose, glm::vec3(0.0f), 180.0f);
  // Standing, a 40-degree turn: too small.
  for (int f = 0; f < 30; ++f) run.add(pose, glm::vec3(0.0f), 140.0f);
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.stand_turns, 0);
  EXPECT_EQ(m.stand_turn_unsettled, 0);
  EXPECT_EQ(m.stand_turn_response_s, 0.0);
  EXPECT_EQ(m.stand_turn_final_error_deg_mean, 0.0);
  EXPECT_EQ(m.stand_turn_peak_rate_deg_s_max, 0.0);
}

TEST(Evaluation, StrafeChestErrorIsTheChestsOffsetWhileStrafingSteadily) {
  FrameFeed run;
  Pose pose;
  pose.chest_yaw = 20.0f;
  // Moving along +X (yaw 90) at 1 m/s facing 0 with the chest 20 degrees off: counted once the
  // velocity and the facing have held for 0.5 s (the 30th frame on).
  for (int f = 0; f < 120; ++f) run.add(pose, glm::vec3(1.0f, 0.0f, 0.0f), 0.0f);
  // Moving 30 degrees off the facing: not a strafe.
  pose.chest_yaw = 50.0f;
  for (int f = 0; f < 120; ++f) run.add(pose, 1.0f * forward_of(30.0f), 0.0f);
  // Too slow.
  for (int f = 0; f < 120; ++f) run.add(pose, glm::vec3(0.2f, 0.0f, 0.0f), 0.0f);
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.strafe_chest_frames, 120 - 29);
  EXPECT_NEAR(m.strafe_chest_error_deg_mean, 20.0, 0.01);
}

TEST(Evaluation, StrafeWaitsForTheFacingToHoldToo) {
  FrameFeed run;
  Pose pose;
  pose.chest_yaw = -10.0f;
  // The velocity held from the start; the facing moves by 1.5 degrees a frame for 60 frames
  // (each step beyond the tolerance), then holds at 90 with the chest 10 degrees short of it.
  for (int f = 0; f < 60; ++f) {
    run.add(pose, glm::vec3(0.0f, 0.0f, -1.0f), -1.5f * static_cast<float>(f));
  }
  pose.chest_yaw = 80.0f;
  for (int f = 0; f < 60; ++f) run.add(pose, glm::vec3(0.0f, 0.0f, -1.0f), 90.0f);
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.strafe_chest_frames, 60 - 29);
  EXPECT_NEAR(m.strafe_chest_error_deg_mean, 10.0, 0.01);
}

TEST(Evaluation, IdleHeadSpeedIsTheHeads3DSpeedAfterTwoSecondsStanding) {
  FrameFeed run;
  Pose pose;
  // 2 s standing: the head moves fast, not counted (it is the 120th standing frame that
  // counts first); then it sways at (3, 4, 0) cm/s: 5 cm/s in 3-D.
  for (int f = 0; f < 119; ++f) {
    pose.head += glm::vec3(0.5f, 0.0f, 0.0f) * kDt;
    run.add(pose);
  }
  for (int f = 0; f < 60; ++f) {
    pose.head += glm::vec3(0.03f, 0.04f, 0.0f) * kDt;
    run.add(pose);
  }
  // Walking again: not idle.
  for (int f = 0; f < 30; ++f) {
    pose.head += glm::vec3(1.0f, 0.0f, 0.0f) * kDt;
    run.add(pose, glm::vec3(1.0f, 0.0f, 0.0f), 90.0f);
  }
  const EvaluationMetrics m = run.metrics();
  EXPECT_EQ(m.idle_head_frames, 60);
  EXPECT_NEAR(m.idle_head_speed_cm_s_mean, 5.0, 0.01);

  FrameFeed held;  // a held-frame idle
  for (int f = 0; f < 200; ++f) held.add(Pose{});
  EXPECT_EQ(held.metrics().idle_head_frames, 200 - 119);
  EXPECT_EQ(held.metrics().idle_head_speed_cm_s_mean, 0.0);
}

// The standing keys skip the second after a change of the desired facing, beyond 1 degree.
TEST(Evaluation, StandingKeysWaitASecondAfterTheFacingChanges) {
  for (const float turn : {90.0f, 0.5f}) {
    FrameFeed run;
    EvaluationFrame f;
    Pose pose;
    std::vector<glm::vec3> joints;
    for (int i = 0; i < 300; ++i) {
      pose.toe[0].x += 0.03f * kDt;  // one foot slides at 3 cm/s
      joints = joints_of(pose);
      f.root_position.x += 0.02f * kDt;  // the root drifts at 2 cm/s
      f.desired_yaw = glm::radians(i >= 150 ? turn : 0.0f);
      f.joints = joints;
      run.accumulator.add(f);
    }
    const EvaluationMetrics m = run.metrics();
    // Standing from frame 0: counted from the 60th frame; after the turn, from the 60th frame
    // of the new facing. A half-degree change is no change.
    EXPECT_EQ(m.stand_frames, turn > 1.0f ? (150 - 59) + (300 - 209) : 300 - 59) << turn;
    EXPECT_NEAR(m.stand_root_speed_cm_s_mean, 2.0, 0.01) << turn;
    EXPECT_NEAR(m.stand_foot_speed_cm_s_mean, (3.0 + 0.0) / 2.0, 0.01) << turn;
  }
}

// Two style requests while walking: the first style plays from the request's 4th frame on, the
// second from its 9th; the style response is their mean and the slowest, and style_match the
// share of moving frames whose clip has the requested style.
TEST(Evaluation, StyleResponseIsTheMeanAndTheSlowestOfTheRequests) {
  EvaluationAccumulator accumulator(synthetic_roles(), kJointCount, kDt);
  const std::vector<glm::vec3> joints = joints_of(Pose{});
  for (int i = 0; i < 20; ++i) {
    EvaluationFrame f;
    f.t = static_cast<float>(i + 1) * kDt;
    f.desired_velocity = glm::vec3(0.0f, 0.0f, 1.4f);
    f.joints = joints;
    f.requested_style = i < 10 ? 1 : 2;
    f.clip_style = i < 3 ? 0 : (i < 10 ? 1 : (i < 18 ? 1 : 2));
    accumulator.add(f);
  }
  const EvaluationMetrics m = accumulator.metrics();
  EXPECT_EQ(m.style_requests, 2);
  EXPECT_EQ(m.style_requests_reached, 2);
  EXPECT_NEAR(m.style_response_s, 0.5 * (3.0 + 8.0) * kDt, 1e-6);
  EXPECT_NEAR(m.style_response_s_max, 8.0 * kDt, 1e-6);
  EXPECT_EQ(m.style_frames, 20);
  EXPECT_NEAR(m.style_match, (7.0 + 2.0) / 20.0, 1e-9);
}

// The largest accelerations the transition metric counts, kept for a report: a transition at
// frame 10 opens a 10-frame window; the head raised 1 cm at frame 12 alone accelerates by
// 2 cm / dt^2 there and 1 cm / dt^2 on the frames either side; a larger jolt at frame 40, in no
// window, is not among them.
TEST(Evaluation, TheTransitionReportListsTheLargestAccelerationsInTheWindows) {
  EvaluationAccumulator accumulator(synthetic_roles(), kJointCount, kDt);
  accumulator.keep_transition_samples(3);
  for (int i = 0; i < 60; ++i) {
    Pose pose;
    if (i == 12) pose.head.y += 0.01f;
    if (i == 40) pose.head.y += 0.05f;
    const std::vector<glm::vec3> joints = joints_of(pose);
    EvaluationFrame f;
    f.t = static_cast<float>(i + 1) * kDt;
    f.transition = i == 10;
    f.clip = 3;
    f.frame = 100 + i;
    f.joints = joints;
    accumulator.add(f);
  }
  const std::vector<TransitionSample> top = accumulator.transition_samples();
  ASSERT_EQ(top.size(), 3u);
  EXPECT_EQ(top[0].joint, kHead);
  EXPECT_NEAR(top[0].acceleration, 0.02 / (kDt * kDt), 0.5);
  EXPECT_NEAR(top[0].t, 13.0f * kDt, 1e-6f);
  EXPECT_EQ(top[0].windows, 1);
  EXPECT_EQ(top[0].clip, 3);
  EXPECT_EQ(top[0].frame, 112);
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(top[k].joint, kHead);
    EXPECT_NEAR(top[k].acceleration, 0.01 / (kDt * kDt), 0.5);
    EXPECT_TRUE(top[k].frame == 111 || top[k].frame == 113) << top[k].frame;
  }
  // The transition metric itself counts the window's samples all the same.
  EXPECT_GT(accumulator.metrics().transition_accel_p99, 0.0);
}

// Nothing is kept unless asked for.
TEST(Evaluation, NoTransitionReportUnlessAsked) {
  EvaluationAccumulator accumulator(synthetic_roles(), kJointCount, kDt);
  for (int i = 0; i < 20; ++i) {
    Pose pose;
    if (i == 12) pose.head.y += 0.01f;
    const std::vector<glm::vec3> joints = joints_of(pose);
    EvaluationFrame f;
    f.t = static_cast<float>(i + 1) * kDt;
    f.transition = i == 10;
    f.joints = joints;
    accumulator.add(f);
  }
  EXPECT_TRUE(accumulator.transition_samples().empty());
}

// leg_accel_max reads the legs' joints between transitions: a toe's jolt outside every window is
// the maximum, at its frame; a larger one inside a transition's window, a toe jumping at a
// transition (its second difference centred on the frame before is the transition's too) and
// the head's own are not counted.
TEST(Evaluation, LegAccelerationIsTheLargestLegJointsJoltOutsideTheTransitionsWindows) {
  EvaluationAccumulator accumulator(synthetic_roles(), kJointCount, kDt);
  for (int i = 0; i < 60; ++i) {
    Pose pose;
    if (i == 12) pose.toe[0].y += 0.05f;  // inside the window of the transition at frame 10
    if (i >= 25) pose.toe[0].z += 0.05f;  // a jump at the transition at frame 25
    if (i == 40) pose.toe[1].x += 0.01f;
    if (i == 50) pose.head.y += 0.05f;
    const std::vector<glm::vec3> joints = joints_of(pose);
    EvaluationFrame f;
    f.t = static_cast<float>(i + 1) * kDt;
    f.transition = i == 10 || i == 25;
    f.joints = joints;
    accumulator.add(f);
  }
  const EvaluationMetrics m = accumulator.metrics();
  // The toe and its foot (placed from the toe) move together: 2 cm of second difference.
  EXPECT_NEAR(m.leg_accel_max, 0.02 / (kDt * kDt), 0.5);
  EXPECT_NEAR(m.leg_accel_max_t, 41.0f * kDt, 1e-6f);
}

TEST(Evaluation, NothingMeasuredGivesZeroesAndZeroCounts) {
  EvaluationAccumulator empty(synthetic_roles(), kJointCount, kDt);
  const EvaluationMetrics m = empty.metrics();
  EXPECT_EQ(m.frames, 0);
  EXPECT_EQ(m.body_turn_rate_deg_s_p99, 0.0);
  EXPECT_EQ(m.body_turn_rate_deg_s_max, 0.0);
  EXPECT_EQ(m.foot_pivot_frames, 0);
  EXPECT_EQ(m.stand_turns, 0);
  EXPECT_EQ(m.strafe_chest_frames, 0);
  EXPECT_EQ(m.idle_head_frames, 0);
  EXPECT_EQ(m.toe_height_min_cm, 0.0);
  EXPECT_EQ(m.transitions_per_s, 0.0);
  EXPECT_EQ(m.leg_accel_max, 0.0);
}

}  // namespace
}  // namespace mm
