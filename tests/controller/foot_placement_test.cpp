// Feet on the world's ground (issue 29; foot_placement.hpp): each rule of FootPlacement on the
// analytic test world (slopes up and down, a stair's edge, a toe swinging toward a riser, a
// probe that misses, a probe that answers garbage, the pelvis drop and its limit), then a
// controller walking on 10, 20 and 30 degree slopes with its planted feet on the surface.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "analytic_world.hpp"
#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/foot_placement.hpp"

namespace mm {
namespace {

using test::AnalyticBox;
using test::AnalyticWorld;

constexpr float kDt = 1.0f / 60.0f;
constexpr float kPi = 3.14159265f;

// A standing leg as the flat data has it: heel (ankle) 8 cm up, toe 15 cm ahead (+Z) and 3 cm
// up, the hip 85 cm above the ankle; heights above `ground`.
PlacementLeg standing_leg(float x, float z, float ground) {
  PlacementLeg leg;
  leg.ankle = glm::vec3(x, ground + 0.08f, z);
  leg.toe = glm::vec3(x, ground + 0.03f, z + 0.15f);
  leg.hip = glm::vec3(x, ground + 0.93f, z - 0.05f);
  leg.length = 0.9f;
  leg.planted = leg.near_ground = true;
  return leg;
}

// Both legs standing side by side, 20 cm apart, about the origin on the plane y = 0's height.
std::array<PlacementLeg, 2> standing_legs() {
  return {standing_leg(-0.1f, 0.0f, 0.0f), standing_leg(0.1f, 0.0f, 0.0f)};
}

// Both legs standing, the left one `z` along +Z and in the air (not planted, not near the ground).
std::array<PlacementLeg, 2> left_swinging(float z) {
  std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, z, 0.0f), standing_leg(0.1f, 0.0f, 0.0f)};
  legs[0].planted = legs[0].near_ground = false;
  return legs;
}

// A riser `height` high across the way at z = `at`, its tread 4 m deep beyond it.
void add_riser(AnalyticWorld& world, float at, float height) {
  world.boxes.push_back(
      AnalyticBox{glm::vec2(0.0f, at + 2.0f), glm::vec2(5.0f, 2.0f), 0.0f, height});
}

// Makes `world`'s ground a plane rising `degrees` toward +Z through the origin (falling for
// negative degrees).
void make_slope(AnalyticWorld& world, float degrees) {
  const double slope = std::tan(degrees * kPi / 180.0f);
  world.height = [slope](double, double z) { return z * slope; };
}

// Runs the placement until its springs have settled (3 s), the body standing on `ground`.
void settle(FootPlacement& p, const AnalyticWorld& world, CharacterMover& mover,
            const std::array<PlacementLeg, 2>& legs, float ground,
            const FootPlacementSettings& settings = {}) {
  p.reset(ground);
  for (int f = 0; f < 180; ++f) {
    p.update(world, glm::dvec3(0.0), mover, settings, legs, ground, glm::vec3(0.0f), kDt);
  }
}

// The toe's height above the surface after the foot is tilted about its heel: the animated
// foot line turned by tilt(), started from the heel on its ground.
float tilted_toe_clearance(const FootPlacement& p, const AnalyticWorld& world,
                           const PlacementLeg& leg, float body_ground) {
  const glm::vec3 along = leg.toe - leg.ankle;
  const glm::vec3 heel = leg.ankle + glm::vec3(0.0f, p.ground(0).heel - body_ground, 0.0f);
  const glm::vec3 toe = heel + p.tilt(0, along, FootPlacementSettings{}.max_foot_tilt) * along;
  return toe.y - static_cast<float>(world.surface(toe.x, toe.z));
}

TEST(FootPlacement, OnSlopesUpAndDownHeelAndToeKeepTheirHeightAboveTheSurface) {
  for (const float degrees : {10.0f, 20.0f, 30.0f}) {
    for (const float direction : {1.0f, -1.0f}) {  // uphill, then downhill (the O3DE case)
      AnalyticWorld world;
      make_slope(world, direction * degrees);
      CharacterMover mover;
      FootPlacement p;
      const std::array<PlacementLeg, 2> legs = standing_legs();
      settle(p, world, mover, legs, 0.0f);
      const PlacementLeg& leg = legs[0];
      EXPECT_NEAR(p.ground(0).heel, world.surface(leg.ankle.x, leg.ankle.z), 1e-3)
          << degrees << " " << direction;
      EXPECT_NEAR(p.ground(0).toe, world.surface(leg.toe.x, leg.toe.z), 1e-3)
          << degrees << " " << direction;
      // The toe sits as high above the slope as it did above the flat floor: downhill it is
      // pitched down onto the surface rather than floating off it.
      EXPECT_NEAR(tilted_toe_clearance(p, world, leg, 0.0f), 0.03f, 2e-3f)
          << degrees << " " << direction;
    }
  }
}

// Both legs standing on a 20 degree slope, the placement settled.
struct StandingOnASlope {
  AnalyticWorld world;
  CharacterMover mover;
  FootPlacement placement;
  std::array<PlacementLeg, 2> legs = standing_legs();
  StandingOnASlope() {
    make_slope(world, 20.0f);
    settle(placement, world, mover, legs, 0.0f);
  }
  float foot_length() const { return glm::length(legs[0].toe - legs[0].ankle); }
};

// A foot turning through vertical (a toe-off's heel swinging over the toe) on a 20 degree slope,
// its heel and toe grounds apart: the tilt's axis turns round there, and a tilt kept to the end
// threw the toe from one side to the other (9 cm at the knee in a course run). Faded out toward
// vertical, the tilted foot line turns as smoothly as the animated one.
TEST(FootPlacement, AFootTurningThroughVerticalOnASlopeIsTiltedContinuously) {
  const StandingOnASlope stand;
  const FootPlacement& p = stand.placement;
  ASSERT_TRUE(p.tilted(0));
  const float length = stand.foot_length();
  const float max_tilt = FootPlacementSettings{}.max_foot_tilt;
  glm::vec3 previous(0.0f);
  for (int k = -20; k <= 20; ++k) {  // 10 degrees either side of straight down, 0.5 a step
    const float angle = glm::radians(0.5f * static_cast<float>(k));
    const glm::vec3 along = length * glm::vec3(0.0f, -std::cos(angle), std::sin(angle));
    const glm::vec3 toe = p.tilt(0, along, max_tilt) * along;
    // The animated line moves 1.3 mm a step; the tilted one no more than a few times that.
    if (k > -20) {
      EXPECT_LT(glm::length(toe - previous), 0.005f) << k;
    }
    previous = toe;
  }
}

