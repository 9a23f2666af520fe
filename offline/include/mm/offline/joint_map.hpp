#pragma once
// Joint map files and `mm build --role`: naming the joint of a role by hand when the names and
// the structure (mm/database/joint_roles.hpp) do not find it.

#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mm/database/joint_roles.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// One assignment of a map file or of `--role`: the role (a row of kJointRoles) and the joint.
struct JointRoleAssignment {
  std::string role;
  std::string joint;
  int line = 0;        // in the map file (0 for a command-line assignment)
  std::string source;  // the map file, for messages (empty for a command-line assignment)
};

// Parses a joint map: lines "role=Joint" (spaces around either side are ignored), '#' starts a
// comment, blank lines are skipped. An unknown role, a missing '=' or joint, or a role given
// twice is refused with "<path>:<line>: ...".
Result<std::vector<JointRoleAssignment>> parse_joint_map(std::string_view text,
                                                         std::string_view path_for_messages);
// Reads and parses a map file.
Result<std::vector<JointRoleAssignment>> load_joint_map(const std::filesystem::path& path);
// Makes each assigned joint the only candidate of its role.
void apply_joint_map(JointRoles& roles, std::span<const JointRoleAssignment> assignments);

}  // namespace mm
