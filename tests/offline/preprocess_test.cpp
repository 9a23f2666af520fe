// Preprocessing on synthetic clips with known answers: resampling, the simulation
// root, contacts, joint roles and mirroring; plus mirroring on a real clip.

#include <gtest/gtest.h>

#include <cmath>

#include "mm/offline/bvh.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 30.0f;
constexpr float kDegree = 3.14159265f / 180.0f;

glm::quat yaw_quat(float yaw) {
  return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f));
}

float yaw_of(const glm::quat& q) {
  const glm::vec3 f = q * glm::vec3(0.0f, 0.0f, 1.0f);
  return std::atan2(f.x, f.z);
}

float angle_difference(float a, float b) {
  float d = std::fmod(a - b, 2.0f * 3.14159265f);
  if (d > 3.14159265f) d -= 2.0f * 3.14159265f;
  if (d < -3.14159265f) d += 2.0f * 3.14159265f;
  return d;
}

// A minimal biped: Root -> Hips -> (UpperLeg_L -> LowerLeg_L -> Foot_L -> Toes_L), (UpperLeg_R
// -> LowerLeg_R -> Foot_R -> Toes_R), Spine -> Head. Rest offsets are symmetric in x.
Skeleton small_biped() {
  std::vector<std::string> names = {"joint_Root", "Hips",   "UpperLeg_L", "LowerLeg_L",
                                    "Foot_L",     "Toes_L", "UpperLeg_R", "LowerLeg_R",
                                    "Foot_R",     "Toes_R", "Spine",      "Head"};
  std::vector<int> parents = {-1, 0, 1, 2, 3, 4, 1, 6, 7, 8, 1, 10};
  std::vector<Transform> rest(names.size());
  const glm::vec3 offsets[] = {{0, 0, 0},          {0, 0.9f, 0},   {0.1f, -0.05f, 0},
                               {0, -0.4f, 0},      {0, -0.35f, 0}, {0, -0.06f, 0.12f},
                               {-0.1f, -0.05f, 0}, {0, -0.4f, 0},  {0, -0.35f, 0},
                               {0, -0.06f, 0.12f}, {0, 0.2f, 0},   {0, 0.4f, 0}};
  for (size_t i = 0; i < names.size(); ++i) rest[i].translation = offsets[i];
  Result<Skeleton> sk = Skeleton::create(names, parents, rest);
  EXPECT_TRUE(sk) << sk.message();
  return *sk;
}

// A clip of the biped in its rest pose everywhere except the hips, which follow hips(t).
template <class HipsFn>
Clip biped_clip(int frames, float frame_time, const HipsFn& hips) {
  Clip clip;
  clip.name = "synthetic";
  clip.skeleton = small_biped();
  clip.frame_time = frame_time;
  clip.frame_count = frames;
  const int joints = clip.joint_count();
  clip.local.resize(static_cast<size_t>(frames) * joints);
  for (int f = 0; f < frames; ++f) {
    std::span<Transform> pose = clip.pose(f);
    for (int j = 0; j < joints; ++j) pose[j] = clip.skeleton.rest(j);
    pose[1] = hips(f * frame_time);
  }
  return clip;
}

std::vector<Transform> globals_of(const Clip& clip, int frame) {
  std::vector<Transform> g(clip.joint_count());
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), g);
  return g;
}

std::vector<Transform> globals_of(const ProcessedClip& p, const Skeleton& db_skeleton, int frame) {
  const int joints = p.joint_count;
  std::vector<Transform> local(joints), g(joints);
  for (int j = 0; j < joints; ++j) {
    local[j].translation = p.local_positions[static_cast<size_t>(frame) * joints + j];
    local[j].rotation = p.local_rotations[static_cast<size_t>(frame) * joints + j];
  }
  forward_kinematics(db_skeleton.parents(), local, g);
  return g;
}

JointRoleIndices biped_roles() {
  Result<JointRoleIndices> roles = find_joint_roles(small_biped(), JointRoles{});
  EXPECT_TRUE(roles) << roles.message();
  return *roles;
}