// The tilt keeps the heel's height above its own ground; a foot pitched steeply toe-down (a
// toe-off, a toe-first landing) needs a turn of the grounds' difference over its short
// horizontal extent for that: over the rough patch's bumps, grounds 2 cm apart turned such a
// foot 25 degrees in an update. Feet steeper than the data's planted ones are tilted less, and
// from under 0.45 of their length across not at all; the tilt fades in without a jump.
TEST(FootPlacement, AFootPitchedSteeplyToeDownIsNotTilted) {
  const StandingOnASlope stand;
  const FootPlacement& p = stand.placement;
  ASSERT_TRUE(p.tilted(0));
  const float length = stand.foot_length();
  const float max_tilt = FootPlacementSettings{}.max_foot_tilt;
  const auto tilt_angle = [&](float across) {  // the horizontal share of the foot's length
    const glm::vec3 along = length * glm::vec3(0.0f, -std::sqrt(1.0f - across * across), across);
    const glm::quat q = p.tilt(0, along, max_tilt);
    return 2.0f * std::atan2(glm::length(glm::vec3(q.x, q.y, q.z)), std::abs(q.w));
  };
  // The rough patch's foot stood at 0.39-0.43 across.
  for (const float across : {0.1f, 0.25f, 0.39f, 0.43f}) EXPECT_EQ(tilt_angle(across), 0.0f);
  // A planted foot of the data (0.77 across) on the slope is tilted as the slope asks.
  EXPECT_GT(tilt_angle(0.77f), glm::radians(18.0f));
  float previous = tilt_angle(0.4f);
  for (float across = 0.41f; across < 0.96f; across += 0.01f) {
    const float angle = tilt_angle(across);
    EXPECT_LT(std::abs(angle - previous), glm::radians(2.5f)) << across;
    previous = angle;
  }
}

// A foot with its toe on a step and its heel out over the step's edge. Planted, it rests on the
// edge level, as a foot stands with its heel off a stair: pitched down into the drop, turning on
// the spot at the top of a stair rocked it as the ankle crossed the edge by millimetres (the
// heel's ground 4 cm down and back in an update). In the air (a step onto the tread, the heel not
// yet over it), the heel hangs toward the lower tread, the foot tilted no more than its limit.
TEST(FootPlacement, AFootOverAStairsEdgeRestsOnTheStepNeverInsideIt) {
  AnalyticWorld world;
  // A 17 cm step whose edge is at z = 0.1: the heel is below it, the toe over it.
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 2.1f), glm::vec2(5.0f, 2.0f), 0.0f, 0.17f});
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.0f), standing_leg(0.1f, 0.0f, 0.0f)};
  settle(p, world, mover, legs, 0.0f);
  EXPECT_NEAR(p.ground(0).toe, 0.17f, 1e-3f);
  EXPECT_NEAR(p.ground(0).heel, 0.17f, 1e-3f);

  legs[0].planted = false;
  settle(p, world, mover, legs, 0.0f);
  const FootPlacementSettings settings;
  const float rise = glm::length(legs[0].toe - legs[0].ankle) * std::tan(settings.max_foot_tilt);
  EXPECT_NEAR(p.ground(0).toe, 0.17f, 1e-3f);
  EXPECT_NEAR(p.ground(0).heel, 0.17f - rise, 2e-3f);
  EXPECT_GT(p.ground(0).heel, 0.0f);
}

// A planted foot whose toe joint is past a step's edge, held on it only by its footprint
// (stand_on_edges): the whole foot is out over the drop, and rested level it would stand on air.
// Its heel hangs toward the lower ground as a foot in the air does.
TEST(FootPlacement, AFootOutOverAStepsEdgeIsNotRestedOnIt) {
  AnalyticWorld world;
  // A 17 cm step ending at z = 0.16; the body stands on it.
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, -0.84f), glm::vec2(5.0f, 1.0f), 0.0f, 0.17f});
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.17f),
                                   standing_leg(0.1f, 0.0f, 0.17f)};
  for (PlacementLeg& leg : legs) {
    // Facing back toward the step: the toe 1 cm past its edge, the ankle 15 cm farther out.
    leg.toe.z = 0.17f;
    leg.ankle.z = 0.32f;
  }
  settle(p, world, mover, legs, 0.17f);
  EXPECT_NEAR(p.ground(0).toe, 0.17f, 1e-3f);  // on the edge by its footprint
  EXPECT_LT(p.ground(0).heel, 0.12f);          // hanging toward the floor, not level
}

TEST(FootPlacement, AToeAtATreadsEdgeStandsOnTheTreadNotBelowItsEdge) {
  // Toes 15 cm ahead of their heels at z = 0.15: the step's edge is 5 mm ahead of the left toe
  // (a probe under the toe itself finds the lower tread) and 3 cm ahead of the right one.
  for (const float edge : {0.155f, 0.18f}) {
    AnalyticWorld world;
    world.boxes.push_back(
        AnalyticBox{glm::vec2(0.0f, edge + 1.0f), glm::vec2(5.0f, 1.0f), 0.0f, 0.17f});
    CharacterMover mover;
    FootPlacement p;
    const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.0f),
                                           standing_leg(0.1f, 0.0f, 0.0f)};
    settle(p, world, mover, legs, 0.0f);
    if (edge - legs[0].toe.z < FootPlacement::kFootprintRadius) {
      EXPECT_NEAR(p.ground(0).toe, 0.17f, 1e-3f) << edge;
    } else {
      EXPECT_EQ(p.ground(0).toe, 0.0f) << edge;  // a toe off the edge stays on its own tread
    }
  }
}

// Ground rising under a standing foot by a step (a block slid under it): the heel's ground
// follows on its spring, never a whole step in one update (a foot turning on its toe at a
// tread's edge had its heel pop up a step, the leg with it); the toe's stands on the ground
// under it at once. A rise slower than kStepChangeSpeed (a slope walked up) is followed at once,
// at every update rate: 5 cm in an update is a slope at 1/30 s but a step at 1/60 and 1/144.
TEST(FootPlacement, ARiseUnderTheHeelIsFollowedOnItsSpringAtEveryRate) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    for (const float rise : {0.05f, 0.15f}) {
      AnalyticWorld world;
      CharacterMover mover;
      FootPlacement p;
      const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.0f),
                                             standing_leg(0.1f, 0.0f, 0.0f)};
      settle(p, world, mover, legs, 0.0f);
      world.boxes.push_back(AnalyticBox{glm::vec2(0.0f), glm::vec2(2.0f), 0.0f, rise});
      p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
               dt);
      EXPECT_NEAR(p.ground(0).toe, rise, 1e-4f) << dt << " " << rise;
      if (rise <= 1.8f * dt) {
        EXPECT_NEAR(p.ground(0).heel, rise, 1e-4f) << dt << " " << rise;
      } else {
        EXPECT_GT(p.ground(0).heel, 0.0f) << dt << " " << rise;
        EXPECT_LT(p.ground(0).heel, rise - 0.01f) << dt << " " << rise;
      }
    }
  }
}

