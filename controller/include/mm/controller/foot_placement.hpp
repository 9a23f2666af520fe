#pragma once
// Feet on the world's ground (docs/world.md, "Feet on the ground"). The data was recorded on a
// flat floor: the animated pose stands on the body's ground (the height the controller lifts
// the body to, under the root). On a level the ground under each foot differs from that: a
// step up, a tread down, a slope under the toe. Once per update, after forward kinematics and
// before foot locking, FootPlacement
// 1. probes the world under each foot's heel (ankle) and toe, and under where they are heading
//    (the body's velocity ahead, and the toe's own, neither much past where the playing clip
//    puts the toe down), in one batched call of kQueries probes, and sweeps each planted toe's
//    way toward its hip, in one more call (two sweeps);
// 2. keeps per foot the height of the ground under its heel and its toe: the higher of "now"
//    and "ahead" (a toe lifts before the stair's riser, never into it), the two heights within
//    the steepest tilt of each other (a foot half over a step edge rests on the higher support,
//    tilted at most max_foot_tilt, the other end hanging over; a toe whose ground that tilt does
//    not reach, level with the heel), each falling on a spring and
//    rising with a bounded acceleration (a toe that meets the step sooner than that allows waits
//    at its riser: the controller keeps it out as a wall, held_at_step), a toe in the air never
//    lower than the data's lowest above the ground probed under it now, a planted one's ground
//    never under it;
// 3. lowers the pelvis (at most max_pelvis_drop, on a spring) so that the lower of the feet near
//    their ground reaches it without straightening its leg further than the animation did (or
//    than kMaxLegExtension of its length, if that is further); and at once, off the spring, as
//    far as a planted toe with a step's side between it and its hip needs to stay within its
//    leg's reach (the heel lifted as far as the foot lock lifts it, kMaxHeelRise) once it was:
//    the body climbing the step would otherwise pull the toe off its point, into the side.
// The foot lock then takes each toe's target from the animation raised or lowered by its
// ground's offset from the body's ground, holds the planted point in 3-D, keeps a toe above
// its own ground, and pitches the foot so that heel and toe each keep their height above their
// ground (tilt()).
//
// A probe that misses, finds ground farther than a step above or below the body's ground (below
// the foot's own where that is lower: a foot still on the floor the body climbed above), or
// returns garbage (rejected by CharacterMover's checks, counted in world_rejected) falls back to
// the body's ground, the capsule's floor: the animation as recorded.

#include <array>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/controller/character_mover.hpp"
#include "mm/controller/world.hpp"

