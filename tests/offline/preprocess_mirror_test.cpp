// Mirroring (mirror_clip, mirror_corrections in preprocess.hpp) in the bone's own frame: on
// synthetic skeletons whose bones point along local X, Y or Z, and on real Bandai clips. The
// name-pattern pairing and the older checks are in preprocess_test.cpp.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mm/offline/bvh.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

// ---- Synthetic skeletons -----------------------------------------------------------------------

// The reflection x -> -x, in the world and as a matrix in a joint's frame.
const glm::mat3 kReflect(glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1));

// A joint of a standing biped in the world (Y up, facing +Z, its left at +X).
struct BodyJoint {
  std::string name;
  int parent;
  glm::vec3 position;  // metres, world
};

// Joints per side; a right joint's index is its left partner's + kSideJoints.
constexpr int kSideJoints = 8;

// Parents before children; every _R joint is the mirror image of its _L joint across x = 0.
std::vector<BodyJoint> standing_biped() {
  std::vector<BodyJoint> body = {{"Hips", -1, {0, 1.0f, 0}},
                                 {"Spine", 0, {0, 1.15f, -0.01f}},
                                 {"Chest", 1, {0, 1.35f, 0.01f}},
                                 {"Neck", 2, {0, 1.55f, 0}},
                                 {"Head", 3, {0, 1.65f, 0.02f}}};
  const auto add_side = [&body](const char* side, float s) {
    const auto name = [side](const char* base) { return std::string(base) + side; };
    const int chest = 2, hips = 0;
    const int shoulder = static_cast<int>(body.size());
    body.push_back({name("Shoulder"), chest, {s * 0.04f, 1.5f, 0}});
    body.push_back({name("UpperArm"), shoulder, {s * 0.18f, 1.5f, -0.01f}});
    body.push_back({name("LowerArm"), shoulder + 1, {s * 0.45f, 1.45f, -0.02f}});
    body.push_back({name("Hand"), shoulder + 2, {s * 0.7f, 1.42f, 0}});
    const int leg = static_cast<int>(body.size());
    body.push_back({name("UpperLeg"), hips, {s * 0.1f, 0.95f, 0}});
    body.push_back({name("LowerLeg"), leg, {s * 0.11f, 0.52f, 0.02f}});
    body.push_back({name("Foot"), leg + 1, {s * 0.1f, 0.08f, -0.02f}});
    body.push_back({name("Toes"), leg + 2, {s * 0.1f, 0.0f, 0.12f}});
  };
  add_side("_L", 1.0f);
  add_side("_R", -1.0f);
  return body;
}

// How a skeleton orients its joints' local axes.
struct AxisStyle {
  const char* label;
  int bone_axis;               // the local axis along each bone (0 X, 1 Y, 2 Z)
  int hips_lateral_axis;       // the hips' local axis along the world's x
  int chain_lateral_axis;      // the same for the spine, chest, neck and head
  glm::mat3 right_convention;  // right frame = M * left frame * this (improper)
};

// Bandai-like: bones along X, a right bone's offsets the negated left ones (every axis
// flipped), the hips' lateral axis Y and the spine's Z.
const AxisStyle kAlongX = {"along X", 0, 1, 2, -glm::mat3(1.0f)};
// Mixamo/glTF-like: bones along Y, right frames the mirror images of the left ones.
const AxisStyle kAlongY = {"along Y", 1, 0, 0, kReflect};
// Bones along Z, a right frame's Y axis flipped against the mirror image.
const AxisStyle kAlongZ = {"along Z", 2, 1, 0,
                           glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, -1, 0), glm::vec3(0, 0, 1))};

// The rotation whose local axis `axis` points along `direction` and local axis `second` along
// `hint` made perpendicular to it.
glm::mat3 frame_along(int axis, const glm::vec3& direction, int second, const glm::vec3& hint) {
  glm::mat3 m;
  m[axis] = glm::normalize(direction);
  m[second] = glm::normalize(hint - glm::dot(hint, m[axis]) * m[axis]);
  const int third = 3 - axis - second;
  m[third] = glm::cross(m[(third + 1) % 3], m[(third + 2) % 3]);
  return m;
}