// A ground already moving is not followed at once, even where its goal comes within an update's
// reach: a fall on its spring was cut short there, the rest jumped and the fall stopped dead in
// one update (a toe's ground over the second course's rough patch, 2.7 cm: the foot 154 m/s^2 at
// 1/60 s). The heel of a foot in the air, its block taken away from under it: the fall's largest
// acceleration is the spring's first update's (about 21 m/s^2; cut short at 3 cm, about 80).
TEST(FootPlacement, AFallUnderWayIsNotCutShortWithinAnUpdatesReach) {
  constexpr float kStep = 1.0f / 60.0f;
  AnalyticWorld world;
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f), glm::vec2(1.0f), 0.0f, 0.1f});
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs = left_swinging(0.0f);
  settle(p, world, mover, legs, 0.0f);
  ASSERT_NEAR(p.ground(0).heel, 0.1f, 1e-4f);
  world.boxes.clear();
  std::vector<float> heights = {p.ground(0).heel, p.ground(0).heel};
  for (int f = 0; f < 60; ++f) {
    p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
             kStep);
    heights.push_back(p.ground(0).heel);
  }
  EXPECT_NEAR(heights.back(), 0.0f, 1e-3f);
  float largest = 0.0f;
  for (size_t i = 2; i < heights.size(); ++i) {
    const float a = (heights[i] - 2.0f * heights[i - 1] + heights[i - 2]) / (kStep * kStep);
    largest = std::max(largest, std::abs(a));
  }
  EXPECT_LT(largest, 50.0f);
}

// A swinging toe the controller first holds at a riser (held_at_step) is only millimetres from
// where the animation has it: looking only back to the animated toe, its probe stayed in front
// of the riser and found the floor, the step its own way had found the update before lost again
// (the ground over a kerb found and lost every other update, the leg lifting and dropping). Its
// own way is looked along too.
TEST(FootPlacement, AToeFirstHeldAtARiserKeepsSeeingTheStep) {
  AnalyticWorld world;
  add_riser(world, 0.2f, 0.15f);
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs = left_swinging(0.0f);
  p.reset(0.0f);
  legs[0].toe.z = 0.15f;
  p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
           kDt);
  // 2 cm on, toward the riser (1.2 m/s), held 3 cm before it, 3 mm behind the animated toe.
  legs[0].toe.z = 0.17f;
  legs[0].held_at_step = true;
  legs[0].shift = glm::vec3(0.0f, 0.0f, -0.003f);
  p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
           kDt);
  EXPECT_GT(p.ground(0).toe, 0.0f);  // on its way up
  EXPECT_EQ(p.ground(1).toe, 0.0f);  // the standing foot stays on the floor
}

// A foot just released with an offset from the animated toe has a toe still at rest, and its
// way back to the animated toe, over a tread's edge (a strafe swinging back onto the tread it
// stood beside), was not probed until it was over it: a frame inside the tread. The way back
// is probed like the toe's own velocity ahead, whichever goes farther.
TEST(FootPlacement, AReleasedToeSeesTheTreadItsOffsetTakesItBackOnto) {
  AnalyticWorld world;
  // A 17 cm tread beside the foot: x < -0.05.
  world.boxes.push_back(AnalyticBox{glm::vec2(-1.05f, 0.0f), glm::vec2(1.0f, 2.0f), 0.0f, 0.17f});
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs{standing_leg(0.0f, 0.0f, 0.0f), standing_leg(0.3f, 0.0f, 0.0f)};
  p.reset(0.0f);
  legs[0].planted = false;
  legs[0].shift = glm::vec3(0.08f, 0.0f, 0.0f);  // the animated toe is 8 cm back, on the tread
  p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
           kDt);
  EXPECT_GT(p.ground(0).toe, 0.0f);  // on its way up
  EXPECT_EQ(p.ground(1).toe, 0.0f);  // the other foot, with no offset, stays on the floor
}

TEST(FootPlacement, AFootOutOverALedgeDeeperThanAStepStaysLevelWithTheBody) {
  // The body stands on a block whose edge is at z = 0.1, the toes beyond it: a 0.45 m drop is a
  // ledge (deeper than step_height, 0.35, and the mover's kStepClearance), a 0.2 m one a step,
  // and so is a 0.36 m one, which the body steps down too; a 0.08 m one the toe reaches.
  for (const float drop : {0.45f, 0.2f, 0.36f, 0.08f}) {
    AnalyticWorld world;
    world.boxes.push_back(
        AnalyticBox{glm::vec2(0.0f, 0.1f - 1.0f), glm::vec2(5.0f, 1.0f), 0.0f, drop});
    CharacterMover mover;
    FootPlacement p;
    const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, drop),
                                           standing_leg(0.1f, 0.0f, drop)};
    settle(p, world, mover, legs, drop);
    const FootPlacementSettings settings;
    // Down a step the foot's tilt reaches (from its heel on the block), the toe goes down to the
    // floor; down a deeper one it stays level with the heel, as a foot standing on a tread's
    // edge does (tilted as far as it may, it hung over the floor all the same), and over a
    // ledge level with the body.
    const float rise = glm::length(legs[0].toe - legs[0].ankle) * std::tan(settings.max_foot_tilt);
    ASSERT_GT(rise, 0.08f);
    const float expected = drop > rise ? drop : 0.0f;
    EXPECT_NEAR(p.ground(0).toe, expected, 2e-3f) << drop;
    EXPECT_NEAR(p.ground(0).heel, drop, 1e-3f) << drop;  // the heel is on the block
  }
}

TEST(FootPlacement, AFootHeldUpASlopeTheBodyRunsDownKeepsItsGround) {
  // Both feet planted on a 0.45 m block while the body's ground goes down to 0 (the body running
  // down a slope away from a held foot): the probes, a step above the body's ground alone, would
  // start inside the block and the feet sink with the body.
  AnalyticWorld world;
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 0.0f), glm::vec2(5.0f, 1.0f), 0.0f, 0.45f});
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.45f),
                                         standing_leg(0.1f, 0.0f, 0.45f)};
  settle(p, world, mover, legs, 0.45f);
  for (int f = 1; f <= 60; ++f) {
    const float body = 0.45f * (1.0f - f / 60.0f);
    p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, body, glm::vec3(0.0f),
             kDt);
  }
  for (int side = 0; side < 2; ++side) {
    EXPECT_NEAR(p.ground(side).toe, 0.45f, 1e-3f) << side;
    EXPECT_NEAR(p.ground(side).heel, 0.45f, 1e-3f) << side;
  }
}

