// The ground metrics (ground_metrics.hpp) on synthetic frames whose answers are known.

#include "mm/programs/ground_metrics.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "analytic_world.hpp"

namespace mm {
namespace {

// Joints: 0 root, 1 hips, 2 left upper leg, 3 left lower leg, 4 left foot, 5 left toe, 6 right
// toe (the right leg has no knee: it never counts as straight).
constexpr float kDt = 0.1f;

JointRoleIndices roles() {
  JointRoleIndices r;
  r.hips = 1;
  r.left_upper_leg = 2;
  r.left_lower_leg = 3;
  r.left_foot = 4;
  r.left_toe = 5;
  r.right_toe = 6;
  return r;
}

// A bent left leg, both toes at `toe_y`, the left toe at x = left_x.
std::vector<glm::vec3> pose(float left_x, float toe_y, float hips_y = 0.9f) {
  return {glm::vec3(0.0f),
          glm::vec3(0.0f, hips_y, 0.0f),
          glm::vec3(0.1f, 0.9f, 0.0f),
          glm::vec3(0.1f, 0.5f, 0.1f),
          glm::vec3(0.1f, 0.1f, 0.0f),
          glm::vec3(left_x, toe_y, 0.1f),
          glm::vec3(-0.1f, toe_y, 0.1f)};
}

TEST(GroundMetrics, GeometricSkatingCountsLowSlowToesWhateverTheirLabels) {
  GroundAccumulator a(roles(), kDt);
  // The left toe slides at 0.2 m/s, 2 cm up, for 10 frames; the right one stands still.
  for (int f = 0; f < 10; ++f) {
    const std::vector<glm::vec3> joints = pose(0.02f * f, 0.02f);
    GroundFrame frame;
    frame.joints = joints;
    a.add(frame);
  }
  // Then the left toe too fast (0.5 m/s) and the right toe too high (7 cm): nothing counts.
  for (int f = 10; f < 15; ++f) {
    const std::vector<glm::vec3> joints = pose(0.2f + 0.05f * (f - 10), 0.07f);
    GroundFrame frame;
    frame.joints = joints;
    a.add(frame);
  }
  const GroundMetrics m = a.metrics();
  // Frames 2..9 have both toes low and slow now and before: 8 samples each.
  EXPECT_EQ(m.foot_skate_geom_frames, 16);
  EXPECT_NEAR(m.foot_skate_geom_cm_s_mean, (8 * 20.0 + 8 * 0.0) / 16, 1e-3);
}

TEST(GroundMetrics, ClearancePenetrationAndFloatAreAgainstTheGroundUnderEachToe) {
  GroundAccumulator a(roles(), kDt);
  const float toe_heights[4] = {0.52f, 0.49f, 0.55f, 0.53f};  // over ground at 0.5
  for (int f = 0; f < 4; ++f) {
    const std::vector<glm::vec3> joints = pose(0.0f, toe_heights[f]);
    GroundFrame frame;
    frame.joints = joints;
    frame.toe_ground[0] = frame.toe_ground[1] = 0.5f;
    frame.contact[0] = f == 2;  // a planted toe 5 cm up: floating
    a.add(frame);
  }
  const GroundMetrics m = a.metrics();
  EXPECT_NEAR(m.toe_clearance_cm_min, -1.0, 1e-3);
  EXPECT_NEAR(m.toe_clearance_cm_p1, -1.0, 0.05);  // nearest rank: the lowest of 4
  EXPECT_NEAR(m.foot_penetration_cm_max, 1.0, 1e-3);
  EXPECT_NEAR(m.foot_penetration_cm_mean, 2.0 / 8.0, 1e-3);  // two toes 1 cm down of 8 samples
  EXPECT_NEAR(m.foot_float_cm_mean, 5.0, 1e-3);
}

// A planted toe's float is against the ground its foot rests on (toe_support), when that is
// higher than the ground under the toe; penetration and clearance stay against the toe's own.
TEST(GroundMetrics, FloatIsAgainstTheGroundTheFootRestsOn) {
  GroundAccumulator a(roles(), kDt);
  const std::vector<glm::vec3> joints = pose(0.0f, 0.24f);
  GroundFrame frame;
  frame.joints = joints;
  frame.toe_ground[0] = frame.toe_ground[1] = 0.0f;  // the floor, a tread's edge beside it
  frame.toe_support[0] = 0.2f;                       // the left foot rests on the tread
  frame.contact[0] = frame.contact[1] = true;
  a.add(frame);
  const GroundMetrics m = a.metrics();
  EXPECT_NEAR(m.foot_float_cm_mean, (4.0 + 24.0) / 2.0, 1e-3);
  EXPECT_NEAR(m.toe_clearance_cm_min, 24.0, 1e-3);
}

// The played clips' own float is taken over the frames the float is (contact on), from the
// playing clip's toe heights; frames that read none are left out.
TEST(GroundMetrics, TheDataFloatIsThePlayedToesOverTheFloatsFrames) {
  GroundAccumulator a(roles(), kDt);
  const std::vector<glm::vec3> joints = pose(0.0f, 0.06f);
  const float played[3] = {0.04f, 0.5f, NAN};  // planted, lifted (label off), none read
  for (int f = 0; f < 3; ++f) {
    GroundFrame frame;
    frame.joints = joints;
    frame.contact[0] = f != 1;
    frame.played_toe[0] = played[f];
    frame.played_toe[1] = 0.03f;  // never planted
    a.add(frame);
  }
  const GroundMetrics m = a.metrics();
  EXPECT_NEAR(m.foot_float_cm_mean, 6.0, 1e-3);
  EXPECT_NEAR(m.foot_float_data_cm_mean, 4.0, 1e-3);
}

GroundHit ground_at(float x, float y, float z, const glm::vec3& normal = {0.0f, 1.0f, 0.0f}) {
  return GroundHit{true, glm::vec3(x, y, z), normal, true};
}

// The ground a foot rests on: an edge under the foot that the toe is above, never the slope it
// stands on, never ground above the toe, never a miss or garbage.
TEST(GroundMetrics, AFootRestsOnAnEdgeUnderItNotOnItsSlope) {
  const GroundHit floor = ground_at(0.0f, 0.0f, 0.0f);
  // Toe 1 cm past a 20 cm tread's edge (z < 0.01 is the tread), the heel on the tread.
  const GroundHit on_tread[4] = {ground_at(0.0f, 0.2f, 0.03f), ground_at(0.0f, 0.2f, 0.07f),
                                 ground_at(0.0f, 0.2f, 0.11f), ground_at(0.0f, 0.2f, 0.15f)};
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, floor, on_tread, 0.24f), 0.2f);
  // The same foot with its toe down on the floor (below the tread): the floor.
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, floor, on_tread, 0.04f), 0.0f);
  // The whole foot over the floor: the floor.
  const GroundHit on_floor[4] = {ground_at(0.0f, 0.0f, -0.03f), ground_at(0.0f, 0.0f, -0.07f),
                                 ground_at(0.0f, 0.0f, -0.11f), ground_at(0.0f, 0.0f, -0.15f)};
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, floor, on_floor, 0.24f), 0.0f);
  // Down a 30 degree slope (the heel uphill, +z rising): the slope is no edge.
  const float rise = std::tan(glm::radians(30.0f));
  const glm::vec3 n = glm::normalize(glm::vec3(0.0f, 1.0f, -rise));
  const GroundHit on_slope[4] = {
      ground_at(0.0f, 0.04f * rise, 0.04f, n), ground_at(0.0f, 0.08f * rise, 0.08f, n),
      ground_at(0.0f, 0.12f * rise, 0.12f, n), ground_at(0.0f, 0.16f * rise, 0.16f, n)};
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, ground_at(0.0f, 0.0f, 0.0f, n), on_slope, 0.2f), 0.0f);
  // Misses and garbage along the foot are ignored; a miss under the toe is level ground there.
  GroundHit garbage[4] = {GroundHit{}, ground_at(0.0f, NAN, 0.1f), ground_at(0.0f, 0.1f, INFINITY),
                          GroundHit{}};
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, floor, garbage, 0.24f), 0.0f);
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, GroundHit{}, on_tread, 0.24f), 0.2f);
  GroundHit bad_normal = floor;
  bad_normal.normal = glm::vec3(NAN);
  EXPECT_FLOAT_EQ(foot_support_height(0.0f, bad_normal, on_tread, 0.24f), 0.2f);
}

