// Joint map files: "role=Joint" lines that name the joint of a role (joint_roles.hpp).

#include <cctype>
#include <string>
#include <string_view>

#include "mm/database/files.hpp"
#include "mm/offline/joint_map.hpp"

namespace mm {

namespace {

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) {
    text.remove_prefix(1);
  }
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

}  // namespace

Result<std::vector<JointRoleAssignment>> parse_joint_map(std::string_view text,
                                                         std::string_view path_for_messages) {
  std::vector<JointRoleAssignment> out;
  int line_number = 0;
  while (!text.empty()) {
    const size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
    ++line_number;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    line = trimmed(line);
    if (line.empty()) continue;
    const std::string where =
        std::string(path_for_messages) + ":" + std::to_string(line_number) + ": ";
    const size_t equals = line.find('=');
    if (equals == std::string_view::npos) {
      return Error{where + "expected 'role=Joint', found '" + std::string(line) + "'"};
    }
    JointRoleAssignment a{std::string(trimmed(line.substr(0, equals))),
                          std::string(trimmed(line.substr(equals + 1))), line_number,
                          std::string(path_for_messages)};
    if (!find_joint_role(a.role)) {
      return Error{where + "unknown role '" + a.role + "' (roles: " + joint_role_names() + ")"};
    }
    if (a.joint.empty()) return Error{where + "no joint name after '" + a.role + "='"};
    for (const JointRoleAssignment& earlier : out) {
      if (earlier.role == a.role) {
        return Error{where + "role '" + a.role + "' is already given on line " +
                     std::to_string(earlier.line)};
      }
    }
    out.push_back(std::move(a));
  }
  return out;
}

Result<std::vector<JointRoleAssignment>> load_joint_map(const std::filesystem::path& path) {
  auto contents = read_whole_file(path, "joint map");
  if (!contents) return contents.error();
  return parse_joint_map(contents->text(), path.string());
}

void apply_joint_map(JointRoles& roles, std::span<const JointRoleAssignment> assignments) {
  for (const JointRoleAssignment& a : assignments) {
    if (const JointRoleInfo* role = find_joint_role(a.role)) roles.*role->candidates = {a.joint};
  }
}

}  // namespace mm