// ---- Resampling --------------------------------------------------------------------------------

TEST(Resample, SixtyToThirtyAndTwentyFourToThirtyFollowTheMotion) {
  for (const float source_rate : {60.0f, 24.0f}) {
    const float dt = 1.0f / source_rate;
    const int frames = static_cast<int>(2.0f * source_rate) + 1;  // exactly 2 s
    auto hips = [](float t) {
      Transform x;
      x.translation = {0.5f * t, 0.9f, -t};
      x.rotation = yaw_quat(0.6f * t);
      return x;
    };
    const Clip clip = biped_clip(frames, dt, hips);
    ASSERT_TRUE(needs_resampling(clip, 30.0f));
    const Clip out = resample_clip(clip, 30.0f);
    EXPECT_EQ(out.frame_count, 61) << source_rate;
    EXPECT_FLOAT_EQ(out.frame_time, 1.0f / 30.0f);
    for (int f = 0; f < out.frame_count; ++f) {
      const Transform expected = hips(f / 30.0f);
      const Transform& got = out.pose(f)[1];
      EXPECT_NEAR(glm::distance(got.translation, expected.translation), 0.0f, 1e-5f) << f;
      EXPECT_NEAR(std::abs(glm::dot(got.rotation, expected.rotation)), 1.0f, 1e-5f) << f;
      EXPECT_NEAR(glm::distance(out.pose(f)[4].translation, clip.skeleton.rest(4).translation),
                  0.0f, 1e-6f);
    }
  }
}

TEST(Resample, BvhFrameTimeOfThirtyHertzNeedsNoResampling) {
  const Clip clip = biped_clip(10, 0.0333333f, [](float) { return Transform{}; });
  EXPECT_FALSE(needs_resampling(clip, 30.0f));
  const Clip out = resample_clip(clip, 30.0f);
  EXPECT_EQ(out.frame_count, 10);
  EXPECT_FLOAT_EQ(out.frame_time, 1.0f / 30.0f);
}

// ---- Simulation root ---------------------------------------------------------------------------

TEST(SimulationRoot, SkeletonGainsJointZero) {
  Result<Skeleton> db = add_simulation_root(small_biped());
  ASSERT_TRUE(db) << db.message();
  EXPECT_EQ(db->joint_count(), 13);
  EXPECT_EQ(db->name(0), "Simulation");
  EXPECT_EQ(db->parent(0), -1);
  EXPECT_EQ(db->name(1), "joint_Root");
  EXPECT_EQ(db->parent(1), 0);
  EXPECT_EQ(db->parent(2), 1);   // Hips under joint_Root
  EXPECT_EQ(db->parent(10), 9);  // Head under Spine
  Result<Skeleton> again = add_simulation_root(*db);
  ASSERT_FALSE(again);
  EXPECT_NE(again.message().find("Simulation"), std::string::npos);
}