// The foot is probed from toe to heel and beside the toe: a foot standing level along a tread's
// side, its toe joint just past the side, rests on the tread with the inside of its foot; a
// whole half-foot past the side, it does not.
TEST(GroundMetrics, AFootRestsOnATreadItsToeIsJustPastTheSideOf) {
  // The tread: x < 0, 36 cm high; the floor elsewhere. The foot points along +z.
  const auto ground = [](const glm::vec3& p) {
    return ground_at(p.x, p.x < 0.0f ? 0.36f : 0.0f, p.z);
  };
  const auto support = [&](float toe_x) {
    const glm::vec3 toe(toe_x, 0.43f, 0.0f), heel(toe_x, 0.48f, -0.15f);
    std::array<GroundHit, kFootSupportProbes> hits;
    const auto points = foot_support_points(toe, heel);
    for (size_t k = 0; k < points.size(); ++k) hits[k] = ground(points[k]);
    const GroundHit under = ground(toe);
    return foot_support_height(under.point.y, under, hits, toe.y);
  };
  EXPECT_FLOAT_EQ(support(0.02f), 0.36f);
  EXPECT_FLOAT_EQ(support(kFootHalfWidth + 0.01f), 0.0f);
  EXPECT_FLOAT_EQ(support(-0.05f), 0.36f);  // on the tread: its own ground
}

