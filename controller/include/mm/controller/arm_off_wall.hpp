#pragma once
// An arm swung out of a wall (issue 28): the body is moved back from a wall only so far
// (the legs must still reach the feet), and an arm swinging wide at a wall beside the character
// reaches past that. What is still in after the body's push is taken by turning the arm about
// its upper arm, toward the wall's outward normal, by the smallest turn that brings its deepest
// joint a margin out: the hand and forearm fold in against the wall rather than through it. The
// turn is a projection onto the wall's plane, so it follows the animation continuously: nothing
// to ease. Called per frame: no allocation.

#include <span>

#include <glm/glm.hpp>

#include "mm/runtime/transform.hpp"

namespace mm {

// A wall as a point on its face and its unit outward normal.
struct WallPlane {
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f};
};

// Turns the joints below `upper_arm` (its descendants in `parents`, which lists every joint's
// parent before the joint) about the upper arm's position so that none is less than `margin`
// in front of `wall`; `globals` are model or world transforms (translation and rotation). Two
// passes: the deepest joint first, then whatever the first turn left in (the elbow when the hand
// came out). Returns how far the deepest joint was past the margin before (0: nothing moved).
// An upper arm itself in the wall, or a wall that no turn of the arm clears, is left to the
// body's push: the joints come as far out as the arm's length allows.
float swing_arm_out_of_wall(std::span<Transform> globals, std::span<const int> parents,
                            int upper_arm, const WallPlane& wall, float margin);

}  // namespace mm
