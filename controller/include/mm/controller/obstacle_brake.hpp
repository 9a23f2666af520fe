#pragma once
// Slowing down before an obstacle (issue 29). The simulation object follows the stick's velocity
// on a spring, and the world stops it where it meets a wall or a ledge's edge: walked into, it
// stopped within an update, and the character kept with it stopped dead (the whole body in one
// update, a toe swung out over the edge pulled back; docs/world.md, sessions 25 and 26). People
// slow down before they get there, and the collided trajectory already shows where: the first
// predicted sample the world stopped short of its goal. Toward it, the velocity the simulation
// object follows is kept to the speed from which a constant deceleration stops in the room left, so
// the character arrives nearly at rest; headed along the obstacle (a slide along a wall) nothing
// changes. The search still sees the stick's own trajectory, stopped at the obstacle, and picks the
// stop.
//
// Units: metres, m/s, m/s^2. Robustness: non-finite positions give no obstacle, a non-finite or
// non-positive deceleration brakes nothing. Called per update: no allocation.

#include <span>

#include <glm/glm.hpp>

namespace mm {

struct ObstacleAhead {
  bool found = false;
  glm::vec3 direction{0.0f};  // horizontal unit vector into the obstacle (against its normal)
  glm::vec3 stop{0.0f};       // where the blocked sample was stopped
};

// A sample stopped more than this (m, horizontally) short of its goal was blocked.
inline constexpr float kBlockedShort = 0.05f;

// The first of the predicted `goals` (in time order) that the world stopped short of: `reached`
// holds where each one's move ended and `normals` the horizontal normal of what stopped it (a
// wall's face, away from it; a ledge's edge, away from the drop), zero where nothing did. The way
// it blocks is against that normal: a move that slid along a wall, or stopped where a second
// wall meets it, is short of its goal along the wall too, and braked that way the simulation
// object stood at the entrance of a corridor it could have slid into. None found: `found` is false.
ObstacleAhead obstacle_ahead(std::span<const glm::vec3> goals, std::span<const glm::vec3> reached,
                             std::span<const glm::vec3> normals);

// A velocity with less than this share of its (horizontal) length along the obstacle heads into
// it; one that goes more along it slides along it as the world lets it, unbraked. Braked, a
// circle run curving beside a stair's side slowed while the clip played on, the character
// running far ahead of the simulation object.
inline constexpr float kAlongShare = 0.5f;

// `velocity` with its part toward `ahead` (horizontal) no faster than the speed from which
// `deceleration` stops within the room left from `position` to where the trajectory was stopped;
// unchanged unless it heads into the obstacle (kAlongShare).
glm::vec3 braked_velocity(const glm::vec3& velocity, const glm::vec3& position,
                          const ObstacleAhead& ahead, float deceleration);

}  // namespace mm