TEST(SimulationRoot, StraightWalkGivesExactFacingAndUnchangedGlobals) {
  // Hips travel at 1.2 m/s along a heading of 30 degrees, facing it, bobbing up and down;
  // joint_Root itself translates too (as in some Bandai takes).
  const float heading = 30.0f * kDegree;
  const glm::vec3 dir(std::sin(heading), 0.0f, std::cos(heading));
  Clip clip = biped_clip(60, kDt, [&](float t) {
    Transform x;
    x.translation = glm::vec3(0.0f, 0.9f + 0.02f * std::sin(9.0f * t), 0.0f) + 1.2f * t * dir;
    x.rotation = yaw_quat(heading);
    return x;
  });
  for (int f = 0; f < clip.frame_count; ++f) clip.pose(f)[0].translation = {0.3f, 0.0f, f * 0.01f};

  ProcessedClip out;
  PreprocessScratch scratch;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), PreprocessOptions{}, out, scratch));
  ASSERT_EQ(out.joint_count, 13);
  ASSERT_EQ(out.frame_count, 60);
  const Skeleton db_skeleton = *add_simulation_root(clip.skeleton);
  for (int f = 0; f < clip.frame_count; ++f) {
    const glm::vec3 root = out.local_positions[static_cast<size_t>(f) * 13];
    const std::vector<Transform> source = globals_of(clip, f);
    EXPECT_EQ(root.y, 0.0f);
    EXPECT_NEAR(root.x, source[1].translation.x, 1e-5f);
    EXPECT_NEAR(root.z, source[1].translation.z, 1e-5f);
    EXPECT_NEAR(angle_difference(yaw_of(out.local_rotations[static_cast<size_t>(f) * 13]), heading),
                0.0f, 1e-4f)
        << f;
    // Re-rooting keeps every global transform.
    const std::vector<Transform> db = globals_of(out, db_skeleton, f);
    for (int j = 0; j < clip.joint_count(); ++j) {
      EXPECT_NEAR(glm::distance(db[j + 1].translation, source[j].translation), 0.0f, 1e-5f);
      EXPECT_NEAR(std::abs(glm::dot(db[j + 1].rotation, source[j].rotation)), 1.0f, 1e-5f);
    }
    // Joint 0 velocity = the hips' ground velocity (their own plus joint_Root's 0.3 m/s along
    // +Z); no turning.
    EXPECT_NEAR(out.local_velocities[static_cast<size_t>(f) * 13].x, 1.2f * dir.x, 1e-3f);
    EXPECT_NEAR(out.local_velocities[static_cast<size_t>(f) * 13].z, 1.2f * dir.z + 0.3f, 1e-3f);
    EXPECT_NEAR(glm::length(out.local_angular_velocities[static_cast<size_t>(f) * 13]), 0.0f,
                1e-4f);
  }
}

TEST(SimulationRoot, HipSwingIsSmoothedAndTurnsAreFollowed) {
  // The hips swing +-8 degrees with a 1.2 s stride period around a heading that turns at a
  // constant 40 degrees per second. A Gaussian of sigma 0.3 s attenuates that frequency to
  // exp(-2 pi^2 sigma^2 f^2) = 0.29, i.e. +-2.3 degrees.
  const float turn_rate = 40.0f * kDegree;
  const float swing = 8.0f * kDegree;
  const Clip clip = biped_clip(150, kDt, [&](float t) {
    Transform x;
    x.translation = {0.0f, 0.9f, 0.0f};
    x.rotation = yaw_quat(turn_rate * t + swing * std::sin(2.0f * 3.14159265f * t / 1.2f));
    return x;
  });
  ProcessedClip out;
  PreprocessScratch scratch;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), PreprocessOptions{}, out, scratch));
  float worst_inside = 0.0f, worst_end = 0.0f;
  for (int f = 0; f < clip.frame_count; ++f) {
    const float yaw = yaw_of(out.local_rotations[static_cast<size_t>(f) * 13]);
    const float error = std::abs(angle_difference(yaw, turn_rate * f * kDt));
    const bool inside = f >= 27 && f < clip.frame_count - 27;
    (inside ? worst_inside : worst_end) = std::max(inside ? worst_inside : worst_end, error);
    // Joint 0 turns about +Y only.
    const glm::quat q = out.local_rotations[static_cast<size_t>(f) * 13];
    EXPECT_NEAR(q.x, 0.0f, 1e-6f);
    EXPECT_NEAR(q.z, 0.0f, 1e-6f);
  }
  EXPECT_LT(worst_inside, 3.0f * kDegree);
  EXPECT_LT(worst_end, 6.0f * kDegree);  // the cut window is less smooth, but has no lag

  // Without smoothing the facing is the raw hips yaw.
  PreprocessOptions raw;
  raw.root.facing_smoothing = 0.0f;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), raw, out, scratch));
  for (int f = 0; f < clip.frame_count; ++f) {
    const float t = f * kDt;
    const float expected = turn_rate * t + swing * std::sin(2.0f * 3.14159265f * t / 1.2f);
    EXPECT_NEAR(
        angle_difference(yaw_of(out.local_rotations[static_cast<size_t>(f) * 13]), expected), 0.0f,
        1e-4f);
  }
}