// The probe points: evenly from toe to heel, the heel last; then a half-width to each side of
// the toe, across the foot on the level (across x for a foot pointing straight down).
TEST(GroundMetrics, FootSupportPointsRunToTheHeelAndBesideTheToe) {
  const glm::vec3 toe(1.0f, 0.1f, 2.0f), heel(1.0f - 0.12f, 0.2f, 2.0f - 0.16f);
  const auto points = foot_support_points(toe, heel);
  for (int k = 0; k < kFootSupportSamples; ++k) {
    const glm::vec3 expected =
        toe + (heel - toe) * (static_cast<float>(k + 1) / kFootSupportSamples);
    EXPECT_NEAR(glm::length(points[static_cast<size_t>(k)] - expected), 0.0f, 1e-6f) << k;
  }
  const glm::vec3 forward = glm::normalize(glm::vec3(toe.x - heel.x, 0.0f, toe.z - heel.z));
  for (size_t k = kFootSupportSamples; k < kFootSupportSamples + 2; ++k) {
    const glm::vec3 out = points[k] - toe;
    EXPECT_NEAR(glm::length(out), kFootHalfWidth, 1e-6f) << k;
    EXPECT_NEAR(glm::dot(out, forward), 0.0f, 1e-6f) << k;
    EXPECT_FLOAT_EQ(out.y, 0.0f) << k;
  }
  EXPECT_NEAR(glm::length(points[kFootSupportSamples] - points[kFootSupportSamples + 1]),
              2.0f * kFootHalfWidth, 1e-6f);
  // The last, ahead of the toe on the level.
  EXPECT_NEAR(glm::length(points.back() - (toe + kToeReach * forward)), 0.0f, 1e-6f);
  const auto down = foot_support_points(toe, toe + glm::vec3(0.0f, 0.2f, 0.0f));
  EXPECT_NEAR(std::abs(down[kFootSupportSamples].x - toe.x), kFootHalfWidth, 1e-6f);
  EXPECT_FLOAT_EQ(down[kFootSupportSamples].z, toe.z);
  EXPECT_EQ(down.back(), toe);
}