TEST(FootPlacement, ASwingingToeRisesBeforeItReachesTheRiser) {
  AnalyticWorld world;
  // The riser at z = 0.3, ahead of a toe at z = 0.15 moving forward with the body.
  add_riser(world, 0.3f, 0.17f);
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs = left_swinging(0.0f);
  p.reset(0.0f);
  const FootPlacementSettings settings;
  const glm::vec3 velocity(0.0f, 0.0f, 1.4f);
  for (int f = 0; f < 6; ++f) {
    p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, velocity, kDt);
  }
  // 0.1 s later the toe, still over the lower tread, stands on the step's height already; the
  // planted foot, looking only where it is, does not.
  EXPECT_GT(p.ground(0).toe, 0.15f);
  EXPECT_EQ(p.ground(1).toe, 0.0f);
}

// A foot swinging toward the foot of a 30 degree ramp: its look-ahead finds the ramp's slope
// higher than the floor's plane carried forward, as a tread would be, but the ramp's own plane
// carried back to the toe passes below the floor: it is a slope that starts ahead, which the foot
// meets as it gets there, not a step to rise to. Raised toward it, a foot about to land at the
// ramp's foot rose 5 cm in an update and sank again (stand-turns before the first course's
// ramp_30 at 1/30 s). A riser ahead is still a step (ASwingingToeRisesBeforeItReachesTheRiser).
TEST(FootPlacement, ASwingingToeDoesNotRiseTowardARampThatStartsAhead) {
  AnalyticWorld world;
  const double slope = std::tan(30.0 * kPi / 180.0);
  world.height = [slope](double, double z) { return z > 0.3 ? (z - 0.3) * slope : 0.0; };
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs = left_swinging(0.1f);  // the toe at z = 0.25
  p.reset(0.0f);
  const FootPlacementSettings settings;
  float highest = 0.0f;
  for (int f = 0; f < 6; ++f) {
    p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, glm::vec3(0.0f, 0.0f, 1.4f), kDt);
    highest = std::max(highest, p.ground(0).toe);
  }
  EXPECT_LT(highest, 0.01f);
}

// A riser seen at the end of the look-ahead (the body's, 0.2 s) is climbed with the toe's ground
// accelerating at about kStepAcceleration (40 m/s^2; the flat data's locomotion p99 is about
// 60), reaching the tread's height before the toe is over it, at every update rate. On a spring
// (0.03 s halflife) the same rise began at over 600 m/s^2, which the foot's joints carried.
TEST(FootPlacement, ARiserSeenAheadIsClimbedWithBoundedAcceleration) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    AnalyticWorld world;
    add_riser(world, 0.6f, 0.17f);
    CharacterMover mover;
    FootPlacement p;
    std::array<PlacementLeg, 2> legs = left_swinging(-0.15f);
    p.reset(0.0f);
    const glm::vec3 velocity(0.0f, 0.0f, 1.2f);
    std::array<float, 3> heights{0.0f, 0.0f, 0.0f};
    float largest = 0.0f;
    int updates = 0;
    while (legs[0].toe.z + velocity.z * dt < 0.6f) {
      legs[0].toe += velocity * dt;
      legs[0].ankle += velocity * dt;
      p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, velocity, dt);
      heights = {heights[1], heights[2], p.ground(0).toe};
      if (++updates >= 3) {
        largest =
            std::max(largest, std::abs(heights[2] - 2.0f * heights[1] + heights[0]) / (dt * dt));
      }
    }
    EXPECT_NEAR(p.ground(0).toe, 0.17f, 1e-3f) << dt;  // on the tread's height, the riser ahead
    EXPECT_LE(largest, 44.0f) << dt;  // kStepAcceleration, the last update landing on the tread
  }
}

// A foot stepping onto a tread (a settling step as the body stops before stairs, the body not
// moving: no body look-ahead) rises toward its landing from the start of its swing, at the
// acceleration that gets it there as the toe arrives, at least kLandingRiseAcceleration (20
// m/s^2), on the tread's height before the toe reaches the riser; its own look-ahead alone saw
// the riser 0.1 s before the toe got there and rose at 40 m/s^2. Not onto a box's top, higher
// than a stair's riser, which a foot stopping short of it was raised toward (the clip's landing
// is predicted for flat ground).
TEST(FootPlacement, AFootLandingAStepUpRisesFromTheStartOfItsSwing) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    for (const float height : {0.17f, 0.3f}) {
      AnalyticWorld world;
      add_riser(world, 0.6f, height);
      CharacterMover mover;
      FootPlacement p;
      std::array<PlacementLeg, 2> legs = left_swinging(-0.45f);
      legs[0].lowest = 0.02f;
      legs[0].lands = true;
      legs[0].landing = glm::vec3(-0.1f, 0.0f, 0.8f);
      p.reset(0.0f);
      const glm::vec3 velocity(0.0f, 0.0f, 0.6f);
      std::array<float, 3> heights{0.0f, 0.0f, 0.0f};
      float largest = 0.0f, halfway = 0.0f;
      int updates = 0;
      while (legs[0].toe.z + velocity.z * dt < 0.6f - 0.03f) {
        legs[0].toe += velocity * dt;
        legs[0].ankle += velocity * dt;
        p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f,
                 glm::vec3(0.0f), dt);
        heights = {heights[1], heights[2], p.ground(0).toe};
        if (legs[0].toe.z < 0.3f) halfway = p.ground(0).toe;
        if (++updates >= 3) {
          largest =
              std::max(largest, std::abs(heights[2] - 2.0f * heights[1] + heights[0]) / (dt * dt));
        }
      }
      if (height < 0.2f) {
        EXPECT_NEAR(halfway, height, 1e-3f) << dt;  // up already, the toe 30 cm from the riser
        EXPECT_LE(largest, 25.0f) << dt;  // kLandingRiseAcceleration, landing on the height
      } else {
        EXPECT_EQ(halfway, 0.0f) << dt;
      }
    }
  }
}

// A step seen ahead for two updates only (a probe grazing the side of stairs_12_35): the toe's
// ground starts up toward it and, the step gone, comes back down on its spring. At the top of
// that short rise the ground is slow, but not on the goal it followed: dropped the rest at once,
// it fell 1.2 cm in one update at 1/144 s.
TEST(FootPlacement, ARiseCutShortComesBackDownOnItsSpring) {
  constexpr float kDt144 = 1.0f / 144.0f;
  AnalyticWorld world;
  CharacterMover mover;
  FootPlacement p;
  p.reset(0.0f);
  std::array<PlacementLeg, 2> legs = left_swinging(0.0f);
  const glm::vec3 body_velocity(0.0f, 0.0f, 1.0f);  // the body's look-ahead 20 cm ahead
  float previous = 0.0f, highest = 0.0f, largest_drop = 0.0f;
  for (int f = 0; f < 40; ++f) {
    world.boxes.clear();
    if (f == 1 || f == 2) {  // a step under the look-ahead, 0.24 m high
      world.boxes.push_back(
          AnalyticBox{glm::vec2(0.0f, 0.35f), glm::vec2(1.0f, 0.1f), 0.0f, 0.24f});
    }
    p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, body_velocity,
             kDt144);
    const float ground = p.ground(0).toe;
    highest = std::max(highest, ground);
    largest_drop = std::max(largest_drop, previous - ground);
    previous = ground;
  }
  EXPECT_GT(highest, 0.005f);  // it did start up
  EXPECT_EQ(previous, 0.0f);   // and came back down
  EXPECT_LT(largest_drop, 0.005f);
}

