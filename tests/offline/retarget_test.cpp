// Retargeting between skeletons: identity on its own skeleton, bone lengths, directions between
// the two real skeletons of ../shared/mocap (Bandai, centimetres; ReActIdle, metres and another
// hierarchy), ground, scale, skating and the refusals.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "mm/offline/bvh.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/offline/retarget.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr float kDegree = 3.14159265f / 180.0f;

Clip load(const std::filesystem::path& path) {
  Result<Clip> clip = load_bvh(path, BvhOptions{0.0f});
  EXPECT_TRUE(clip) << clip.message();
  return clip ? std::move(clip).value() : Clip{};
}

Clip bandai(const std::string& stem) {
  return load(test::clip_path(stem));
}

Clip reactidle(const std::string& stem) {
  return load(test::mocap_dir() / "reactidle" / "genuine" / (stem + ".bvh"));
}

JointRoleIndices roles_of(const Clip& clip) {
  Result<JointRoleIndices> roles = find_joint_roles(clip.skeleton, JointRoles{});
  EXPECT_TRUE(roles) << roles.message();
  return roles ? *roles : JointRoleIndices{};
}

RetargetSkeleton describe(const Clip& clip) {
  Result<RetargetSkeleton> s = describe_for_retargeting(clip, roles_of(clip));
  EXPECT_TRUE(s) << s.message();
  return s ? std::move(s).value() : RetargetSkeleton{};
}

Clip retarget(const Clip& source, const Clip& target, RetargetReport* report = nullptr) {
  Result<Clip> out = retarget_clip(source, describe(source), describe(target), report);
  EXPECT_TRUE(out) << out.message();
  return out ? std::move(out).value() : Clip{};
}

std::vector<Transform> globals(const Clip& clip, int frame) {
  std::vector<Transform> g(static_cast<size_t>(clip.joint_count()));
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), g);
  return g;
}

glm::vec3 at(const std::vector<Transform>& g, int joint) {
  return g[static_cast<size_t>(joint)].translation;
}

// Mean angle between the world directions of matched bones (joint to child role) over a clip.
float mean_direction_error(const Clip& a, const Clip& b) {
  const JointRoleIndices ra = roles_of(a), rb = roles_of(b);
  const char* bones[][2] = {{"left_upper_leg", "left_lower_leg"},
                            {"right_upper_leg", "right_lower_leg"},
                            {"left_lower_leg", "left_foot"},
                            {"right_lower_leg", "right_foot"},
                            {"left_upper_arm", "left_lower_arm"},
                            {"right_upper_arm", "right_lower_arm"},
                            {"left_shoulder", "left_upper_arm"},
                            {"right_shoulder", "right_upper_arm"},
                            {"spine", "neck"},
                            {"neck", "head"}};
  double sum = 0.0;
  int count = 0;
  for (int f = 0; f < a.frame_count; f += 5) {
    const std::vector<Transform> ga = globals(a, f), gb = globals(b, f);
    for (const auto& bone : bones) {
      const int a0 = ra.*find_joint_role(bone[0])->index, a1 = ra.*find_joint_role(bone[1])->index;
      const int b0 = rb.*find_joint_role(bone[0])->index, b1 = rb.*find_joint_role(bone[1])->index;
      if (a0 < 0 || a1 < 0 || b0 < 0 || b1 < 0) continue;
      const glm::vec3 da = glm::normalize(at(ga, a1) - at(ga, a0));
      const glm::vec3 db = glm::normalize(at(gb, b1) - at(gb, b0));
      sum += std::acos(std::clamp(glm::dot(da, db), -1.0f, 1.0f));
      ++count;
    }
  }
  return count ? static_cast<float>(sum / count) : 0.0f;
}

