#pragma once
// The simulation object beside the wall it last met (issue 29). Sliding along a wall, it gives
// way to the character (the synchronization's yield) only so far back along its slide: the clip
// played does not slide, and given back to the character whole each update, the object stood
// still beside the wall where it could have slid. The limit holds while the object is beside the
// wall, and fades out over the last kBesideFade of the distances that say so: cut off there, the
// yield was whole on one update and limited on the next, back and forth as the object crossed
// the line, and the character, clamped to it, shook with it (docs/world.md, session 26).
//
// Units: metres, m/s, seconds. Robustness: a weight is in [0, 1] for any finite input (0 where
// a distance is not finite); a zero slide, a zero weight or dt <= 0 leaves the step as it is.
// Called per update: no allocation.

#include <glm/glm.hpp>

namespace mm {

// The object is beside its wall while no farther than kBesideObstacle from the wall's plane
// through where it met it, and within its radius of that point (the plane goes on past the
// wall's end).
inline constexpr float kBesideObstacle = 0.05f;
// Over this much (m) of each of those two distances the limit fades in.
inline constexpr float kBesideFade = 0.02f;
// The most of the object's slide along the wall (share) its yield may take back in an update.
inline constexpr float kMaxSlideBack = 0.5f;

struct WallMet {
  glm::vec3 point{0.0f};   // where the object's centre was when it met the wall
  glm::vec3 normal{0.0f};  // the wall's normal there (horizontal, away from the wall)
};

// Whether the object at `position` (radius `radius`) is beside the wall it met.
bool beside_wall(const glm::vec3& position, const WallMet& wall, float radius);

// How much of the limit holds at `position`: 1 well within both distances, falling to 0 at
// either's end (and beyond it).
float beside_weight(const glm::vec3& position, const WallMet& wall, float radius);

// `step` (the yield, horizontal) with its part back along the object's slide (its `velocity`
// along the wall over `dt`) at most kMaxSlideBack of the slide, that limit weighted by `weight`.
glm::vec3 without_slide_back(const glm::vec3& step, const glm::vec3& velocity,
                             const glm::vec3& normal, float weight, float dt);

}  // namespace mm
