#pragma once
// mm::WorldQueries (mm/controller/world.hpp) answered by Bullet over a level's triangles and
// optional static boxes. Bullet stays private to this library: nothing here names it.
//
// - probe_ground: a ray from `from` straight down `max_distance`, the closest hit; its point
//   (x and z of `from`), the surface's unit normal turned to face up, walkable when
//   normal.y >= min_walkable_normal_y.
// - sweep: a capsule along Y (btCapsuleShape; `height` is the whole capsule, so Bullet's
//   cylinder part is height - 2 * radius, and a height below 2 * radius is a sphere) standing on
//   `from`: its centre is from + (0, height / 2, 0). Cast from `from` to `to`, the closest hit:
//   the fraction of the way it got and the contact's unit normal, turned against the motion
//   (out of the obstacle). A capsule that starts touching or overlapping something hits it at
//   fraction 0 when the motion goes into it (Bullet's convex cast rules).
// - A query Bullet cannot take is answered "no hit" (the defaults) without calling it: a
//   non-finite value, radius <= 0, max_distance < 0, or a point farther than kMaxQueryReach
//   from the world's origin on any axis. Mismatched span sizes are a caller's error
//   (MM_ASSERT).
//
// Precision far from the world origin: the geometry is held in float relative to
// origin() (the level's origin, a double), and every query is converted in double
// (query origin + position - origin()) and rounded to float once; answers come back the same
// way. So a query d metres from origin() is exact to d * 2^-24 (0.06 mm at 1 km): a level
// 100 km from the world origin, queried with an `origin` 100 km out, answers as one at the
// world origin does (tests/world/bullet_world_test.cpp). Bullet's own accuracy, as measured
// there: ray hits to float rounding; sweep fractions against a face within 1e-4; a normal at an
// edge contact within 1e-3 (its conservative advancement stops a hair short of the contact).
//
// Threads: probe_ground and sweep are const and may run on any number of threads at once, on
// one world, while nothing calls add_box. They do not go through btCollisionWorld::rayTest and
// convexSweepTest: in Bullet built without BT_THREADSAFE (Debian's libbullet 3.24 is),
// btDbvtBroadphase::rayTest, which both call, works in one traversal stack the broadphase
// owns (m_rayTestStacks[0]), and convexSweepTest enters Bullet's profiler, whose state is
// global. Each query instead tests the world's few collision objects' bounds itself and hands
// the ones it touches to btCollisionWorld::rayTestSingle or objectQuerySingle, which keep all
// their state on the caller's stack (result callbacks, simplex solvers, temporary triangle
// shapes) and walk the mesh's quantized tree without a stack. See docs/world-levels.md.
//
// Allocation: none per query, on our side or in Bullet (tests/world/no_allocation_test.cpp
// counts operator new and Bullet's btAlignedAlloc over thousands of queries).

#include <cstddef>
#include <memory>
#include <span>

#include <glm/glm.hpp>

#include "mm/controller/world.hpp"
#include "mm/runtime/result.hpp"
#include "mm/world/level.hpp"

namespace mm {

// A query point farther than this (m) from the world's origin() on any axis cannot touch its
// geometry (which lies within 2 * kMaxLevelCoordinate of it) and is answered "no hit": it
// keeps every float Bullet sees far from overflow.
inline constexpr double kMaxQueryReach = 1'000'000.0;

// A static box: centre in the world frame (double), half extents along its own axes, turned
// by `yaw` radians about +Y (its local +Z goes to (sin yaw, 0, cos yaw)).
struct WorldBox {
  glm::dvec3 center{0.0};
  glm::vec3 half_extents{0.5f};
  float yaw = 0.0f;
};

// The smallest half extent a box may have (m): Bullet rounds a box's edges by its collision
// margin (4 cm, inside the box's extents), which needs room inside.
inline constexpr float kMinBoxHalfExtent = 0.05f;

class BulletWorld final : public WorldQueries {
 public:
  // A world of the level's triangles (validated with Level::validate; an empty level makes a
  // world of boxes alone). The triangles are copied: `level` need not outlive the world.
  static Result<BulletWorld> create(const Level& level);

  BulletWorld(BulletWorld&&) noexcept;
  BulletWorld& operator=(BulletWorld&&) noexcept;
  ~BulletWorld() override;

  // Adds a static box. Refused when not finite, a half extent is below kMinBoxHalfExtent, or a
  // corner lies beyond ±kMaxLevelCoordinate. Not while queries run on other threads. Boxes are
  // tested one by one by every query that reaches them: for tests and a few obstacles; many
  // belong in the level's mesh.
  Status add_box(const WorldBox& box);

  void probe_ground(const glm::dvec3& origin, std::span<const GroundProbe> probes,
                    std::span<GroundHit> hits) const override;
  void sweep(const glm::dvec3& origin, std::span<const ShapeSweep> sweeps,
             std::span<SweepHit> hits) const override;

  // Where the geometry is measured from (the level's origin).
  glm::dvec3 origin() const;
  size_t triangle_count() const;
  size_t box_count() const;

 private:
  struct State;
  explicit BulletWorld(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace mm
