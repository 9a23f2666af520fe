#include "mm/offline/character_body.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>

#include "mm/offline/gltf.hpp"
#include "mm/offline/idle.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {
namespace {

const glm::vec3 kUp(0.0f, 1.0f, 0.0f);
const glm::vec3 kLateral(1.0f, 0.0f, 0.0f);  // the character's left in the bind pose
const glm::vec3 kForward(0.0f, 0.0f, 1.0f);

// The hips height of the adult the radii below are measured on (metres).
constexpr float kReferenceHipsHeight = 0.92f;

// ---------------------------------------------------------------------------------------------
// Hierarchy helpers

bool is_ancestor(const Skeleton& skeleton, int ancestor, int joint) {
  for (int p = skeleton.parent(joint); p >= 0; p = skeleton.parent(p)) {
    if (p == ancestor) return true;
  }
  return false;
}

// The joints strictly below `ancestor` down to `joint` inclusive, top-down (empty when
// `ancestor` is not an ancestor of `joint`).
std::vector<int> chain_below(const Skeleton& skeleton, int ancestor, int joint) {
  std::vector<int> chain;
  for (int j = joint; j >= 0 && j != ancestor; j = skeleton.parent(j)) chain.push_back(j);
  if (chain.empty() || skeleton.parent(chain.back()) != ancestor) return {};
  std::reverse(chain.begin(), chain.end());
  return chain;
}

glm::vec3 horizontal(const glm::vec3& v) {
  return {v.x, 0.0f, v.z};
}

glm::vec3 unit_or(const glm::vec3& v, const glm::vec3& fallback) {
  const float len = glm::length(v);
  return len > 1e-6f ? v / len : fallback;
}

// The shortest rotation taking unit vector `from` to unit vector `to`; half a turn about
// `axis` when they are opposite.
glm::quat rotation_between(const glm::vec3& from, const glm::vec3& to, const glm::vec3& axis) {
  if (glm::dot(from, to) < -0.9999f) return glm::angleAxis(glm::pi<float>(), axis);
  return glm::rotation(from, to);
}

// Where the limbs are, found from the roles.
struct Limbs {
  std::vector<int> spine;              // hips down to head, top-down; empty without both
  std::vector<std::vector<int>> arms;  // each from the spine's child down to an arm end
  std::vector<std::vector<int>> legs;  // each from the hips' child down to a foot
};

Limbs find_limbs(const Skeleton& skeleton, const JointRoleIndices& roles) {
  Limbs limbs;
  const int hips = roles.hips, head = roles.head;
  if (hips >= 0 && head >= 0 && is_ancestor(skeleton, hips, head)) {
    limbs.spine.push_back(hips);
    for (int j : chain_below(skeleton, hips, head)) limbs.spine.push_back(j);
  }
  for (int foot : {roles.left_foot, roles.right_foot}) {
    if (hips >= 0 && foot >= 0 && is_ancestor(skeleton, hips, foot)) {
      limbs.legs.push_back(chain_below(skeleton, hips, foot));
    }
  }
  for (int end : arm_end_joints(skeleton, roles)) {
    int branch = skeleton.parent(end);
    while (branch >= 0 &&
           std::find(limbs.spine.begin(), limbs.spine.end(), branch) == limbs.spine.end()) {
      branch = skeleton.parent(branch);
    }
    if (branch < 0) continue;
    std::vector<int> chain = chain_below(skeleton, branch, end);
    // Finger tips of one hand share the chain's start: keep the first.
    const bool known = std::any_of(limbs.arms.begin(), limbs.arms.end(),
                                   [&](const std::vector<int>& a) { return a[0] == chain[0]; });
    if (!known) limbs.arms.push_back(std::move(chain));
  }
  return limbs;
}

// The joints of an arm chain that play upper arm, lower arm and hand (and the clavicle before
// them when the chain has one), or nothing for chains too short to tell. A chain that ends at a
// lower arm role belongs to a skeleton without hands (ReActIdle's): it has no hand.
struct ArmJoints {
  int clavicle = -1, upper = -1, lower = -1, hand = -1;
};
ArmJoints arm_joints(const std::vector<int>& chain, const JointRoleIndices& roles) {
  ArmJoints a;
  const size_t n = chain.size();
  if (n >= 2 && (chain.back() == roles.left_lower_arm || chain.back() == roles.right_lower_arm)) {
    a = {n >= 3 ? chain[n - 3] : -1, chain[n - 2], chain[n - 1], -1};
  } else if (n >= 4) {
    a = {chain[0], chain[1], chain[2], chain[3]};
  } else if (chain.size() == 3) {
    a = {-1, chain[0], chain[1], chain[2]};
  }
  return a;
}

struct LegJoints {
  int thigh = -1, shin = -1, foot = -1;
};
LegJoints leg_joints(const std::vector<int>& chain) {
  const size_t n = chain.size();
  if (n < 3) return {};
  return {chain[n - 3], chain[n - 2], chain[n - 1]};
}

// ---------------------------------------------------------------------------------------------
// Bind pose, on global transforms

// Turns joint `joint` and everything below it by `rotation` about `pivot`.
void rotate_subtree(std::vector<Transform>& global, const Skeleton& skeleton, int joint,
                    const glm::quat& rotation, const glm::vec3& pivot) {
  for (int k = joint; k < skeleton.joint_count(); ++k) {
    if (k != joint && !is_ancestor(skeleton, joint, k)) continue;
    Transform& t = global[static_cast<size_t>(k)];
    t.rotation = glm::normalize(rotation * t.rotation);
    t.translation = pivot + rotation * (t.translation - pivot);
  }
}

// Turns `joint` (and its subtree) about itself so that its child lies in direction `dir`.
void aim(std::vector<Transform>& global, const Skeleton& skeleton, int joint, int child,
         const glm::vec3& dir) {
  const glm::vec3 from = global[static_cast<size_t>(joint)].translation;
  const glm::vec3 bone = global[static_cast<size_t>(child)].translation - from;
  if (glm::length(bone) < 1e-6f) return;
  rotate_subtree(global, skeleton, joint, rotation_between(glm::normalize(bone), dir, kForward),
                 from);
}

// The direction of a leaf bone (a lower arm without a hand), which has no child to point to: the
// axis of its own frame that its parent's bone runs along in the parent's frame. Rigs keep one
// convention for every bone (along local Y in Blender's, X in Bandai's), so this is its bone.
glm::vec3 leaf_direction(std::span<const Transform> global, int parent, int joint) {
  const Transform& p = global[static_cast<size_t>(parent)];
  const Transform& j = global[static_cast<size_t>(joint)];
  const glm::vec3 bone = j.translation - p.translation;
  if (glm::length(bone) < 1e-6f) return -kUp;
  return glm::normalize(j.rotation * (glm::inverse(p.rotation) * glm::normalize(bone)));
}

// Turns the pose about the vertical through the hips so that the right thigh -> left thigh
// axis is +X, and moves it so that the hips are above the origin.
void face_forward_at_origin(std::vector<Transform>& global, const Skeleton& skeleton,
                            const JointRoleIndices& roles, const Limbs& limbs) {
  if (roles.hips < 0) return;
  if (limbs.legs.size() == 2) {
    const int left = limbs.legs[0][0], right = limbs.legs[1][0];
    const glm::vec3 lateral = horizontal(global[static_cast<size_t>(left)].translation -
                                         global[static_cast<size_t>(right)].translation);
    if (glm::length(lateral) > 1e-4f) {
      const glm::quat turn = rotation_between(glm::normalize(lateral), kLateral, kUp);
      for (int root = 0; root < skeleton.joint_count(); ++root) {
        if (skeleton.parent(root) < 0) {
          rotate_subtree(global, skeleton, root, turn,
                         global[static_cast<size_t>(roles.hips)].translation);
        }
      }
    }
  }
  const glm::vec3 shift = -horizontal(global[static_cast<size_t>(roles.hips)].translation);
  for (Transform& t : global) t.translation += shift;
}

// The lowest height of any joint in a foot's subtree (the foot and its toes).
float lowest_foot_height(const std::vector<Transform>& global, const Skeleton& skeleton,
                         const Limbs& limbs) {
  float lowest = std::numeric_limits<float>::infinity();
  for (const std::vector<int>& leg : limbs.legs) {
    const int foot = leg.back();
    for (int k = foot; k < skeleton.joint_count(); ++k) {
      if (k == foot || is_ancestor(skeleton, foot, k)) {
        lowest = std::min(lowest, global[static_cast<size_t>(k)].translation.y);
      }
    }
  }
  return lowest;
}

// +1 for a limb on the character's left (+X of the hips), -1 on its right.
float side_of(const std::vector<Transform>& global, const JointRoleIndices& roles, int joint) {
  const float hips_x =
      roles.hips >= 0 ? global[static_cast<size_t>(roles.hips)].translation.x : 0.0f;
  return global[static_cast<size_t>(joint)].translation.x >= hips_x ? 1.0f : -1.0f;
}

void pose_arms(std::vector<Transform>& global, const Skeleton& skeleton,
               const JointRoleIndices& roles, const Limbs& limbs, float angle) {
  for (const std::vector<int>& chain : limbs.arms) {
    const ArmJoints arm = arm_joints(chain, roles);
    if (arm.upper < 0) continue;
    const float side = side_of(global, roles, arm.upper);
    const glm::vec3 dir(side * std::cos(angle), -std::sin(angle), 0.0f);
    aim(global, skeleton, arm.upper, arm.lower, dir);
    if (arm.hand >= 0) {
      aim(global, skeleton, arm.lower, arm.hand, dir);
    } else {
      const glm::vec3& elbow = global[static_cast<size_t>(arm.lower)].translation;
      rotate_subtree(global, skeleton, arm.lower,
                     rotation_between(leaf_direction(global, arm.upper, arm.lower), dir, kForward),
                     elbow);
    }
  }
}

// Straight legs spread by `angle`; each foot keeps its orientation, so it stays flat.
void pose_legs(std::vector<Transform>& global, const Skeleton& skeleton,
               const JointRoleIndices& roles, const Limbs& limbs, float angle) {
  for (const std::vector<int>& chain : limbs.legs) {
    const LegJoints leg = leg_joints(chain);
    if (leg.thigh < 0) continue;
    const float side = side_of(global, roles, leg.thigh);
    const glm::vec3 dir(side * std::sin(angle), -std::cos(angle), 0.0f);
    const glm::quat foot_rotation = global[static_cast<size_t>(leg.foot)].rotation;
    aim(global, skeleton, leg.thigh, leg.shin, dir);
    aim(global, skeleton, leg.shin, leg.foot, dir);
    const Transform& foot = global[static_cast<size_t>(leg.foot)];
    rotate_subtree(global, skeleton, leg.foot, foot_rotation * glm::inverse(foot.rotation),
                   foot.translation);
  }
}

std::vector<Transform> locals_of(const Skeleton& skeleton, const std::vector<Transform>& global) {
  std::vector<Transform> local(global.size());
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const int p = skeleton.parent(j);
    local[static_cast<size_t>(j)] =
        p < 0 ? global[static_cast<size_t>(j)]
              : compose(inverse(global[static_cast<size_t>(p)]), global[static_cast<size_t>(j)]);
    local[static_cast<size_t>(j)].rotation = glm::normalize(local[static_cast<size_t>(j)].rotation);
  }
  return local;
}

