// Name-based joint lookups of the preprocessing: joint roles and left/right mirror pairs.

#include <cctype>
#include <string_view>

#include "mm/database/preprocess.hpp"

namespace mm {

namespace {

bool equal_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) !=
        std::tolower(static_cast<unsigned char>(b[i]))) {
      return false;
    }
  }
  return true;
}

int find_ignoring_case(const Skeleton& skeleton, std::string_view name) {
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    if (equal_ignoring_case(skeleton.name(j), name)) return j;
  }
  return -1;
}

std::string joined(const std::vector<std::string>& names, size_t limit) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < limit; ++i) {
    if (i) out += ", ";
    out += names[i];
  }
  if (names.size() > limit) out += ", ... (" + std::to_string(names.size()) + " in all)";
  return out;
}

int find_role(const Skeleton& skeleton, const std::vector<std::string>& candidates) {
  for (const std::string& candidate : candidates) {
    if (const int j = find_ignoring_case(skeleton, candidate); j >= 0) return j;
  }
  return -1;
}

char swap_side_letter(char c) {
  switch (c) {
    case 'L':
      return 'R';
    case 'R':
      return 'L';
    case 'l':
      return 'r';
    case 'r':
      return 'l';
    default:
      return 0;
  }
}

bool is_separator(char c) {
  return c == '_' || c == '.' || c == '-' || c == ' ';
}

// Candidate names of the other side's joint, most specific pattern first.
std::vector<std::string> mirror_candidates(const std::string& name) {
  std::vector<std::string> out;
  const size_t n = name.size();
  // Suffix: "Foot_L", "foot.l", "Hand-R".
  if (n >= 2 && is_separator(name[n - 2]) && swap_side_letter(name[n - 1])) {
    std::string other = name;
    other[n - 1] = swap_side_letter(name[n - 1]);
    out.push_back(other);
  }
  // Prefix: "L_Foot", "r.hand", "l_ankle".
  if (n >= 2 && is_separator(name[1]) && swap_side_letter(name[0])) {
    std::string other = name;
    other[0] = swap_side_letter(name[0]);
    out.push_back(other);
  }
  // The words Left / Right anywhere: "LeftFoot", "mixamorig:RightHand", "left_knee".
  const std::pair<std::string_view, std::string_view> words[] = {
      {"Left", "Right"}, {"Right", "Left"}, {"left", "right"},
      {"right", "left"}, {"LEFT", "RIGHT"}, {"RIGHT", "LEFT"}};
  for (const auto& [from, to] : words) {
    if (const size_t at = name.find(from); at != std::string::npos) {
      std::string other = name;
      other.replace(at, from.size(), to);
      out.push_back(other);
    }
  }
  // Camel-case prefix: "lFoot" / "rHand".
  if (n >= 2 && (name[0] == 'l' || name[0] == 'r') &&
      std::isupper(static_cast<unsigned char>(name[1]))) {
    std::string other = name;
    other[0] = swap_side_letter(name[0]);
    out.push_back(other);
  }
  return out;
}

}  // namespace

Result<JointRoleIndices> find_joint_roles(const Skeleton& skeleton, const JointRoles& roles) {
  JointRoleIndices out;
  for (const JointRoleInfo& role : kJointRoles) {
    const std::vector<std::string>& candidates = roles.*role.candidates;
    out.*role.index = find_role(skeleton, candidates);
    if (!role.required || out.*role.index >= 0) continue;
    return Error{
        "no joint for the required role '" + std::string(role.name) +
        "': looked for (ignoring case) " +
        (candidates.empty() ? std::string("nothing (the list is empty)") : joined(candidates, 16)) +
        "; the skeleton's joints are " + joined(skeleton.names(), 40)};
  }
  return out;
}

Result<std::vector<int>> mirror_joint_map(const Skeleton& skeleton,
                                          std::span<const MirrorPair> overrides) {
  const int count = skeleton.joint_count();
  std::vector<int> map(count, -1);
  for (const MirrorPair& pair : overrides) {
    const int left = skeleton.find(pair.left);
    const int right = skeleton.find(pair.right);
    if (left < 0 || right < 0) {
      return Error{"mirror pair '" + pair.left + "' / '" + pair.right + "': no joint named '" +
                   (left < 0 ? pair.left : pair.right) + "' in the skeleton"};
    }
    for (const int j : {left, right}) {
      if (map[j] >= 0 && map[j] != (j == left ? right : left)) {
        return Error{"mirror pairs: joint '" + skeleton.name(j) + "' is paired twice"};
      }
    }
    map[left] = right;
    map[right] = left;
  }
  for (int j = 0; j < count; ++j) {
    if (map[j] >= 0) continue;
    for (const std::string& candidate : mirror_candidates(skeleton.name(j))) {
      const int other = skeleton.find(candidate);
      if (other >= 0 && other != j) {
        map[j] = other;
        break;
      }
    }
  }
  for (int j = 0; j < count; ++j) {
    if (map[j] < 0) map[j] = j;
  }
  for (int j = 0; j < count; ++j) {
    if (map[map[j]] != j) {
      return Error{"mirror pairs: joint '" + skeleton.name(j) + "' pairs with '" +
                   skeleton.name(map[j]) + "', which pairs with '" + skeleton.name(map[map[j]]) +
                   "'; give explicit mirror pairs for these joints"};
    }
  }
  return map;
}

}  // namespace mm
