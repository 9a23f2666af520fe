#pragma once
// Moving a character's capsule through the game's world (world.hpp): the rules the controller
// applies to its simulation object, its predicted trajectory and its animated root, in one
// place so that all three meet walls, steps and slopes alike.
//
// A move goes from a point standing on the ground toward a horizontal goal (its y is ignored):
// 1. sweep: the capsule, lifted by step_height (so a step lower than that passes under it),
//    from the start toward the goal. A hit stops it `kSkin` short of the contact;
// 2. slide: what the hit cut off, less its part into the obstacle (the contact normal made
//    horizontal), is swept again from there: pushing diagonally along a wall keeps moving along
//    it, pushing head-on stops. The slide is swept from kSkin off the face's plane (a stop kSkin
//    short along a glancing move leaves the capsule nearly touching the face, and a sweep along
//    it from there meets it at once). A second hit stops the slide (a corner). A step exactly
//    step_height high (the physics engine's sweep meets its top within a few millimetres of the
//    lifted capsule's bottom, a contact facing up, kStepTopNormalY) is climbed, not a wall: the
//    rest is swept again kStepClearance higher. A step up to step_height is climbed; a higher one
//    meets the capsule's side and is slid along. Taken head-on it stalled the character at the
//    step's edge for seconds;
// 3. ground: a probe down from step_height + kStepClearance above the start's height (a ray
//    starting exactly on a step's top misses it), as far as step_height + kStepClearance +
//    max_step_down, at where the sweeps ended. Walkable ground there is the new height (up a
//    step, down a step, along a slope). No ground within reach (a ledge) or ground too steep:
//    the move does not happen, the character stays where it was (never launched into the air,
//    never below the ground). A drop deeper than step_height, under the capsule's centre or
//    kLedgeLead of its radius ahead of it, is a ledge too: lowered that far, the lifted capsule
//    would overlap the edge it left, and a sweep that starts inside geometry sees nothing, so the
//    next move would walk back through the ledge's side (found strafing off a ramp's side). The
//    lead keeps the centre, and so the feet, back from the edge. A short move (at most a radius)
//    also probes a ring of kEdgeProbes points around its end, kEdgeRing radii out, each reached
//    in two hops (a probe halfway out: over two hops no longer than a steep stair's tread, a
//    stair is no ledge): a drop deeper than a step on either hop is an edge beside the capsule, its
//    normal the mean of their directions turned away (a ring fixed to the world, not to the move:
//    probes turned with the move pointed a new way on every update of a slow move, and the velocity
//    taken into each stalled it). Met like a wall: only the part of the step toward it is taken
//    away, so a move along it or away from it goes on; a step that had a part toward it is
//    `blocked`, and every such move reports the edge (`edge_normal`) for the trajectory.
//    max_step_down is how far the probe reaches: ground found below a drop it cannot take still
//    tells a ledge from a hole.
// Each phase is one batched call to the world (all trajectory samples at once). Answers that
// fail the checks of world.hpp count as no hit and are counted in rejected().
//
// No allocation: the buffers are sized for kMaxMoves moves at once.

#include <array>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include "mm/controller/world.hpp"