// Ahead of the toe too: a foot facing a riser, its toe joint just before it and above the tread
// beyond, has its toes on that tread's edge (stop-and-go from x = 14.6 on the second course at
// 1/30 s: standing on stairs_down with the toe joint 9 mm before the edge above, the float read
// 22 cm over the tread below); a toe joint a whole toe's length before it does not, nor one below
// the tread's top (its toes against the riser).
TEST(GroundMetrics, AFootRestsOnTheTreadItsToesReachBeforeARiser) {
  // The tread above: z > 0, 16 cm higher than the one below. The foot points along +z.
  const auto ground = [](const glm::vec3& p) {
    return ground_at(p.x, p.z > 0.0f ? 0.32f : 0.16f, p.z);
  };
  const auto support = [&](float toe_z, float toe_y) {
    const glm::vec3 toe(0.0f, toe_y, toe_z), heel(0.0f, toe_y + 0.05f, toe_z - 0.15f);
    std::array<GroundHit, kFootSupportProbes> hits;
    const auto points = foot_support_points(toe, heel);
    for (size_t k = 0; k < points.size(); ++k) hits[k] = ground(points[k]);
    const GroundHit under = ground(toe);
    return foot_support_height(under.point.y, under, hits, toe.y);
  };
  EXPECT_FLOAT_EQ(support(-0.009f, 0.38f), 0.32f);
  EXPECT_FLOAT_EQ(support(-(kToeReach + 0.01f), 0.38f), 0.16f);
  EXPECT_FLOAT_EQ(support(-0.009f, 0.2f), 0.16f);
}

TEST(GroundMetrics, HipsHeightAboveTheirGroundAndVerticalAcceleration) {
  GroundAccumulator a(roles(), kDt);
  // The hips 0.9 m above a ground rising 1 cm a frame, accelerating upward at 2 m/s^2 on top.
  for (int f = 0; f < 20; ++f) {
    const float t = kDt * f;
    const float ground = 0.01f * f;
    const std::vector<glm::vec3> joints = pose(0.0f, 0.02f, ground + 0.9f + 0.5f * 2.0f * t * t);
    GroundFrame frame;
    frame.joints = joints;
    frame.hips_ground = ground;
    a.add(frame);
  }
  const GroundMetrics m = a.metrics();
  EXPECT_NEAR(m.hips_vertical_accel_p99_m_s2, 2.0, 0.01);
  double mean = 0.0, squares = 0.0;
  for (int f = 0; f < 20; ++f) {
    const double h = 100.0 * (0.9 + std::pow(kDt * f, 2));
    mean += h / 20;
    squares += h * h / 20;
  }
  EXPECT_NEAR(m.hips_height_cm_mean, mean, 1e-3);
  EXPECT_NEAR(m.hips_height_cm_std, std::sqrt(squares - mean * mean), 1e-2);
}

TEST(GroundMetrics, StraightKneesWallDepthAndStuckTime) {
  GroundAccumulator a(roles(), kDt);
  for (int f = 0; f < 6; ++f) {
    std::vector<glm::vec3> joints = pose(0.0f, 0.02f);
    if (f < 2) joints[3] = glm::vec3(0.1f, 0.5f, 0.0f);  // hip, knee, ankle in a line
    GroundFrame frame;
    frame.joints = joints;
    frame.wall_depth = 0.01f * f;
    frame.stuck = f >= 3;
    a.add(frame);
  }
  const GroundMetrics m = a.metrics();
  EXPECT_EQ(m.knee_overextension_frames, 2);
  EXPECT_NEAR(m.wall_depth_cm_max, 5.0, 1e-4);
  EXPECT_NEAR(m.stuck_s, 3 * kDt, 1e-6);
}

// A wall whose normal is +x; the stick pushes along it (+z) and a little into it.
TEST(GroundMetrics, HeldAtAWallOnlyWhenItsOwnVelocityAsksToMove) {
  const glm::vec3 normal(1.0f, 0.0f, 0.0f);
  const glm::vec3 push(-0.3f, 0.0f, 1.0f);
  const glm::vec3 fast(0.0f, 0.0f, 0.4f);
  // Snagged: its velocity along the wall is 0.4 m/s through the frame, it moved 1 cm/s.
  EXPECT_TRUE(held_at_wall(true, normal, push, fast, fast, 0.01f));
  // Starting from rest beside the wall: the spring has built 6 cm/s of the 1 m/s asked for, or
  // 15 cm/s at the frame's end but 8 at its start: as slow as in the open, not held.
  const glm::vec3 slow(0.0f, 0.0f, 0.06f);
  EXPECT_FALSE(held_at_wall(true, normal, push, slow, slow, 0.01f));
  EXPECT_FALSE(held_at_wall(true, normal, push, glm::vec3(0.0f, 0.0f, 0.08f),
                            glm::vec3(0.0f, 0.0f, 0.15f), 0.04f));
  // Its velocity points back along the wall (the stick has just turned): not held.
  EXPECT_FALSE(held_at_wall(true, normal, push, -fast, -fast, 0.01f));
  // Moving at kStuckSpeed or faster, not blocked, or no contact normal: not held.
  EXPECT_FALSE(held_at_wall(true, normal, push, fast, fast, kStuckSpeed));
  EXPECT_FALSE(held_at_wall(false, normal, push, fast, fast, 0.01f));
  EXPECT_FALSE(held_at_wall(true, glm::vec3(0.0f), push, fast, fast, 0.01f));
  // Pushed head-on: nothing along the wall to slide by.
  EXPECT_FALSE(held_at_wall(true, normal, glm::vec3(-1.0f, 0.0f, 0.1f), fast, fast, 0.01f));
}

