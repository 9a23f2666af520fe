#pragma once
// Analytic two-bone inverse kinematics (hip -> knee -> ankle, or shoulder -> elbow -> wrist).
//
// The solve works on global (model-space) transforms and returns new local rotations for the
// upper (root) and middle joints; bone lengths never change because only rotations do. Given
// the knee's hinge (TwoBoneIkInput::hinge), the knee turns about it to the angle that makes the
// hip-to-ankle distance the (clamped) target distance and the chain swings the least way onto
// the line to the target. Without one, in order: the knee bends about the current bend axis until
// the hip-to-ankle distance equals the (clamped) target distance, with the hip turning by the
// matching angle; the chain swings so the ankle points at the target; finally it twists about the
// hip->target line so the knee lies in the half-plane of the pole direction. A limb bent away from
// the pole (a knee overstretched backward) unbends through straight toward it, as a hinge, instead
// of twisting half a turn about the hip->target line. Reach limits: a target farther than (1 -
// extension_epsilon) * (upper + lower length) is clamped to that distance on the line toward it (a
// nearly straight limb keeps a hint of bend, so its bend plane stays defined); one closer than
// |upper - lower| + extension_epsilon * (upper + lower) is pushed out to that. Degenerate inputs
// (zero-length bones, target at the hip, pole along the hip->target line, straight or folded limbs)
// never produce NaN.

#include <span>

#include "mm/runtime/transform.hpp"

namespace mm {

// Everything a two-bone solve needs, in model space.
struct TwoBoneIkInput {
  Transform root;  // global transform of the upper joint (hip)
  Transform mid;   // global transform of the middle joint (knee); its parent is the root joint
  Transform end;   // global transform of the end joint (ankle); its parent is the middle joint
  glm::quat root_parent_rotation{1.0f, 0.0f, 0.0f, 0.0f};  // global rotation of the hip's parent
  glm::vec3 target{0.0f};                                  // where the end joint should go
  glm::vec3 pole{0.0f, 0.0f, 1.0f};                        // direction the knee should bend toward
  // The knee's own bend axis, when known (a hinge; bending is a positive turn about it): the
  // knee turns about it alone, an overstretched knee through straight, and the chain swings
  // the least way onto the target line, so the thigh and shin keep their twist. The pole is
  // then not read (but where the axis lies along the thigh). Zero: no hinge.
  glm::vec3 hinge{0.0f};
  float extension_epsilon = 1e-4f;  // fraction of full reach kept as a minimal bend
};

// The solved chain. Rotations are unit quaternions; positions are where FK will put the joints.
struct TwoBoneIkResult {
  glm::quat root_local{1.0f, 0.0f, 0.0f, 0.0f};   // new local rotation of the hip
  glm::quat mid_local{1.0f, 0.0f, 0.0f, 0.0f};    // new local rotation of the knee
  glm::quat root_global{1.0f, 0.0f, 0.0f, 0.0f};  // new global rotation of the hip
  glm::quat mid_global{1.0f, 0.0f, 0.0f, 0.0f};   // new global rotation of the knee
  glm::vec3 mid_position{0.0f};                   // new global knee position
  glm::vec3 end_position{0.0f};                   // new global ankle position
  bool reached = false;  // true when the target was within the reach limits (not clamped)
};

// Solves the two-bone chain. Zero-length bones or non-finite inputs return the input rotations
// unchanged (reached = false).
TwoBoneIkResult solve_two_bone_ik(const TwoBoneIkInput& input);

// Solves the chain root -> mid -> end of a pose in place: writes the new local rotations of
// root and mid and recomputes the global transforms of root and its descendants. Requires
// parents[mid] == root, parents[end] == mid, and `global` to be the FK of `local`. The result
// holds the locals and `reached` only (the new globals are in `global`); a chain the solve cannot
// bend (zero-length bones, non-finite input) keeps its locals.
TwoBoneIkResult apply_two_bone_ik(std::span<const int> parents, std::span<Transform> local,
                                  std::span<Transform> global, int root, int mid, int end,
                                  const glm::vec3& target, const glm::vec3& pole,
                                  const glm::vec3& hinge = glm::vec3(0.0f),
                                  float extension_epsilon = 1e-4f);

// apply_two_bone_ik for a caller that sets the end joint's local rotation after the solve (a foot
// turned to its own rotation) and refreshes the end's subtree itself: the globals of the root's
// descendants are refreshed except the end and its descendants, which keep their old values.
// Requires the joints in depth-first order (a joint's descendants are the next
// subtree_sizes[joint] - 1 joints, as Skeleton keeps them).
TwoBoneIkResult apply_two_bone_ik_above_end(std::span<const int> parents,
                                            std::span<const int> subtree_sizes,
                                            std::span<Transform> local, std::span<Transform> global,
                                            int root, int mid, int end, const glm::vec3& target,
                                            const glm::vec3& pole,
                                            const glm::vec3& hinge = glm::vec3(0.0f),
                                            float extension_epsilon = 1e-4f);

}  // namespace mm