// The world rest rotation of every joint of `body` in `style`: each bone along the style's
// axis (a leaf continues its parent's bone), centre joints with the style's lateral axis, a
// right joint the mirror of its left partner by the style's convention.
std::vector<glm::mat3> world_frames(const std::vector<BodyJoint>& body, const AxisStyle& style) {
  const int n = static_cast<int>(body.size());
  const int first_right = n - kSideJoints;
  std::vector<glm::mat3> frames(n);
  for (int j = 0; j < first_right; ++j) {
    int child = -1;
    for (int c = n - 1; c > j; --c) child = body[c].parent == j ? c : child;
    const glm::vec3 from = child >= 0 ? body[j].position : body[body[j].parent].position;
    const glm::vec3 to = child >= 0 ? body[child].position : body[j].position;
    if (body[j].name.ends_with("_L")) {
      const int second = (style.bone_axis + 1) % 3;
      frames[j] = frame_along(style.bone_axis, to - from, second, {0.3f, 0.2f, 1.0f});
    } else {
      const int lateral = j == 0 ? style.hips_lateral_axis : style.chain_lateral_axis;
      frames[j] = frame_along(style.bone_axis, to - from, lateral, {1, 0, 0});
    }
  }
  for (int j = first_right; j < n; ++j) {
    frames[j] = kReflect * frames[j - kSideJoints] * style.right_convention;
  }
  return frames;
}

// Local rest transforms from world rest positions and rotations.
std::vector<Transform> local_rest(const std::vector<BodyJoint>& body,
                                  const std::vector<glm::mat3>& frames) {
  std::vector<Transform> rest(body.size());
  for (size_t j = 0; j < body.size(); ++j) {
    const int p = body[j].parent;
    const glm::mat3 parent = p < 0 ? glm::mat3(1.0f) : frames[p];
    const glm::vec3 origin = p < 0 ? glm::vec3(0.0f) : body[p].position;
    rest[j].rotation = glm::normalize(glm::quat_cast(glm::transpose(parent) * frames[j]));
    rest[j].translation = glm::transpose(parent) * (body[j].position - origin);
  }
  return rest;
}

Skeleton make_skeleton(const std::vector<BodyJoint>& body, std::vector<Transform> rest) {
  std::vector<std::string> names;
  std::vector<int> parents;
  for (const BodyJoint& b : body) {
    names.push_back(b.name);
    parents.push_back(b.parent);
  }
  Result<Skeleton> sk = Skeleton::create(names, parents, std::move(rest));
  EXPECT_TRUE(sk) << sk.message();
  return *sk;
}

// The standing biped in `style`, its rest pose the standing pose.
Skeleton standing_skeleton(const AxisStyle& style) {
  const std::vector<BodyJoint> body = standing_biped();
  return make_skeleton(body, local_rest(body, world_frames(body, style)));
}

// The Bandai layout: the offsets of the standing biped with bones along X, but every rest
// rotation identity, so the rest pose lays every bone along X and is no pose at all.
Skeleton identity_rest_skeleton() {
  std::vector<Transform> rest = standing_skeleton(kAlongX).rest();
  for (Transform& t : rest) t.rotation = glm::quat(1, 0, 0, 0);
  return make_skeleton(standing_biped(), std::move(rest));
}

// A clip of `frames` frames: every joint at `base` (local transforms) turned by a small
// rotation that changes from frame to frame, the root walking forward while turning left.
Clip animated_clip(const Skeleton& skeleton, const std::vector<Transform>& base, int frames) {
  Clip clip;
  clip.name = "synthetic";
  clip.skeleton = skeleton;
  clip.frame_count = frames;
  const int joints = skeleton.joint_count();
  clip.local.resize(static_cast<size_t>(frames) * joints);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<glm::vec3> axes(joints);
  for (glm::vec3& a : axes) a = glm::normalize(glm::vec3(unit(random), unit(random), unit(random)));
  for (int f = 0; f < frames; ++f) {
    std::span<Transform> pose = clip.pose(f);
    for (int j = 0; j < joints; ++j) {
      pose[j] = base[j];
      const float angle = 0.4f * std::sin(0.3f * f + j);
      pose[j].rotation = base[j].rotation * glm::angleAxis(angle, axes[j]);
    }
    const glm::quat yaw = glm::angleAxis(0.05f * f, glm::vec3(0, 1, 0));  // left turn
    pose[0].rotation = yaw * pose[0].rotation;
    pose[0].translation = base[0].translation + glm::vec3(0.02f * f, 0.0f, 0.03f * f);
  }
  return clip;
}

