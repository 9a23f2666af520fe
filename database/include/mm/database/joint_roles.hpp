#pragma once
// The joint roles: a humanoid map from meaning (hips, spine, left upper arm, ...) to the joints
// of a skeleton, so that features, contacts, the controller, the viewer and retargeting never
// depend on joint names. kJointRoles is the one table of them: validation, feature bone names,
// the database file, the builder, retargeting and `mm info` iterate it, so a new role is one
// more row here (and one more field in the two structs below).
//
// A role is resolved in three steps (find_joint_roles in preprocess.hpp):
//   1. a map file or `--role` names its joint (the only candidate then);
//   2. otherwise the first of its name candidates found in the skeleton, compared ignoring case
//      and ignoring a namespace prefix ("mixamorig:LeftArm" matches "LeftArm");
//   3. otherwise the structure decides, from roles already found: the lower leg is the foot's
//      parent and the upper leg the lower leg's; the toe is the foot's only child; the lower arm
//      is the hand's parent, the upper arm the lower arm's, the shoulder (clavicle) the upper
//      arm's parent when that joint is on one side only; the chest is where the two arms branch
//      off; the neck is the head's parent; the spine is the hips' child on the way to the chest.
// Names that mean different joints in different conventions (CMU's "LeftShoulder" is the
// clavicle, "Spine1" is CMU's chest but Mixamo's middle spine) are left to the structure.

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mm {

// Joint indices of the roles (-1 when absent).
struct JointRoleIndices {
  int hips = -1;
  int spine = -1;
  int chest = -1;
  int neck = -1;
  int head = -1;
  int left_shoulder = -1;
  int right_shoulder = -1;
  int left_upper_arm = -1;
  int right_upper_arm = -1;
  int left_lower_arm = -1;
  int right_lower_arm = -1;
  int left_hand = -1;
  int right_hand = -1;
  int left_upper_leg = -1;
  int right_upper_leg = -1;
  int left_lower_leg = -1;
  int right_lower_leg = -1;
  int left_foot = -1;
  int right_foot = -1;
  int left_toe = -1;
  int right_toe = -1;
};

// The name candidates of one side's joint: each pattern expanded for that side, where "{Side}"
// stands for Left / Right, "{side}" for left / right, "{S}" for L / R and "{s}" for l / r.
std::vector<std::string> side_names(bool left, std::span<const std::string_view> patterns);

namespace joint_name_patterns {

// Bandai, CMU as BVH, Mixamo (after its "mixamorig:" prefix), Blender rigify, Unreal's
// mannequin, LAFAN1 and other common BVH names. The clavicle: Bandai "Shoulder_L", rigify
// "shoulder.L", Unreal "clavicle_l" (CMU's and Mixamo's "LeftShoulder" is found by structure
// as the upper arm's parent; it is also listed, after the unambiguous names).
inline constexpr std::string_view kShoulder[] = {"Shoulder_{S}",  "shoulder.{S}", "clavicle_{s}",
                                                 "{S}_Clavicle",  "Clavicle_{S}", "{Side}Collar",
                                                 "{Side}Shoulder"};
inline constexpr std::string_view kUpperArm[] = {
    "UpperArm_{S}",   "upper_arm.{S}", "upperarm_{s}", "{Side}Arm",       "{Side}UpArm",
    "{Side}UpperArm", "{S}_UpperArm",  "Arm_{S}",      "{side}_upper_arm"};
inline constexpr std::string_view kLowerArm[] = {
    "LowerArm_{S}",   "forearm.{S}", "lowerarm_{s}", "{Side}ForeArm", "{Side}LowArm",
    "{Side}LowerArm", "{S}_Forearm", "ForeArm_{S}",  "{Side}Elbow",   "{side}_lower_arm"};
inline constexpr std::string_view kHand[] = {"Hand_{S}", "hand.{S}",    "hand_{s}",   "{Side}Hand",
                                             "{S}_Hand", "{Side}Wrist", "{side}_hand"};
inline constexpr std::string_view kUpperLeg[] = {
    "UpperLeg_{S}", "thigh.{S}", "thigh_{s}", "{Side}UpLeg", "{Side}UpperLeg",
    "{Side}Thigh",  "{S}_Thigh", "UpLeg_{S}", "{Side}Hip",   "{side}_upper_leg"};
inline constexpr std::string_view kLowerLeg[] = {
    "LowerLeg_{S}", "shin.{S}", "calf_{s}",   "{Side}Leg",    "{Side}LowerLeg",  "{Side}Shin",
    "{S}_Calf",     "Leg_{S}",  "{Side}Knee", "{Side}LowLeg", "{side}_lower_leg"};
inline constexpr std::string_view kFoot[] = {"Foot_{S}",   "foot.{S}", "foot_{s}",
                                             "{Side}Foot", "{S}_Foot", "{Side}Ankle",
                                             "{s}_ankle",  "{s}Foot",  "{side}_foot"};
inline constexpr std::string_view kToe[] = {"Toes_{S}",  "toe.{S}",   "ball_{s}", "{Side}ToeBase",
                                            "{Side}Toe", "{S}_Toe",   "toes.{S}", "{s}_toes",
                                            "Toe_{S}",   "{side}_toe"};

}  // namespace joint_name_patterns

// The joint names each role may have, tried in order (see the top of this file). Override a
// role by replacing its list, e.g. roles.left_foot = {"l_ankle"}; an empty list leaves the role
// to the structure.
struct JointRoles {
  std::vector<std::string> hips = {"Hips", "Hip", "Pelvis", "root_hips"};
  std::vector<std::string> spine = {"Spine", "spine_01", "LowerBack", "Spine0"};
  std::vector<std::string> chest = {"Chest", "UpperChest"};
  std::vector<std::string> neck = {"Neck", "neck_01", "Neck1"};
  std::vector<std::string> head = {"Head", "face", "head_top"};
  std::vector<std::string> left_shoulder = side_names(true, joint_name_patterns::kShoulder);
  std::vector<std::string> right_shoulder = side_names(false, joint_name_patterns::kShoulder);
  std::vector<std::string> left_upper_arm = side_names(true, joint_name_patterns::kUpperArm);
  std::vector<std::string> right_upper_arm = side_names(false, joint_name_patterns::kUpperArm);
  std::vector<std::string> left_lower_arm = side_names(true, joint_name_patterns::kLowerArm);
  std::vector<std::string> right_lower_arm = side_names(false, joint_name_patterns::kLowerArm);
  std::vector<std::string> left_hand = side_names(true, joint_name_patterns::kHand);
  std::vector<std::string> right_hand = side_names(false, joint_name_patterns::kHand);
  std::vector<std::string> left_upper_leg = side_names(true, joint_name_patterns::kUpperLeg);
  std::vector<std::string> right_upper_leg = side_names(false, joint_name_patterns::kUpperLeg);
  std::vector<std::string> left_lower_leg = side_names(true, joint_name_patterns::kLowerLeg);
  std::vector<std::string> right_lower_leg = side_names(false, joint_name_patterns::kLowerLeg);
  std::vector<std::string> left_foot = side_names(true, joint_name_patterns::kFoot);
  std::vector<std::string> right_foot = side_names(false, joint_name_patterns::kFoot);
  std::vector<std::string> left_toe = side_names(true, joint_name_patterns::kToe);
  std::vector<std::string> right_toe = side_names(false, joint_name_patterns::kToe);
};

// One row of the role table.
struct JointRoleInfo {
  // The role's name: what a feature channel's bone, `mm build --role`, a map file and messages
  // call it.
  std::string_view name;
  // Hips, upper legs, lower legs and feet are required (the features, the contacts and
  // retargeting need them); every other role may be absent.
  bool required;
  int JointRoleIndices::*index;                      // its field in JointRoleIndices
  std::vector<std::string> JointRoles::*candidates;  // its field in JointRoles
};

// Every role, in the order the database file stores them.
inline constexpr std::array<JointRoleInfo, 21> kJointRoles = {{
    {"hips", true, &JointRoleIndices::hips, &JointRoles::hips},
    {"spine", false, &JointRoleIndices::spine, &JointRoles::spine},
    {"chest", false, &JointRoleIndices::chest, &JointRoles::chest},
    {"neck", false, &JointRoleIndices::neck, &JointRoles::neck},
    {"head", false, &JointRoleIndices::head, &JointRoles::head},
    {"left_shoulder", false, &JointRoleIndices::left_shoulder, &JointRoles::left_shoulder},
    {"right_shoulder", false, &JointRoleIndices::right_shoulder, &JointRoles::right_shoulder},
    {"left_upper_arm", false, &JointRoleIndices::left_upper_arm, &JointRoles::left_upper_arm},
    {"right_upper_arm", false, &JointRoleIndices::right_upper_arm, &JointRoles::right_upper_arm},
    {"left_lower_arm", false, &JointRoleIndices::left_lower_arm, &JointRoles::left_lower_arm},
    {"right_lower_arm", false, &JointRoleIndices::right_lower_arm, &JointRoles::right_lower_arm},
    {"left_hand", false, &JointRoleIndices::left_hand, &JointRoles::left_hand},
    {"right_hand", false, &JointRoleIndices::right_hand, &JointRoles::right_hand},
    {"left_upper_leg", true, &JointRoleIndices::left_upper_leg, &JointRoles::left_upper_leg},
    {"right_upper_leg", true, &JointRoleIndices::right_upper_leg, &JointRoles::right_upper_leg},
    {"left_lower_leg", true, &JointRoleIndices::left_lower_leg, &JointRoles::left_lower_leg},
    {"right_lower_leg", true, &JointRoleIndices::right_lower_leg, &JointRoles::right_lower_leg},
    {"left_foot", true, &JointRoleIndices::left_foot, &JointRoles::left_foot},
    {"right_foot", true, &JointRoleIndices::right_foot, &JointRoles::right_foot},
    {"left_toe", false, &JointRoleIndices::left_toe, &JointRoles::left_toe},
    {"right_toe", false, &JointRoleIndices::right_toe, &JointRoles::right_toe},
}};
inline constexpr size_t kJointRoleCount = kJointRoles.size();

// The row of the role called `name`, or null when no role has that name.
inline const JointRoleInfo* find_joint_role(std::string_view name) {
  for (const JointRoleInfo& role : kJointRoles) {
    if (role.name == name) return &role;
  }
  return nullptr;
}

// "hips, spine, chest, ...", for messages.
inline std::string joint_role_names() {
  std::string out;
  for (const JointRoleInfo& role : kJointRoles) {
    if (!out.empty()) out += ", ";
    out += role.name;
  }
  return out;
}

}  // namespace mm