namespace mm {

// The character's shape and how it climbs (metres; the slope as the cosine of the steepest
// walkable one).
struct CharacterShape {
  float radius = 0.3f;
  float height = 1.7f;
  float step_height = 0.35f;
  float max_step_down = 0.5f;
  float min_walkable_normal_y = 0.7f;
};

// Where a move ended.
struct MoveResult {
  glm::vec3 position{0.0f};      // on the ground
  glm::vec3 normal{0.0f};        // the (horizontal) normal of the first obstacle met, else zero
  glm::vec3 slide_normal{0.0f};  // of a second one that stopped the slide along it (a corner)
  bool blocked = false;          // the sweeps met something
  bool no_ground = false;        // no walkable ground at the end: the move was cancelled
  bool edge = false;             // blocked by a ledge's edge beside its end (normal: away from it)
  // The horizontal unit normal (away from the drop) of a ledge's edge within kEdgeRing radii of
  // a short move's end, whether or not the move went toward it, or of the ledge straight ahead
  // that cancelled it (no_ground); else zero.
  glm::vec3 edge_normal{0.0f};
  glm::vec3 ground_normal{0.0f, 1.0f, 0.0f};  // the surface under `position`
};

class CharacterMover {
 public:
  // At most this many moves in one collide() call (the trajectory's samples).
  static constexpr int kMaxMoves = 16;
  // How far short of a contact a sweep stops (m), so that the next sweep does not start
  // touching the obstacle.
  static constexpr float kSkin = 0.01f;
  // Where ahead of the capsule's centre, in radii along the move, a drop makes a ledge: within
  // one tread of steep stairs (a 0.26 m tread is more than half a 0.3 m radius).
  static constexpr float kLedgeLead = 0.5f;
  // A sweep's contact whose normal is at least this close to straight up (its y) is the lifted
  // capsule's bottom on the top of a step as high as the lift (step_height): climbed, not a wall.
  static constexpr float kStepTopNormalY = 0.99f;
  // How much higher (m) the rest of a move is swept after meeting such a step, how far above the
  // lift the ground probe starts, and how much deeper than step_height a drop may be and still be
  // a step down.
  static constexpr float kStepClearance = 0.02f;
  // The ring of probes that finds a ledge's edge beside a short move's end: this many, evenly
  // around it, this many radii out (1 / cos(180 / kEdgeProbes degrees): an edge between two
  // probes is met when it comes within a radius of the centre).
  static constexpr int kEdgeProbes = 8;
  static constexpr float kEdgeRing = 1.0823922f;

  // Moves each start[i] toward goal[i] (y ignored) and writes where it ended to out[i]: three
  // batched calls to the world (sweep, slide, ground), whatever the count (at most kMaxMoves).
  // Positions relative to `origin`, as the world's queries take them.
  void collide(const WorldQueries& world, const glm::dvec3& origin, const CharacterShape& shape,
               std::span<const glm::vec3> starts, std::span<const glm::vec3> goals,
               std::span<MoveResult> out);

  // One move.
  MoveResult move(const WorldQueries& world, const glm::dvec3& origin, const CharacterShape& shape,
                  const glm::vec3& start, const glm::vec3& goal);

  // The walkable ground under `position`, probed from `above` metres above it down to
  // max_step_down below it; false when there is none within reach.
  bool ground(const WorldQueries& world, const glm::dvec3& origin, const CharacterShape& shape,
              const glm::vec3& position, float above, GroundHit& hit);

  // A horizontal `step` from `position` (the simulation object's give toward the character) less
  // its part into whatever the capsule meets on the way: one sweep, no slide, no ground probe. A
  // step's top under the capsule's bottom is no obstacle.
  glm::vec3 free_step(const WorldQueries& world, const glm::dvec3& origin,
                      const CharacterShape& shape, const glm::vec3& position,
                      const glm::vec3& step);

  // Ground probes as given, in one call to the world; an answer that fails the checks
  // (world.hpp) becomes no hit and is counted in rejected(). `hits` is as long as `probes`.
  void probe(const WorldQueries& world, const glm::dvec3& origin,
             std::span<const GroundProbe> probes, std::span<GroundHit> hits);
  // Shape sweeps as given, in one call to the world, checked the same way.
  void sweep(const WorldQueries& world, const glm::dvec3& origin,
             std::span<const ShapeSweep> sweeps, std::span<SweepHit> hits);

  // Answers ignored because they failed the checks (world.hpp), since creation.
  int64_t rejected() const { return rejected_; }