// A toe held at a riser's face (controller_world.cpp keeps a toe in the air out of the riser it
// meets, PlacementLeg::held_at_step) while the animation takes it over the step and along the
// face (a strafe's swing): it looks for its ground where the animation has it, over the step,
// and rises onto the step's height at about kStepAcceleration. Looking along its own way, beside
// the step, it found only the floor and stayed there, pushed farther from the animation with
// every update (and on the second course a leg that could not reach that floor pulled its toe
// 8.8 cm into box_35's side).
TEST(FootPlacement, AToeHeldAtARiserLooksOverTheStepAndRisesOntoIt) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    AnalyticWorld world;
    add_riser(world, 0.2f, 0.2f);
    CharacterMover mover;
    FootPlacement p;
    // The toe 3 cm before the riser, sliding along it (+X, 2 m/s); the animation's toe 10 cm
    // past it (the toe's shift back to it).
    std::array<PlacementLeg, 2> legs = left_swinging(0.02f);
    legs[0].held_at_step = true;
    legs[0].shift = glm::vec3(0.0f, 0.0f, -0.13f);
    const glm::vec3 velocity(2.0f, 0.0f, 0.0f);
    p.reset(0.0f);
    std::array<float, 3> heights{0.0f, 0.0f, 0.0f};  // at rest on the floor before
    float largest = 0.0f;
    for (int updates = 1; updates * dt <= 0.5f; ++updates) {
      legs[0].toe += velocity * dt;
      legs[0].ankle += velocity * dt;
      p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
               dt);
      heights = {heights[1], heights[2], p.ground(0).toe};
      largest =
          std::max(largest, std::abs(heights[2] - 2.0f * heights[1] + heights[0]) / (dt * dt));
    }
    EXPECT_NEAR(p.ground(0).toe, 0.2f, 1e-3f) << dt;  // up, on the step's height
    // kStepAcceleration, and a little more in the update that lands on the step.
    EXPECT_LE(largest, 46.0f) << dt;
  }
}

// A rise a little more than an update's reach (kStepChangeSpeed, 1.8 m/s, times the update)
// under a foot is climbed at the bounded acceleration all the way, at every update rate: within
// reach of its goal after its first update, the climb was cut short by following the goal at
// once, the rest in one update (a heel 2.9 cm at 1/60 s, stand-turns from x = 8.7 on the second
// course: the knee 280 m/s^2).
TEST(FootPlacement, ARiseJustBeyondAnUpdatesReachIsClimbedWithBoundedAcceleration) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    const float rise = 1.8f * dt + 20.0f * dt * dt;  // reach, and half an update at 40 m/s^2
    AnalyticWorld world;
    CharacterMover mover;
    FootPlacement p;
    const std::array<PlacementLeg, 2> legs = standing_legs();
    settle(p, world, mover, legs, 0.0f);
    world.boxes.push_back(AnalyticBox{glm::vec2(0.0f), glm::vec2(2.0f), 0.0f, rise});
    std::array<float, 3> heels{0.0f, 0.0f, 0.0f};  // at rest on the floor before
    float largest = 0.0f;
    for (int updates = 1; updates * dt <= 0.5f; ++updates) {
      p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f, glm::vec3(0.0f),
               dt);
      heels = {heels[1], heels[2], p.ground(0).heel};
      largest = std::max(largest, std::abs(heels[2] - 2.0f * heels[1] + heels[0]) / (dt * dt));
    }
    EXPECT_NEAR(p.ground(0).heel, rise, 1e-5f) << dt;
    // kStepAcceleration, and a little more in the update that lands.
    EXPECT_LE(largest, 46.0f) << dt;
  }
}

// A planted foot's heel onto a step rises at half the bounded acceleration (a foot turning on its
// held toe has its ankle cross a tread's edge, and the leg carried the whole rise into the knee:
// the lower leg 156 m/s^2 at 1/60 s on the first course's stairs); a foot in the air rises at
// the whole of it.
TEST(FootPlacement, APlantedHeelRisesOntoAStepMoreGentlyThanAFootInTheAir) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    for (const bool planted : {true, false}) {
      AnalyticWorld world;
      CharacterMover mover;
      FootPlacement p;
      std::array<PlacementLeg, 2> legs = standing_legs();
      legs[0].planted = planted;
      settle(p, world, mover, legs, 0.0f);
      world.boxes.push_back(AnalyticBox{glm::vec2(0.0f), glm::vec2(2.0f), 0.0f, 0.1f});
      std::array<float, 3> heels{0.0f, 0.0f, 0.0f};
      float largest = 0.0f;
      for (int updates = 1; updates * dt <= 0.5f; ++updates) {
        p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.0f,
                 glm::vec3(0.0f), dt);
        heels = {heels[1], heels[2], p.ground(0).heel};
        largest = std::max(largest, std::abs(heels[2] - 2.0f * heels[1] + heels[0]) / (dt * dt));
      }
      EXPECT_NEAR(p.ground(0).heel, 0.1f, 1e-5f) << dt << " " << planted;
      if (planted) {
        EXPECT_LE(largest, 23.0f) << dt;  // 20 m/s^2, a little more in the update that lands
      } else {
        EXPECT_GT(largest, 38.0f) << dt;
      }
    }
  }
}

// The body rises up stairs ahead of a foot still on the floor before them, more than a step
// above it: that floor is the foot's own, not a ledge below the body (measured from the body's
// ground alone, the foot's ground jumped up to the body's in an update, 35 cm).
TEST(FootPlacement, AFootStillOnTheFloorTheBodyClimbedAboveStandsOnThatFloor) {
  AnalyticWorld world;
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs = standing_legs();
  settle(p, world, mover, legs, 0.0f);
  for (int f = 1; f <= 30; ++f) {
    const float body = 0.5f * static_cast<float>(f) / 30.0f;  // 0.5 m up in half a second
    p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, body, glm::vec3(0.0f),
             kDt);
    for (int side = 0; side < 2; ++side) {
      EXPECT_NEAR(p.ground(side).toe, 0.0f, 1e-4f) << f;
      EXPECT_NEAR(p.ground(side).heel, 0.0f, 1e-4f) << f;
    }
  }
}

