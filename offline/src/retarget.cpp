#include "mm/offline/retarget.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string_view>

#include <glm/gtc/quaternion.hpp>

#include "mm/runtime/pose.hpp"

namespace mm {

namespace {

// Bones shorter than this have no usable direction (ReActIdle's spine starts at the pelvis).
constexpr float kMinBoneLength = 0.01f;

int role_row(std::string_view name) {
  return static_cast<int>(find_joint_role(name) - kJointRoles.data());
}

int joint_of(const JointRoleIndices& roles, int row) {
  return roles.*kJointRoles[static_cast<size_t>(row)].index;
}

// Per role: the role whose alignment a bone without a direction takes, and the roles its bone
// points to (the first one present), by name.
struct RoleBone {
  std::string_view role;
  std::string_view parent;
  std::array<std::string_view, 4> children;
};
constexpr RoleBone kRoleBones[] = {
    {"hips", "", {"spine", "chest", "neck", "head"}},
    {"spine", "hips", {"chest", "neck", "head"}},
    {"chest", "spine", {"neck", "head"}},
    {"neck", "chest", {"head"}},
    {"head", "neck", {}},
    {"left_shoulder", "chest", {"left_upper_arm"}},
    {"right_shoulder", "chest", {"right_upper_arm"}},
    {"left_upper_arm", "left_shoulder", {"left_lower_arm"}},
    {"right_upper_arm", "right_shoulder", {"right_lower_arm"}},
    {"left_lower_arm", "left_upper_arm", {"left_hand"}},
    {"right_lower_arm", "right_upper_arm", {"right_hand"}},
    {"left_hand", "left_lower_arm", {}},
    {"right_hand", "right_lower_arm", {}},
    {"left_upper_leg", "hips", {"left_lower_leg"}},
    {"right_upper_leg", "hips", {"right_lower_leg"}},
    {"left_lower_leg", "left_upper_leg", {"left_foot"}},
    {"right_lower_leg", "right_upper_leg", {"right_foot"}},
    {"left_foot", "left_lower_leg", {"left_toe"}},
    {"right_foot", "right_lower_leg", {"right_toe"}},
    {"left_toe", "left_foot", {}},
    {"right_toe", "right_foot", {}},
};
static_assert(std::size(kRoleBones) == kJointRoleCount, "one bone row per role, in table order");

std::vector<Transform> globals_of(const Skeleton& skeleton, std::span<const Transform> local) {
  std::vector<Transform> global(local.size());
  forward_kinematics(skeleton.parents(), local, global);
  return global;
}

glm::vec3 position(const std::vector<Transform>& global, int joint) {
  return global[static_cast<size_t>(joint)].translation;
}

// The world direction of a role's bone in a posed skeleton: towards its first child role that
// lies away from it, else along its End Site; nothing when neither exists.
std::optional<glm::vec3> bone_direction(const RetargetSkeleton& s,
                                        const std::vector<Transform>& global, size_t row) {
  const int joint = joint_of(s.roles, static_cast<int>(row));
  if (joint < 0) return std::nullopt;
  for (std::string_view child : kRoleBones[row].children) {
    if (child.empty()) break;
    const int c = joint_of(s.roles, role_row(child));
    if (c < 0) continue;
    const glm::vec3 d = position(global, c) - position(global, joint);
    if (glm::length(d) > kMinBoneLength) return glm::normalize(d);
  }
  if (static_cast<size_t>(joint) < s.end_sites.size()) {
    const glm::vec3 d =
        global[static_cast<size_t>(joint)].rotation * s.end_sites[static_cast<size_t>(joint)];
    if (glm::length(d) > kMinBoneLength) return glm::normalize(d);
  }
  return std::nullopt;
}

// The spine's direction: from the hips to the highest trunk role present.
glm::vec3 trunk_up(const RetargetSkeleton& s, const std::vector<Transform>& global) {
  for (std::string_view top : {"head", "neck", "chest", "spine"}) {
    const int j = joint_of(s.roles, role_row(top));
    if (j < 0) continue;
    const glm::vec3 d = position(global, j) - position(global, s.roles.hips);
    if (glm::length(d) > kMinBoneLength) return glm::normalize(d);
  }
  // No trunk: up is away from the feet.
  const glm::vec3 feet =
      0.5f * (position(global, s.roles.left_foot) + position(global, s.roles.right_foot));
  return glm::normalize(position(global, s.roles.hips) - feet);
}

// The body's frame in a posed skeleton: columns left, up, forward.
glm::quat body_frame(const RetargetSkeleton& s, const std::vector<Transform>& global) {
  const glm::vec3 up = trunk_up(s, global);
  glm::vec3 left =
      position(global, s.roles.left_upper_leg) - position(global, s.roles.right_upper_leg);
  left = glm::normalize(left - glm::dot(left, up) * up);
  return glm::quat_cast(glm::mat3(left, up, glm::cross(left, up)));
}

// The shortest rotation turning unit vector a onto unit vector b.
glm::quat swing(const glm::vec3& a, const glm::vec3& b) {
  const float d = glm::dot(a, b);
  if (d < -0.9999f) {
    // Opposite: half a turn about any axis perpendicular to a.
    glm::vec3 axis = glm::cross(a, glm::vec3(1.0f, 0.0f, 0.0f));
    if (glm::length(axis) < 1e-3f) axis = glm::cross(a, glm::vec3(0.0f, 1.0f, 0.0f));
    return glm::angleAxis(glm::pi<float>(), glm::normalize(axis));
  }
  const glm::vec3 c = glm::cross(a, b);
  return glm::normalize(glm::quat(1.0f + d, c.x, c.y, c.z));
}

bool stands(const RetargetSkeleton& s, const std::vector<Transform>& global) {
  const float leg = leg_length(s.skeleton, s.roles);
  const float hips = position(global, s.roles.hips).y;
  for (const int foot : {s.roles.left_foot, s.roles.right_foot}) {
    if (position(global, foot).y > hips - 0.5f * leg) return false;
  }
  return trunk_up(s, global).y > 0.7f;
}

// The lowest of the two toes (the feet where there are no toes) in a posed skeleton, or of their
// End Sites when `end_sites` (one offset per joint) is given.
float lowest_toe(const JointRoleIndices& roles, const std::vector<Transform>& global,
                 std::span<const glm::vec3> end_sites = {}) {
  float lowest = std::numeric_limits<float>::infinity();
  const int toes[2] = {roles.left_toe >= 0 ? roles.left_toe : roles.left_foot,
                       roles.right_toe >= 0 ? roles.right_toe : roles.right_foot};
  for (const int toe : toes) {
    const glm::vec3 site =
        end_sites.empty() ? glm::vec3(0.0f) : end_sites[static_cast<size_t>(toe)];
    lowest = std::min(lowest, transform_point(global[static_cast<size_t>(toe)], site).y);
  }
  return lowest;
}

// Per target role row: the rotation C with G_T = G_S * C (see the top of retarget.hpp), for the
// roles both skeletons have.
std::vector<std::optional<glm::quat>> alignments(const RetargetSkeleton& from,
                                                 const RetargetSkeleton& to) {
  const std::vector<Transform> rest_s = globals_of(from.skeleton, from.rest_pose);
  const std::vector<Transform> rest_t = globals_of(to.skeleton, to.rest_pose);
  const glm::quat body = body_frame(from, rest_s) * glm::inverse(body_frame(to, rest_t));
  std::vector<glm::quat> align(kJointRoleCount, body);  // A per row, parents before children
  std::vector<std::optional<glm::quat>> out(kJointRoleCount);
  for (size_t row = 0; row < kJointRoleCount; ++row) {
    const std::string_view parent = kRoleBones[row].parent;
    align[row] = parent.empty() ? body : align[static_cast<size_t>(role_row(parent))];
    const std::optional<glm::vec3> ds = bone_direction(from, rest_s, row);
    const std::optional<glm::vec3> dt = bone_direction(to, rest_t, row);
    if (ds && dt) align[row] = swing(body * *dt, *ds) * body;
    const int js = joint_of(from.roles, static_cast<int>(row));
    const int jt = joint_of(to.roles, static_cast<int>(row));
    if (js < 0 || jt < 0) continue;
    out[row] = glm::normalize(glm::inverse(rest_s[static_cast<size_t>(js)].rotation) * align[row] *
                              rest_t[static_cast<size_t>(jt)].rotation);
  }
  return out;
}

// Per target joint: the source joint whose rotation it follows and how, or none.
struct JointSource {
  int source = -1;
  glm::quat correction{1.0f, 0.0f, 0.0f, 0.0f};
  bool above_hips = false;  // takes the source joint's position too (scaled)
};

bool is_above(const Skeleton& skeleton, int ancestor, int joint) {
  for (int j = skeleton.parent(joint); j >= 0; j = skeleton.parent(j)) {
    if (j == ancestor) return true;
  }
  return false;
}

std::vector<JointSource> match_joints(const RetargetSkeleton& from, const RetargetSkeleton& to,
                                      RetargetReport& report) {
  const std::vector<std::optional<glm::quat>> align = alignments(from, to);
  std::vector<JointSource> out(static_cast<size_t>(to.skeleton.joint_count()));
  for (size_t row = 0; row < kJointRoleCount; ++row) {
    if (!align[row]) continue;
    const int js = joint_of(from.roles, static_cast<int>(row));
    const int jt = joint_of(to.roles, static_cast<int>(row));
    out[static_cast<size_t>(jt)] = {js, *align[row]};
    report.matched.push_back(std::string(kJointRoles[row].name) + ": " + from.skeleton.name(js) +
                             " -> " + to.skeleton.name(jt));
  }
  // Joints above the hips (a capture's world root, e.g. Bandai's joint_Root) carry motion too:
  // they follow the source joint of the same name above the source's hips.
  for (int j = to.roles.hips; j >= 0; j = to.skeleton.parent(j)) {
    const int js = from.skeleton.find(to.skeleton.name(j));
    if (j == to.roles.hips || js < 0 || !is_above(from.skeleton, js, from.roles.hips)) continue;
    out[static_cast<size_t>(j)] = {js, glm::quat(1.0f, 0.0f, 0.0f, 0.0f), true};
    report.matched.push_back("(above the hips): " + from.skeleton.name(js) + " -> " +
                             to.skeleton.name(j));
  }
  for (int j = 0; j < to.skeleton.joint_count(); ++j) {
    if (out[static_cast<size_t>(j)].source < 0) report.left_at_rest.push_back(to.skeleton.name(j));
  }
  return out;
}

// One target frame's globals from the source frame's globals; the hips at `hips_position`.
void retarget_frame(const RetargetSkeleton& to, const std::vector<JointSource>& sources,
                    const std::vector<Transform>& source_global, float scale,
                    const glm::vec3& hips_position, std::vector<Transform>& global) {
  const Skeleton& sk = to.skeleton;
  for (int j = 0; j < sk.joint_count(); ++j) {
    const size_t i = static_cast<size_t>(j);
    const int parent = sk.parent(j);
    Transform local = sk.rest(j);
    local.rotation = to.rest_pose[i].rotation;
    global[i] = parent < 0 ? local : compose(global[static_cast<size_t>(parent)], local);
    if (sources[i].source >= 0) {
      global[i].rotation = glm::normalize(
          source_global[static_cast<size_t>(sources[i].source)].rotation * sources[i].correction);
      if (sources[i].above_hips) {
        global[i].translation =
            scale * source_global[static_cast<size_t>(sources[i].source)].translation;
      }
    }
    if (j == to.roles.hips) global[i].translation = hips_position;
  }
}

// The locals of a frame whose globals are known; bones keep their rest offsets exactly.
void locals_from_globals(const RetargetSkeleton& to, const std::vector<Transform>& global,
                         std::span<Transform> local) {
  const Skeleton& sk = to.skeleton;
  for (int j = 0; j < sk.joint_count(); ++j) {
    const size_t i = static_cast<size_t>(j);
    const int parent = sk.parent(j);
    if (parent < 0) {
      local[i] = global[i];
      continue;
    }
    const Transform& p = global[static_cast<size_t>(parent)];
    local[i].rotation = glm::normalize(glm::inverse(p.rotation) * global[i].rotation);
    const bool placed = j == to.roles.hips || is_above(sk, j, to.roles.hips);
    local[i].translation = placed
                               ? glm::inverse(p.rotation) * (global[i].translation - p.translation)
                               : sk.rest(j).translation;
    local[i].scale = glm::vec3(1.0f);
  }
}

Status check_roles(const RetargetSkeleton& s, const char* side) {
  for (const JointRoleInfo& role : kJointRoles) {
    const int j = s.roles.*role.index;
    if (role.required && (j < 0 || j >= s.skeleton.joint_count())) {
      return Error{std::string("retarget: the ") + side + " skeleton has no joint for the " +
                   "required role '" + std::string(role.name) + "'"};
    }
  }
  if (s.rest_pose.size() != static_cast<size_t>(s.skeleton.joint_count())) {
    return Error{std::string("retarget: the ") + side + " rest pose has " +
                 std::to_string(s.rest_pose.size()) + " transforms for " +
                 std::to_string(s.skeleton.joint_count()) + " joints"};
  }
  if (!(leg_length(s.skeleton, s.roles) > kMinBoneLength)) {
    return Error{std::string("retarget: the ") + side + " skeleton's legs have no length"};
  }
  return Status::success();
}

}  // namespace

float leg_length(const Skeleton& skeleton, const JointRoleIndices& roles) {
  float sum = 0.0f;
  for (const int foot : {roles.left_foot, roles.right_foot}) {
    const int lower = foot >= 0 ? skeleton.parent(foot) : -1;
    if (lower < 0) continue;
    sum += glm::length(skeleton.rest(foot).translation) +
           glm::length(skeleton.rest(lower).translation);
  }
  return 0.5f * sum;
}

Result<RetargetSkeleton> describe_for_retargeting(const Clip& clip, const JointRoleIndices& roles,
                                                  int rest_frame) {
  if (rest_frame >= clip.frame_count) {
    return Error{"clip '" + clip.name + "': rest frame " + std::to_string(rest_frame) +
                 " is past its last frame " + std::to_string(clip.frame_count - 1)};
  }
  RetargetSkeleton s;
  s.skeleton = clip.skeleton;
  s.roles = roles;
  s.end_sites = clip.end_sites;
  if (Status ok = check_roles(RetargetSkeleton{s.skeleton, roles, clip.skeleton.rest(), {}, 0, {}},
                              "clip's");
      !ok) {
    return Error{"clip '" + clip.name + "': " + ok.message()};
  }
  s.rest_pose = clip.skeleton.rest();
  s.rest_description = "bind pose";
  if (rest_frame >= 0 || !stands(s, globals_of(s.skeleton, s.rest_pose))) {
    const int frame = std::max(rest_frame, 0);
    const std::span<const Transform> pose = clip.pose(frame);
    s.rest_pose.assign(pose.begin(), pose.end());
    s.rest_description = "frame " + std::to_string(frame);
    if (rest_frame < 0) s.rest_description += " (the bind pose does not stand)";
  }
  s.toe_floor = std::numeric_limits<float>::infinity();
  for (int f = 0; f < clip.frame_count; ++f) {
    s.toe_floor = std::min(s.toe_floor, lowest_toe(roles, globals_of(s.skeleton, clip.pose(f))));
  }
  return s;
}

float lowest_foot_end(const Clip& clip, const JointRoleIndices& roles) {
  float lowest = std::numeric_limits<float>::infinity();
  for (int f = 0; f < clip.frame_count; ++f) {
    lowest = std::min(lowest,
                      lowest_toe(roles, globals_of(clip.skeleton, clip.pose(f)), clip.end_sites));
  }
  return lowest;
}

Result<Clip> retarget_clip(const Clip& source, const RetargetSkeleton& from,
                           const RetargetSkeleton& to, RetargetReport* report) {
  if (Status s = check_roles(from, "source"); !s) return Error{s.message()};
  if (Status s = check_roles(to, "target"); !s) return Error{s.message()};
  if (!from.skeleton.same_topology(source.skeleton)) {
    return Error{"retarget: clip '" + source.name + "' is not on the source skeleton"};
  }
  RetargetReport local_report;
  RetargetReport& r = report ? *report : local_report;
  r = RetargetReport{};
  r.scale = leg_length(to.skeleton, to.roles) / leg_length(from.skeleton, from.roles);
  const std::vector<JointSource> sources = match_joints(from, to, r);

  Clip out;
  out.name = source.name;
  out.source_path = source.source_path;
  out.skeleton = to.skeleton;
  out.end_sites = to.end_sites;
  out.frame_time = source.frame_time;
  out.frame_count = source.frame_count;
  const size_t joints = static_cast<size_t>(to.skeleton.joint_count());
  out.local.resize(joints * static_cast<size_t>(source.frame_count));
  std::vector<std::vector<Transform>> globals(static_cast<size_t>(source.frame_count));
  float lowest = std::numeric_limits<float>::infinity();
  for (int f = 0; f < source.frame_count; ++f) {
    const std::vector<Transform> g = globals_of(source.skeleton, source.pose(f));
    std::vector<Transform>& target = globals[static_cast<size_t>(f)];
    target.resize(joints);
    retarget_frame(to, sources, g, r.scale, r.scale * position(g, from.roles.hips), target);
    lowest = std::min(lowest, lowest_toe(to.roles, target));
  }
  // Standing on the target's ground moves the whole body: only the hips' position changes.
  r.ground_shift = to.toe_floor - lowest;
  for (int f = 0; f < source.frame_count; ++f) {
    std::vector<Transform>& target = globals[static_cast<size_t>(f)];
    target[static_cast<size_t>(to.roles.hips)].translation.y += r.ground_shift;
    locals_from_globals(to, target, out.pose(f));
  }
  return out;
}

}  // namespace mm
