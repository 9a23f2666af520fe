#pragma once
// Retargeting: a clip of one skeleton (the source, S) becomes a clip of another (the target, T).
//
// Joints are matched by role (joint_roles.hpp). Each matched bone's world direction follows the
// source: with RS and RT the rest-pose global rotations of the matched joints,
//   G_T(t) = G_S(t) * inverse(RS) * A * RT,
// where A turns T's rest bone onto S's rest bone: first the body (the facing and up of the two
// rest poses, from the upper legs and the spine) and then the shortest swing of the bone's
// direction (towards its child role, or its End Site where the child role is missing, e.g. a
// wrist). So a T-pose source drives an A-pose target, and the twist about each bone is carried
// over as the rest poses relate it. A role whose bone has no direction (a hand, a toe, the head)
// takes its parent role's alignment. Unmatched target joints keep their rest local rotation,
// every bone keeps T's length, and the root follows the source hips scaled by the ratio of the
// two skeletons' leg lengths, then stands on T's ground: the result is lifted or lowered so that
// its lowest toe over the clip sits where T's own data puts its lowest toe.
//
// Rest poses: a skeleton's bind pose (the importer's rest transforms) when it stands (both feet
// at least half a leg below the hips and the spine pointing up), else its first frame, unless a
// frame is named. The Bandai bind pose lays every bone along its local X, so its data is aligned
// through a frame of motion instead.

#include <string>
#include <vector>

#include "mm/database/joint_roles.hpp"
#include "mm/offline/clip.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// One side of a retargeting: a skeleton with its roles, the rest pose its bones are aligned by,
// and where its toes touch the ground.
struct RetargetSkeleton {
  Skeleton skeleton;
  JointRoleIndices roles;
  // Local transforms of the rest pose (one per joint): the bind pose or a frame of motion.
  std::vector<Transform> rest_pose;
  // Per joint, its End Site offset (zero where none), or empty.
  std::vector<glm::vec3> end_sites;
  // The lowest height (metres above y = 0) the toe joints (the feet where there are no toes)
  // reach in this skeleton's own data; where the retargeted clip's lowest toe is put.
  float toe_floor = 0.0f;
  // What rest_pose is, for reports: "bind pose" or "frame N".
  std::string rest_description;
};

// Describes `clip`'s skeleton for retargeting. `rest_frame` >= 0 names the frame of the rest
// pose; -1 takes the bind pose if it stands, else frame 0 (see the top of this file). The toe
// floor is measured over every frame of the clip. Fails when the frame is out of range.
Result<RetargetSkeleton> describe_for_retargeting(const Clip& clip, const JointRoleIndices& roles,
                                                  int rest_frame = -1);

// What a retargeting did.
struct RetargetReport {
  std::vector<std::string> matched;       // "role: source joint -> target joint"
  std::vector<std::string> left_at_rest;  // target joints that keep their rest rotation
  float scale = 1.0f;                     // target leg length / source leg length
  float ground_shift = 0.0f;              // metres the result was raised (negative: lowered)
};

// The source clip on the target's skeleton (its names, hierarchy and rest offsets), with the
// source's frame time and frame count. Fails when a required role is missing on either side.
Result<Clip> retarget_clip(const Clip& source, const RetargetSkeleton& from,
                           const RetargetSkeleton& to, RetargetReport* report = nullptr);

// Leg length of a skeleton: upper leg to foot through the lower leg, averaged over both sides,
// from the rest offsets (metres).
float leg_length(const Skeleton& skeleton, const JointRoleIndices& roles);

// The lowest height (metres) a foot's end reaches in any frame of `clip`: per side the toe's End
// Site (the toe joint where it has none), or without a toe role the foot's End Site (or the foot
// joint). Where a skeleton has its soles in the data, this is about where its ground is.
float lowest_foot_end(const Clip& clip, const JointRoleIndices& roles);

}  // namespace mm