// On a circle or a step to the side the swinging toe heads where the body does not, and
// farther in the body's 0.2 s than in its own 0.1 s: looking only the farther way, the toe met
// the riser it swung into (the course off its lanes, circle at 1/144: 12 cm into the stairs).
TEST(FootPlacement, AToeSwingingAcrossTheBodysPathRisesBeforeTheRiserItHeadsFor) {
  AnalyticWorld world;
  add_riser(world, 0.3f, 0.17f);
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs = left_swinging(-0.35f);
  p.reset(0.0f);
  const FootPlacementSettings settings;
  const glm::vec3 body_velocity(3.0f, 0.0f, 0.0f);  // sideways: 0.6 m in 0.2 s
  const glm::vec3 toe_velocity(0.0f, 0.0f, 2.0f);   // toward the riser: 0.2 m in 0.1 s
  for (int f = 0; f < 14; ++f) {
    legs[0].toe += toe_velocity * kDt;
    legs[0].ankle += toe_velocity * kDt;
    p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, body_velocity, kDt);
  }
  ASSERT_LT(legs[0].toe.z, 0.3f);  // still over the lower ground, the riser 3 cm ahead
  EXPECT_GT(p.ground(0).toe, 0.15f);
}

// Circling onto stairs, a toe swung over a tread's front corner toward the stairs' side: its
// look-ahead and the body's were already beside the stairs, and the toe was over the tread
// before anything saw it (the first course, circle from x = 7 at 1/60 s: 3.9 cm inside the
// second tread). The ground under the heel is a floor its ground never lags under, and the toe
// is never lower above the ground under it than the data's toes go (its ground lifted as far as
// that needs, no farther: lifted onto the tread, a toe already above it popped up by the
// difference).
// A tread 0.17 m high for x < 1 and z > 0.3 (its front face at z = 0.3, its side at x = 1), and a
// left toe in the air before its corner, the right foot standing back.
void add_tread_with_a_corner(AnalyticWorld& world) {
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 1.3f), glm::vec2(1.0f, 1.0f), 0.0f, 0.17f});
}
std::array<PlacementLeg, 2> left_before_the_corner() {
  std::array<PlacementLeg, 2> legs{standing_leg(0.85f, 0.05f, 0.0f),
                                   standing_leg(0.5f, -0.5f, 0.0f)};
  legs[0].planted = legs[0].near_ground = false;
  return legs;
}
constexpr glm::vec3 kAcrossTheCorner(1.6f, 0.0f, 1.6f);  // diagonally across the tread's corner

TEST(FootPlacement, AToeCrossingATreadsCornerIsNeverBelowTheTreadItIsOver) {
  AnalyticWorld world;
  add_tread_with_a_corner(world);
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs = left_before_the_corner();
  const FootPlacementSettings settings;
  const glm::vec3 velocity = kAcrossTheCorner;
  // The toe swinging 1 cm above its lowest (3 cm up), then 11 cm.
  for (const float lowest : {0.02f, -0.08f}) {
    std::array<PlacementLeg, 2> swinging = legs;
    swinging[0].lowest = lowest;
    p.reset(0.0f);
    int over = 0, lagging = 0;
    for (int f = 0; f < 10; ++f) {
      swinging[0].toe += velocity * kDt;
      swinging[0].ankle += velocity * kDt;
      p.update(world, glm::dvec3(0.0), mover, settings, swinging, 0.0f, velocity, kDt);
      const glm::vec3& toe = swinging[0].toe;
      const glm::vec3& ankle = swinging[0].ankle;
      const float under_toe = static_cast<float>(world.surface(toe.x, toe.z));
      const float under_heel = static_cast<float>(world.surface(ankle.x, ankle.z));
      over += under_toe > 0.0f;
      lagging += under_toe > 0.0f && p.ground(0).toe < under_toe - 0.01f;
      // The toe as placed: its animated height over the body's ground (0), over its own ground.
      EXPECT_GE(toe.y + p.ground(0).toe, under_toe + lowest - 1e-6f) << f << " " << lowest;
      EXPECT_GE(p.ground(0).heel, under_heel) << f << " " << lowest;
    }
    EXPECT_GE(over, 2) << lowest;  // the toe did cross the tread
    // High above the tread, the toe's ground is not lifted onto it at once: still on its way.
    if (lowest < 0.0f) {
      EXPECT_GE(lagging, 1);
    }
  }
}

// A toe swung low across a tread's corner is lifted onto the tread the update it is over it
// (stay_above), and its ground's follower goes on from rest there: the rise a lock must not begin
// during (Controller::on_its_ground) is the ground's whole change over the update, the lift
// included, not the follower's velocity.
TEST(FootPlacement, AToesGroundLiftedOntoATreadReportsTheWholeRise) {
  AnalyticWorld world;
  add_tread_with_a_corner(world);
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs = left_before_the_corner();
  legs[0].lowest = 0.02f;
  const FootPlacementSettings settings;
  const glm::vec3 velocity = kAcrossTheCorner;
  p.reset(0.0f);
  float largest = 0.0f;
  for (int f = 0; f < 10; ++f) {
    legs[0].toe += velocity * kDt;
    legs[0].ankle += velocity * kDt;
    const float before = p.ground(0).toe;
    p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, velocity, kDt);
    const float rise = (p.ground(0).toe - before) / kDt;
    EXPECT_NEAR(p.toe_ground_rise(0), rise, 1e-3f) << f;
    largest = std::max(largest, rise);
  }
  EXPECT_GT(largest, 0.5f);  // lifted onto the tread faster than a lock may begin on
}

// A toe swinging along a box's front face (the body walking beside it), its own velocity veering
// toward the face: its own look-ahead reaches over the box. Where the clip lands it on the floor
// in front of the face, its ground stays on the floor; where the clip lands it on the box, or
// where it is held at the face (a riser) with the animation 13 cm over the box, it rises.
TEST(FootPlacement, AToeSwingingBesideABoxRisesOnlyWhereItGoesOntoIt) {
  AnalyticWorld world;
  // A box 0.3 m high (above a stair's riser) for z > 0.3.
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 1.3f), glm::vec2(1.0f, 1.0f), 0.0f, 0.3f});
  CharacterMover mover;
  const FootPlacementSettings settings;
  const glm::vec3 body_velocity(-1.0f, 0.0f, 0.0f);  // along the face
  const glm::vec3 toe_velocity(-1.0f, 0.0f, 0.6f);   // veering toward it
  enum Case { kLandsBeside, kLandsOnIt, kHeldAtIt };
  for (const Case c : {kLandsBeside, kLandsOnIt, kHeldAtIt}) {
    FootPlacement p;
    p.reset(0.0f);
    std::array<PlacementLeg, 2> legs{standing_leg(0.5f, 0.08f, 0.0f),
                                     standing_leg(0.0f, -0.3f, 0.0f)};
    legs[0].planted = legs[0].near_ground = false;
    legs[0].lowest = 0.02f;
    legs[0].lands = true;
    if (c == kHeldAtIt) {
      legs[0].held_at_step = true;
      legs[0].shift = glm::vec3(0.0f, 0.0f, -0.13f);
    }
    float highest = 0.0f;
    for (int f = 0; f < 5; ++f) {
      legs[0].toe += toe_velocity * kDt;
      legs[0].ankle += toe_velocity * kDt;
      legs[0].landing =
          glm::vec3(legs[0].toe.x - 0.1f, 0.0f, c == kLandsOnIt ? 0.4f : legs[0].toe.z);
      p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, body_velocity, kDt);
      ASSERT_LT(legs[0].toe.z, 0.3f);  // never over the box itself
      highest = std::max(highest, p.ground(0).toe);
    }
    if (c == kLandsBeside) {
      EXPECT_EQ(highest, 0.0f);
    } else {
      EXPECT_GT(highest, 0.02f) << c;
    }
  }
}

