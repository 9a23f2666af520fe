// The idle clip: choosing the calmest standing frame and holding it (idle.hpp) on a hand-made
// database with one frame failing each criterion, and the builder's idle clip on an in-memory
// standing clip and on real Bandai clips (a wave and a walk), the choice checked against a
// brute-force search written here.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "database_helpers.hpp"
#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/offline/feature_extraction.hpp"
#include "mm/offline/idle.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

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
DatabaseContents hand_made_database() {
  DatabaseContents db;
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
  return db;
}

TEST(IdleHandMade, TheIdleClipIsNamedAndTagged) {
  DatabaseContents db = hand_made_database();
  EXPECT_TRUE(is_idle_clip(db, db.clips[2]));
  EXPECT_FALSE(is_idle_clip(db, db.clips[0]));
  EXPECT_EQ(find_idle_clip(db), 2);
  // A source clip called "idle" carries no idle tag.
  db.clips[2].tags = 0;
  EXPECT_FALSE(is_idle_clip(db, db.clips[2]));
  EXPECT_EQ(find_idle_clip(db), -1);
}

TEST(IdleHandMade, EnergyCountsJointTurningAndTheBodyDriftingOverTheRoot) {
  const DatabaseContents db = hand_made_database();
  EXPECT_DOUBLE_EQ(idle_motion_energy(db, 0), 1.0);
  EXPECT_DOUBLE_EQ(idle_motion_energy(db, 1), 0.0);
  // Exact ties, so that the search's tie rule decides between frames 5, 6 and 7.
  EXPECT_EQ(idle_motion_energy(db, 5), 0.25);
  EXPECT_EQ(idle_motion_energy(db, 6), 0.25);
  // Joint 0's motion and a velocity below the source roots are not counted.
  EXPECT_EQ(idle_motion_energy(db, 7), 0.25);
}

TEST(IdleHandMade, FeetDistanceAndArmEnds) {
  const DatabaseContents db = hand_made_database();
  EXPECT_NEAR(horizontal_feet_distance(db, 0), 0.2f, 1e-6f);
  EXPECT_NEAR(horizontal_feet_distance(db, 3), 0.6f, 1e-6f);
  EXPECT_EQ(arm_end_joints(db.skeleton, db.roles), std::vector<int>{kHand});
  EXPECT_NEAR(highest_arm_end_over_hips(db, 0), -0.1f, 1e-6f);
  EXPECT_NEAR(highest_arm_end_over_hips(db, 4), 0.2f, 1e-6f);
  // Without a head role the head would pass for a raised hand: no arm ends, no check.
  JointRoleIndices no_head = db.roles;
  no_head.head = -1;
  EXPECT_TRUE(arm_end_joints(db.skeleton, no_head).empty());
  DatabaseContents headless = db;
  headless.roles.head = -1;
  EXPECT_EQ(highest_arm_end_over_hips(headless, 4), -std::numeric_limits<float>::infinity());
}

TEST(IdleHandMade, ArmEndsComeFromTheArmRolesWhenTheMapHasThem) {
  // Leaves that are not arms (ReActIdle's pelvis stubs) are left out once the roles name arms.
  const Skeleton sk =
      Skeleton::create({"Hips", "Stub", "Chest", "Head", "ArmL", "ForeL", "ArmR", "ForeR"},
                       {-1, 0, 0, 2, 2, 4, 2, 6}, std::vector<Transform>(8))
          .value();
  JointRoleIndices roles;
  roles.hips = 0;
  roles.head = 3;
  EXPECT_EQ(arm_end_joints(sk, roles), (std::vector<int>{1, 5, 7}));  // the leaves
  roles.left_lower_arm = 5;
  roles.right_lower_arm = 7;
  EXPECT_EQ(arm_end_joints(sk, roles), (std::vector<int>{5, 7}));
}

