#pragma once
// A joint hierarchy stored parent-before-child: joint i's parent index is < i (or -1 for a
// root). Each joint has a name, a rest local transform and the size of its subtree (the joint
// itself plus all its descendants). Importers store joints depth-first, where a joint's
// descendants are exactly the next subtree_size - 1 joints.

#include <string>
#include <string_view>
#include <vector>

#include "mm/runtime/result.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

class Skeleton {
 public:
  Skeleton() = default;

  // Builds a skeleton from its parts and validates it: every parent index is -1 or refers to an
  // earlier joint (which also rules out cycles), names are non-empty and unique, and the three
  // arrays have the same length.
  static Result<Skeleton> create(std::vector<std::string> names, std::vector<int> parents,
                                 std::vector<Transform> rest);

  // Checks the same rules as create() on raw arrays without building anything. Parent indices
  // that point forward or out of range, cycles, duplicate or empty names are each named.
  static Status validate(const std::vector<std::string>& names, const std::vector<int>& parents,
                         size_t rest_count);

  int joint_count() const { return static_cast<int>(parents_.size()); }
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<int>& parents() const { return parents_; }
  const std::vector<Transform>& rest() const { return rest_; }
  const std::vector<int>& subtree_sizes() const { return subtree_sizes_; }

  const std::string& name(int joint) const { return names_[joint]; }
  int parent(int joint) const { return parents_[joint]; }
  const Transform& rest(int joint) const { return rest_[joint]; }
  int subtree_size(int joint) const { return subtree_sizes_[joint]; }

  // Index of the joint with this exact name, or -1.
  int find(std::string_view name) const;

  // True when both skeletons have the same joint names in the same order with the same parents
  // (rest transforms may differ, e.g. between actors).
  bool same_topology(const Skeleton& other) const;

 private:
  std::vector<std::string> names_;
  std::vector<int> parents_;
  std::vector<Transform> rest_;
  std::vector<int> subtree_sizes_;
};

}  // namespace mm