// ---------------------------------------------------------------------------------------------
// Bone segments

// A capsule's radii (metres, for the reference adult) and, for the torso, the half distance
// between the two capsules laid side by side along X.
struct Shape {
  float head_radius = 0.0f;
  float tail_radius = 0.0f;
  float head_half_width = 0.0f;
  float tail_half_width = 0.0f;
};

// The torso along the spine, by height fraction u (0 at the hips, 1 at the head joint):
// pelvis, waist, chest, neck.
Shape torso_at(float u) {
  struct Key {
    float u, radius, half_width;
  };
  static constexpr Key keys[] = {{0.00f, 0.100f, 0.045f},
                                 {0.35f, 0.092f, 0.045f},
                                 {0.60f, 0.105f, 0.050f},
                                 {0.85f, 0.050f, 0.000f},
                                 {1.00f, 0.050f, 0.000f}};
  u = std::clamp(u, 0.0f, 1.0f);
  size_t k = 0;
  while (k + 2 < std::size(keys) && u > keys[k + 1].u) ++k;
  const float t = (u - keys[k].u) / (keys[k + 1].u - keys[k].u);
  Shape s;
  s.head_radius = s.tail_radius = glm::mix(keys[k].radius, keys[k + 1].radius, t);
  s.head_half_width = s.tail_half_width = glm::mix(keys[k].half_width, keys[k + 1].half_width, t);
  return s;
}

