// Name-based joint lookups of the preprocessing: joint roles and left/right mirror pairs.

#include <cctype>
#include <string_view>
#include <utility>

#include "mm/offline/preprocess.hpp"

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

// The joint's name after its namespace prefix ("mixamorig:LeftArm" -> "LeftArm").
std::string_view without_namespace(std::string_view name) {
  const size_t colon = name.rfind(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

int find_role(const Skeleton& skeleton, const std::vector<std::string>& candidates) {
  for (const std::string& candidate : candidates) {
    if (const int j = find_ignoring_case(skeleton, candidate); j >= 0) return j;
  }
  for (const std::string& candidate : candidates) {
    for (int j = 0; j < skeleton.joint_count(); ++j) {
      if (equal_ignoring_case(without_namespace(skeleton.name(j)), candidate)) return j;
    }
  }
  return -1;
}

bool is_ancestor(const Skeleton& skeleton, int ancestor, int joint) {
  for (int j = joint; j >= 0; j = skeleton.parent(j)) {
    if (j == ancestor) return true;
  }
  return false;
}

// The only child of `joint`, or -1 when it has none or several.
int only_child(const Skeleton& skeleton, int joint) {
  int child = -1;
  for (int j = joint + 1; j < skeleton.joint_count(); ++j) {
    if (skeleton.parent(j) != joint) continue;
    if (child >= 0) return -1;
    child = j;
  }
  return child;
}

// The parent of `joint` when it is a joint of its own (not `stop`, not a root), else -1.
int parent_unless(const Skeleton& skeleton, int joint, int stop) {
  if (joint < 0) return -1;
  const int p = skeleton.parent(joint);
  return p >= 0 && p != stop && skeleton.parent(p) >= 0 ? p : -1;
}

// The deepest joint that is an ancestor of (or equal to) both joints.
int common_ancestor(const Skeleton& skeleton, int a, int b) {
  for (int j = a; j >= 0; j = skeleton.parent(j)) {
    if (is_ancestor(skeleton, j, b)) return j;
  }
  return -1;
}

// Step 3 of the resolution (joint_roles.hpp): roles the names left open, from the structure.
void fill_roles_from_structure(const Skeleton& sk, JointRoleIndices& r) {
  struct Side {
    int &upper_leg, &lower_leg, &foot, &toe, &shoulder, &upper_arm, &lower_arm, &hand;
  };
  Side sides[2] = {{r.left_upper_leg, r.left_lower_leg, r.left_foot, r.left_toe, r.left_shoulder,
                    r.left_upper_arm, r.left_lower_arm, r.left_hand},
                   {r.right_upper_leg, r.right_lower_leg, r.right_foot, r.right_toe,
                    r.right_shoulder, r.right_upper_arm, r.right_lower_arm, r.right_hand}};
  for (Side& s : sides) {
    if (s.lower_leg < 0) s.lower_leg = parent_unless(sk, s.foot, r.hips);
    if (s.upper_leg < 0) s.upper_leg = parent_unless(sk, s.lower_leg, r.hips);
    if (s.toe < 0 && s.foot >= 0) s.toe = only_child(sk, s.foot);
    if (s.lower_arm < 0) s.lower_arm = parent_unless(sk, s.hand, -1);
    if (s.upper_arm < 0) s.upper_arm = parent_unless(sk, s.lower_arm, -1);
  }
  const int left_arm = sides[0].upper_arm, right_arm = sides[1].upper_arm;
  if (r.chest < 0 && left_arm >= 0 && right_arm >= 0) {
    const int branch = common_ancestor(sk, left_arm, right_arm);
    // The arms may hang off a clavicle each; the chest is where the two sides meet.
    if (branch != left_arm && branch != right_arm && branch != r.hips) r.chest = branch;
  }
  for (Side& s : sides) {
    // A clavicle: the upper arm's parent, on one side only (not the chest the arms share).
    const int p = parent_unless(sk, s.upper_arm, r.chest);
    if (s.shoulder < 0 && p >= 0 && p != r.neck &&
        !is_ancestor(sk, p, left_arm == s.upper_arm ? right_arm : left_arm)) {
      s.shoulder = p;
    }
    if (s.shoulder >= 0 &&
        (s.shoulder == s.upper_arm || !is_ancestor(sk, s.shoulder, s.upper_arm))) {
      s.shoulder = -1;
    }
  }
  if (r.neck < 0 && r.head >= 0) {
    const int p = sk.parent(r.head);
    if (p >= 0 && p != r.chest && p != r.hips) r.neck = p;
  }
  if (r.spine < 0 && r.chest >= 0 && r.hips >= 0 && is_ancestor(sk, r.hips, r.chest)) {
    int j = r.chest;
    while (sk.parent(j) >= 0 && sk.parent(j) != r.hips) j = sk.parent(j);
    if (j != r.chest) r.spine = j;
  }
  if (r.spine == r.chest) r.spine = -1;
}

// A required role's chain must run hips -> upper leg -> lower leg -> foot.
Status check_leg_chains(const Skeleton& sk, const JointRoleIndices& r) {
  const struct {
    const char* side;
    int upper, lower, foot;
  } legs[2] = {{"left", r.left_upper_leg, r.left_lower_leg, r.left_foot},
               {"right", r.right_upper_leg, r.right_lower_leg, r.right_foot}};
  for (const auto& leg : legs) {
    const std::pair<int, int> links[] = {
        {r.hips, leg.upper}, {leg.upper, leg.lower}, {leg.lower, leg.foot}};
    for (const auto& [above, below] : links) {
      if (above == below || !is_ancestor(sk, above, below)) {
        return Error{std::string("the ") + leg.side + " leg's joints are not one chain: '" +
                     sk.name(above) + "' is not above '" + sk.name(below) +
                     "' in the hierarchy; name them with --map or --role"};
      }
    }
  }
  return Status::success();
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
    out.*role.index = find_role(skeleton, roles.*role.candidates);
  }
  fill_roles_from_structure(skeleton, out);
  for (const JointRoleInfo& role : kJointRoles) {
    if (!role.required || out.*role.index >= 0) continue;
    const std::vector<std::string>& candidates = roles.*role.candidates;
    return Error{
        "no joint for the required role '" + std::string(role.name) +
        "': looked for (ignoring case) " +
        (candidates.empty() ? std::string("nothing (the list is empty)") : joined(candidates, 16)) +
        ", then by structure; the skeleton's joints are " + joined(skeleton.names(), 40) +
        " (name it with a map line " + std::string(role.name) + "=JOINT)"};
  }
  if (Status chains = check_leg_chains(skeleton, out); !chains) return Error{chains.message()};
  return out;
}

Status check_joint_map(const Skeleton& skeleton, std::span<const JointRoleAssignment> assignments) {
  for (const JointRoleAssignment& a : assignments) {
    if (find_role(skeleton, {a.joint}) >= 0) continue;
    const std::string where =
        a.source.empty() ? std::string("--role ") : a.source + ":" + std::to_string(a.line) + ": ";
    return Error{where + a.role + "=" + a.joint + ": no joint named '" + a.joint +
                 "' in the skeleton; its joints are " + joined(skeleton.names(), 40)};
  }
  return Status::success();
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
