#pragma once
// How far a leg reaches toward its target (the foot lock's IK, controller.cpp): where the ankle
// goes when the hip-to-ankle distance asked for is at or beyond what the leg should stretch to.
//
// Near full extension a knee's angle changes ever faster with the hip-to-ankle distance, so a
// target at the edge of reach makes the knee snap. Reach is softened instead (soft_reach):
// distances up to kSoftReach of the leg's length, or up to the animation's own hip-to-ankle
// distance when its leg is straighter than that (but no nearer the full length than kMinSoftSpan
// of it), are kept; longer ones approach the full length exponentially, never reaching it. The
// animation's own extension is kept only standing, where poses lock their knees and softening them
// would bend both knees forward by centimetres; in motion the shorter span it leaves makes knees
// snap straight at the transitions.
//
// A leg that falls short falls short along the hip-to-target line, except a foot reaching down
// to ground lower than the body's (reach_down): it stays over the point it reaches for.
//
// Units: metres. Robustness: a zero vector or a zero length gives the zero vector back; weights
// are clamped to [0, 1]. Called per update: no allocation.

#include <glm/glm.hpp>

namespace mm {

inline constexpr float kSoftReach = 0.96f;
inline constexpr float kMinSoftSpan = 0.01f;

// `hip_to_ankle` shortened to the softened reach of a leg of `length` whose animation has the
// ankle `animated_distance` from the hip; `keep_animated` in [0, 1] is how much of the
// animation's own extension beyond kSoftReach is kept (1 standing, 0 in motion, eased between,
// so the reach never jumps).
glm::vec3 soft_reach(const glm::vec3& hip_to_ankle, float animated_distance, float keep_animated,
                     float length);

// `hip_to_ankle` shortened to `length` by its height, not along itself: the ankle stays over the
// point it reaches for (as far out as `length` allows) and falls short of it below.
glm::vec3 short_below(const glm::vec3& hip_to_ankle, float length);

// `reached` (the softened reach toward `hip_to_ankle`, no longer than it) turned toward
// short_below by `weight`, keeping its length: a foot whose ground lies below the body's stays
// over where it reaches for until the pelvis comes down, rather than swinging back toward the
// hip (into the side of the step the body stands on). Unchanged where the leg reaches, or where
// the target is not below the hip.
glm::vec3 reach_down(const glm::vec3& hip_to_ankle, const glm::vec3& reached, float weight);

// `hip_to_ankle` (where a heel lifted about a held toe puts the ankle) no longer than `length`:
// cut along itself, or, by `weight` as reach_down's, kept over the point it reaches for.
glm::vec3 reach_at_most(const glm::vec3& hip_to_ankle, float length, float weight);

}  // namespace mm