namespace mm {

// What the placement reads of one leg, after forward kinematics (relative to the controller's
// origin, before the pelvis drop).
struct PlacementLeg {
  glm::vec3 hip{0.0f};
  glm::vec3 ankle{0.0f};
  glm::vec3 toe{0.0f};
  // The toe's horizontal shift from the animated toe: a lock's hold, a released foot's offset,
  // which decays back to none, or a wall's push.
  glm::vec3 shift{0.0f};
  float length = 0.0f;       // upper plus lower leg (m)
  float lowest = 0.0f;       // the data's lowest toe height above its floor (m)
  bool planted = false;      // locked or in contact: its probes look only where it is
  bool near_ground = false;  // planted or about to be: its reach counts for the pelvis
  // Held back by the side of a step it is not yet above (a riser): it waits there while it
  // rises, looking for its ground over the step.
  bool held_at_step = false;
  // Where the playing clip next puts this toe down, when it does soon
  // (ControllerDatabase::next_landing): a toe in the air looks no farther ahead than past it.
  glm::vec3 landing{0.0f};
  bool lands = false;
};

struct FootPlacementSettings {
  float max_pelvis_drop = 0.35f;       // m
  float pelvis_drop_halflife = 0.24f;  // s
  float max_foot_tilt = 0.6f;          // radians, pitch of the heel-to-toe line
  float step_height = 0.35f;           // m: ground higher than this above the body's is a wall
  float max_step_down = 0.5f;          // m: ground lower than this below the body's is a ledge
  // The climbing pace (climb_pace.hpp), in (0, 1]: the clip plays at this rate, and the feet's
  // grounds follow as much slower (a rise's acceleration times its square, a fall's halflife
  // over it), so that the legs lift and lower over the time they swing in; the probes look as
  // far ahead as the unslowed body would go. The pelvis drop's springs keep their time: slowed,
  // the planted toes up a stair floated 2 cm higher (docs/world.md, session 24).
  float pace = 1.0f;
};

// One foot's ground (heights in the controller's frame, m).
struct FootGround {
  float heel = 0.0f;
  float toe = 0.0f;
};

class FootPlacement {
 public:
  // Heel and toe of each foot, now, where the body takes them and where their own velocity does.
  static constexpr int kProbes = 12;
  // Around each toe, kFootprint probes kFootprintRadius out (m): a toe joint at a tread's or a
  // ramp's edge is a point the ground under it changes at, and a probe a millimetre on the low
  // side let a toe sink below the edge it was on. The toe stands on the highest of them.
  static constexpr int kFootprint = 4;
  static constexpr float kFootprintRadius = 0.015f;
  // Ground probes per update, all in one call: the probes, the footprints, and where each toe
  // lands.
  static constexpr int kQueries = kProbes + 2 * kFootprint + 2;
  // How far ahead the probes look: the body's velocity times this (s), and the toe's own
  // (a step to the side or a turn's step goes where the body does not) times kToeLookahead.
  static constexpr float kLookahead = 0.2f;
  static constexpr float kToeLookahead = 0.1f;
  // A toe about to land looks at most this far (m) past where it lands, along either
  // look-ahead: what lies farther is where the body goes, not the foot (a box the next step
  // reaches, seen from the step landing short of it, raised that foot toward its top).
  static constexpr float kPastLanding = 0.1f;
  // A leg may straighten to this share of its length to reach a lower foot's ground before
  // the pelvis has to drop.
  static constexpr float kMaxLegExtension = 0.97f;
  // The most (radians) a held foot's heel lifts about its toe for a leg that falls short of it
  // (the foot lock's reach, controller.cpp).
  static constexpr float kMaxHeelRise = 0.5f;

  // Every foot's ground at `ground`, the pelvis not dropped: a placement or a new world.
  void reset(float ground);

  // Probes under both feet (one call to the world through `mover`, whose checks apply) and
  // moves the grounds and the pelvis drop on their springs by dt (0: only probes).
  void update(const WorldQueries& world, const glm::dvec3& origin, CharacterMover& mover,
              const FootPlacementSettings& settings, std::span<const PlacementLeg, 2> legs,
              float body_ground, const glm::vec3& body_velocity, float dt);

  const FootGround& ground(int side) const { return feet_[side != 0 ? 1 : 0].ground; }
  // How fast each toe's ground rose over the last update (m/s; negative falling): its follower's
  // climb and any lift onto the ground under the toe, which its follower answers from rest.
  float toe_ground_rise(int side) const { return feet_[side != 0 ? 1 : 0].toe_rise; }
  float pelvis_drop() const { return pelvis_drop_; }
  // The ground probed under the toe now (its footprint's edge included), without the look-ahead
  // that raises a foot's ground before a step.
  float ground_under_toe(int side) const;
  // The ground probed under the heel now (resting on a tread's edge where the toe is on it), also
  // without the look-ahead.
  float ground_under_heel(int side) const;

  // The rotation that pitches a foot whose heel-to-toe line is `along` (the animated one, after
  // any heading swivel) so that heel and toe each keep their animated height above their own
  // ground: the toe rises by toe - heel relative to the heel. At most max_foot_tilt.
  glm::quat tilt(int side, const glm::vec3& along, float max_tilt) const;
  // Whether tilt() turns the foot at all: its heel and toe stand at different heights.
  bool tilted(int side) const {
    const FootGround& g = ground(side);
    return g.toe != g.heel;
  }