// A foot planted on the floor before a box (0.35 m, higher than the foot's tilt reaches), its
// heel swung back over the box's edge: lifted level with the heel it stood a box's height in the
// air; it stays on the floor. A foot that already stood up there (its heel on the edge, its toe
// out over the floor, as on a tread's edge going down stairs) stays up there.
TEST(FootPlacement, APlantedFootsHeelOverAHighStepDoesNotLiftItOffTheFloor) {
  AnalyticWorld world;
  // A box 0.35 m high for z < 0: its face at z = 0.
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, -1.0f), glm::vec2(2.0f, 1.0f), 0.0f, 0.35f});
  CharacterMover mover;
  const FootPlacementSettings settings;
  // Toe 10 cm before the face (+Z), heel 5 cm over the box: the foot points away from it.
  std::array<PlacementLeg, 2> legs{standing_leg(0.0f, -0.05f, 0.0f),
                                   standing_leg(0.3f, 0.5f, 0.0f)};
  legs[0].toe = glm::vec3(0.0f, 0.03f, 0.1f);
  // Planted on the floor, then the same foot already standing on the box's edge (its ground
  // there), the body on the floor both times: each foot stays on the ground it stood on.
  for (const float stood : {0.0f, 0.35f}) {
    FootPlacement p;
    p.reset(stood);
    for (int f = 0; f < 30; ++f) {
      p.update(world, glm::dvec3(0.0), mover, settings, legs, 0.0f, glm::vec3(0.0f), kDt);
    }
    EXPECT_NEAR(p.ground(0).toe, stood, 1e-3f);
    EXPECT_NEAR(p.ground(0).heel, stood, 1e-3f);
  }
}

TEST(FootPlacement, AProbeThatMissesFallsBackToTheBodysGround) {
  AnalyticWorld world;
  world.height = [](double, double) { return -5.0; };  // far below any probe's reach
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.3f),
                                         standing_leg(0.1f, 0.0f, 0.3f)};
  settle(p, world, mover, legs, 0.3f);
  EXPECT_EQ(p.ground(0).heel, 0.3f);
  EXPECT_EQ(p.ground(1).toe, 0.3f);
  EXPECT_EQ(p.pelvis_drop(), 0.0f);
  EXPECT_EQ(p.probe_grounds()[0].y, 0.3f);
}

TEST(FootPlacement, GarbageAnswersAreIgnoredAndCounted) {
  AnalyticWorld world;
  world.garbage = true;
  CharacterMover mover;
  FootPlacement p;
  const std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.2f),
                                         standing_leg(0.1f, 0.0f, 0.2f)};
  settle(p, world, mover, legs, 0.2f);
  // Every probe and both planted toes' sweeps toward their hips.
  EXPECT_EQ(mover.rejected(), 180 * (FootPlacement::kQueries + 2));
  for (int side = 0; side < 2; ++side) {
    EXPECT_EQ(p.ground(side).heel, 0.2f);
    EXPECT_EQ(p.ground(side).toe, 0.2f);
  }
  EXPECT_EQ(p.pelvis_drop(), 0.0f);
}

TEST(FootPlacement, ThePelvisComesDownSoThatTheLowerFootReachesWithinItsLimit) {
  AnalyticWorld world;
  // The right foot's ground 12 cm lower than the body's: a step down under it.
  world.height = [](double x, double) { return x > 0.0 ? -0.12 : 0.0; };
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.0f), standing_leg(0.1f, 0.0f, 0.0f)};
  legs[1].length = 0.86f;  // as straight as the animation has it: any lower needs the pelvis
  settle(p, world, mover, legs, 0.0f);
  const PlacementLeg& low = legs[1];
  const float ankle_y = low.ankle.y - 0.12f;
  const glm::vec3 hip = low.hip - glm::vec3(0.0f, p.pelvis_drop(), 0.0f);
  const float reach = glm::length(hip - glm::vec3(low.ankle.x, ankle_y, low.ankle.z));
  EXPECT_GT(p.pelvis_drop(), 0.05f);
  EXPECT_NEAR(reach, std::max(glm::length(low.hip - low.ankle), 0.97f * low.length), 2e-3f);

  // Far deeper than the limit (yet within a step: deeper is a ledge the foot stays above), the
  // drop stops at the limit.
  world.height = [](double x, double) { return x > 0.0 ? -0.33 : 0.0; };
  FootPlacementSettings settings;
  settings.max_pelvis_drop = 0.2f;
  settle(p, world, mover, legs, 0.0f, settings);
  EXPECT_FLOAT_EQ(p.pelvis_drop(), 0.2f);
}

// Whether the hip lowered by `drop` reaches a planted toe on `toe_ground` with a leg of at most
// 0.97 of its length: the ankle turned about the toe, toward the hip, by any heel rise up to
// FootPlacement::kMaxHeelRise, tried in small steps.
bool toe_in_reach(const PlacementLeg& leg, float toe_ground, float body_ground, float drop) {
  const glm::vec3 toe = leg.toe + glm::vec3(0.0f, toe_ground - body_ground, 0.0f);
  const glm::vec3 hip = leg.hip - glm::vec3(0.0f, drop, 0.0f);
  const glm::vec3 axis = glm::normalize(glm::cross(leg.ankle - leg.toe, hip - toe));
  for (int k = 0; k <= 100; ++k) {
    const glm::quat rise = glm::angleAxis(FootPlacement::kMaxHeelRise * k / 100.0f, axis);
    const glm::vec3 ankle = toe + rise * (leg.ankle - leg.toe);
    if (glm::length(hip - ankle) <= 0.97f * leg.length + 1e-3f) return true;
  }
  return false;
}

// A leg planted on the floor with its toe 5 cm before a step's side (at z = 0.3, the step
// beyond it toward -Z), pointing at it, its hip over the step: a step up onto a box begun beside
// it. Heights above `body_ground`, where the animation has them.
PlacementLeg planted_before_a_step(float body_ground) {
  PlacementLeg leg;
  leg.ankle = glm::vec3(0.1f, body_ground + 0.08f, 0.5f);
  leg.toe = glm::vec3(0.1f, body_ground + 0.03f, 0.35f);
  leg.hip = glm::vec3(0.1f, body_ground + 0.93f, 0.25f);
  leg.length = 1.0f;
  leg.planted = leg.near_ground = true;
  return leg;
}