// Mean horizontal speed (m/s) of the feet on frames where a foot is within 2 cm of its lowest
// height in the clip: the skating of planted feet.
float planted_foot_speed(const Clip& clip) {
  const JointRoleIndices r = roles_of(clip);
  double sum = 0.0;
  int count = 0;
  for (const int foot : {r.left_foot, r.right_foot}) {
    float lowest = 1e9f;
    for (int f = 0; f < clip.frame_count; ++f)
      lowest = std::min(lowest, at(globals(clip, f), foot).y);
    for (int f = 1; f < clip.frame_count; ++f) {
      const glm::vec3 p = at(globals(clip, f), foot), q = at(globals(clip, f - 1), foot);
      if (p.y > lowest + 0.02f || q.y > lowest + 0.02f) continue;
      sum += glm::length(glm::vec2(p.x - q.x, p.z - q.z)) / clip.frame_time;
      ++count;
    }
  }
  return count ? static_cast<float>(sum / count) : 0.0f;
}

float mean_hips_speed(const Clip& clip) {
  const int hips = roles_of(clip).hips;
  double sum = 0.0;
  for (int f = 1; f < clip.frame_count; ++f) {
    const glm::vec3 d = at(globals(clip, f), hips) - at(globals(clip, f - 1), hips);
    sum += glm::length(glm::vec2(d.x, d.z));
  }
  return static_cast<float>(sum / ((clip.frame_count - 1) * clip.frame_time));
}

// How far a clip's own bones stretch away from their rest offsets (ReActIdle's thighs move by
// up to 3 mm; Bandai's bones never do): retargeting gives every bone its rest length.
float largest_stretch(const Clip& clip) {
  const JointRoleIndices r = roles_of(clip);
  float largest = 0.0f;
  for (int f = 0; f < clip.frame_count; ++f) {
    for (int j = r.hips + 1; j < clip.joint_count(); ++j) {
      largest = std::max(largest, glm::distance(clip.pose(f)[static_cast<size_t>(j)].translation,
                                                clip.skeleton.rest(j).translation));
    }
  }
  return largest;
}

TEST(Retarget, OntoItsOwnSkeletonTheClipComesBackUnchanged) {
  // The second Bandai clip moves its joint_Root too (above the hips).
  for (const Clip& clip : {bandai("dataset-2_walk-turn-left_normal_001"),
                           bandai("dataset-1_walk-back_normal_001"), reactidle("003_genuine")}) {
    RetargetReport report;
    const Clip out = retarget(clip, clip, &report);
    ASSERT_EQ(out.frame_count, clip.frame_count);
    EXPECT_FLOAT_EQ(report.scale, 1.0f);
    const float stretch = largest_stretch(clip);
    EXPECT_NEAR(report.ground_shift, 0.0f, 1e-5f + stretch);
    float worst = 0.0f;
    for (int f = 0; f < clip.frame_count; f += 3) {
      const std::vector<Transform> a = globals(clip, f), b = globals(out, f);
      for (size_t j = 0; j < a.size(); ++j) {
        worst = std::max(worst, glm::distance(a[j].translation, b[j].translation));
      }
    }
    EXPECT_LT(worst, 1e-5f + 2.0f * stretch) << clip.name;
    if (clip.name.rfind("dataset", 0) == 0) {
      EXPECT_LT(stretch, 1e-6f);
    }
  }
}

TEST(Retarget, BonesHaveTheTargetsLengthsAndItsNames) {
  const Clip target = bandai("dataset-2_walk_normal_001");
  const Clip out = retarget(reactidle("000_genuine"), target);
  ASSERT_TRUE(out.validate()) << out.validate().message();
  EXPECT_EQ(out.skeleton.names(), target.skeleton.names());
  EXPECT_EQ(out.skeleton.parents(), target.skeleton.parents());
  const int hips = roles_of(target).hips;
  for (int f = 0; f < out.frame_count; f += 97) {
    const std::vector<Transform> g = globals(out, f);
    for (int j = 0; j < out.joint_count(); ++j) {
      const int p = out.skeleton.parent(j);
      if (p < 0 || j == hips) continue;
      EXPECT_NEAR(glm::distance(at(g, j), at(g, p)),
                  glm::length(target.skeleton.rest(j).translation), 1e-5f)
          << out.skeleton.name(j);
    }
  }
}