// The standing pose of the identity-rest skeleton: the standing skeleton's rest locals.
std::vector<Transform> standing_pose() {
  return standing_skeleton(kAlongX).rest();
}

std::vector<int> joint_map(const Skeleton& skeleton) {
  Result<std::vector<int>> map = mirror_joint_map(skeleton);
  EXPECT_TRUE(map) << map.message();
  return *map;
}

std::vector<Transform> globals_of(const Clip& clip, int frame) {
  std::vector<Transform> g(clip.joint_count());
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), g);
  return g;
}

// The angle of the rotation between a and b, accurate for tiny angles too.
float angle_between(const glm::quat& a, const glm::quat& b) {
  const glm::quat d = glm::conjugate(b) * a;
  return 2.0f * std::atan2(glm::length(glm::vec3(d.x, d.y, d.z)), std::abs(d.w));
}

// Each synthetic skeleton with the pose it is symmetric in.
struct Case {
  std::string label;
  Skeleton skeleton;
  std::vector<Transform> symmetric_pose;  // local transforms
};

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const AxisStyle* style : {&kAlongX, &kAlongY, &kAlongZ}) {
    Skeleton sk = standing_skeleton(*style);
    std::vector<Transform> rest = sk.rest();
    out.push_back({style->label, std::move(sk), std::move(rest)});
  }
  out.push_back({"along X, identity rest", identity_rest_skeleton(), standing_pose()});
  return out;
}

// ---- Synthetic tests ---------------------------------------------------------------------------

TEST(MirrorCorrections, IdentityWhereTheRestFramesAreAlreadyMirrorImages) {
  // Bones along Y, right frames the mirror images of the left ones, centre frames with local X
  // lateral: the plain reflection already keeps every joint's convention.
  const Skeleton sk = standing_skeleton(kAlongY);
  const std::vector<glm::quat> c = mirror_corrections(sk, joint_map(sk));
  ASSERT_EQ(static_cast<int>(c.size()), sk.joint_count());
  for (int j = 0; j < sk.joint_count(); ++j) {
    EXPECT_LT(angle_between(c[j], glm::quat(1, 0, 0, 0)), 1e-4f) << sk.name(j);
  }
  // With bones along X the hips' and the spine's lateral axes are not local X, and a right
  // limb's axes are all flipped: those joints need a correction.
  const Skeleton x = standing_skeleton(kAlongX);
  const std::vector<glm::quat> cx = mirror_corrections(x, joint_map(x));
  for (const char* name : {"Hips", "Spine", "Head", "UpperArm_L", "Foot_R"}) {
    EXPECT_GT(angle_between(cx[x.find(name)], glm::quat(1, 0, 0, 0)), 3.0f) << name;
  }
}

TEST(Mirror, TheSymmetricPoseMirrorsToItself) {
  for (const Case& c : cases()) {
    Clip still = animated_clip(c.skeleton, c.symmetric_pose, 1);
    std::copy(c.symmetric_pose.begin(), c.symmetric_pose.end(), still.pose(0).begin());
    const Clip mirrored = mirror_clip(still, joint_map(c.skeleton));
    for (int j = 0; j < still.joint_count(); ++j) {
      const Transform& m = mirrored.pose(0)[j];
      const Transform& expected = c.symmetric_pose[j];
      EXPECT_LT(angle_between(m.rotation, expected.rotation), 1e-5f)
          << c.label << " " << c.skeleton.name(j);
      EXPECT_LT(glm::distance(m.translation, expected.translation), 1e-5f)
          << c.label << " " << c.skeleton.name(j);
    }
  }
}

TEST(Mirror, MirroringTwiceGivesTheClipBack) {
  for (const Case& c : cases()) {
    const std::vector<int> map = joint_map(c.skeleton);
    const Clip clip = animated_clip(c.skeleton, c.symmetric_pose, 20);
    const Clip twice = mirror_clip(mirror_clip(clip, map), map);
    for (int f = 0; f < clip.frame_count; ++f) {
      const std::vector<Transform> g = globals_of(clip, f), g2 = globals_of(twice, f);
      for (int j = 0; j < clip.joint_count(); ++j) {
        EXPECT_LT(glm::distance(g[j].translation, g2[j].translation), 1e-5f) << c.label << f;
        EXPECT_LT(angle_between(clip.pose(f)[j].rotation, twice.pose(f)[j].rotation), 1e-5f)
            << c.label << " " << f << " " << c.skeleton.name(j);
      }
    }
  }
}

