#pragma once
// Poses are arrays of local transforms, one per joint, relative to the joint's parent.
// Forward kinematics turns them into global (model-space) transforms. Functions take spans so
// callers own the memory; none of them allocates.

#include <span>

#include "mm/runtime/skeleton.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// global[i] = global[parent[i]] * local[i] for every joint, in order (parents come first).
// A root's global transform is its local transform. Requires local.size() == global.size() ==
// parents.size().
void forward_kinematics(std::span<const int> parents, std::span<const Transform> local,
                        std::span<Transform> global);

// The global transform of one joint, walking only its chain of ancestors.
Transform forward_kinematics_joint(std::span<const int> parents, std::span<const Transform> local,
                                   int joint);

// Bone lengths from global transforms: a child's length is the distance between its global
// position and its parent's; a root's length is the length of its translation.
void bone_lengths(std::span<const int> parents, std::span<const Transform> global,
                  std::span<float> lengths);

}  // namespace mm
