#include "mm/runtime/skeleton.hpp"

#include <algorithm>
#include <unordered_map>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtx/quaternion.hpp>

namespace mm {

glm::mat4 to_matrix(const Transform& t) {
  glm::mat4 m = glm::mat4_cast(t.rotation);
  m[0] *= t.scale.x;
  m[1] *= t.scale.y;
  m[2] *= t.scale.z;
  m[3] = glm::vec4(t.translation, 1.0f);
  return m;
}

Status Skeleton::validate(const std::vector<std::string>& names, const std::vector<int>& parents,
                          size_t rest_count) {
  if (names.size() != parents.size() || names.size() != rest_count) {
    return Error{"skeleton: " + std::to_string(names.size()) + " names, " +
                 std::to_string(parents.size()) + " parents and " + std::to_string(rest_count) +
                 " rest transforms; the three must have the same length"};
  }
  std::unordered_map<std::string_view, size_t> seen;
  seen.reserve(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty())
      return Error{"skeleton: joint " + std::to_string(i) + " has an empty name"};
    auto [it, inserted] = seen.emplace(names[i], i);
    if (!inserted) {
      return Error{"skeleton: duplicate joint name '" + names[i] + "' (joints " +
                   std::to_string(it->second) + " and " + std::to_string(i) + ")"};
    }
    const int p = parents[i];
    if (p == static_cast<int>(i)) {
      return Error{"skeleton: joint '" + names[i] + "' is its own parent (a cycle)"};
    }
    if (p < -1 || p >= static_cast<int>(names.size())) {
      return Error{"skeleton: joint '" + names[i] + "' has parent index " + std::to_string(p) +
                   ", out of range [-1, " + std::to_string(names.size()) + ")"};
    }
    if (p > static_cast<int>(i)) {
      // A forward parent either forms a cycle or breaks the parent-before-child order; name which.
      std::vector<bool> visited(names.size(), false);
      int j = static_cast<int>(i);
      while (j >= 0 && !visited[j]) {
        visited[j] = true;
        j = parents[j] < -1 || parents[j] >= static_cast<int>(names.size()) ? -1 : parents[j];
      }
      if (j >= 0) {
        return Error{"skeleton: joint '" + names[i] + "' is part of a parent cycle"};
      }
      return Error{"skeleton: joint '" + names[i] + "' (index " + std::to_string(i) +
                   ") comes before its parent '" + names[p] + "' (index " + std::to_string(p) +
                   "); joints must be stored parent-before-child"};
    }
  }
  return Status::success();
}

Result<Skeleton> Skeleton::create(std::vector<std::string> names, std::vector<int> parents,
                                  std::vector<Transform> rest) {
  if (Status s = validate(names, parents, rest.size()); !s) return Error{s.message()};
  Skeleton sk;
  sk.names_ = std::move(names);
  sk.parents_ = std::move(parents);
  sk.rest_ = std::move(rest);
  const int n = sk.joint_count();
  sk.subtree_sizes_.assign(n, 1);
  // Children come after parents, so accumulating from the back visits every child first.
  for (int i = n - 1; i >= 0; --i) {
    if (sk.parents_[i] >= 0) sk.subtree_sizes_[sk.parents_[i]] += sk.subtree_sizes_[i];
  }
  return sk;
}

int Skeleton::find(std::string_view name) const {
  auto it = std::find(names_.begin(), names_.end(), name);
  return it == names_.end() ? -1 : static_cast<int>(it - names_.begin());
}

bool Skeleton::same_topology(const Skeleton& other) const {
  return names_ == other.names_ && parents_ == other.parents_;
}

}  // namespace mm
