#pragma once
// The metrics of feet and body against the ground (issues 28 and 29), for `mm eval`: on the flat
// plane the ground is y = 0; in a world (EvaluationOptions::world) it is what the world's ground
// probe finds under each joint. Fed one frame at a time, like EvaluationAccumulator, which owns
// one and reports its metrics with the others.
//
// Definitions (heights relative to the ground under the joint; "planted by geometry": a toe
// below kGeomPlantedHeight above its ground and horizontally slower than kGeomPlantedSpeed, on
// this frame and the previous one):
// - foot_skate_geom_cm_s_mean: the horizontal speed of planted-by-geometry toes, over both
//   feet; unlike foot_skate_cm_s_mean it does not trust the contact labels, so it sees a foot
//   that slides while its label is off (beside it, the database's own value under the same
//   rule at the run's time step: foot_skate_geom_data_cm_s_mean, evaluation.hpp);
// - toe_clearance_cm_min / _p1: the lower toe's height above its ground, every frame (nearest
//   rank percentile);
// - foot_penetration_cm_mean / _max: how deep a toe is below its ground (0 when above), over
//   every frame and both toes (PhysDiff's penetration);
// - foot_float_cm_mean: the height of a toe whose contact label is on above the ground its foot
//   rests on (PhysDiff's float: a planted foot hovering): the ground under the toe, or an edge
//   under the foot that the toe is above (foot_support_height: a foot held level on a tread,
//   its toe a centimetre past the tread's edge or its side, rests on the tread, not on the
//   floor below);
// - foot_float_data_cm_mean: over the same frames, the height the playing clip's own toe has
//   above its flat ground at the playing time (GroundFrame::played_toe): how high the planted
//   toes of what played sit in the data. The float is read against it rather than against
//   another run on flat ground, which may be doing something else by then (a course that stops
//   the character at a wall has it stand on an idle while the flat run walks on);
// - hips_height_cm_mean / _std: the hips' height above the ground under them;
//   hips_vertical_accel_p99_m_s2: the p99 of the hips' vertical acceleration (second
//   differences of their height above the world's y = 0);
// - knee_overextension_frames: frames where either knee (upper leg, lower leg, foot) is within
//   kStraightKneeDegrees of straight;
// - wall_depth_cm_max: the deepest any joint is inside a wall (EvaluationFrame::wall_depth,
//   from the world's queries by WallDepthReader; 0 without a world);
// - stuck_s: time the simulation object was blocked by a wall while the stick pushed at least
//   kStuckAlongSpeed along the wall and it moved slower than kStuckSpeed although its own
//   velocity along the push was at least twice that through the frame (held_at_wall): stuck
//   where it could have slid. An object starting from rest there (the stick just turned along
//   the wall) is not held back: its spring starts as slowly as in the open, and the yield
//   toward the character may take back half of a slide along a wall. A stop at a ledge (no ground
//   ahead, no wall: the mover does not step off) has no wall to slide along and is not counted, nor
//   is a push into a concave corner, where the capsule swept along the wall meets another within a
//   few centimetres.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/world.hpp"
#include "mm/database/database.hpp"
#include "mm/database/joint_roles.hpp"

namespace mm {

inline constexpr float kGeomPlantedHeight = 0.06f;  // m
inline constexpr float kGeomPlantedSpeed = 0.35f;   // m/s, horizontal
inline constexpr float kStraightKneeDegrees = 1.0f;
inline constexpr float kStuckAlongSpeed = 0.2f;  // m/s of desired velocity along the obstacle
inline constexpr float kStuckSpeed = 0.05f;      // m/s
// Ground under a foot this much higher than the plane of the surface under its toe is an edge
// the foot may rest on (m); the foot is probed at foot_support_points.
inline constexpr float kFootEdgeRise = 0.01f;
inline constexpr int kFootSupportSamples = 4;  // from the toe to the heel
// Beside the toe, on either side, this far out (m): the ball of a foot is about three times as
// wide, so a toe joint this far past a tread's side still has the inside of its foot on it.
inline constexpr float kFootHalfWidth = 0.03f;
// Ahead of the toe joint, along the heel-to-toe line on the level, this far (m): the toes reach
// past their joint (the ball of the foot), so a toe joint this close before a riser has its toes
// on the tread above it.
inline constexpr float kToeReach = 0.03f;
inline constexpr int kFootSupportProbes = kFootSupportSamples + 3;
inline constexpr float kNoSupport = std::numeric_limits<float>::infinity();

struct GroundMetrics {
  double foot_skate_geom_cm_s_mean = 0.0;
  int foot_skate_geom_frames = 0;  // toe samples counted
  double toe_clearance_cm_min = 0.0;
  double toe_clearance_cm_p1 = 0.0;
  double foot_penetration_cm_mean = 0.0;
  double foot_penetration_cm_max = 0.0;
  double foot_float_cm_mean = 0.0;
  double foot_float_data_cm_mean = 0.0;
  double hips_height_cm_mean = 0.0;
  double hips_height_cm_std = 0.0;
  double hips_vertical_accel_p99_m_s2 = 0.0;
  int knee_overextension_frames = 0;
  double wall_depth_cm_max = 0.0;
  double stuck_s = 0.0;
};

// What one frame gives the ground metrics: joint positions (world y; any horizontal frame, as
// long as consecutive frames share it), the ground's height under the toes and the hips, the
// contact labels, and from the world the wall depth and whether the simulation was stuck.
struct GroundFrame {
  std::span<const glm::vec3> joints;
  float toe_ground[2] = {0.0f, 0.0f};  // left, right
  // The ground each foot rests on near its toe (foot_support_height); lower than toe_ground
  // (as by default) counts as toe_ground.
  float toe_support[2] = {-kNoSupport, -kNoSupport};
  float hips_ground = 0.0f;
  bool contact[2] = {false, false};
  // The playing clip's own toe heights above its flat ground at the playing time (m; NaN where
  // nothing plays): the data's float on these frames.
  float played_toe[2] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::quiet_NaN()};
  float wall_depth = 0.0f;  // m
  bool stuck = false;
};

