#pragma once
// Forward kinematics four joints at a time. A skeleton's joints are put, once, into blocks of up
// to four whose parents all lie in earlier blocks (the longest chains first, so a humanoid's 23
// joints take 9 blocks, the chain from the root to a hand being 9 long); each block is composed in
// SSE lanes with GLM's operations in their order, so the global transforms equal
// forward_kinematics' to the bit.

#include <array>
#include <span>
#include <vector>

#include "mm/runtime/transform.hpp"

namespace mm {

class ForwardKinematicsPlan {
 public:
  ForwardKinematicsPlan() = default;
  // The plan of a skeleton (parents as forward_kinematics takes them). Allocates: build it once.
  explicit ForwardKinematicsPlan(std::span<const int> parents);

  // forward_kinematics(parents, local, global) of the plan's skeleton, to the bit.
  void run(std::span<const Transform> local, std::span<Transform> global) const;
  // The same for a pose whose every scale is exactly (1, 1, 1), as every pose sampled from a
  // database is (it stores none): the scales' products, which would multiply by one, are
  // skipped and the globals' scales written as one, so the result still equals run's to the
  // bit. Scales other than one are not looked at (the caller's promise).
  void run_unit_scale(std::span<const Transform> local, std::span<Transform> global) const;

  size_t joint_count() const { return parents_.size(); }

 private:
  struct Block {
    std::array<int, 4> joints{};   // unused lanes repeat the last joint
    std::array<int, 4> parents{};  // the lanes' parents, looked up once here
    int count = 0;
    bool lanes = false;  // composed in SSE lanes: more than one joint, none a root
  };
  template <bool kUnitScale>
  void run_blocks(std::span<const Transform> local, std::span<Transform> global) const;

  std::vector<int> parents_;
  std::vector<Block> blocks_;
};

}  // namespace mm
