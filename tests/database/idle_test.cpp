// Choosing the calmest standing frame and holding it (idle.hpp), on a hand-made database with
// one frame failing each criterion.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "mm/database/idle.hpp"

namespace mm {
namespace {

// ---- A hand-made database ----------------------------------------------------------------------

// Joints: 0 Simulation, 1 Hips, 2 Foot_L, 3 Foot_R, 4 Head, 5 Hand_L, 6 Toes_L (a leaf under
// a foot), 7 HeadTop (a leaf under the head). The only arm end is Hand_L.
constexpr int kJoints = 8;
constexpr int kHips = 1, kFootL = 2, kFootR = 3, kHead = 4, kHand = 5;

// Clip "take" (frames 0-7), its mirrored copy (8-9) and an idle clip (10-11). In the take:
//   0  energy 1: qualifies
//   1  left foot off the ground (energy 0)
//   2  the root moves at 0.06 m/s (energy 0)
//   3  the feet 0.6 m apart (energy 0)
//   4  the hand above the hips (energy 0)
//   5  energy 0.25 (the hips drift over the root): qualifies, the calmest
//   6  energy 0.25 (the hand turns): qualifies, ties with 5
//   7  energy 0.25 plus motion the energy ignores (joint 0 turning, a foot moving relative
//      to the hips): qualifies, ties with 5
// The mirrored copy and the idle clip are perfectly still and would win if searched.
Database hand_made_database() {
  Database db;
  std::vector<Transform> rest(kJoints);
  db.skeleton = Skeleton::create({"Simulation", "Hips", "Foot_L", "Foot_R", "Head", "Hand_L",
                                  "Toes_L", "HeadTop"},
                                 {-1, 0, 1, 1, 1, 1, 2, 4}, rest)
                    .value();
  db.roles.hips = kHips;
  db.roles.left_foot = kFootL;
  db.roles.right_foot = kFootR;
  db.roles.left_toe = 6;
  db.roles.head = kHead;
  db.frame_count = 12;
  const glm::vec3 pose[kJoints] = {{0.0f, 0.0f, 0.0f},   {0.0f, 0.9f, 0.0f}, {0.1f, -0.8f, 0.0f},
                                   {-0.1f, -0.8f, 0.0f}, {0.0f, 0.6f, 0.0f}, {0.2f, -0.1f, 0.0f},
                                   {0.0f, -0.05f, 0.1f}, {0.0f, 0.1f, 0.0f}};
  for (int f = 0; f < db.frame_count; ++f) {
    for (int j = 0; j < kJoints; ++j) {
      // A different facing and place per frame: the criteria must not depend on them.
      db.local_positions.push_back(j == 0 ? glm::vec3(f * 0.5f, 0.0f, -f * 0.25f) : pose[j]);
      db.local_rotations.push_back(j == 0 ? glm::angleAxis(0.3f * f, glm::vec3(0, 1, 0))
                                          : glm::quat(1, 0, 0, 0));
      db.local_velocities.emplace_back(0.0f);
      db.local_angular_velocities.emplace_back(0.0f);
    }
    db.contacts.insert(db.contacts.end(), {1, 1});
  }
  auto at = [&](std::vector<glm::vec3>& v, int f, int j) -> glm::vec3& {
    return v[static_cast<size_t>(f) * kJoints + j];
  };
  at(db.local_angular_velocities, 0, kHead) = {1.0f, 0.0f, 0.0f};
  db.contacts[1 * 2] = 0;
  at(db.local_velocities, 2, 0) = {0.06f, 0.0f, 0.0f};
  at(db.local_positions, 3, kFootL) = {0.5f, -0.8f, 0.0f};
  at(db.local_positions, 4, kHand) = {0.2f, 0.2f, 0.0f};
  at(db.local_velocities, 5, kHips) = {0.0f, 0.0f, -0.5f};
  at(db.local_angular_velocities, 6, kHand) = {0.0f, 0.5f, 0.0f};
  at(db.local_angular_velocities, 7, kHand) = {0.0f, 0.0f, -0.5f};
  at(db.local_angular_velocities, 7, 0) = {0.0f, 10.0f, 0.0f};
  at(db.local_velocities, 7, 0) = {0.0f, 3.0f, 0.0f};  // vertical: not travelling
  at(db.local_velocities, 7, kFootL) = {5.0f, 0.0f, 0.0f};
  db.tag_names = {"idle", "mirrored"};
  db.clips.push_back({"take", 0, 8, 0, false});
  db.clips.push_back({"take_mirror", 8, 10, 0b10, true});
  db.clips.push_back({kIdleClipName, 10, 12, 0b01, false});
  db.frame_clip = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 2, 2};
  return db;
}

TEST(IdleHandMade, TheIdleClipIsNamedAndTagged) {
  Database db = hand_made_database();
  EXPECT_TRUE(is_idle_clip(db, db.clips[2]));
  EXPECT_FALSE(is_idle_clip(db, db.clips[0]));
  EXPECT_EQ(find_idle_clip(db), 2);
  // A source clip called "idle" carries no idle tag.
  db.clips[2].tags = 0;
  EXPECT_FALSE(is_idle_clip(db, db.clips[2]));
  EXPECT_EQ(find_idle_clip(db), -1);
}

TEST(IdleHandMade, EnergyCountsJointTurningAndTheBodyDriftingOverTheRoot) {
  const Database db = hand_made_database();
  EXPECT_DOUBLE_EQ(idle_motion_energy(db, 0), 1.0);
  EXPECT_DOUBLE_EQ(idle_motion_energy(db, 1), 0.0);
  // Exact ties, so that the search's tie rule decides between frames 5, 6 and 7.
  EXPECT_EQ(idle_motion_energy(db, 5), 0.25);
  EXPECT_EQ(idle_motion_energy(db, 6), 0.25);
  // Joint 0's motion and a velocity below the source roots are not counted.
  EXPECT_EQ(idle_motion_energy(db, 7), 0.25);
}

TEST(IdleHandMade, FeetDistanceAndArmEnds) {
  const Database db = hand_made_database();
  EXPECT_NEAR(horizontal_feet_distance(db, 0), 0.2f, 1e-6f);
  EXPECT_NEAR(horizontal_feet_distance(db, 3), 0.6f, 1e-6f);
  EXPECT_EQ(arm_end_joints(db.skeleton, db.roles), std::vector<int>{kHand});
  EXPECT_NEAR(highest_arm_end_over_hips(db, 0), -0.1f, 1e-6f);
  EXPECT_NEAR(highest_arm_end_over_hips(db, 4), 0.2f, 1e-6f);
  // Without a head role the head would pass for a raised hand: no arm ends, no check.
  JointRoleIndices no_head = db.roles;
  no_head.head = -1;
  EXPECT_TRUE(arm_end_joints(db.skeleton, no_head).empty());
  Database headless = db;
  headless.roles.head = -1;
  EXPECT_EQ(highest_arm_end_over_hips(headless, 4), -std::numeric_limits<float>::infinity());
}

TEST(IdleHandMade, EachCriterionRemovesItsFrameAndTheCalmestLowestFrameWins) {
  const Database db = hand_made_database();
  const IdleSourceSearch s = search_idle_source(db);
  EXPECT_EQ(s.on_both_feet, 7);
  EXPECT_EQ(s.slow, 6);
  EXPECT_EQ(s.feet_together, 5);
  EXPECT_EQ(s.arms_down, 4);
  EXPECT_EQ(s.frame, 5);
  EXPECT_EQ(s.energy, 0.25);
  EXPECT_EQ(find_calmest_standing_frame(db), 5);
  EXPECT_EQ(idle_search_failure(s), "");

  // Each threshold, loosened, lets its still frame win.
  IdleCriteria loose_speed;
  loose_speed.max_root_speed = 0.1f;
  EXPECT_EQ(find_calmest_standing_frame(db, loose_speed), 2);
  IdleCriteria loose_feet;
  loose_feet.max_feet_distance = 1.0f;
  EXPECT_EQ(find_calmest_standing_frame(db, loose_feet), 3);
  IdleCriteria loose_arms;
  loose_arms.max_arm_end_over_hips = 0.5f;
  EXPECT_EQ(find_calmest_standing_frame(db, loose_arms), 4);
}

TEST(IdleHandMade, WhyNoFrameQualifies) {
  Database db = hand_made_database();
  IdleCriteria criteria;
  criteria.max_arm_end_over_hips = -0.5f;
  IdleSourceSearch s = search_idle_source(db, criteria);
  EXPECT_EQ(s.frame, -1);
  EXPECT_EQ(idle_search_failure(s, criteria),
            "7 frames stand on both feet, 6 of them with the simulation root slower than 0.05 "
            "m/s, 5 of these with the feet closer than 0.4 m apart, but none with the hands (arm "
            "ends) lower than -0.5 m above the hips");
  criteria.max_feet_distance = 0.1f;
  s = search_idle_source(db, criteria);
  EXPECT_EQ(idle_search_failure(s, criteria),
            "7 frames stand on both feet, 6 of them with the simulation root slower than 0.05 "
            "m/s, but none with the feet closer than 0.1 m apart");
  criteria.max_root_speed = 0.0f;
  s = search_idle_source(db, criteria);
  EXPECT_EQ(idle_search_failure(s, criteria),
            "7 frames stand on both feet but in all of them the simulation root moves at 0 m/s "
            "or faster");
  std::fill(db.contacts.begin(), db.contacts.begin() + 16, uint8_t{0});
  s = search_idle_source(db);
  EXPECT_EQ(s.on_both_feet, 0);
  EXPECT_EQ(idle_search_failure(s), "no frame stands with both feet in contact");
}

TEST(IdleHandMade, FillHoldsTheSourcePoseAtTheOriginWithoutMotion) {
  Database db = hand_made_database();
  const ClipRange idle = db.clips[2];
  fill_idle_clip(db, idle, 7);
  for (int f = idle.start; f < idle.end; ++f) {
    const size_t base = static_cast<size_t>(f) * kJoints;
    EXPECT_EQ(db.local_positions[base], glm::vec3(0.0f));
    EXPECT_EQ(db.local_rotations[base], glm::quat(1, 0, 0, 0));
    for (int j = 1; j < kJoints; ++j) {
      EXPECT_EQ(db.local_positions[base + j], db.local_positions[7 * kJoints + j]) << j;
      EXPECT_EQ(db.local_rotations[base + j], db.local_rotations[7 * kJoints + j]) << j;
    }
    for (int j = 0; j < kJoints; ++j) {
      EXPECT_EQ(db.local_velocities[base + j], glm::vec3(0.0f)) << j;
      EXPECT_EQ(db.local_angular_velocities[base + j], glm::vec3(0.0f)) << j;
    }
    EXPECT_EQ(db.contacts[2 * f], 1);
    EXPECT_EQ(db.contacts[2 * f + 1], 1);
  }
  // The source frame itself is untouched.
  EXPECT_EQ(db.local_velocities[7 * kJoints + kFootL], glm::vec3(5.0f, 0.0f, 0.0f));
}

}  // namespace
}  // namespace mm