constexpr Shape kClavicleBase{0.070f, 0.060f};  // spine -> clavicle
constexpr Shape kClavicle{0.060f, 0.052f};      // clavicle -> upper arm
constexpr Shape kUpperArm{0.050f, 0.040f};
constexpr Shape kLowerArm{0.040f, 0.030f};
constexpr Shape kHand{0.032f, 0.025f};
constexpr float kHandLength = 0.12f;
constexpr Shape kHip{0.090f, 0.080f};  // hips -> thigh
constexpr Shape kThigh{0.075f, 0.052f};
constexpr Shape kShin{0.050f, 0.040f};
constexpr Shape kFoot{0.040f, 0.030f};
constexpr Shape kHeel{0.040f, 0.035f};
constexpr glm::vec3 kHeelOffset{0.0f, -0.075f, -0.025f};
constexpr Shape kToe{0.030f, 0.022f};
constexpr float kToeLength = 0.06f;
constexpr float kFootLength = 0.15f;  // for a foot without toes
// Thicker than the torso's end at the neck, so the neck's own joint is nearest there.
constexpr Shape kNeck{0.056f, 0.052f};
constexpr Shape kHead{0.090f, 0.090f};
constexpr float kHeadStart = 0.09f, kHeadEnd = 0.12f;  // along the neck, from the head joint

