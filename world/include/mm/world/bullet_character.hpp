#pragma once
// A game's own character capsules, moved by Bullet's kinematic character controller
// (btKinematicCharacterController on a btPairCachingGhostObject), over a level's triangles: the
// game-owned mode of docs/world.md ("A game that owns its capsule") with a real physics engine.
// Per frame the game updates the controller, moves the capsule toward where the controller's
// simulation object went (Controller::simulation_position_world()), and hands the resolved feet
// position back (Controller::set_simulation_position_world). Bullet stays private to this
// library: nothing here names it.
//
// What Bullet's controller does with a move (and so what a game using it gets): the capsule
// slides along walls, climbs steps up to step_height (and slopes up to max_slope), and falls
// under gravity where there is no ground. It stops at a wall to within a few millimetres, either
// side of the contact. With the dispatcher's allowed CCD penetration set to 0 here (Bullet's
// default, 4 cm, lets the capsule rest that deep in the ground and walls), feet() stands on the
// surface, and over a step's edge on its rounded bottom (tests/world/bullet_character_test.cpp
// checks both).
//
// Frame: world positions in double, converted once to the float frame of the level's origin,
// where the geometry and the capsules are held.
// Not thread safe: one thread moves every capsule of one BulletCharacters.

#include <cstddef>
#include <memory>

#include <glm/glm.hpp>

#include "mm/runtime/result.hpp"
#include "mm/world/level.hpp"

namespace mm {

struct CapsuleSettings {
  float radius = 0.3f;        // m
  float height = 1.7f;        // m, the whole capsule (at least 2 * radius)
  float step_height = 0.35f;  // m: a step up to this is climbed
  float max_slope = 0.8f;     // rad: steeper ground is a wall
  float gravity = 9.81f;      // m/s², down
};

class BulletCharacters {
 public:
  // A collision world of the level's triangles (validated with Level::validate; it must hold
  // some). The triangles are copied.
  static Result<BulletCharacters> create(const Level& level);

  BulletCharacters(BulletCharacters&&) noexcept;
  BulletCharacters& operator=(BulletCharacters&&) noexcept;
  ~BulletCharacters();

  // A capsule standing with its feet at `feet` (world). Refused when the settings are not
  // finite and positive (height >= 2 * radius) or `feet` is not finite or beyond
  // ±kMaxLevelCoordinate. Returns the capsule's index.
  Result<size_t> add(const glm::dvec3& feet, const CapsuleSettings& settings = {});

  // Walks capsule `index` toward `goal`'s x and z (its y is the physics' own: ground and
  // gravity) over `dt` seconds and returns where its feet ended. A goal that is not finite or
  // out of reach is taken as no move.
  glm::dvec3 move(size_t index, const glm::dvec3& goal, float dt);

  glm::dvec3 feet(size_t index) const;
  bool on_ground(size_t index) const;
  size_t size() const;

 private:
  struct State;
  explicit BulletCharacters(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace mm