 private:
  bool accept(const ShapeSweep& query, SweepHit& hit);
  bool accept(const GroundProbe& query, GroundHit& hit);
  void keep_off_edges(const glm::vec3& start, const GroundHit& ground, float step_down,
                      size_t first, MoveResult& out);
  static bool drops(const GroundHit& from, const GroundHit& lead, float step_down);
  static constexpr size_t kLeads = 1 + 2 * kEdgeProbes;  // per short move: ahead, the rings

  std::array<ShapeSweep, kMaxMoves> sweeps_{};
  std::array<SweepHit, kMaxMoves> sweep_hits_{};
  // Per move: its end, then (short moves that go anywhere) ahead of it and the ring.
  std::array<GroundProbe, (1 + kLeads) * kMaxMoves> probes_{};
  std::array<GroundHit, (1 + kLeads) * kMaxMoves> ground_hits_{};
  std::array<int, kMaxMoves> lead_{};      // the probe ahead of each move's end, or -1
  std::array<int, kMaxMoves> ring_{};      // the first probe of the ring around it, or -1
  std::array<int, kMaxMoves> slid_{};      // the move each slide sweep belongs to
  std::array<bool, kMaxMoves> climbed_{};  // the sweep met a step's top (phase 2), not a wall
  int64_t rejected_ = 0;
};

// The obstacles one repeated move (the animated root's, update after update) met lately: a
// wall's face or a ledge's edge, each remembered as a half-plane for kMemory seconds. Judged
// afresh on every update, the obstacle was met on one and missed on the next (a sweep stops kSkin
// short, and the next step starting inside the skin misses the face; a probe of the ring sees a
// drop from one end and not from the next, or sees it in the next of its eight directions), and
// the end went in and out by millimetres on alternate updates, sliding one way and then another:
// a jitter the joints' accelerations show at once. Held inside every remembered half-plane, the
// end slides along the obstacle the same way on every update. Held on the line, the move no
// longer reaches the obstacle (a wall kSkin beyond it), so a move pushing past a line is made
// kReach deeper (reach()) to meet it again while it is there. A half-plane is forgotten once the
// end is kRelease off its line (the move went away) or kMemory after it was last met (the
// obstacle ended). No allocation.
class HeldContacts {
 public:
  static constexpr int kMax = 3;
  static constexpr float kMemory = 0.25f;   // s
  static constexpr float kRelease = 0.02f;  // m
  static constexpr float kReach = 0.02f;    // m
  // Two half-planes whose normals are this close (cosine) are the same obstacle.
  static constexpr float kSameNormal = 0.99f;

  // Ages the remembered half-planes by dt (forgetting those kMemory old), remembers what `move`
  // met (the obstacle that blocked it, the one that stopped its slide, a ledge's edge beside or
  // ahead of it) with the move's end on their lines, holds `end` inside every half-plane (at most
  // kMax, projected in turn, twice) and forgets those `end` is kRelease off.
  void hold(glm::vec3& end, const MoveResult& move, float dt);
  // The goal to move toward instead of `goal`: kReach deeper into every remembered obstacle whose
  // line `goal` is at or past.
  glm::vec3 reach(const glm::vec3& goal) const;
  void shift(const glm::vec3& by);  // every remembered point, by `by`
  void clear() { count_ = 0; }
  int count() const { return count_; }

 private:
  struct HalfPlane {
    glm::vec3 point{0.0f};   // on the line
    glm::vec3 normal{0.0f};  // horizontal, unit, away from the obstacle
    float age = 0.0f;
  };
  void remember(const glm::vec3& point, const glm::vec3& normal);
  // Keeps the half-planes `keep` is true of, in their order.
  template <typename Keep>
  void keep_if(Keep keep) {
    int kept = 0;
    for (int i = 0; i < count_; ++i) {
      if (keep(planes_[static_cast<size_t>(i)])) {
        planes_[static_cast<size_t>(kept++)] = planes_[static_cast<size_t>(i)];
      }
    }
    count_ = kept;
  }

  std::array<HalfPlane, kMax> planes_{};
  int count_ = 0;
};

}  // namespace mm