// What a joint is to the body.
enum class Part {
  Other,
  None,
  Spine,
  Head,
  Clavicle,
  UpperArm,
  LowerArm,
  Hand,
  Thigh,
  Shin,
  Foot,
  Toe
};

struct SegmentBuilder {
  const Skeleton& skeleton;
  std::span<const Transform> global;
  float scale = 1.0f;
  float min_radius = 0.0f;
  std::vector<BoneSegment> segments;

  glm::vec3 at(int joint) const { return global[static_cast<size_t>(joint)].translation; }

  void add(int joint, const glm::vec3& a, const glm::vec3& b, const Shape& shape) {
    auto segment = [&](float head_offset, float tail_offset) {
      BoneSegment s;
      s.head = a + kLateral * (head_offset * scale);
      s.tail = b + kLateral * (tail_offset * scale);
      s.head_radius = std::max(shape.head_radius * scale, min_radius);
      s.tail_radius = std::max(shape.tail_radius * scale, min_radius);
      s.joint = joint;
      segments.push_back(s);
    };
    if (shape.head_half_width > 0.0f || shape.tail_half_width > 0.0f) {
      segment(shape.head_half_width, shape.tail_half_width);
      segment(-shape.head_half_width, -shape.tail_half_width);
    } else {
      segment(0.0f, 0.0f);
    }
  }

  // A capsule to a child whose radius follows the bone's length (in metres, not scaled).
  void add_by_length(int joint, int child) {
    const float length = glm::distance(at(joint), at(child));
    if (length < 1e-4f) return;
    const float radius = std::min(0.2f * length, 0.1f * scale);
    Shape shape{radius / scale, 0.8f * radius / scale};
    add(joint, at(joint), at(child), shape);
  }

  // A capsule from the joint onward along `dir` (for leaves that have no length).
  void add_extension(int joint, const glm::vec3& dir, float length, const Shape& shape) {
    add(joint, at(joint), at(joint) + dir * (length * scale), shape);
  }
};

std::vector<Part> classify(const Skeleton& skeleton, const JointRoleIndices& roles,
                           const Limbs& limbs) {
  std::vector<Part> part(static_cast<size_t>(skeleton.joint_count()), Part::Other);
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const bool above_hips = roles.hips >= 0 && is_ancestor(skeleton, j, roles.hips);
    const bool below_head = roles.head >= 0 && is_ancestor(skeleton, roles.head, j);
    if (above_hips || below_head) part[static_cast<size_t>(j)] = Part::None;
  }
  for (int j : limbs.spine) part[static_cast<size_t>(j)] = Part::Spine;
  if (roles.head >= 0) part[static_cast<size_t>(roles.head)] = Part::Head;
  for (const std::vector<int>& chain : limbs.arms) {
    const ArmJoints a = arm_joints(chain, roles);
    if (a.clavicle >= 0) part[static_cast<size_t>(a.clavicle)] = Part::Clavicle;
    if (a.upper < 0) continue;
    part[static_cast<size_t>(a.upper)] = Part::UpperArm;
    part[static_cast<size_t>(a.lower)] = Part::LowerArm;
    if (a.hand >= 0) part[static_cast<size_t>(a.hand)] = Part::Hand;
  }
  for (const std::vector<int>& chain : limbs.legs) {
    const LegJoints l = leg_joints(chain);
    if (l.thigh < 0) continue;
    part[static_cast<size_t>(l.thigh)] = Part::Thigh;
    part[static_cast<size_t>(l.shin)] = Part::Shin;
    part[static_cast<size_t>(l.foot)] = Part::Foot;
  }
  for (int toe : {roles.left_toe, roles.right_toe}) {
    const int parent = toe >= 0 ? skeleton.parent(toe) : -1;
    if (parent >= 0 && part[static_cast<size_t>(parent)] == Part::Foot) {
      part[static_cast<size_t>(toe)] = Part::Toe;
    }
  }
  return part;
}