  // The probes' last answers, for the debug drawing: the points probed and the ground found
  // (the body's ground where nothing acceptable was).
  const std::array<glm::vec3, kProbes>& probe_points() const { return probe_points_; }
  const std::array<glm::vec3, kProbes>& probe_grounds() const { return probe_grounds_; }

 private:
  struct Foot {
    FootGround ground;
    FootGround velocity;
    FootGround last_goal;  // the goals the grounds followed on the last update
    float toe_rise = 0.0f;
    glm::vec3 toe{0.0f};  // the toe's position last update, and its horizontal velocity
    glm::vec3 toe_velocity{0.0f};
    bool has_toe = false;
    // While planted: how far the pelvis drop fell short of keeping the toe reached (m), only
    // ever shrinking (keep_planted_toes_reached).
    float reach_shortfall = 0.0f;
    bool reach_planted = false;
  };
  void probe(const WorldQueries& world, const glm::dvec3& origin, CharacterMover& mover,
             const FootPlacementSettings& settings, std::span<const PlacementLeg, 2> legs,
             float body_ground, const glm::vec3& body_velocity);
  void place_probes(const FootPlacementSettings& settings, std::span<const PlacementLeg, 2> legs,
                    float body_ground, const glm::vec3& body_velocity);
  glm::vec3 own_lookahead(int side, const PlacementLeg& leg) const;
  static glm::vec3 short_of_landing(const glm::vec3& from, const glm::vec3& way,
                                    const PlacementLeg& leg);
  float below_foot(int side, float body_ground) const;
  float found(int i, float body_ground, const FootPlacementSettings& settings) const;
  void stand_on_edges(float body_ground, const FootPlacementSettings& settings);
  void rest_heels_on_edges(std::span<const PlacementLeg, 2> legs);
  void keep_steps_ahead();
  void keep_own_lookahead_to_landings(std::span<const PlacementLeg, 2> legs, float body_ground,
                                      const FootPlacementSettings& settings);
  float plane_height(int side, int which, const glm::vec3& at) const;
  void follow_toes(std::span<const PlacementLeg, 2> legs, float dt);
  FootGround goal(int side, const FootPlacementSettings& settings, float foot_length,
                  bool planted) const;
  float rise_to_landing(int side, const PlacementLeg& leg, float body_ground,
                        const FootPlacementSettings& settings, FootGround& g) const;
  void sweep_toes(const WorldQueries& world, const glm::dvec3& origin, CharacterMover& mover,
                  std::span<const PlacementLeg, 2> legs, float body_ground);
  float drop_goal(const FootPlacementSettings& settings, std::span<const PlacementLeg, 2> legs,
                  float body_ground) const;
  float reach_drop(int side, const PlacementLeg& leg, float body_ground, float from,
                   float max_drop) const;
  void keep_planted_toes_reached(const FootPlacementSettings& settings,
                                 std::span<const PlacementLeg, 2> legs, float body_ground,
                                 float drop_before, float dt);

  std::array<Foot, 2> feet_{};
  float pelvis_drop_ = 0.0f;
  float pelvis_drop_velocity_ = 0.0f;
  float drop_goal_ = 0.0f;  // the drop's goal, smoothed
  float drop_goal_velocity_ = 0.0f;
  std::array<GroundProbe, kQueries> probes_{};
  std::array<GroundHit, kQueries> hits_{};
  std::array<glm::vec3, kProbes> probe_points_{};
  std::array<glm::vec3, kProbes> probe_grounds_{};
  // Per planted toe, whether a step's side stands between it and its hip (sweep_toes).
  std::array<bool, 2> toe_beside_step_{false, false};
};

}  // namespace mm