TEST(SimulationRoot, ForwardAxisIsConfigurable) {
  // Hips whose local +X points forward (heading 0 = world +Z after a -90 degree yaw).
  const Clip clip = biped_clip(40, kDt, [&](float) {
    Transform x;
    x.translation = {0.0f, 0.9f, 0.0f};
    x.rotation = yaw_quat(-90.0f * kDegree);
    return x;
  });
  PreprocessOptions options;
  options.root.hips_forward_axis = {1.0f, 0.0f, 0.0f};
  ProcessedClip out;
  PreprocessScratch scratch;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), options, out, scratch));
  EXPECT_NEAR(yaw_of(out.local_rotations[0]), 0.0f, 1e-4f);
  options.root.hips_forward_axis = {0.0f, 0.0f, 0.0f};
  EXPECT_FALSE(preprocess_clip(clip, biped_roles(), options, out, scratch));
}

// ---- Contacts ----------------------------------------------------------------------------------

TEST(Contacts, PlantedLiftedAndFlickerFiltered) {
  // The left leg is planted (frames 0-9), swings (10-19: 0.3 m up, moving 1.5 m/s forward), and
  // is planted again (20-29). The right leg stays planted except that at frame 5 its toe rises
  // 3 cm, just above the toe height threshold, for one frame.
  Clip clip = biped_clip(30, kDt, [](float) {
    Transform x;
    x.translation = {0.0f, 0.9f, 0.0f};
    return x;
  });
  // In rest pose the toes are at 0.9 - 0.05 - 0.75 - 0.06 = 0.04 m, the feet at 0.10 m.
  for (int f = 0; f < 30; ++f) {
    std::span<Transform> pose = clip.pose(f);
    if (f >= 10 && f < 20) pose[2].translation += glm::vec3(0.0f, 0.3f, 0.05f * (f - 10));
    if (f == 5) pose[6].translation.y += 0.03f;
  }
  ProcessedClip out;
  PreprocessScratch scratch;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), PreprocessOptions{}, out, scratch));
  for (int f = 0; f < 30; ++f) {
    // Frames 9 and 20 are still low, but central differences reach into the swing: 0.3 m in two
    // frames is 4.5 m/s, above the 0.6 m/s threshold, so they are not contacts.
    const bool left = f < 9 || f > 20;
    EXPECT_EQ(out.contacts[f * 2 + 0], left ? 1 : 0) << "left, frame " << f;
    // At frame 5 the toe is too high but the foot (ankle, 0.13 m) is low and still: contact.
    EXPECT_EQ(out.contacts[f * 2 + 1], 1) << "right, frame " << f;
  }

  // With the toe alone deciding, frame 5 flickers off for one frame (frames 4 and 6 move at
  // 0.03 m / 2 frames = 0.45 m/s, still below the threshold), and the filter removes it.
  PreprocessOptions toe_only;
  toe_only.contacts.foot_height = 0.0f;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), toe_only, out, scratch));
  for (int f = 0; f < 30; ++f) EXPECT_EQ(out.contacts[f * 2 + 1], 1) << "right, frame " << f;
  toe_only.contacts.filter_window = 0.0f;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), toe_only, out, scratch));
  for (int f = 0; f < 30; ++f) {
    EXPECT_EQ(out.contacts[f * 2 + 1], f == 5 ? 0 : 1) << "unfiltered right, frame " << f;
  }
}

// ---- Roles -------------------------------------------------------------------------------------

