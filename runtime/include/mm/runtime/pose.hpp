#pragma once
// Poses are arrays of local transforms, one per joint, relative to the joint's parent.
// Forward kinematics turns them into global (model-space) transforms. Functions take spans so
// callers own the memory; none of them allocates.

#include <array>
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

// forward_kinematics_joint(...).translation, to the bit, without the rotations and scales of the
// chain (a position depends only on its ancestors' transforms, never on the accumulated
// rotation below them).
glm::vec3 forward_kinematics_position(std::span<const int> parents,
                                      std::span<const Transform> local, int joint);
// forward_kinematics_position of two joints, each to the bit, in one walk where their chains
// meet: from the joint both descend from (the hips, for the upper legs), their two positions
// go up the rest of the chain together, in SSE lanes.
std::array<glm::vec3, 2> forward_kinematics_positions(std::span<const int> parents,
                                                      std::span<const Transform> local, int a,
                                                      int b);
// forward_kinematics_joint(...).rotation, to the bit, without the chain's translations.
glm::quat forward_kinematics_rotation(std::span<const int> parents,
                                      std::span<const Transform> local, int joint);

// The facing of a body from a left/right pair of joints' global positions (the hips' from the
// upper legs, the chest's from the upper arms): the yaw (radians about +Y, atan2(x, z), as
// quat_yaw) of the horizontal vector (left - right) x up, or `fallback` when the pair has no
// horizontal separation. Any skeleton gives it the same way, whatever its bones' axes.
float pair_yaw(const glm::vec3& left, const glm::vec3& right, float fallback = 0.0f);

// Bone lengths from global transforms: a child's length is the distance between its global
// position and its parent's; a root's length is the length of its translation.
void bone_lengths(std::span<const int> parents, std::span<const Transform> global,
                  std::span<float> lengths);

}  // namespace mm
