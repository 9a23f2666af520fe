#pragma once
// The game's world, as the controller asks about it: the query interface a game implements
// with its own physics or collision (docs/world.md; `world/` has one over Bullet, outside the
// game-facing libraries). The controller links no physics engine.
//
// Who calls, how often: the controller, inside update(), a fixed number of batched calls per
// update (at most kMaxWorldCallsPerUpdate), each carrying every query of one kind that one of
// its moves needs: a sweep, a slide and a ground probe (character_mover.hpp) for the simulation
// object (and one sweep of its give toward the character), the same for the animated root, and
// the same for every predicted trajectory sample at once; one call probing the ground under the
// feet (foot_placement.hpp) and one sweeping toward the toes and arms. The spans are the
// controller's own pre-sized buffers: an implementation must not keep them past the call. A
// call must not allocate if the game's frame must not, and must be safe to make from the thread
// that runs this controller's update (several controllers may query one world from several
// threads at once: queries are const).
//
// In what frame: every position is relative to `origin` (world = origin + position, added in
// double), the controller's local origin (local_origin.hpp): near the world origin it is zero
// and positions are world positions; far away, the game adds the origin in double precision and
// answers relative to it, so queries stay exact 100 km out. Y is up, metres.
//
// Robustness: the controller checks every answer. A non-finite value, a normal of (near) zero
// length, a ground point off the probe's segment, or a sweep that ends off its segment is
// ignored (treated as no hit) and counted in ControllerDebug::world_rejected.

#include <span>

#include <glm/glm.hpp>

namespace mm {

// At most this many query calls per update: three moves (simulation, root, trajectory) of at
// most three calls each, the feet's ground probes (foot_placement.hpp), the sweeps toward the
// toes and arms (walls near the feet), and the simulation object's give toward the character
// (one sweep).
inline constexpr int kMaxWorldCallsPerUpdate = 12;

// From `from`, straight down (-Y), at most `max_distance` metres.
struct GroundProbe {
  glm::vec3 from{0.0f};
  float max_distance = 1.0f;
  // The surface is walkable when its normal's Y is at least this (the cosine of the steepest
  // walkable slope).
  float min_walkable_normal_y = 0.7f;
};

struct GroundHit {
  bool hit = false;           // a surface within max_distance below `from`
  glm::vec3 point{0.0f};      // where the ray meets it (x and z of `from`)
  glm::vec3 normal{0, 1, 0};  // the surface's unit normal, facing up
  bool walkable = false;      // normal.y >= min_walkable_normal_y (or the game's own rule)
};

// A vertical capsule (radius, height from the bottom of its lower sphere to the top of its
// upper one; height = 2 * radius is a sphere) moved from `from` to `to`, both the centre of its
// bottom sphere's base point (the capsule stands on `from`).
struct ShapeSweep {
  glm::vec3 from{0.0f};
  glm::vec3 to{0.0f};
  float radius = 0.3f;
  float height = 1.0f;
};

struct SweepHit {
  bool hit = false;        // the shape touched something before reaching `to`
  float fraction = 1.0f;   // how far along from -> to it got, in [0, 1]
  glm::vec3 normal{0.0f};  // the contact's unit normal, pointing out of the obstacle
};

// The game's world. Implementations fill every element of the output span (same size as the
// input's); a query that finds nothing leaves the defaults (no hit).
class WorldQueries {
 public:
  virtual ~WorldQueries() = default;

  virtual void probe_ground(const glm::dvec3& origin, std::span<const GroundProbe> probes,
                            std::span<GroundHit> hits) const = 0;
  virtual void sweep(const glm::dvec3& origin, std::span<const ShapeSweep> sweeps,
                     std::span<SweepHit> hits) const = 0;
};

}  // namespace mm