TEST(IdleHandMade, EachCriterionRemovesItsFrameAndTheCalmestLowestFrameWins) {
  const DatabaseContents db = hand_made_database();
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
  DatabaseContents db = hand_made_database();
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
  DatabaseContents db = hand_made_database();
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

// ---- The builder's idle clip on real clips -----------------------------------------------------

const char* const kWave = "dataset-2_wave-left-hand_normal_001";
const char* const kWalk = "dataset-2_walk_normal_001";

std::vector<fs::path> wave_and_walk() {
  return {test::clip_path(kWave), test::clip_path(kWalk)};
}

struct Built {
  std::optional<Database> db;
  BuildReport report;
};

// Built once with the default options and shared by the tests that only read it.
const Built& built() {
  static const Built b = [] {
    Built out;
    Result<Database> db = build_database(wave_and_walk(), BuildOptions{}, &out.report);
    EXPECT_TRUE(db) << db.message();
    if (db) out.db.emplace(std::move(db).value());
    return out;
  }();
  return b;
}

using test::has_tag;
constexpr auto globals = test::frame_globals;

// The database frame the report names.
int reported_source_frame(const DatabaseView& db, const BuildReport& report) {
  for (const ClipRange& c : db.clips) {
    if (c.name == report.idle_source_clip) return c.start + report.idle_source_frame;
  }
  return -1;
}

TEST(IdleBuild, OneIdleClipLastWithItsFramesAndTag) {
  const Built& b = built();
  const DatabaseView db = *b.db;
  ASSERT_TRUE(validate_database(db)) << validate_database(db).message();
  ASSERT_EQ(db.clips.size(), 3u);
  EXPECT_EQ(b.report.clips, 3);
  const ClipRange& idle = db.clips[2];
  EXPECT_EQ(idle.name, "idle");
  EXPECT_FALSE(idle.mirrored);
  EXPECT_EQ(idle.start, db.clips[1].end);
  EXPECT_EQ(idle.end, db.frame_count);
  EXPECT_EQ(idle.frame_count(), 90);  // 3 s at 30 Hz
  EXPECT_EQ(b.report.idle_frames, 90);
  EXPECT_TRUE(std::is_sorted(db.tag_names.begin(), db.tag_names.end()));
  EXPECT_NE(std::find(db.tag_names.begin(), db.tag_names.end(), "idle"), db.tag_names.end());
  // The idle tag only, through the same bits as every other tag.
  const std::string idle_names[] = {"idle"};
  EXPECT_EQ(idle.tags, db.tag_mask(idle_names));
  EXPECT_FALSE(has_tag(db, db.clips[0], "idle"));
  EXPECT_FALSE(has_tag(db, db.clips[1], "idle"));
  EXPECT_TRUE(has_tag(db, db.clips[0], "wave-left-hand"));
  EXPECT_TRUE(has_tag(db, db.clips[1], "walk"));
  EXPECT_EQ(find_idle_clip(db), 2);
  for (int f = idle.start; f < idle.end; ++f) EXPECT_EQ(db.frame_clip[f], 2);
  for (const std::string& w : b.report.warnings) EXPECT_EQ(w.find("idle"), std::string::npos) << w;
}

TEST(IdleBuild, EveryFrameHoldsTheSourcePoseStillAtTheOrigin) {
  const Built& b = built();
  const DatabaseView db = *b.db;
  const ClipRange& idle = db.clips[2];
  const int source = reported_source_frame(db, b.report);
  ASSERT_GE(source, 0) << b.report.idle_source_clip;
  ASSERT_LT(source, idle.start);
  EXPECT_EQ(db.frame_clip[source], b.report.idle_source_clip == kWave ? 0 : 1);
  const size_t joints = static_cast<size_t>(db.joint_count());
  for (int f = idle.start; f < idle.end; ++f) {
    const size_t base = static_cast<size_t>(f) * joints;
    ASSERT_EQ(db.local_positions[base], glm::vec3(0.0f)) << f;
    ASSERT_EQ(db.local_rotations[base], glm::quat(1, 0, 0, 0)) << f;
    for (size_t j = 1; j < joints; ++j) {
      ASSERT_EQ(db.local_positions[base + j], db.local_positions[source * joints + j]) << f;
      ASSERT_EQ(db.local_rotations[base + j], db.local_rotations[source * joints + j]) << f;
    }
    for (size_t j = 0; j < joints; ++j) {
      ASSERT_EQ(db.local_velocities[base + j], glm::vec3(0.0f)) << f << " " << j;
      ASSERT_EQ(db.local_angular_velocities[base + j], glm::vec3(0.0f)) << f << " " << j;
    }
    ASSERT_EQ(db.contacts[2 * f], 1);
    ASSERT_EQ(db.contacts[2 * f + 1], 1);
  }
}

TEST(IdleBuild, FeaturesStandStillAndTheFramesAreSearchable) {
  const Built& b = built();
  const DatabaseView db = *b.db;
  const ClipRange& idle = db.clips[2];
  // The default schema looks 1 s (30 frames) ahead: all but the last 30 frames are searchable.
  for (int f = idle.start; f < idle.end; ++f) {
    EXPECT_EQ(db.searchable[f], f < idle.end - 30 ? 1 : 0) << f;
  }
  const size_t dims = static_cast<size_t>(db.feature_dims());
  std::vector<float> raw(db.features.begin(), db.features.end());
  denormalize_features(raw, db.feature_offset, db.feature_scale);
  const int source = reported_source_frame(db, b.report);
  const float* held = raw.data() + static_cast<size_t>(source) * dims;
  for (int f = idle.start; f < idle.end; ++f) {
    const float* row = raw.data() + static_cast<size_t>(f) * dims;
    // The normalized rows are identical, bit for bit.
    ASSERT_TRUE(std::equal(db.feature_row(f).begin(), db.feature_row(f).end(),
                           db.feature_row(idle.start).begin()))
        << f;
    for (size_t c = 0; c < db.schema.channels.size(); ++c) {
      const FeatureChannel& channel = db.schema.channels[c];
      const int first = db.schema.offset(static_cast<int>(c));
      for (int k = 0; k < channel.dims(); ++k) {
        const float x = row[first + k];
        switch (channel.kind) {
          case FeatureKind::BoneVelocity:
          case FeatureKind::TrajectoryPosition:
            EXPECT_NEAR(x, 0.0f, 1e-5f) << channel.name << " " << k;
            break;
          case FeatureKind::TrajectoryDirection:
            EXPECT_NEAR(x, k % 2 == 0 ? 0.0f : 1.0f, 1e-5f) << channel.name << " " << k;
            break;
          case FeatureKind::BonePosition:
          case FeatureKind::BoneDirection:
            // Relative to the root, the pose is the source frame's.
            EXPECT_NEAR(x, held[first + k], 1e-4f) << channel.name << " " << k;
            break;
        }
      }
    }
  }
}

TEST(IdleBuild, TheChosenFrameIsTheCalmestStandingFrameByBruteForce) {
  const Built& b = built();
  const DatabaseView db = *b.db;
  const int joints = db.joint_count();
  const int hips = db.skeleton.find("Hips");
  const int hands[] = {db.skeleton.find("Hand_L"), db.skeleton.find("Hand_R")};
  const int feet[] = {db.skeleton.find("Foot_L"), db.skeleton.find("Foot_R")};
  ASSERT_TRUE(hips > 0 && hands[0] > 0 && hands[1] > 0 && feet[0] > 0 && feet[1] > 0);
  EXPECT_EQ(arm_end_joints(db.skeleton, db.roles), (std::vector<int>{hands[0], hands[1]}));

  int best = -1;
  double best_energy = 0.0;
  int qualifying = 0;
  for (int f = 0; f < db.clips[2].start; ++f) {
    const size_t base = static_cast<size_t>(f) * joints;
    if (!db.contacts[2 * f] || !db.contacts[2 * f + 1]) continue;
    const glm::vec3 root_velocity = db.local_velocities[base];
    if (std::sqrt(root_velocity.x * root_velocity.x + root_velocity.z * root_velocity.z) >= 0.05f)
      continue;
    const std::vector<Transform> g = globals(db, f);
    glm::vec3 apart = g[feet[0]].translation - g[feet[1]].translation;
    apart.y = 0.0f;
    if (glm::length(apart) >= 0.4f) continue;
    const float hips_height = g[hips].translation.y;
    if (g[hands[0]].translation.y >= hips_height || g[hands[1]].translation.y >= hips_height)
      continue;
    ++qualifying;
    double energy = 0.0;
    for (int j = 1; j < joints; ++j) {
      energy +=
          glm::dot(db.local_angular_velocities[base + j], db.local_angular_velocities[base + j]);
      if (db.skeleton.parent(j) == 0) {
        energy += glm::dot(db.local_velocities[base + j], db.local_velocities[base + j]);
      }
    }
    if (best < 0 || energy < best_energy) {
      best = f;
      best_energy = energy;
    }
  }
  ASSERT_GT(qualifying, 1);
  EXPECT_EQ(reported_source_frame(db, b.report), best);
  const IdleSourceSearch s = search_idle_source(db);
  EXPECT_EQ(s.frame, best);
  EXPECT_EQ(s.arms_down, qualifying);
  EXPECT_NEAR(s.energy, best_energy, 1e-9 * best_energy);
  // The chosen pose stands: both feet planted near the ground, the hips above them.
  const std::vector<Transform> g = globals(db, db.clips[2].start);
  for (const int foot : feet) EXPECT_LT(g[foot].translation.y, 0.15f);
  EXPECT_GT(g[hips].translation.y, 0.8f);
}

TEST(IdleBuild, FromAnInMemoryStandingClip) {
  // A figure standing still whose hand swings to a stop at frame 25 and back: the hand's
  // rotation angle is a parabola, so its central-difference angular velocity is zero at 25
  // and grows away from it.
  Clip clip;
  clip.name = "stand";
  std::vector<Transform> rest(9);
  clip.skeleton = Skeleton::create({"Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg",
                                    "RightLeg", "RightFoot", "Head", "LeftHand"},
                                   {-1, 0, 1, 2, 0, 4, 5, 0, 0}, rest)
                      .value();
  clip.frame_count = 40;
  for (int f = 0; f < clip.frame_count; ++f) {
    Transform hips, left, right, head, hand, at_parent;  // the upper and lower legs: at the hips
    hips.translation = {0.0f, 0.9f, 0.0f};
    left.translation = {0.1f, -0.85f, 0.0f};
    right.translation = {-0.1f, -0.85f, 0.0f};
    head.translation = {0.0f, 0.6f, 0.0f};
    hand.translation = {0.25f, -0.1f, 0.0f};
    const float angle = 0.002f * static_cast<float>((f - 25) * (f - 25));
    hand.rotation = glm::angleAxis(angle, glm::vec3(0.0f, 0.0f, 1.0f));
    clip.local.insert(clip.local.end(),
                      {hips, at_parent, at_parent, left, at_parent, at_parent, right, head, hand});
  }
  BuildReport report;
  Result<Database> db = build_database_from_clips(std::span(&clip, 1), BuildOptions{}, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 2u);
  EXPECT_TRUE(std::ranges::equal(db->tag_names(), std::vector<std::string>{"idle"}));
  EXPECT_EQ(db->clips()[0].tags, 0u);
  EXPECT_EQ(db->clips()[1].tags, 1u);
  EXPECT_EQ(report.idle_source_clip, "stand");
  EXPECT_EQ(report.idle_source_frame, 25);
  EXPECT_EQ(db->frame_count(), 40 + 90);
  std::vector<float> raw(db->feature_row(40).begin(), db->feature_row(40).end());
  denormalize_features(raw, db->feature_offset(), db->feature_scale());
  // left_foot_position, right_foot_position: the feet where they stand, around the origin.
  EXPECT_NEAR(raw[0], 0.1f, 1e-5f);
  EXPECT_NEAR(raw[1], 0.05f, 1e-5f);
  EXPECT_NEAR(raw[2], 0.0f, 1e-5f);
  EXPECT_NEAR(raw[3], -0.1f, 1e-5f);
}

TEST(IdleBuild, ZeroSecondsGivesNoIdleClip) {
  BuildOptions options;
  options.idle_seconds = 0.0f;
  BuildReport report;
  Result<Database> db = build_database(wave_and_walk(), options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 2u);
  EXPECT_EQ(db->frame_count(), db->clips()[1].end);
  EXPECT_EQ(std::find(db->tag_names().begin(), db->tag_names().end(), "idle"),
            db->tag_names().end());
  EXPECT_EQ(find_idle_clip(*db), -1);
  EXPECT_EQ(report.idle_frames, 0);
  EXPECT_EQ(report.idle_source_frame, -1);
  EXPECT_TRUE(report.idle_source_clip.empty());
  // The other clips are what the default build made of them.
  EXPECT_EQ(db->clips()[1].end, built().db->clips()[1].end);
  EXPECT_EQ(db->tag_names().size() + 1, built().db->tag_names().size());
}

TEST(IdleBuild, InvalidLengthsAreRefusedByMessage) {
  const fs::path one[] = {test::clip_path(kWave)};
  for (const float seconds : {-1.0f, 60.5f, std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity()}) {
    BuildOptions options;
    options.idle_seconds = seconds;
    Result<Database> db = build_database(one, options);
    ASSERT_FALSE(db) << seconds;
    EXPECT_NE(db.message().find("the idle clip must last from 0 to 60 seconds"), std::string::npos)
        << db.message();
  }
  // 1 s is 30 frames, one short of a searchable frame with the default schema at 30 Hz.
  BuildOptions short_idle;
  short_idle.idle_seconds = 1.0f;
  Result<Database> db = build_database(one, short_idle);
  ASSERT_FALSE(db);
  EXPECT_NE(db.message().find("is 30 frames at 30 Hz"), std::string::npos) << db.message();
  EXPECT_NE(db.message().find("at least 31 frames"), std::string::npos) << db.message();
  // The shortest accepted: one searchable frame.
  short_idle.idle_seconds = 31.0f / 30.0f;
  db = build_database(one, short_idle);
  ASSERT_TRUE(db) << db.message();
  const ClipRange& idle = db->clips().back();
  ASSERT_EQ(idle.name, "idle");
  EXPECT_EQ(idle.frame_count(), 31);
  EXPECT_EQ(std::count(db->searchable().begin() + idle.start, db->searchable().end(), uint8_t{1}),
            1);
  // The longest accepted.
  BuildOptions longest;
  longest.idle_seconds = 60.0f;
  db = build_database(one, longest);
  ASSERT_TRUE(db) << db.message();
  EXPECT_EQ(db->clips().back().frame_count(), 1800);
}

TEST(IdleBuild, LengthFollowsTheRate) {
  BuildOptions options;
  options.rate = 60.0f;
  options.idle_seconds = 2.5f;
  const fs::path one[] = {test::clip_path(kWave)};
  Result<Database> db = build_database(one, options);
  ASSERT_TRUE(db) << db.message();
  const ClipRange& idle = db->clips().back();
  ASSERT_EQ(idle.name, "idle");
  EXPECT_EQ(idle.frame_count(), 150);
  EXPECT_EQ(std::count(db->searchable().begin() + idle.start, db->searchable().end(), uint8_t{1}),
            90);
}

TEST(IdleBuild, NoStandingFrameMeansNoIdleClipAndAWarning) {
  // Zero contact heights leave no frame in contact.
  BuildOptions options;
  options.contacts.foot_height = 0.0f;
  options.contacts.toe_height = 0.0f;
  BuildReport report;
  Result<Database> db = build_database(wave_and_walk(), options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_TRUE(db->validate()) << db->validate().message();
  ASSERT_EQ(db->clips().size(), 2u);
  EXPECT_EQ(db->frame_count(), db->clips()[1].end);
  EXPECT_EQ(db->features().size(), static_cast<size_t>(db->frame_count()) * db->feature_dims());
  EXPECT_EQ(db->local_positions().size(),
            static_cast<size_t>(db->frame_count()) * db->joint_count());
  EXPECT_EQ(std::find(db->tag_names().begin(), db->tag_names().end(), "idle"),
            db->tag_names().end());
  // The other tags keep their bits once "idle" is gone.
  EXPECT_TRUE(has_tag(*db, db->clips()[0], "wave-left-hand"));
  EXPECT_TRUE(has_tag(*db, db->clips()[1], "walk"));
  EXPECT_FALSE(has_tag(*db, db->clips()[1], "action"));
  EXPECT_EQ(report.clips, 2);
  EXPECT_EQ(report.frames, db->frame_count());
  EXPECT_EQ(report.idle_frames, 0);
  EXPECT_EQ(report.idle_source_frame, -1);
  const auto warning = std::find_if(report.warnings.begin(), report.warnings.end(),
                                    [](const std::string& w) { return w.starts_with("no idle"); });
  ASSERT_NE(warning, report.warnings.end());
  EXPECT_EQ(*warning, "no idle clip: no frame stands with both feet in contact");
}

TEST(IdleBuild, ManifestRulesMatchTheNameIdle) {
  const fs::path dir = test::scratch_dir();
  std::ofstream(dir / "idle.tags") << "idle calm\n*wave* hello\n";
  BuildOptions options;
  options.tags_file = dir / "idle.tags";
  Result<Database> db = build_database(wave_and_walk(), options);
  ASSERT_TRUE(db) << db.message();
  const ClipRange& idle = db->clips().back();
  ASSERT_EQ(idle.name, "idle");
  EXPECT_TRUE(has_tag(*db, idle, "idle"));
  EXPECT_TRUE(has_tag(*db, idle, "calm"));
  EXPECT_FALSE(has_tag(*db, idle, "hello"));
  EXPECT_TRUE(has_tag(*db, db->clips()[0], "hello"));
  EXPECT_FALSE(has_tag(*db, db->clips()[0], "calm"));
}

TEST(IdleBuild, MirroredBuildHasOneUnmirroredIdleClipFromAnOriginal) {
  BuildOptions options;
  options.mirror = true;
  BuildReport report;
  Result<Database> db = build_database(wave_and_walk(), options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_EQ(db->clips().size(), 5u);
  const ClipRange& idle = db->clips()[4];
  EXPECT_EQ(idle.name, "idle");
  EXPECT_FALSE(idle.mirrored);
  EXPECT_FALSE(has_tag(*db, idle, "mirrored"));
  EXPECT_EQ(report.idle_source_clip, built().report.idle_source_clip);
  EXPECT_EQ(report.idle_source_frame, built().report.idle_source_frame);
}

TEST(IdleBuild, SurvivesTheDatabaseFile) {
  const DatabaseView db = *built().db;
  const fs::path file = test::scratch_dir() / "idle.mmdb";
  ASSERT_TRUE(save_database(*built().db, file));
  Result<Database> loaded = load_database(file);
  ASSERT_TRUE(loaded) << loaded.message();
  EXPECT_EQ(find_idle_clip(*loaded), 2);
  // Searching the loaded database skips the idle clip and finds the same source again.
  EXPECT_EQ(find_calmest_standing_frame(*loaded), reported_source_frame(db, built().report));
}

// A database on the ReActIdle skeleton (first input, no hands: the lower arms are the arm ends)
// finds its calmest standing frame: standing people's elbows hang at the waist, above the hips.
TEST(IdleBuild, OnASkeletonWithoutHandsTheElbowsHangAtTheWaist) {
  const fs::path take = test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh";
  BuildOptions options;
  options.bvh.scale = 0.0f;
  BuildReport report;
  Result<Database> db = build_database(std::span(&take, 1), options, &report);
  ASSERT_TRUE(db) << db.message();
  ASSERT_LT(db->roles().left_hand, 0);
  const IdleSourceSearch search = search_idle_source(*db);
  EXPECT_GT(search.arms_down, 0) << idle_search_failure(search);
  ASSERT_GE(search.frame, 0);
  EXPECT_LT(highest_arm_end_over_hips(*db, search.frame), 0.0f);
  // The elbows themselves are above the hips, which a hand would not be.
  const size_t joints = static_cast<size_t>(db->joint_count());
  std::vector<Transform> local(joints), global(joints);
  for (size_t j = 0; j < joints; ++j) {
    local[j].translation = db->local_positions()[static_cast<size_t>(search.frame) * joints + j];
    local[j].rotation = db->local_rotations()[static_cast<size_t>(search.frame) * joints + j];
  }
  forward_kinematics(db->skeleton().parents(), local, global);
  const float hips = global[static_cast<size_t>(db->roles().hips)].translation.y;
  EXPECT_GT(global[static_cast<size_t>(db->roles().left_lower_arm)].translation.y, hips);
  EXPECT_GT(global[static_cast<size_t>(db->roles().right_lower_arm)].translation.y, hips);
}

// ---- Calm segments of idle takes --------------------------------------------------------------

// A standing figure at 30 Hz for `seconds`: hips, two legs of upper leg, lower leg and foot; the
// left foot and the body's facing follow the given functions of time.
template <class FootFn, class YawFn>
Clip standing_take(float seconds, const FootFn& left_foot_offset, const YawFn& yaw) {
  Clip clip;
  clip.name = "003_genuine";
  clip.skeleton = Skeleton::create({"Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "RightUpLeg",
                                    "RightLeg", "RightFoot"},
                                   {-1, 0, 1, 2, 0, 4, 5}, std::vector<Transform>(7))
                      .value();
  clip.frame_time = 1.0f / 30.0f;
  clip.frame_count = static_cast<int>(seconds * 30.0f) + 1;
  for (int f = 0; f < clip.frame_count; ++f) {
    const float t = f * clip.frame_time;
    Transform hips, up_l, leg_l, foot_l, up_r, leg_r, foot_r;
    hips.translation = {0.0f, 0.9f, 0.0f};
    hips.rotation = glm::angleAxis(yaw(t), glm::vec3(0.0f, 1.0f, 0.0f));
    up_l.translation = {0.1f, 0.0f, 0.0f};
    up_r.translation = {-0.1f, 0.0f, 0.0f};
    leg_l.translation = leg_r.translation = {0.0f, -0.4f, 0.0f};
    foot_l.translation = glm::vec3(0.0f, -0.4f, 0.0f) + left_foot_offset(t);
    foot_r.translation = {0.0f, -0.4f, 0.0f};
    clip.local.insert(clip.local.end(), {hips, up_l, leg_l, foot_l, up_r, leg_r, foot_r});
  }
  return clip;
}

JointRoleIndices standing_roles(const Clip& clip) {
  Result<JointRoleIndices> roles = find_joint_roles(clip.skeleton, JointRoles{});
  EXPECT_TRUE(roles) << roles.message();
  return *roles;
}

TEST(CalmIdleSegments, AStepSplitsTheTakeAndShortPiecesAreDropped) {
  // 20 s standing; from 8 to 8.5 s the left foot steps 0.3 m forward (0.6 m/s), and from 18 to
  // 18.5 s back: calm 0-8 s, 8.5-18 s, and 18.5-20 s (too short).
  const Clip take = standing_take(
      20.0f,
      [](float t) {
        const float out = std::clamp((t - 8.0f) / 0.5f, 0.0f, 1.0f);
        const float back = std::clamp((t - 18.0f) / 0.5f, 0.0f, 1.0f);
        return glm::vec3(0.0f, 0.0f, 0.3f * (out - back));
      },
      [](float) { return 0.0f; });
  const std::vector<Clip> segments = calm_idle_segments(take, standing_roles(take));
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0].name, "003_genuine_at0s");
  EXPECT_NEAR(segments[0].frame_count / 30.0f, 8.0f, 0.1f);
  EXPECT_EQ(segments[1].name, "003_genuine_at8s");
  EXPECT_NEAR(segments[1].frame_count / 30.0f, 9.5f, 0.1f);
  // A segment holds the take's own frames.
  const int first = static_cast<int>(std::lround(8.5f * 30.0f)) + 1;
  EXPECT_EQ(segments[1].pose(0)[3].translation, take.pose(first)[3].translation);
  ASSERT_TRUE(segments[1].validate());
}

TEST(CalmIdleSegments, ATurnEndsASegment) {
  // The body turns slowly (3 degrees a second, feet planted): a segment ends once it has turned
  // the criteria's 15 degrees, after 5 s, and the next one starts there.
  const Clip take = standing_take(
      12.0f, [](float) { return glm::vec3(0.0f); }, [](float t) { return glm::radians(3.0f) * t; });
  CalmIdleCriteria criteria;
  criteria.max_turn = glm::radians(15.0f);
  const std::vector<Clip> segments = calm_idle_segments(take, standing_roles(take), criteria);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_NEAR(segments[0].frame_count / 30.0f, 5.0f, 0.1f);
  EXPECT_NEAR(segments[1].frame_count / 30.0f, 5.0f, 0.1f);
}

}  // namespace
}  // namespace mm