TEST(JointRoleLookup, BandaiAndCommonBvhNamesIgnoringCase) {
  JointRoleIndices r = biped_roles();
  EXPECT_EQ(r.hips, 1);
  EXPECT_EQ(r.left_upper_leg, 2);
  EXPECT_EQ(r.left_lower_leg, 3);
  EXPECT_EQ(r.left_foot, 4);
  EXPECT_EQ(r.left_toe, 5);
  EXPECT_EQ(r.right_foot, 8);
  EXPECT_EQ(r.right_toe, 9);
  EXPECT_EQ(r.spine, 10);
  EXPECT_EQ(r.head, 11);
  EXPECT_EQ(r.chest, -1);  // no arms to branch off it

  Result<Skeleton> cmu =
      Skeleton::create({"hips", "LeftUpLeg", "LeftLeg", "leftfoot", "LeftToeBase", "RightUpLeg",
                        "RightLeg", "RightFoot", "RightToe"},
                       {-1, 0, 1, 2, 3, 0, 5, 6, 7}, std::vector<Transform>(9));
  ASSERT_TRUE(cmu);
  Result<JointRoleIndices> roles = find_joint_roles(*cmu, JointRoles{});
  ASSERT_TRUE(roles) << roles.message();
  EXPECT_EQ(roles->hips, 0);
  EXPECT_EQ(roles->left_foot, 3);
  EXPECT_EQ(roles->left_toe, 4);
  EXPECT_EQ(roles->right_foot, 7);
  EXPECT_EQ(roles->right_toe, 8);
  EXPECT_EQ(roles->head, -1);  // optional
}

TEST(JointRoleLookup, MissingRequiredRoleNamesWhatWasLookedFor) {
  Result<Skeleton> sk = Skeleton::create(
      {"Hips", "UpperLeg_L", "LowerLeg_L", "Ankle_Left", "UpperLeg_R", "LowerLeg_R", "Foot_R"},
      {-1, 0, 1, 2, 0, 4, 5}, std::vector<Transform>(7));
  ASSERT_TRUE(sk);
  Result<JointRoleIndices> roles = find_joint_roles(*sk, JointRoles{});
  ASSERT_FALSE(roles);
  EXPECT_NE(roles.message().find("left_foot"), std::string::npos) << roles.message();
  EXPECT_NE(roles.message().find("LeftFoot"), std::string::npos) << roles.message();
  EXPECT_NE(roles.message().find("Ankle_Left"), std::string::npos) << roles.message();
  JointRoles custom;
  custom.left_foot = {"ankle_left"};
  roles = find_joint_roles(*sk, custom);
  ASSERT_TRUE(roles) << roles.message();
  EXPECT_EQ(roles->left_foot, 3);
}

// ---- Mirroring ---------------------------------------------------------------------------------

