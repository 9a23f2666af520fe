// Feet on the world's ground: probes, per-foot ground heights, the pelvis drop, the foot's tilt
// (foot_placement.hpp).

#include "mm/controller/foot_placement.hpp"

#include <algorithm>
#include <cmath>

#include "mm/controller/climb_pace.hpp"
#include "mm/runtime/approach.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/spring.hpp"

namespace mm {

namespace {

// A foot's ground follows its goal at once where the goal moves little in an update and the
// ground is at rest (along a slope, over bumps: anything slower would lag behind a slope and land
// the foot above or in it; a follow at once leaves it at rest); across a step (a tread's edge: the
// foot would pop) down on a spring, up with an acceleration of kStepAcceleration, arriving at rest.
// A spring answers a step with its largest acceleration at once (a 20 cm riser at a 0.03 s
// halflife: over 600 m/s^2, where the data's locomotion p99 is about 60), and the foot's joints
// carry it. A toe that meets the step sooner than that rise takes waits at its riser (the
// controller keeps it out, as a wall), and one already over the step is kept above it (stay_above).
// The goal's change is measured as a speed, so that the same ground is followed the same way at
// every update rate (6 cm an update at 1/30 s; the same 6 cm at 1/144 s is a step).
constexpr float kStepChangeSpeed = 1.8f;           // m/s: a step, not a slope
constexpr float kAtRestSpeed = 0.05f;              // m/s: slower, a ground is at rest
constexpr float kOnGoalDistance = 0.001f;          // m: nearer, it is on its goal
constexpr float kStepAcceleration = 40.0f;         // m/s^2
constexpr float kPlantedHeelAcceleration = 20.0f;  // m/s^2: a planted foot's heel
constexpr float kFallHalflife = 0.06f;             // s
// A foot rising to a landing a step up (rise_to_landing): the least acceleration it rises at,
// and the least toe speed its time to the landing is reckoned with.
constexpr float kLandingRiseAcceleration = 20.0f;  // m/s^2
constexpr float kLandingRiseMinSpeed = 0.3f;       // m/s
// The lowest and highest step up a foot rises to as its swing starts (m): a stair's riser, a
// kerb. Not a bump of rough ground, nor a box's top, which the clip's landing, predicted for
// flat ground, finds beyond a foot that stops short of the box (the look-ahead's cut at
// kPastLanding keeps the rest from rising toward it).
constexpr float kLandingRiseMin = 0.1f;
constexpr float kLandingRiseMax = 0.25f;
// The sphere swept from a planted toe toward its hip (m, sweep_toes), how far toward its hip (m)
// it looks for a step's side its leg would drag it into, and the largest vertical share of a
// normal that is such a side (a slope's is larger).
constexpr float kToeSweepRadius = 0.02f;
constexpr float kBesideStepReach = 0.1f;
constexpr float kSideNormalY = 0.5f;
// How far above the highest walkable step a probe starts (m): the point it starts from is
// never inside that step.
constexpr float kProbeMargin = 0.02f;
// Ground ahead this much higher than the plane of the ground under the foot (m) is a step.
constexpr float kStepRise = 0.02f;
// A step only a toe's own look-ahead sees, and not where it lands, is one it swings beside when
// it is higher than this (m), a stair's riser: a lower one (a tread, a kerb, a bump of rough
// ground) a foot crosses over on its way and has to clear (cut, a toe strafing across
// stairs_down's treads toward a landing on the floor barely cleared a tread's corner; on rough
// ground the cut came and went as the landing moved over the bumps, dropping a swinging toe in
// an update).
constexpr float kBesideStepRise = 0.2f;
// Ground around the toe this much higher than the plane under it (m) is an edge the toe is at.
constexpr float kEdgeRise = 0.01f;
// A foot whose heel-to-toe line's horizontal extent is at least this share of its length is
// tilted fully, one under kTiltNoneShare not at all (tilt()). The data's planted feet stand at
// 0.77 (median), 0.70 or more in 98 % of their frames.
constexpr float kTiltFullShare = 0.7f;
constexpr float kTiltNoneShare = 0.45f;
// Halvings of the pelvis drop's range that find the least drop reaching a planted toe
// (reach_drop): 0.35 m to well under a millimetre.
constexpr int kReachDropBisections = 12;

// Probe slots: per side, heel and toe now, where the body takes them, where their own velocity
// takes them.
constexpr int kHeel = 0, kToe = 1, kHeelAhead = 2, kToeAhead = 3, kHeelOwn = 4, kToeOwn = 5;
constexpr int kPerSide = 6;
static_assert(2 * kPerSide == FootPlacement::kProbes);
constexpr int slot(int side, int which) {
  return side * kPerSide + which;
}
// The heel's or the toe's slot that a look-ahead slot looks ahead of.
constexpr int now_of(int which) {
  return which % 2;
}
// The query slot probing where a side's toe lands.
constexpr int landing_slot(int side) {
  return FootPlacement::kProbes + 2 * FootPlacement::kFootprint + side;
}

// `pace` (FootPlacementSettings::pace) stretches the follower's time.
// `last_goal` is the goal it followed on the update before, updated here.
void follow_ground(float& height, float& velocity, float& last_goal, float goal, float acceleration,
                   float pace, float dt) {
  if (!(dt > 0.0f) || !std::isfinite(goal)) return;
  const float step_change = kStepChangeSpeed * dt;
  // A rise under way lands on its own (approach): followed at once within an update's reach of
  // its goal, a climb was cut short, the rest in one update. So does any move under way: a fall
  // on its spring, or a rise whose goal went back down (a bump a probe ahead found, passed), cut
  // short, jumped the rest and stopped dead in an update (a toe over the rough patch, 2.7 cm in
  // 1/60 s). At rest means slow and on the goal it followed: at the top of a rise whose goal went
  // back down the ground is slow too, and was dropped the rest at once (a probe that saw the side
  // of stairs_12_35 for two updates).
  const bool rising = goal > height && velocity > 0.0f;
  const bool at_rest =
      std::abs(velocity) <= kAtRestSpeed && std::abs(height - last_goal) <= kOnGoalDistance;
  last_goal = goal;
  if (!rising && std::abs(goal - height) <= step_change && at_rest) {
    height = goal;
    velocity = 0.0f;
    return;
  }
  if (goal < height) {
    critical_spring_update(height, velocity, goal, kFallHalflife / pace, dt);
  } else {
    approach(height, velocity, goal, acceleration * pace * pace, dt);
  }
}

// The height at `at` (horizontally) of the plane through `point` tilted as the surface `hit`
// found (level where it hit nothing).
float height_on_plane(const glm::vec3& point, const GroundHit& hit, const glm::vec3& at) {
  const glm::vec3 n = hit.hit ? hit.normal : glm::vec3(0.0f, 1.0f, 0.0f);
  return point.y - (n.x * (at.x - point.x) + n.z * (at.z - point.z)) / std::max(n.y, 0.1f);
}

// A ground height held at or above `floor`: lifted onto it, it goes on from rest there
// (with the speed it had, it would overshoot the floor and the goal).
void stay_above(float& height, float& velocity, float floor) {
  if (height >= floor) return;
  height = floor;
  velocity = 0.0f;
}

}  // namespace

void FootPlacement::reset(float ground) {
  for (Foot& foot : feet_) {
    foot.ground = foot.last_goal = FootGround{ground, ground};
    foot.velocity = FootGround{};
    foot.toe_rise = 0.0f;
    foot.has_toe = false;
    foot.toe_velocity = glm::vec3(0.0f);
    foot.reach_shortfall = 0.0f;
    foot.reach_planted = false;
  }
  pelvis_drop_ = pelvis_drop_velocity_ = drop_goal_ = drop_goal_velocity_ = 0.0f;
  toe_beside_step_.fill(false);
  probe_grounds_.fill(glm::vec3(0.0f, ground, 0.0f));
}

void FootPlacement::update(const WorldQueries& world, const glm::dvec3& origin,
                           CharacterMover& mover, const FootPlacementSettings& settings,
                           std::span<const PlacementLeg, 2> legs, float body_ground,
                           const glm::vec3& body_velocity, float dt) {
  const float pace =
      std::isfinite(settings.pace) ? std::clamp(settings.pace, ClimbPace::kMinRate, 1.0f) : 1.0f;
  follow_toes(legs, dt);
  probe(world, origin, mover, settings, legs, body_ground, body_velocity / pace);
  for (int side = 0; side < 2; ++side) {
    const float foot_length = glm::length(legs[side].toe - legs[side].ankle);
    FootGround g = goal(side, settings, foot_length, legs[side].planted);
    Foot& foot = feet_[side];
    const float toe_before = foot.ground.toe;
    const float rise = rise_to_landing(side, legs[side], body_ground, settings, g);
    // A planted foot's heel crossing a tread's edge (its ankle passing the edge by millimetres
    // as the foot turns on its held toe) rises more gently: the foot pivots about the held toe,
    // and the leg carried the whole rise into the knee (docs/world.md, session 23).
    const float heel_rise = legs[side].planted ? kPlantedHeelAcceleration : rise;
    follow_ground(foot.ground.heel, foot.velocity.heel, foot.last_goal.heel, g.heel, heel_rise,
                  pace, dt);
    follow_ground(foot.ground.toe, foot.velocity.toe, foot.last_goal.toe, g.toe, rise, pace, dt);
    // The ground under the toe now is a floor the toe never lags under. Across a step the
    // look-ahead sees the tread first, but a toe swinging over a tread's front corner toward its
    // side (circling onto stairs, the look-ahead already beside them) reaches the tread the
    // update it is over it, and the height left it inside the tread's side (up to 3.9 cm). A toe
    // in the air is kept the data's lowest above it, its ground lifted only as far as that
    // needs: lifted onto the tread, a toe the animation had above it already popped up by the
    // difference (a toe let go at a riser's top edge, 4.6 cm in 1/144 s). Not the heel's: a foot
    // turning on its toe at a tread's edge has its ankle cross the edge, and the heel's ground
    // jumped a whole step in an update, popping the leg straight.
    const PlacementLeg& leg = legs[side];
    const float lifted = leg.planted ? 0.0f : std::max(0.0f, leg.toe.y - body_ground - leg.lowest);
    stay_above(foot.ground.toe, foot.velocity.toe, probe_grounds_[slot(side, kToe)].y - lifted);
    if (dt > 0.0f) foot.toe_rise = (foot.ground.toe - toe_before) / dt;
  }
  // Two springs in a row, each of half the halflife: the goal jumps as feet land and lift, and
  // one spring would answer each jump with a jump of the hips' vertical acceleration.
  const float halflife = 0.5f * settings.pelvis_drop_halflife;
  const float drop_before = pelvis_drop_;
  critical_spring_update(drop_goal_, drop_goal_velocity_, drop_goal(settings, legs, body_ground),
                         halflife, dt);
  critical_spring_update(pelvis_drop_, pelvis_drop_velocity_, drop_goal_, halflife, dt);
  pelvis_drop_ = std::clamp(pelvis_drop_, 0.0f, settings.max_pelvis_drop);
  keep_planted_toes_reached(settings, legs, body_ground, drop_before, dt);
}

// Each toe's horizontal velocity, from where it was on the last update (none on the first, or
// after an update of no time).
void FootPlacement::follow_toes(std::span<const PlacementLeg, 2> legs, float dt) {
  for (int side = 0; side < 2; ++side) {
    Foot& foot = feet_[side];
    const glm::vec3 toe = legs[side].toe;
    if (dt > 0.0f) {
      foot.toe_velocity = foot.has_toe
                              ? glm::vec3(toe.x - foot.toe.x, 0.0f, toe.z - foot.toe.z) / dt
                              : glm::vec3(0.0f);
      if (!finite(foot.toe_velocity)) foot.toe_velocity = glm::vec3(0.0f);
    }
    foot.toe = toe;
    foot.has_toe = true;
  }
}

void FootPlacement::probe(const WorldQueries& world, const glm::dvec3& origin,
                          CharacterMover& mover, const FootPlacementSettings& settings,
                          std::span<const PlacementLeg, 2> legs, float body_ground,
                          const glm::vec3& body_velocity) {
  place_probes(settings, legs, body_ground, body_velocity);
  mover.probe(world, origin, probes_, hits_);
  for (int i = 0; i < kProbes; ++i) {
    probe_grounds_[i] =
        glm::vec3(probe_points_[i].x, found(i, body_ground, settings), probe_points_[i].z);
  }
  rest_heels_on_edges(legs);
  stand_on_edges(body_ground, settings);
  keep_steps_ahead();
  keep_own_lookahead_to_landings(legs, body_ground, settings);
  sweep_toes(world, origin, mover, legs, body_ground);
}

// Each planted toe's way toward its hip swept with a small sphere at the toe's height as placed
// (the animation's height over the body's ground, over the toe's ground instead), never lower
// than a step above that ground, kBesideStepReach long: a step's side there is one that the
// leg's reach would drag the toe into (keep_planted_toes_reached). One call for both.
void FootPlacement::sweep_toes(const WorldQueries& world, const glm::dvec3& origin,
                               CharacterMover& mover, std::span<const PlacementLeg, 2> legs,
                               float body_ground) {
  std::array<ShapeSweep, 2> sweeps;
  size_t count = 0;
  std::array<int, 2> sides{};
  for (int side = 0; side < 2; ++side) {
    toe_beside_step_[side] = false;
    const PlacementLeg& leg = legs[side];
    if (!leg.planted) continue;
    const glm::vec3 to_hip(leg.hip.x - leg.toe.x, 0.0f, leg.hip.z - leg.toe.z);
    const float across = glm::length(to_hip);
    const glm::vec3 way = across > 1e-3f ? to_hip * (kBesideStepReach / across) : glm::vec3(0.0f);
    const float length = glm::length(way);
    if (length < 1e-3f) continue;
    const glm::vec3& toe = leg.toe;
    const float ground = feet_[side].ground.toe;
    const float bottom =
        std::max(toe.y - body_ground + ground - kToeSweepRadius, ground + kStepRise);
    // From a radius behind the toe: a sphere starting in contact finds nothing.
    const glm::vec3 back = way * (kToeSweepRadius / length);
    sweeps[count] = ShapeSweep{glm::vec3(toe.x - back.x, bottom, toe.z - back.z),
                               glm::vec3(toe.x + way.x, bottom, toe.z + way.z), kToeSweepRadius,
                               2.0f * kToeSweepRadius};
    sides[count++] = side;
  }
  std::array<SweepHit, 2> hits;
  mover.sweep(world, origin, std::span(sweeps).first(count), std::span(hits).first(count));
  for (size_t i = 0; i < count; ++i) {
    // A side, not a slope rising toward the hip.
    if (hits[i].hit) toe_beside_step_[sides[i]] = std::abs(hits[i].normal.y) < kSideNormalY;
  }
}

// Heel and toe, where they are and (for a foot in the air) where the body's velocity takes them
// shortly and where their own does: a swinging toe sees the riser before it reaches it, also
// when the body moves another way (a step to the side, a turn's step, a swing across the body's
// path on a circle). A planted foot looks only where it is: ahead, up a slope, it would rise off
// the surface it stands on. Then the toe's footprint around it, and where the toe lands.
void FootPlacement::place_probes(const FootPlacementSettings& settings,
                                 std::span<const PlacementLeg, 2> legs, float body_ground,
                                 const glm::vec3& body_velocity) {
  const glm::vec3 ahead(body_velocity.x * kLookahead, 0.0f, body_velocity.z * kLookahead);
  // Each foot's probes start a step above the higher of the body's ground and the foot's own: a
  // foot held up a slope the body runs down would otherwise be probed from inside the slope,
  // find nothing, and its lock sink into the slope with the body's ground.
  std::array<float, 2> top{}, reach{};
  for (int side = 0; side < 2; ++side) {
    const FootGround& g = feet_[side].ground;
    top[side] = std::max({body_ground, g.heel, g.toe}) + settings.step_height + kProbeMargin;
    reach[side] =
        top[side] - (below_foot(side, body_ground) - settings.max_step_down - kProbeMargin);
  }
  for (int side = 0; side < 2; ++side) {
    const PlacementLeg& leg = legs[side];
    const glm::vec3 body = leg.planted ? glm::vec3(0.0f) : ahead;
    const glm::vec3 own = leg.planted ? glm::vec3(0.0f) : own_lookahead(side, leg);
    probe_points_[slot(side, kHeel)] = leg.ankle;
    probe_points_[slot(side, kToe)] = leg.toe;
    probe_points_[slot(side, kHeelAhead)] = short_of_landing(leg.ankle, body, leg);
    probe_points_[slot(side, kToeAhead)] = short_of_landing(leg.toe, body, leg);
    probe_points_[slot(side, kHeelOwn)] = short_of_landing(leg.ankle, own, leg);
    probe_points_[slot(side, kToeOwn)] = short_of_landing(leg.toe, own, leg);
    for (int which = 0; which < kPerSide; ++which) {
      const glm::vec3& p = probe_points_[slot(side, which)];
      probes_[slot(side, which)] = GroundProbe{glm::vec3(p.x, top[side], p.z), reach[side], 0.0f};
    }
    constexpr float kAround[kFootprint][2] = {
        {1.0f, 0.0f}, {-1.0f, 0.0f}, {0.0f, 1.0f}, {0.0f, -1.0f}};
    for (int k = 0; k < kFootprint; ++k) {
      const glm::vec3 at(leg.toe.x + kFootprintRadius * kAround[k][0], top[side],
                         leg.toe.z + kFootprintRadius * kAround[k][1]);
      probes_[kProbes + side * kFootprint + k] = GroundProbe{at, reach[side], 0.0f};
    }
    probes_[landing_slot(side)] =
        GroundProbe{glm::vec3(leg.landing.x, top[side], leg.landing.z), reach[side], 0.0f};
  }
}

// Where a foot in the air is heading by its own motion: its toe's velocity ahead, or, farther,
// back to the animated toe that a released foot's offset decays toward. Just released, the toe
// is still at rest, and the first updates of its way back (a strafe's swing back over the
// tread's edge it stood in front of) went unprobed.
glm::vec3 FootPlacement::own_lookahead(int side, const PlacementLeg& leg) const {
  const glm::vec3 ahead = feet_[side].toe_velocity * kToeLookahead;
  const glm::vec3 back(-leg.shift.x, 0.0f, -leg.shift.z);
  // Held at a riser, over the step and on by the toe's way: sliding along its face, the toe's own
  // way alone looked beside it; the update it is first held, the animated toe only just reached
  // the face, and its way back alone was millimetres short of the step (the ground found over a
  // kerb and lost again every other update, the swinging leg lifting and dropping).
  if (leg.held_at_step) return back + ahead;
  return glm::dot(back, back) > glm::dot(ahead, ahead) ? back : ahead;
}

// `from` (the heel or the toe) moved by a look-ahead `way` (horizontal), the way shortened to end
// at most kPastLanding beyond where the toe lands (measured along the way): the heel too looks
// as far as that, a foot's length past its own landing. Given the toe's shortened way instead, a
// heel coming onto a stair's landing behind a toe already over it dipped 7 cm toward the tread
// below, its look-ahead no longer on the landing (the first course's stairs).
glm::vec3 FootPlacement::short_of_landing(const glm::vec3& from, const glm::vec3& way,
                                          const PlacementLeg& leg) {
  const float length = glm::length(way);
  if (!leg.lands || !(length > 1e-4f)) return from + way;
  const glm::vec3 to_landing(leg.landing.x - from.x, 0.0f, leg.landing.z - from.z);
  const float reach = glm::dot(to_landing, way) / length + kPastLanding;
  return from + way * std::clamp(reach / length, 0.0f, 1.0f);
}

// What a foot's steps down and ledges are measured from: the body's ground, or the foot's own
// where it is lower. A foot still on the floor the body has climbed more than a step above (the
// body rises up the stairs ahead of a foot about to leave the floor) stands on a floor, not over
// a ledge: measured from the body alone, its ground jumped up to the body's in an update (35 cm
// over the floor, with the toe at the first riser).
float FootPlacement::below_foot(int side, float body_ground) const {
  const FootGround& own = feet_[side].ground;
  return std::min({body_ground, own.heel, own.toe});
}

// The ground query `i` found. Deeper below the body (or the foot's own ground: below_foot) than
// the body steps down (a step and the mover's kStepClearance, character_mover.hpp), it is over a
// ledge: a foot out over it stays
// level with the body, so that swinging back it passes over the edge instead of through the
// ledge's side. (With the step alone, a foot beside stairs_12_35's 0.36 m side, which the body
// steps down, was held level with the body 43 cm over the floor.)
float FootPlacement::found(int i, float body_ground, const FootPlacementSettings& settings) const {
  const GroundHit& hit = hits_[static_cast<size_t>(i)];
  const int side = i < kProbes           ? i / kPerSide
                   : i < landing_slot(0) ? (i - kProbes) / kFootprint
                                         : i - landing_slot(0);
  const float deepest =
      below_foot(side, body_ground) - settings.step_height - CharacterMover::kStepClearance;
  return hit.hit && hit.point.y >= deepest ? hit.point.y : body_ground;
}

// Around the toe, only an edge counts: ground above the plane of the surface under the toe (on a
// slope the footprint's uphill side is only the slope, and would lift the toe off it).
void FootPlacement::stand_on_edges(float body_ground, const FootPlacementSettings& settings) {
  for (int side = 0; side < 2; ++side) {
    const GroundHit& under = hits_[slot(side, kToe)];
    const glm::vec3 n = under.hit ? under.normal : glm::vec3(0.0f, 1.0f, 0.0f);
    float& toe = probe_grounds_[slot(side, kToe)].y;
    const float plane_rise =
        kFootprintRadius * std::sqrt(std::max(0.0f, 1.0f - n.y * n.y)) / std::max(n.y, 0.1f);
    float edge = toe;
    for (int k = 0; k < kFootprint; ++k) {
      const float y = found(kProbes + side * kFootprint + k, body_ground, settings);
      if (y > toe + plane_rise + kEdgeRise) edge = std::max(edge, y);
    }
    toe = edge;
  }
}

// The height at `at` (horizontally) of the plane through the ground probe `which` of a side found,
// tilted as the surface it hit (level where it hit nothing).
float FootPlacement::plane_height(int side, int which, const glm::vec3& at) const {
  return height_on_plane(probe_grounds_[slot(side, which)], hits_[slot(side, which)], at);
}

// A planted foot whose toe stands on a tread and whose heel is out over the edge behind it rests
// on the edge, level with the toe's surface, as a foot does with its heel off a stair: the heel's
// ground is the plane under the toe, where the ground found under the heel drops below it (an
// edge, not a slope). Pitched down into the drop instead, the foot rocked as the ankle crossed the
// edge by millimetres (turning on the spot at the top of stairs_12_35, the heel's ground fell 4 cm
// and came back the next update). Only where the toe joint itself is over the tread (called
// before stand_on_edges): a toe only its footprint holds on an edge has the whole foot out over
// the drop, and rested level it stood on air.
void FootPlacement::rest_heels_on_edges(std::span<const PlacementLeg, 2> legs) {
  for (int side = 0; side < 2; ++side) {
    if (!legs[side].planted) continue;
    glm::vec3& heel = probe_grounds_[slot(side, kHeel)];
    const float plane = plane_height(side, kToe, heel);
    if (heel.y < plane - kStepRise) heel.y = plane;
  }
}

// Ahead counts only where the ground steps up: up a slope it is only the slope, which the foot
// will meet as it gets there (counted now, a landing foot would lock in the air), and so is the
// start of a slope ahead.
void FootPlacement::keep_steps_ahead() {
  for (int side = 0; side < 2; ++side) {
    for (const int later : {kHeelAhead, kToeAhead, kHeelOwn, kToeOwn}) {
      const int now = now_of(later);
      glm::vec3& ahead_ground = probe_grounds_[slot(side, later)];
      const glm::vec3& now_ground = probe_grounds_[slot(side, now)];
      // Nor where the ground ahead is a slope whose own plane, carried back, passes below the
      // ground here: a ramp starting ahead, which the foot meets as it gets there (raised toward
      // it, a foot landing at ramp_30's foot rose 5 cm in an update and sank again: docs/world.md,
      // session 32).
      const bool slope_starts = plane_height(side, later, now_ground) < now_ground.y + kStepRise;
      if (ahead_ground.y < plane_height(side, now, ahead_ground) + kStepRise || slope_starts) {
        ahead_ground.y = now_ground.y;
      }
    }
  }
}

// A foot in the air comes down where its clip puts it (PlacementLeg::landing): a step that only
// its own look-ahead sees, more than kBesideStepRise above the ground where it lands, under it now
// and on the body's path (the body's look-ahead), is one it swings beside, not onto. Raised
// toward it, a foot swinging along box_35's front face to land beside it rose to the box's top
// over the floor it came down on (docs/world.md, session 29). The body's look-ahead is not
// cut so: on stairs the clip's landing, predicted for flat ground, falls short of the tread the
// foot goes onto. Nor a toe a riser holds back farther than kPastLanding from where the
// animation puts it: the animation takes it over the step (a toe held at the side of
// stairs_20_25's last tread, the animation well onto it, was dragged into the tread's corner by a
// leg that could not reach it on the floor).
void FootPlacement::keep_own_lookahead_to_landings(std::span<const PlacementLeg, 2> legs,
                                                   float body_ground,
                                                   const FootPlacementSettings& settings) {
  for (int side = 0; side < 2; ++side) {
    const PlacementLeg& leg = legs[side];
    const bool headed_over =
        leg.held_at_step && std::hypot(leg.shift.x, leg.shift.z) > kPastLanding;
    if (leg.planted || !leg.lands || headed_over) continue;
    const float landing = found(landing_slot(side), body_ground, settings);
    const float cap = std::max(
        {landing, probe_grounds_[slot(side, kHeel)].y, probe_grounds_[slot(side, kToe)].y,
         probe_grounds_[slot(side, kHeelAhead)].y, probe_grounds_[slot(side, kToeAhead)].y});
    for (const int own : {kHeelOwn, kToeOwn}) {
      float& ahead = probe_grounds_[slot(side, own)].y;
      if (ahead > cap + kBesideStepRise) ahead = cap;
    }
  }
}

// A foot in the air landing a step up (a tread, a kerb: higher than the plane of the ground under
// its toe by kLandingRiseMin to kLandingRiseMax) rises toward the landing's ground from the start
// of its swing, with the acceleration that gets it there as the toe arrives at its toe's speed
// (at least kLandingRiseAcceleration, at most kStepAcceleration), rather than when its
// look-ahead meets the riser, just before the toe does, at kStepAcceleration (a settling step
// onto stairs_20_25's landing, well short of the tread's height, rose onto it while its toe
// waited at the riser; docs/world.md). `g` is raised to the landing's ground; returns the rise's
// acceleration.
float FootPlacement::rise_to_landing(int side, const PlacementLeg& leg, float body_ground,
                                     const FootPlacementSettings& settings, FootGround& g) const {
  if (leg.planted || !leg.lands) return kStepAcceleration;
  const float landing = found(landing_slot(side), body_ground, settings);
  const Foot& foot = feet_[side];
  // A step both ways: above the plane of the ground under the toe (up a ramp the landing is only
  // the slope), and the plane of the landing's ground above the toe's (where a ramp starts, the
  // landing up its slope is above the floor's plane, but the ramp's plane meets the floor).
  const float landing_plane_at_toe =
      height_on_plane(glm::vec3(leg.landing.x, landing, leg.landing.z),
                      hits_[static_cast<size_t>(landing_slot(side))], leg.toe);
  const float up = landing - std::max(g.toe, plane_height(side, kToe, leg.landing));
  if (!(up > kLandingRiseMin) || up > kLandingRiseMax ||
      !(landing_plane_at_toe - g.toe > kLandingRiseMin)) {
    return kStepAcceleration;
  }
  const float left = std::max(0.0f, landing - foot.ground.toe);
  const float distance =
      glm::length(glm::vec2(leg.landing.x - leg.toe.x, leg.landing.z - leg.toe.z));
  const float speed = std::max(glm::length(glm::vec2(foot.toe_velocity.x, foot.toe_velocity.z)),
                               kLandingRiseMinSpeed);
  const float time = distance / speed;
  g.toe = landing;
  g.heel = std::max(g.heel, landing);
  const float needed = time > 1e-3f ? 4.0f * left / (time * time) : kStepAcceleration;
  return std::clamp(needed, kLandingRiseAcceleration, kStepAcceleration);
}

// The heights a foot's heel and toe go to: the highest of now and ahead, then each raised to
// within the steepest tilt of the other (a foot over a step's edge rests on the higher side),
// a toe beyond that tilt's reach below the heel level with it.
FootGround FootPlacement::goal(int side, const FootPlacementSettings& settings, float foot_length,
                               bool planted) const {
  const auto height = [&](int which) { return probe_grounds_[slot(side, which)].y; };
  const float heel = std::max({height(kHeel), height(kHeelAhead), height(kHeelOwn)});
  const float toe = std::max({height(kToe), height(kToeAhead), height(kToeOwn)});
  const float rise = foot_length * std::tan(settings.max_foot_tilt);
  // A planted foot whose heel comes over a step higher than the tilt reaches, while its toe
  // stands on the ground below (as it did when it was planted), stays on the toe's ground, level:
  // lifted level with the heel, a foot planted on the floor before a box, its heel swung over
  // the box's edge, stood a box's height up in the air (docs/world.md, session 27). A foot that
  // already stood up there (its heel on a tread's edge, its toe over the tread below) stays.
  if (planted && toe < heel - rise && feet_[side].ground.toe < heel - rise) {
    return FootGround{toe, toe};
  }
  // A toe whose ground is out of the tilt's reach below the heel's hangs level with the heel, as
  // a foot standing on a tread's edge does: pitched down toward the ground below, it hung in
  // the air all the same. Not the heel: held level with a toe on the tread above too, a walk
  // up stairs_20_25 on another database ended with a held toe dragged 3 cm into a riser.
  return FootGround{std::max(heel, toe - rise), toe >= heel - rise ? toe : heel};
}

// How far the pelvis must come down so that every leg near its ground reaches the ground under
// its heel: the ankle, lowered by its ground's depth below the body's, no farther from the hip
// than the animation had it or than kMaxLegExtension of the leg, whichever is farther.
float FootPlacement::drop_goal(const FootPlacementSettings& settings,
                               std::span<const PlacementLeg, 2> legs, float body_ground) const {
  float drop = 0.0f;
  for (int side = 0; side < 2; ++side) {
    const PlacementLeg& leg = legs[side];
    // A foot on ground no lower than the body's reaches it as the animation does.
    if (!leg.near_ground || feet_[side].ground.heel >= body_ground) continue;
    const float ankle_y = leg.ankle.y + (feet_[side].ground.heel - body_ground);
    const float below_hip = leg.hip.y - ankle_y;
    const float across = glm::length(glm::vec2(leg.hip.x - leg.ankle.x, leg.hip.z - leg.ankle.z));
    const float allowed = std::max(glm::length(leg.hip - leg.ankle), kMaxLegExtension * leg.length);
    const float reachable =
        allowed > across ? std::sqrt(allowed * allowed - across * across) : 0.0f;
    drop = std::max(drop, below_hip - reachable);
  }
  return std::clamp(drop, 0.0f, settings.max_pelvis_drop);
}

// The least pelvis drop, no less than `from`, that keeps a planted toe within its leg's reach:
// the ankle, turned about the toe toward the hip by at most kMaxHeelRise (the foot lock's heel
// rise), no farther from the hip than kMaxLegExtension of the leg. The toe stands on its ground,
// the ankle where the animation has it above the toe. max_pelvis_drop where even that is short.
float FootPlacement::reach_drop(int side, const PlacementLeg& leg, float body_ground, float from,
                                float max_drop) const {
  const glm::vec3 toe = leg.toe + glm::vec3(0.0f, feet_[side].ground.toe - body_ground, 0.0f);
  const glm::vec3 foot = leg.ankle - leg.toe;
  const float reach = kMaxLegExtension * leg.length;
  const float foot_length = glm::length(foot);
  // The ankle's nearest approach to the hip lowered by `d`: the toe-to-ankle line turned toward
  // the toe-to-hip line, in their plane, by up to the heel's limit (law of cosines).
  const auto reached = [&](float d) {
    const glm::vec3 to_hip = leg.hip - glm::vec3(0.0f, d, 0.0f) - toe;
    const float h = glm::length(to_hip);
    if (foot_length < 1e-4f || h < 1e-4f) return h <= reach;
    const float angle =
        std::acos(std::clamp(glm::dot(foot, to_hip) / (foot_length * h), -1.0f, 1.0f));
    const float left = std::max(0.0f, angle - kMaxHeelRise);
    return foot_length * foot_length + h * h - 2.0f * foot_length * h * std::cos(left) <=
           reach * reach;
  };
  if (reached(from)) return from;
  if (!reached(max_drop)) return max_drop;
  // Lowering the hip toward a toe below it brings the ankle nearer: the least drop that reaches
  // lies between one that does not and one that does.
  float low = from, high = max_drop;
  for (int i = 0; i < kReachDropBisections; ++i) {
    const float middle = 0.5f * (low + high);
    (reached(middle) ? high : low) = middle;
  }
  return high;
}

// The pelvis drop kept from falling behind what a planted toe beside a step's side needs, off the
// springs: the body climbing the step would otherwise pull the toe off its point, toward the hip
// and into the side. Only there: elsewhere (up a ramp) the leg's reach releases the toe to step
// (the foot lock's out_of_reach), and a pelvis held down for it kept the lock past its time. A toe
// planted out of reach (landing farther down than the springs have lowered the pelvis) keeps that
// shortfall, which only shrinks as the springs catch up: held at once, the pelvis fell a whole step
// in an update.
void FootPlacement::keep_planted_toes_reached(const FootPlacementSettings& settings,
                                              std::span<const PlacementLeg, 2> legs,
                                              float body_ground, float drop_before, float dt) {
  const float sprung = pelvis_drop_;
  float floor = 0.0f;
  for (int side = 0; side < 2; ++side) {
    Foot& foot = feet_[side];
    if (!legs[side].planted || !toe_beside_step_[side]) {
      foot.reach_planted = false;
      continue;
    }
    const float need = reach_drop(side, legs[side], body_ground, sprung, settings.max_pelvis_drop);
    const float shortfall = need - sprung;
    foot.reach_shortfall =
        foot.reach_planted ? std::min(foot.reach_shortfall, shortfall) : shortfall;
    foot.reach_planted = true;
    floor = std::max(floor, need - foot.reach_shortfall);
  }
  if (floor > pelvis_drop_) {
    // It goes on from there with the speed it came down at.
    pelvis_drop_velocity_ = dt > 0.0f ? (floor - drop_before) / dt : 0.0f;
    pelvis_drop_ = floor;
  }
}

float FootPlacement::ground_under_toe(int side) const {
  return probe_grounds_[slot(side != 0 ? 1 : 0, kToe)].y;
}

float FootPlacement::ground_under_heel(int side) const {
  return probe_grounds_[slot(side != 0 ? 1 : 0, kHeel)].y;
}

glm::quat FootPlacement::tilt(int side, const glm::vec3& along, float max_tilt) const {
  const glm::quat none(1.0f, 0.0f, 0.0f, 0.0f);
  const float length = glm::length(along);
  const glm::vec3 level(along.x, 0.0f, along.z);
  if (length < 1e-4f || glm::length(level) < 1e-4f) return none;
  if (!tilted(side)) return none;
  const FootGround& g = feet_[side != 0 ? 1 : 0].ground;
  // In the foot's vertical plane: the heel-to-toe line (h0, y0) turned about the heel to
  // (h1, y1), same length, so that the toe is as high above the line from the heel's ground to
  // the toe's (slope s) as it was above the flat floor: y1 = s h1 + y0.
  const float h0 = glm::length(level), y0 = along.y;
  const float s = (g.toe - g.heel) / h0;
  const float a = 1.0f + s * s;
  const float h1 =
      (-s * y0 + std::sqrt(std::max(0.0f, s * s * y0 * y0 - a * (y0 * y0 - length * length)))) / a;
  const float y1 = s * h1 + y0;
  // A foot pitched steeper than it stands (a toe-off, a toe-first landing) is tilted less, none
  // from kTiltNoneShare on. Keeping its heel's height over its own ground takes a turn of the
  // grounds' difference over the foot's horizontal extent, which a steep foot makes large: on the
  // rough patch, grounds under heel and toe 2 cm apart turned a toe-first foot 25 degrees in an
  // update (the knee 6 cm; random-long from x = 8.7 of the second course at 1/144 s, t = 63.37
  // s). Toward vertical the tilt's axis turns round as the heel swings over the toe: kept to
  // the end, it turned the foot from one side to the other in an update (a ramp's slope).
  const float fade =
      std::clamp((h0 / length - kTiltNoneShare) / (kTiltFullShare - kTiltNoneShare), 0.0f, 1.0f);
  const float angle =
      fade * std::clamp(std::atan2(y1, h1) - std::atan2(y0, h0), -max_tilt, max_tilt);
  return glm::angleAxis(angle, glm::normalize(glm::cross(level, glm::vec3(0.0f, 1.0f, 0.0f))));
}

}  // namespace mm