TEST(GroundMetrics, AShiftedFrameIsNotASlide) {
  GroundAccumulator a(roles(), kDt);
  for (int f = 0; f < 6; ++f) {
    // The origin moves by 8 m after frame 2; the toes stand still in the world.
    const float shift = f >= 3 ? 8.0f : 0.0f;
    if (f == 3) a.shift(glm::vec3(8.0f, 0.0f, 0.0f));
    std::vector<glm::vec3> joints = pose(0.3f, 0.02f);
    for (glm::vec3& joint : joints) joint.x -= shift;
    GroundFrame frame;
    frame.joints = joints;
    a.add(frame);
  }
  EXPECT_EQ(a.metrics().foot_skate_geom_frames, 8);
  EXPECT_NEAR(a.metrics().foot_skate_geom_cm_s_mean, 0.0, 1e-3);
}

// The wall depth (WallDepthReader) against analytic boxes: the root on the floor at z = 4.7, a
// box 0.35 m high (a step exactly the default step_height) whose near face is z = 5, 1.2 m deep,
// and a wall 2 m high beside it whose near face is z = 5 too.
TEST(GroundMetrics, AJointIsInAWallByTheNearestFaceItIsBehind) {
  test::AnalyticWorld world;
  world.boxes.push_back(test::AnalyticBox{glm::vec2(0.0f, 5.6f), glm::vec2(0.6f), 0.0f, 0.35f});
  world.boxes.push_back(
      test::AnalyticBox{glm::vec2(2.0f, 5.15f), glm::vec2(1.0f, 0.15f), 0.0f, 2.0f});
  const glm::vec3 root(0.0f, 0.0f, 4.7f);
  WallDepthReader reader(4);
  const auto depth = [&](const glm::vec3& joint, int* deepest = nullptr) {
    const glm::vec3 joints[2] = {glm::vec3(0.0f, 1.0f, 4.7f),
                                 joint};  // the first on the root's line
    return reader.read(world, glm::dvec3(0.0), root, joints, 0.3f, deepest);
  };
  // A foot 5 mm over the box's top, 30 cm past its face: the sweep at its height meets the box's
  // top edge, but the foot is above the box, in nothing.
  EXPECT_EQ(depth({0.0f, 0.355f, 5.3f}), 0.0f);
  // 1 cm below the top, 30 cm past the face: inside by the nearer face, the top.
  EXPECT_NEAR(depth({0.0f, 0.34f, 5.3f}), 0.01f, 1e-4f);
  // A hand 5 cm behind the tall wall's face, 1.2 m up: 80 cm below its top, 5 cm behind its face.
  int deepest = -2;
  EXPECT_NEAR(depth({2.0f, 1.2f, 5.05f}, &deepest), 0.05f, 1e-4f);
  EXPECT_EQ(deepest, 1);
  // On the face itself, in front of it, and lower than `above`: nothing.
  EXPECT_NEAR(depth({2.0f, 1.2f, 5.0f}, &deepest), 0.0f, 1e-4f);
  EXPECT_EQ(deepest, -1);
  EXPECT_EQ(depth({2.0f, 1.2f, 4.9f}), 0.0f);
  EXPECT_EQ(depth({2.0f, 0.25f, 5.05f}), 0.0f);
}

}  // namespace
}  // namespace mm
