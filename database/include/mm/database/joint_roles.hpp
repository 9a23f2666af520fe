#pragma once
// The joint roles: the joints the features, the contacts, the controller and the viewer need
// by meaning (hips, feet, toes, head) rather than by name. kJointRoles is the one table of them:
// validation, feature bone names, the database file, the builder and `mm info` iterate it, so a
// new role is one more row here (and one more field in the two structs below).

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace mm {

// Joint indices of the roles (-1 when absent).
struct JointRoleIndices {
  int hips = -1;
  int left_foot = -1;
  int right_foot = -1;
  int left_toe = -1;
  int right_toe = -1;
  int head = -1;
};

// The joint names each role may have, tried in order and compared case-insensitively; the
// first candidate found in the skeleton wins. The defaults recognise the Bandai names (Hips,
// Foot_L, Toes_L, Head, ...) and common BVH/Mixamo/Blender names (LeftFoot, LeftToeBase,
// foot.L, ...). Override a role by replacing its list, e.g. roles.left_foot = {"l_ankle"}.
struct JointRoles {
  std::vector<std::string> hips = {"Hips", "Hip", "Pelvis", "mixamorig:Hips", "root_hips"};
  std::vector<std::string> left_foot = {
      "Foot_L",  "LeftFoot",           "L_Foot", "Foot.L", "LeftAnkle",
      "l_ankle", "mixamorig:LeftFoot", "lFoot"};
  std::vector<std::string> right_foot = {
      "Foot_R",  "RightFoot",           "R_Foot", "Foot.R", "RightAnkle",
      "r_ankle", "mixamorig:RightFoot", "rFoot"};
  std::vector<std::string> left_toe = {"Toes_L", "LeftToeBase", "LeftToe", "L_Toe",
                                       "Toe.L",  "Toes.L",      "l_toes",  "mixamorig:LeftToeBase"};
  std::vector<std::string> right_toe = {
      "Toes_R", "RightToeBase", "RightToe", "R_Toe",
      "Toe.R",  "Toes.R",       "r_toes",   "mixamorig:RightToeBase"};
  std::vector<std::string> head = {"Head", "mixamorig:Head"};
};

// One row of the role table.
struct JointRoleInfo {
  // The role's name: what a feature channel's bone, `mm build --role` and messages call it.
  std::string_view name;
  // Hips and both feet are required (the default features and the contacts need them).
  bool required;
  int JointRoleIndices::*index;                      // its field in JointRoleIndices
  std::vector<std::string> JointRoles::*candidates;  // its field in JointRoles
};

// Every role, in the order the database file stores them.
inline constexpr std::array<JointRoleInfo, 6> kJointRoles = {{
    {"hips", true, &JointRoleIndices::hips, &JointRoles::hips},
    {"left_foot", true, &JointRoleIndices::left_foot, &JointRoles::left_foot},
    {"right_foot", true, &JointRoleIndices::right_foot, &JointRoles::right_foot},
    {"left_toe", false, &JointRoleIndices::left_toe, &JointRoles::left_toe},
    {"right_toe", false, &JointRoleIndices::right_toe, &JointRoles::right_toe},
    {"head", false, &JointRoleIndices::head, &JointRoles::head},
}};
inline constexpr size_t kJointRoleCount = kJointRoles.size();

// The row of the role called `name`, or null when no role has that name.
inline const JointRoleInfo* find_joint_role(std::string_view name) {
  for (const JointRoleInfo& role : kJointRoles) {
    if (role.name == name) return &role;
  }
  return nullptr;
}

// "hips, left_foot, right_foot, left_toe, right_toe, head", for messages.
inline std::string joint_role_names() {
  std::string out;
  for (const JointRoleInfo& role : kJointRoles) {
    if (!out.empty()) out += ", ";
    out += role.name;
  }
  return out;
}

}  // namespace mm