// The height of the ground a foot rests on near its toe (foot_float_cm_mean): `toe_ground`, the
// ground under the toe (with `under`, the probe's answer there, whose normal gives the surface's
// plane; a miss is level), raised to the highest of `along` (the answers under the foot from toe
// to heel) that stands more than kFootEdgeRise above that plane and no higher than `toe_y`, the
// toe joint's height: an edge the foot can rest on. The slope the foot stands on is no edge, nor
// is ground above the toe (the toe is down on the lower side of a step). Misses and non-finite
// answers are ignored.
float foot_support_height(float toe_ground, const GroundHit& under,
                          std::span<const GroundHit> along, float toe_y);

// Where foot_support_height's `along` is probed for a foot: kFootSupportSamples points from the
// toe to the heel (the ankle), evenly, the heel last, then one kFootHalfWidth to each side of the
// toe, across the heel-to-toe line on the level (across x where the foot points straight up or
// down), then one kToeReach ahead of the toe along that line (none where the foot points straight
// up or down: the last point is the toe itself).
std::array<glm::vec3, kFootSupportProbes> foot_support_points(const glm::vec3& toe,
                                                              const glm::vec3& heel);

class GroundAccumulator {
 public:
  GroundAccumulator(const JointRoleIndices& roles, float dt);
  ~GroundAccumulator();
  GroundAccumulator(const GroundAccumulator&) = delete;
  GroundAccumulator& operator=(const GroundAccumulator&) = delete;

  void add(const GroundFrame& frame);
  // The horizontal frame moved by `by` (a rebased origin): what is kept of the previous frame
  // moves with it.
  void shift(const glm::vec3& by);
  GroundMetrics metrics() const;

  // The toe (or foot where a side has no toe) joint of each side, -1 for none.
  int toe(int side) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// How deep a pose's joints are inside walls, from the world's queries (positions relative to
// `origin`, as the queries take them). A joint counts when it is higher than `above` (lower ones
// meet the ground's slopes and steps, and are the penetration metrics' to judge) and is inside
// by the lesser of:
// - how far it is behind the face it is behind: a sphere of kWallProbeRadius swept at the
//   joint's height from the root's vertical line out to it meets the face; the depth is the
//   joint's distance behind that face's plane (its contact normal made horizontal), so a joint
//   on the face reads 0 (a sweep met where it starts, the root's line inside or against a wall,
//   reads the whole way out to the joint);
// - how far it is below the top found straight above it: a ground probe from kTopProbeHeight
//   above the joint, reaching a metre below it. A joint above the surface under it is in no
//   wall: a foot passing a few millimetres over a box's top edge meets the edge with the sweep
//   (the box's whole length read as depth, 33 cm) but is above the box.
// What it cannot see: a solid with no top face (an open mesh: probes find the ground below the
// joint) reads 0, and under a roof over a box the roof is the "top" and the face's depth stands.
// The buffers are sized once, for `joints` joints.
class WallDepthReader {
 public:
  static constexpr float kWallProbeRadius = 0.01f;  // m
  static constexpr float kTopProbeHeight = 100.0f;  // m

  explicit WallDepthReader(size_t joints);
  // The deepest of `joints` inside a wall (m; 0 when none is); the joint in `deepest` (-1).
  float read(const WorldQueries& world, const glm::dvec3& origin, const glm::vec3& root,
             std::span<const glm::vec3> joints, float above, int* deepest = nullptr);

 private:
  std::vector<ShapeSweep> sweeps_;
  std::vector<SweepHit> sweep_hits_;
  std::vector<GroundProbe> probes_;
  std::vector<GroundHit> probe_hits_;
  std::vector<float> depth_;  // behind the face, of each joint past one
  std::vector<int> joint_;    // the joint each query is about
};

// Whether the simulation object is held at a wall (stuck_s, before asking the world whether
// it could slide there): `blocked` by an obstacle of horizontal normal `contact` while the stick
// asks `desired_velocity` (m/s) of at least kStuckAlongSpeed along it, the object moving at
// `moved_speed` (m/s, horizontal) over the frame, slower than kStuckSpeed, although its own
// velocity along the push was at least twice that at the frame's start and end
// (`velocity_before`, `velocity_now`).
bool held_at_wall(bool blocked, const glm::vec3& contact, const glm::vec3& desired_velocity,
                  const glm::vec3& velocity_before, const glm::vec3& velocity_now,
                  float moved_speed);

// The database's own geometric skating: every clip that carries none of `excluded_tags` played
// straight through at `dt` (linear interpolation between frames, as database_acceleration_p99)
// on the flat ground, under the rule above (cm/s).
double database_geometric_skate(const Database& db, float dt, uint64_t excluded_tags);

}  // namespace mm