std::vector<int> children_of(const Skeleton& skeleton, int joint) {
  std::vector<int> children;
  for (int k = joint + 1; k < skeleton.joint_count(); ++k) {
    if (skeleton.parent(k) == joint) children.push_back(k);
  }
  return children;
}

// The spine joint's capsules: the torso to the next spine joint, and the roots of the limbs
// that branch off it.
void add_spine(SegmentBuilder& b, const std::vector<Part>& part, const std::vector<int>& spine,
               int joint) {
  const float bottom = b.at(spine.front()).y;
  const float height = std::max(b.at(spine.back()).y - bottom, 1e-3f);
  for (int child : children_of(b.skeleton, joint)) {
    const Part p = part[static_cast<size_t>(child)];
    if (p == Part::Head) {
      b.add(joint, b.at(joint), b.at(child), kNeck);
    } else if (p == Part::Spine) {
      Shape shape = torso_at((b.at(joint).y - bottom) / height);
      const Shape tail = torso_at((b.at(child).y - bottom) / height);
      shape.tail_radius = tail.tail_radius;
      shape.tail_half_width = tail.tail_half_width;
      b.add(joint, b.at(joint), b.at(child), shape);
    } else if (p == Part::Clavicle || p == Part::UpperArm) {
      b.add(joint, b.at(joint), b.at(child), kClavicleBase);
    } else if (p == Part::Thigh) {
      b.add(joint, b.at(joint), b.at(child), kHip);
    } else if (p != Part::None) {
      b.add_by_length(joint, child);
    }
  }
}

// The capsules of one joint by its part.
void add_joint(SegmentBuilder& b, const std::vector<Part>& part, const Limbs& limbs, int joint) {
  const Skeleton& skeleton = b.skeleton;
  const int parent = skeleton.parent(joint);
  const glm::vec3 from_parent = parent >= 0 ? unit_or(b.at(joint) - b.at(parent), kUp) : kUp;
  const std::vector<int> children = children_of(skeleton, joint);
  auto first_child_with = [&](Part p) {
    for (int c : children) {
      if (part[static_cast<size_t>(c)] == p) return c;
    }
    return -1;
  };
  auto to_child = [&](Part p, const Shape& shape) {
    const int c = first_child_with(p);
    if (c >= 0) b.add(joint, b.at(joint), b.at(c), shape);
    for (int other : children) {
      if (other != c) b.add_by_length(joint, other);
    }
  };
  switch (part[static_cast<size_t>(joint)]) {
    case Part::None:
      return;
    case Part::Spine:
      return add_spine(b, part, limbs.spine, joint);
    case Part::Head:
      b.add(joint, b.at(joint) + from_parent * (kHeadStart * b.scale),
            b.at(joint) + from_parent * (kHeadEnd * b.scale), kHead);
      return;
    case Part::Clavicle:
      return to_child(Part::UpperArm, kClavicle);
    case Part::UpperArm:
      return to_child(Part::LowerArm, kUpperArm);
    case Part::LowerArm:
      if (first_child_with(Part::Hand) < 0 && parent >= 0) {
        // No hand (a skeleton without): the forearm as long as the upper arm, and a hand.
        const glm::vec3 along = leaf_direction(b.global, parent, joint);
        const float forearm = glm::distance(b.at(parent), b.at(joint));
        b.add(joint, b.at(joint), b.at(joint) + along * forearm, kLowerArm);
        b.add(joint, b.at(joint) + along * forearm,
              b.at(joint) + along * (forearm + kHandLength * b.scale), kHand);
      }
      return to_child(Part::Hand, kLowerArm);
    case Part::Hand:
      b.add_extension(joint, from_parent, kHandLength, kHand);
      for (int c : children) b.add_by_length(joint, c);
      return;
    case Part::Thigh:
      return to_child(Part::Shin, kThigh);
    case Part::Shin:
      return to_child(Part::Foot, kShin);
    case Part::Foot:
      b.add(joint, b.at(joint), b.at(joint) + kHeelOffset * b.scale, kHeel);
      if (children.empty()) return b.add_extension(joint, kForward, kFootLength, kFoot);
      for (int c : children) b.add(joint, b.at(joint), b.at(c), kFoot);
      return;
    case Part::Toe:
      if (children.empty()) {
        return b.add_extension(joint, unit_or(horizontal(from_parent), kForward), kToeLength, kToe);
      }
      for (int c : children) b.add_by_length(joint, c);
      return;
    case Part::Other:
      for (int c : children) b.add_by_length(joint, c);
      return;
  }
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Status validate_roles(const Skeleton& skeleton, const JointRoleIndices& roles) {
  for (const JointRoleInfo& role : kJointRoles) {
    const int joint = roles.*role.index;
    if (joint < -1 || joint >= skeleton.joint_count()) {
      return Error{"character body: the " + std::string(role.name) + " role is joint " +
                   std::to_string(joint) + ", out of range (the skeleton has " +
                   std::to_string(skeleton.joint_count()) + " joints)"};
    }
  }
  return Status::success();
}

}  // namespace