TEST(Mirror, LeftTurnBecomesTheReflectedPositionsWithSidesSwapped) {
  for (const Case& c : cases()) {
    const std::vector<int> map = joint_map(c.skeleton);
    const Clip clip = animated_clip(c.skeleton, c.symmetric_pose, 20);
    const Clip mirrored = mirror_clip(clip, map);
    for (int f = 0; f < clip.frame_count; ++f) {
      const std::vector<Transform> g = globals_of(clip, f), m = globals_of(mirrored, f);
      for (int j = 0; j < clip.joint_count(); ++j) {
        const glm::vec3 expected = kReflect * g[map[j]].translation;
        EXPECT_LT(glm::distance(m[j].translation, expected), 1e-5f)
            << c.label << " " << f << " " << c.skeleton.name(j);
      }
    }
  }
}

TEST(Mirror, LocalRotationsStayAsFarFromTheSymmetricPoseAsThePartners) {
  // No half turns: a mirrored joint is exactly as far from its symmetric-pose rotation as the
  // partner it copies is from its own, on every frame.
  for (const Case& c : cases()) {
    const std::vector<int> map = joint_map(c.skeleton);
    const Clip clip = animated_clip(c.skeleton, c.symmetric_pose, 20);
    const Clip mirrored = mirror_clip(clip, map);
    for (int f = 0; f < clip.frame_count; ++f) {
      for (int j = 1; j < clip.joint_count(); ++j) {  // the root carries the turn
        const float original =
            angle_between(clip.pose(f)[map[j]].rotation, c.symmetric_pose[map[j]].rotation);
        const float mirror =
            angle_between(mirrored.pose(f)[j].rotation, c.symmetric_pose[j].rotation);
        EXPECT_NEAR(mirror, original, 1e-4f) << c.label << " " << f << " " << c.skeleton.name(j);
      }
    }
  }
}

// ---- Real clips --------------------------------------------------------------------------------

// The mean of a joint's local rotations over a clip (signs aligned with the first frame's).
glm::quat mean_local_rotation(const Clip& clip, int joint) {
  const glm::quat first = clip.pose(0)[joint].rotation;
  glm::vec4 sum(0.0f);
  for (int f = 0; f < clip.frame_count; ++f) {
    const glm::quat q = clip.pose(f)[joint].rotation;
    const float sign = glm::dot(q, first) < 0.0f ? -1.0f : 1.0f;
    sum += sign * glm::vec4(q.w, q.x, q.y, q.z);
  }
  sum = glm::normalize(sum);
  return glm::quat(sum.x, sum.y, sum.z, sum.w);
}

TEST(MirrorRealClips, AMirroredLeftTurnReflectsPositionsAndKeepsTheDatasLocalFrames) {
  Result<Clip> left = load_bvh(test::clip_path("dataset-2_walk-turn-left_normal_001"));
  Result<Clip> right = load_bvh(test::clip_path("dataset-2_walk-turn-right_normal_001"));
  ASSERT_TRUE(left) << left.message();
  ASSERT_TRUE(right) << right.message();
  const std::vector<int> map = joint_map(left->skeleton);
  const Clip mirrored = mirror_clip(*left, map);
  ASSERT_TRUE(mirrored.validate()) << mirrored.validate().message();
  for (int f = 0; f < left->frame_count; ++f) {
    const std::vector<Transform> g = globals_of(*left, f), m = globals_of(mirrored, f);
    for (int j = 0; j < left->joint_count(); ++j) {
      EXPECT_LT(glm::distance(m[j].translation, kReflect * g[map[j]].translation), 1e-5f)
          << f << " " << left->skeleton.name(j);
    }
  }
  // Every joint's local rotations look like a real right turn's: on average within the spread
  // between takes (a half turn, or a frame flipped about its bone, is far outside it). The hips
  // are left out: their local rotation is the world heading, which depends on the take.
  for (int j = 0; j < left->joint_count(); ++j) {
    if (left->skeleton.name(j) == "Hips") continue;
    const float degrees = glm::degrees(
        angle_between(mean_local_rotation(mirrored, j), mean_local_rotation(*right, j)));
    EXPECT_LT(degrees, 20.0f) << left->skeleton.name(j);
  }
}

}  // namespace
}  // namespace mm