// Both directions between the two real skeletons: the bones point where the source's do, the
// toes stand on the target's ground, the root's speed scales with the legs, and planted feet
// skate no more than the source's.
TEST(Retarget, BetweenBandaiAndReActIdleBothWays) {
  const Clip walk = bandai("dataset-2_walk_normal_001");
  const Clip idle = reactidle("000_genuine");
  struct Case {
    const Clip& source;
    const Clip& target;
  };
  for (const Case& c : {Case{idle, walk}, Case{walk, idle}}) {
    RetargetReport report;
    const Clip out = retarget(c.source, c.target, &report);
    const float error = mean_direction_error(c.source, out);
    const RetargetSkeleton target = describe(c.target);
    float lowest = 1e9f;
    for (int f = 0; f < out.frame_count; ++f) {
      const std::vector<Transform> g = globals(out, f);
      for (const int toe : {roles_of(out).left_toe, roles_of(out).right_toe,
                            roles_of(out).left_foot, roles_of(out).right_foot}) {
        if (toe >= 0 && (toe != roles_of(out).left_foot || roles_of(out).left_toe < 0)) {
          lowest = std::min(lowest, at(g, toe).y);
        }
      }
    }
    const float speed_ratio = mean_hips_speed(out) / mean_hips_speed(c.source);
    const float skate_source = planted_foot_speed(c.source), skate_out = planted_foot_speed(out);
    std::printf(
        "[ measure  ] %s -> %s skeleton: bone directions %.2f deg off on average; scale "
        "%.3f, root speed ratio %.3f; lowest toe %.3f m (target's own %.3f); planted feet "
        "%.2f cm/s (source %.2f)\n",
        c.source.name.c_str(), c.target.name.c_str(), error / kDegree, report.scale, speed_ratio,
        lowest, target.toe_floor, 100.0f * skate_out, 100.0f * skate_source);
    EXPECT_LT(error, 10.0f * kDegree);
    EXPECT_NEAR(lowest, target.toe_floor, 0.02f);
    EXPECT_NEAR(speed_ratio, report.scale, 0.02f * report.scale);
    // The bound is for walks; the idle's planted feet are held by the controller's locks.
    if (&c.source == &walk) {
      EXPECT_LT(skate_out, skate_source + 0.01f);
    }
  }
}

TEST(Retarget, SkeletonsThatCannotBeMatchedAreRefused) {
  const Clip walk = bandai("dataset-2_walk_normal_001");
  RetargetSkeleton target = describe(walk);
  RetargetSkeleton broken = target;
  broken.roles.left_lower_leg = -1;
  Result<Clip> out = retarget_clip(walk, describe(walk), broken);
  ASSERT_FALSE(out);
  EXPECT_NE(out.message().find("the target skeleton has no joint for the required role "
                               "'left_lower_leg'"),
            std::string::npos)
      << out.message();
  out = retarget_clip(reactidle("000_genuine"), target, target);
  ASSERT_FALSE(out);
  EXPECT_NE(out.message().find("is not on the source skeleton"), std::string::npos)
      << out.message();
  Result<RetargetSkeleton> late = describe_for_retargeting(walk, roles_of(walk), 100000);
  ASSERT_FALSE(late);
  EXPECT_NE(late.message().find("rest frame 100000 is past its last frame"), std::string::npos)
      << late.message();
}

TEST(Retarget, RestPoseIsTheBindPoseOnlyWhenItStands) {
  // ReActIdle's bind pose is a T-pose; Bandai's lays every bone along X, so its first frame is
  // used instead.
  EXPECT_EQ(describe(reactidle("000_genuine")).rest_description, "bind pose");
  EXPECT_EQ(describe(bandai("dataset-2_walk_normal_001")).rest_description.rfind("frame 0", 0), 0u);
}

}  // namespace
}  // namespace mm