int bind_source_frame(const DatabaseView& db) {
  if (db.frame_count <= 0) return -1;
  if (const int idle = find_idle_clip(db); idle >= 0)
    return db.clips[static_cast<size_t>(idle)].start;
  if (const int calm = find_calmest_standing_frame(db); calm >= 0) return calm;
  return 0;
}

std::vector<Transform> make_bind_pose(const Skeleton& skeleton, std::span<const Transform> local,
                                      const JointRoleIndices& roles,
                                      const BindPoseOptions& options) {
  std::vector<Transform> global(local.size());
  if (local.size() != static_cast<size_t>(skeleton.joint_count()) ||
      !validate_roles(skeleton, roles)) {
    return {local.begin(), local.end()};
  }
  forward_kinematics(skeleton.parents(), local, global);
  const Limbs limbs = find_limbs(skeleton, roles);
  face_forward_at_origin(global, skeleton, roles, limbs);

  const float feet_before = lowest_foot_height(global, skeleton, limbs);
  pose_arms(global, skeleton, roles, limbs, glm::radians(options.arm_angle_degrees));
  pose_legs(global, skeleton, roles, limbs, glm::radians(options.leg_angle_degrees));
  const float feet_after = lowest_foot_height(global, skeleton, limbs);
  if (std::isfinite(feet_before) && std::isfinite(feet_after)) {
    for (Transform& t : global) t.translation.y += feet_before - feet_after;
  }
  // The joints above the hips carry no geometry: the origin, facing +Z.
  for (int j = 0; j < skeleton.joint_count() && roles.hips >= 0; ++j) {
    if (is_ancestor(skeleton, j, roles.hips)) global[static_cast<size_t>(j)] = Transform{};
  }
  return locals_of(skeleton, global);
}

std::vector<BoneSegment> character_bone_segments(const Skeleton& skeleton,
                                                 std::span<const Transform> bind_global,
                                                 const JointRoleIndices& roles, float min_radius) {
  if (bind_global.size() != static_cast<size_t>(skeleton.joint_count()) ||
      !validate_roles(skeleton, roles)) {
    return {};
  }
  SegmentBuilder builder{skeleton, bind_global, 1.0f, min_radius, {}};
  if (roles.hips >= 0) {
    const float hips_height = bind_global[static_cast<size_t>(roles.hips)].translation.y;
    if (hips_height > 0.05f && std::isfinite(hips_height)) {
      builder.scale = hips_height / kReferenceHipsHeight;
    }
  }
  const Limbs limbs = find_limbs(skeleton, roles);
  const std::vector<Part> part = classify(skeleton, roles, limbs);
  for (int j = 0; j < skeleton.joint_count(); ++j) add_joint(builder, part, limbs, j);
  return std::move(builder.segments);
}