// The body climbing a 30 cm step at 1 m/s beside a toe planted on the floor before it: the
// pelvis comes down as fast as the toe needs to stay within its leg's reach, at every rate. On
// its springs alone it fell 16 cm behind and the leg dragged the toe toward the hip, into the
// step's side (the second course, random-long from x = 39.05). The same toe with no step in the
// way (a ramp's slope does not count) is left to the springs.
TEST(FootPlacement, AToePlantedBeforeAStepTheBodyClimbsStaysWithinReach) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    for (const bool step : {true, false}) {
      AnalyticWorld world;
      if (step) {
        world.boxes.push_back(
            AnalyticBox{glm::vec2(0.0f, 0.3f - 2.0f), glm::vec2(5.0f, 2.0f), 0.0f, 0.3f});
      }
      CharacterMover mover;
      FootPlacement p;
      p.reset(0.0f);
      int short_updates = 0;
      for (int f = 0;; ++f) {
        const float body_ground = std::min(0.3f, f * dt * 1.0f);
        std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, body_ground),
                                         planted_before_a_step(body_ground)};
        legs[0].planted = false;
        p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, body_ground,
                 glm::vec3(0.0f), dt);
        ASSERT_NEAR(p.ground(1).toe, 0.0f, 1e-4f) << dt;
        if (!toe_in_reach(legs[1], 0.0f, body_ground, p.pelvis_drop())) ++short_updates;
        if (body_ground >= 0.3f) break;
      }
      if (step) {
        EXPECT_EQ(short_updates, 0) << dt;
      } else {
        EXPECT_GT(short_updates, 0) << dt;
      }
    }
  }
}

// A toe landing farther below than the springs have lowered the pelvis (a foot put down off a
// tread, onto the floor 25 cm below, before the tread's side) keeps its shortfall: the pelvis
// comes down on its springs, not a whole step in an update.
TEST(FootPlacement, AToeLandingOutOfReachLowersThePelvisOnItsSprings) {
  AnalyticWorld world;
  world.boxes.push_back(
      AnalyticBox{glm::vec2(0.0f, 0.3f - 2.0f), glm::vec2(5.0f, 2.0f), 0.0f, 0.25f});
  CharacterMover mover;
  FootPlacement p;
  std::array<PlacementLeg, 2> legs{standing_leg(-0.1f, 0.0f, 0.25f), planted_before_a_step(0.25f)};
  legs[1].hip.z = 0.1f;  // farther over the tread: out of reach of the floor
  legs[1].planted = legs[1].near_ground = false;
  settle(p, world, mover, legs, 0.25f);
  ASSERT_EQ(p.pelvis_drop(), 0.0f);
  ASSERT_FALSE(toe_in_reach(legs[1], 0.0f, 0.25f, 0.0f));
  legs[1].planted = legs[1].near_ground = true;
  float drop = 0.0f;
  for (int f = 0; f < 60; ++f) {
    p.update(world, glm::dvec3(0.0), mover, FootPlacementSettings{}, legs, 0.25f, glm::vec3(0.0f),
             kDt);
    EXPECT_LE(p.pelvis_drop() - drop, 0.02f) << f;
    drop = p.pelvis_drop();
  }
  // Settled, the foot reaches its ground.
  EXPECT_TRUE(toe_in_reach(legs[1], 0.0f, 0.25f, p.pelvis_drop()));
}

// Walking up and down a slope, a planted foot stands on it as on flat ground: its toe and its
// heel (ankle) about as high above the surface under them as the flat run has them (no more
// than 1.5 and 2 cm higher, 3.5 for the heel on 30 degrees: not floating), and every toe at
// least 1 cm above it.
TEST(FootPlacementController, OnSlopesThePlantedFeetStandOnTheSurface) {
  const auto clearances = [](const AnalyticWorld& world, float yaw_degrees) {
    Controller c = test::make_controller();
    c.set_world(&world);
    const Database& db = c.controller_database().database();
    const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
    const int feet[2] = {db.roles().left_foot, db.roles().right_foot};
    double toe_sum = 0.0, heel_sum = 0.0, lowest = 1e9;
    int count = 0;
    for (int f = 0; f < 5 * 60; ++f) {
      c.update(kDt, test::push_toward(yaw_degrees, false));
      if (f < 60) continue;
      for (int side = 0; side < 2; ++side) {
        const glm::vec3 toe = c.global_transforms()[static_cast<size_t>(toes[side])].translation;
        const glm::vec3 heel = c.global_transforms()[static_cast<size_t>(feet[side])].translation;
        const double toe_clearance = toe.y - world.surface(toe.x, toe.z);
        lowest = std::min(lowest, toe_clearance);
        if (!c.debug().locked[side]) continue;
        toe_sum += toe_clearance;
        heel_sum += heel.y - world.surface(heel.x, heel.z);
        ++count;
      }
    }
    return std::array<double, 3>{toe_sum / count, heel_sum / count, lowest};
  };
  AnalyticWorld flat;
  const std::array<double, 3> on_flat = clearances(flat, 0.0f);
  for (const float degrees : {10.0f, 20.0f, 30.0f}) {
    for (const float yaw : {0.0f, 180.0f}) {  // up the slope (+Z), then down it
      AnalyticWorld world;
      const double slope = std::tan(degrees * kPi / 180.0f);
      world.height = [slope](double, double z) { return z * slope; };
      const std::array<double, 3> on_slope = clearances(world, yaw);
      // No higher than on flat ground (the 1.5 cm for the toe), and not sunk into the
      // slope either.
      EXPECT_LT(on_slope[0], on_flat[0] + 0.015) << degrees << " yaw " << yaw;
      EXPECT_GT(on_slope[0], on_flat[0] - 0.02) << degrees << " yaw " << yaw;
      // The heel 2 cm, 3.5 on 30 degrees: walked up at the climbing pace (climb_pace.hpp, 0.41 of
      // the clip's rate there) the ankle of a planted foot stands 2.5 cm higher over the slope
      // (3.0 since session 30, where a held toe comes down with the animation's: the flat run's
      // planted heels 1.8 cm lower, the slope's 1.3).
      const double heel_margin = degrees >= 30.0f ? 0.035 : 0.02;
      EXPECT_LT(on_slope[1], on_flat[1] + heel_margin) << degrees << " yaw " << yaw;
      EXPECT_GT(on_slope[1], on_flat[1] - 0.03) << degrees << " yaw " << yaw;
      EXPECT_GT(on_slope[2], 0.01) << degrees << " yaw " << yaw;
    }
  }
}

}  // namespace
}  // namespace mm