TEST(MirrorMap, DetectsCommonNamingPatterns) {
  Result<Skeleton> sk = Skeleton::create(
      {"Hips", "Foot_L", "Foot_R", "LeftHand", "RightHand", "thigh.l", "thigh.r", "l_ankle",
       "r_ankle", "mixamorig:LeftArm", "mixamorig:RightArm", "lToe", "rToe", "Head"},
      {-1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, std::vector<Transform>(14));
  ASSERT_TRUE(sk);
  Result<std::vector<int>> map = mirror_joint_map(*sk);
  ASSERT_TRUE(map) << map.message();
  EXPECT_EQ(*map, (std::vector<int>{0, 2, 1, 4, 3, 6, 5, 8, 7, 10, 9, 12, 11, 13}));
}

TEST(MirrorMap, OverridesAndConflicts) {
  Result<Skeleton> sk = Skeleton::create({"Hips", "A", "B", "Foot_L", "Foot_R"}, {-1, 0, 0, 0, 0},
                                         std::vector<Transform>(5));
  ASSERT_TRUE(sk);
  const MirrorPair pairs[] = {{"A", "B"}};
  Result<std::vector<int>> map = mirror_joint_map(*sk, pairs);
  ASSERT_TRUE(map) << map.message();
  EXPECT_EQ(*map, (std::vector<int>{0, 2, 1, 4, 3}));
  const MirrorPair missing[] = {{"A", "C"}};
  map = mirror_joint_map(*sk, missing);
  ASSERT_FALSE(map);
  EXPECT_NE(map.message().find("'C'"), std::string::npos);
  const MirrorPair twice[] = {{"A", "B"}, {"A", "Hips"}};
  EXPECT_FALSE(mirror_joint_map(*sk, twice));
}

TEST(Mirror, RealClipSwapsFeetAndMirroringTwiceRestoresIt) {
  Result<Clip> loaded = load_bvh(test::clip_path("dataset-2_walk-turn-left_normal_001"));
  ASSERT_TRUE(loaded) << loaded.message();
  const Clip& clip = *loaded;
  Result<std::vector<int>> map = mirror_joint_map(clip.skeleton);
  ASSERT_TRUE(map) << map.message();
  const int left = clip.skeleton.find("Foot_L"), right = clip.skeleton.find("Foot_R");
  ASSERT_EQ((*map)[left], right);
  ASSERT_EQ((*map)[clip.skeleton.find("Hips")], clip.skeleton.find("Hips"));
  const Clip mirrored = mirror_clip(clip, *map);
  EXPECT_EQ(mirrored.name, clip.name + "_mirror");
  ASSERT_TRUE(mirrored.validate()) << mirrored.validate().message();
  const Clip twice = mirror_clip(mirrored, *map);
  for (int f = 0; f < clip.frame_count; f += 7) {
    const std::vector<Transform> g = globals_of(clip, f);
    const std::vector<Transform> m = globals_of(mirrored, f);
    const glm::vec3 expected = g[right].translation * glm::vec3(-1.0f, 1.0f, 1.0f);
    EXPECT_NEAR(m[left].translation.x, expected.x, 1e-5f) << f;
    EXPECT_NEAR(m[left].translation.y, expected.y, 1e-5f) << f;
    EXPECT_NEAR(m[left].translation.z, expected.z, 1e-5f) << f;
    // The hips' forward axis is mirrored: its x flips.
    const glm::vec3 fwd = g[1].rotation * glm::vec3(0, 0, 1);
    const glm::vec3 mfwd = m[1].rotation * glm::vec3(0, 0, 1);
    EXPECT_NEAR(mfwd.x, -fwd.x, 1e-5f);
    EXPECT_NEAR(mfwd.z, fwd.z, 1e-5f);
    for (int j = 0; j < clip.joint_count(); ++j) {
      const Transform& a = clip.pose(f)[j];
      const Transform& b = twice.pose(f)[j];
      EXPECT_NEAR(glm::distance(a.translation, b.translation), 0.0f, 1e-5f) << f << " " << j;
      EXPECT_NEAR(std::abs(glm::dot(a.rotation, b.rotation)), 1.0f, 1e-5f) << f << " " << j;
    }
  }
}

TEST(Mirror, TurningLeftBecomesTurningRight) {
  // After mirroring, the simulation root of a left turn turns right at the same rate.
  const float rate = 50.0f * kDegree;
  const Clip clip = biped_clip(60, kDt, [&](float t) {
    Transform x;
    x.translation = {0.0f, 0.9f, 0.0f};
    x.rotation = yaw_quat(rate * t);
    return x;
  });
  const Clip mirrored = mirror_clip(clip, *mirror_joint_map(clip.skeleton));
  ProcessedClip a, b;
  PreprocessScratch scratch;
  ASSERT_TRUE(preprocess_clip(clip, biped_roles(), PreprocessOptions{}, a, scratch));
  ASSERT_TRUE(preprocess_clip(mirrored, biped_roles(), PreprocessOptions{}, b, scratch));
  for (int f = 0; f < 60; ++f) {
    EXPECT_NEAR(b.local_angular_velocities[f * 13].y, -a.local_angular_velocities[f * 13].y, 1e-4f)
        << f;
    // Inside the clip the smoothing window is whole and the turn rate is exact.
    if (f >= 27 && f < 33) {
      EXPECT_NEAR(a.local_angular_velocities[f * 13].y, rate, 1e-3f) << f;
    }
  }
}

}  // namespace
}  // namespace mm