Result<CharacterBody> build_character_body(const Skeleton& skeleton,
                                           std::span<const Transform> bind_local,
                                           const JointRoleIndices& roles,
                                           const CharacterBodyOptions& options) {
  const size_t joints = static_cast<size_t>(skeleton.joint_count());
  if (bind_local.size() != joints) {
    return Error{"character body: the bind pose has " + std::to_string(bind_local.size()) +
                 " transforms for a skeleton of " + std::to_string(joints) + " joints"};
  }
  if (Status s = validate_roles(skeleton, roles); !s) return Error{s.message()};
  CharacterBody body;
  body.bind_local.assign(bind_local.begin(), bind_local.end());
  body.skinned.bind_global.resize(joints);
  forward_kinematics(skeleton.parents(), bind_local, body.skinned.bind_global);
  body.segments =
      character_bone_segments(skeleton, body.skinned.bind_global, roles, options.mesh.voxel_size);
  if (body.segments.empty()) {
    return Error{"character body: no bone of the skeleton has any length to build a body around"};
  }

  auto start = std::chrono::steady_clock::now();
  Result<TriangleMesh> mesh = generate_body_mesh(body.segments, options.mesh);
  if (!mesh) return Error{"character body: " + mesh.message()};
  body.mesh_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  Result<std::vector<VertexInfluences>> weights =
      compute_bone_weights(*mesh, body.segments, options.weights);
  if (!weights) return Error{"character body: " + weights.message()};
  body.weight_seconds = seconds_since(start);
  body.skinned.mesh = std::move(*mesh);
  body.skinned.influences = std::move(*weights);
  return body;
}

Result<CharacterBody> build_character_body(const DatabaseView& db,
                                           const CharacterBodyOptions& options) {
  const int frame = bind_source_frame(db);
  if (frame < 0) return Error{"character body: the database has no frames to take a pose from"};
  const int joints = db.joint_count();
  std::vector<Transform> local(static_cast<size_t>(joints));
  for (int j = 0; j < joints; ++j) {
    const size_t i =
        static_cast<size_t>(frame) * static_cast<size_t>(joints) + static_cast<size_t>(j);
    local[static_cast<size_t>(j)].translation = db.local_positions[i];
    local[static_cast<size_t>(j)].rotation = db.local_rotations[i];
  }
  local[0] = Transform{};  // the simulation root: the character at the origin, facing +Z
  const std::vector<Transform> bind = make_bind_pose(db.skeleton, local, db.roles, options.pose);
  return build_character_body(db.skeleton, bind, db.roles, options);
}

Result<SkinnedMesh> load_body_gltf(const std::filesystem::path& path, const Skeleton& skeleton) {
  GltfImportOptions options;
  options.read_skinned_mesh = true;
  Result<GltfAsset> asset = load_gltf(path, options);
  if (!asset) return asset.error();
  const Skeleton& body_skeleton = asset->skeleton;
  SkinnedMesh& body = *asset->skinned_mesh;

  // The skeleton joint of every body joint (-1: not there) and which of those carry weight.
  std::vector<int> target(static_cast<size_t>(body_skeleton.joint_count()));
  std::vector<bool> weighted(target.size(), false);
  for (int j = 0; j < body_skeleton.joint_count(); ++j) {
    target[static_cast<size_t>(j)] = skeleton.find(body_skeleton.name(j));
  }
  for (const VertexInfluences& in : body.influences) {
    for (int k = 0; k < 4; ++k) {
      if (in.weights[k] > 0.0f) weighted[static_cast<size_t>(in.joints[k])] = true;
    }
  }
  std::string missing;
  for (size_t j = 0; j < target.size(); ++j) {
    if (weighted[j] && target[j] < 0) {
      missing += (missing.empty() ? "" : ", ") + body_skeleton.name(static_cast<int>(j));
    }
  }
  if (!missing.empty()) {
    return Error{path.string() + ": the body is weighted to joints the skeleton lacks: " + missing};
  }

  for (VertexInfluences& in : body.influences) {
    for (int k = 0; k < 4; ++k) {
      in.joints[k] = in.weights[k] > 0.0f ? target[static_cast<size_t>(in.joints[k])] : 0;
    }
  }
  // Bind transforms by name; the skeleton's other joints hang off their parents at rest.
  std::vector<Transform> bind(static_cast<size_t>(skeleton.joint_count()));
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const int from = body_skeleton.find(skeleton.name(j));
    const int parent = skeleton.parent(j);
    bind[static_cast<size_t>(j)] =
        from >= 0    ? body.bind_global[static_cast<size_t>(from)]
        : parent < 0 ? skeleton.rest(j)
                     : compose(bind[static_cast<size_t>(parent)], skeleton.rest(j));
  }
  body.bind_global = std::move(bind);
  return std::move(body);
}

}  // namespace mm
