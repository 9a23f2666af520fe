// The controller on the shipped courses, through the evaluation's scripts and metrics: runs where
// a rule of the world's placement was seen to fail, frame by frame, before it was fixed.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string_view>
#include <utility>

#include "../controller/controller_support.hpp"
#include "course_support.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"

namespace mm {
namespace {

struct CourseRun {
  const char* course;  // nullptr: the flat plane
  const char* script;  // a file of scripts/input, or the script itself where it holds a line break
  glm::dvec2 start;
  float dt;
  ControllerSettings settings = {};
};

// The run's metrics (the test fails, and they are empty, when it cannot run).
EvaluationMetrics run(const CourseRun& r,
                      std::function<void(const EvaluationFrame&)> on_frame = {}) {
  const std::filesystem::path source(MM_SOURCE_DIR);
  // The flat plane's run has a world loaded all the same (built in place), not handed over.
  const BulletWorld world =
      test::course_world(source / (r.course ? r.course : "data/levels/course.glb"));
  const std::string_view text(r.script);
  Result<InputScript> script = text.find('\n') != std::string_view::npos
                                   ? parse_input_script(text, "inline script")
                                   : load_input_script(source / "scripts/input" / r.script);
  EXPECT_TRUE(script.ok()) << script.message();
  if (!script) return {};
  EvaluationOptions options;
  options.dt = r.dt;
  options.world = r.course ? &world : nullptr;
  options.start = r.start;
  options.on_frame = std::move(on_frame);
  options.settings = r.settings;
  const Result<EvaluationResult> result =
      evaluate_script(test::normal_controller_database(), *script, options);
  EXPECT_TRUE(result.ok()) << result.message();
  return result ? result->metrics : EvaluationMetrics{};
}

// How many times the run's foot locks let go while the foot's contact label was on (on the
// update before), in locomotion: a character standing (at a ledge's edge the stick pushes
// toward) steps to settle by design.
int labelled_releases(const CourseRun& r) {
  const Database& db = test::normal_controller_database()->database();
  const std::string idle_tag[] = {"idle"};
  const uint64_t idle = db.tag_mask(idle_tag);
  int releases = 0;
  bool was_locked[2] = {false, false}, was_contact[2] = {false, false};
  run(r, [&](const EvaluationFrame& frame) {
    const bool standing =
        frame.clip >= 0 && (db.clips()[static_cast<size_t>(frame.clip)].tags & idle) != 0;
    for (int side = 0; side < 2; ++side) {
      if (was_locked[side] && !frame.locked[side] && was_contact[side] && !standing) ++releases;
      was_locked[side] = frame.locked[side];
      was_contact[side] = frame.contact[side];
    }
  });
  return releases;
}

// A toe a wall keeps out (controller_world.cpp, place_feet): the capsule stands a radius back
// from a ledge's edge (the side of a stair's landing, a step higher than the tread the body
// stands on), the animation swings a toe out over the drop, and keep_toe_off_wall holds it on
// the landing. Its ground was probed where the animation had it, out over the drop (the body's
// ground there, a step lower), so the toe held on the landing sank below its top (1.66 and 1.40
// cm in the two runs below). Probed where it is held, it stays above it.
TEST(CourseRuns, AToeHeldOnALandingBesideItsDropStaysAboveTheLanding) {
  // The second course's stairs_20_25 (a 0.8 m landing, its side a ledge to the floor) walked
  // back and forth; the first course's stairs stopped on.
  const CourseRun runs[] = {
      {"data/levels/course2.glb", "reversals.txt", {11.5, 2.0}, 1.0f / 60.0f},
      {"data/levels/course.glb", "stop-and-go.txt", {10.0, 3.0}, 1.0f / 30.0f}};
  for (const CourseRun& r : runs) {
    const EvaluationMetrics m = run(r);
    // The floor: a toe at least 1 cm above the surface under it.
    EXPECT_GE(m.ground.toe_clearance_cm_min, 1.0) << r.course << " " << r.script;
    EXPECT_EQ(m.ground.foot_penetration_cm_max, 0.0) << r.course << " " << r.script;
  }
}

// A toe planted on the floor before a step's side while the body climbs the step (the second
// course's box_35 walked onto; its stairs_20_25 turned on at the first riser): the pelvis came
// down on its springs only, too slowly, and the leg, short of the held toe, pulled it toward the
// hip into the side (0.9 cm into the box's side, read 18.5 cm below its top; 8.6 cm below the
// first tread). The pelvis now comes down as far as such a toe needs at once
// (FootPlacement::keep_planted_toes_reached).
TEST(CourseRuns, AToePlantedBeforeAStepTheBodyClimbsStaysOutOfItsSide) {
  const CourseRun runs[] = {
      {"data/levels/course2.glb", "random-long.txt", {39.05, 2.0}, 1.0f / 60.0f},
      {"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 1.0f / 30.0f}};
  for (const CourseRun& r : runs) {
    const EvaluationMetrics m = run(r);
    EXPECT_GE(m.ground.toe_clearance_cm_min, 1.0) << r.course << " " << r.script;
    EXPECT_EQ(m.ground.foot_penetration_cm_max, 0.0) << r.course << " " << r.script;
  }
}

// Sliding along a turned wall (the first course's wall_30 strafed into, the second's wall_60
// zigzagged along): the simulation object's yield toward the character (synchronize) gave the
// whole slide back each update, the clip played not sliding, and the character stood still
// beside the wall where it could have slid (0.77 and 0.63 s stuck as first measured; 0.63 and
// 0.37 s under today's stuck_s, which leaves out starts from rest). The yield may take back only
// part of the slide (without_slide_back): not a frame stuck.
TEST(CourseRuns, AlongATurnedWallTheCharacterKeepsSliding) {
  const CourseRun runs[] = {{"data/levels/course.glb", "strafe.txt", {22.0, 3.0}, 1.0f / 60.0f},
                            {"data/levels/course2.glb", "zigzag.txt", {25.8, 2.0}, 1.0f / 60.0f}};
  for (const CourseRun& r : runs) {
    const EvaluationMetrics m = run(r);
    EXPECT_LT(m.ground.stuck_s, 0.1) << r.course << " " << r.script;
    EXPECT_LT(m.ground.wall_depth_cm_max, 2.0) << r.course << " " << r.script;
    EXPECT_LT(m.ground.foot_skate_geom_cm_s_mean, m.foot_skate_geom_data_cm_s_mean)
        << r.course << " " << r.script;
  }
}

// Strafing across steep ramps (the second course's ramp_25, the first's ramp_30): the downhill
// foot's held toe was out of the leg's reach with the pelvis dropped as far as it goes, so its
// lock let go (out of reach) while its contact label was on, the toe stepped to the animated
// toe, as far out of reach, locked again and let go, over and over: a foot shuffling where it
// stood, slow and low, which the geometric skating counts. A held toe now steps only where the
// animated one is nearer the hip: on the ramps, about as many locks let go during their
// contacts as on flat ground (7 and 18 more on the tests' database before).
// The climbing pace is off (max_climb_speed 0): it slows the strafes up and down the ramps and
// changes where their steps fall, two more releases on the second course (its geometric
// skating lower all the same; docs/world.md, session 24), and the count is this rule's.
TEST(CourseRuns, ADownhillFootOutOfReachStaysHeld) {
  constexpr float kDt = 1.0f / 144.0f;
  ControllerSettings unpaced;
  unpaced.max_climb_speed = 0.0f;
  const CourseRun flat{nullptr, "strafe.txt", {0.0, 0.0}, kDt, unpaced};
  const CourseRun ramps[] = {{"data/levels/course2.glb", "strafe.txt", {3.4, 2.0}, kDt, unpaced},
                             {"data/levels/course.glb", "strafe.txt", {7.0, 3.0}, kDt, unpaced}};
  const int on_flat = labelled_releases(flat);
  EXPECT_GT(on_flat, 10);  // the count sees releases at all
  for (const CourseRun& r : ramps) EXPECT_LE(labelled_releases(r), on_flat + 5) << r.course;
}

// Calls `each(frame, d)` from a run's third update on with `d`, the second difference (m) of the
// point `at(frame)` gives over that update and the two before it; returns the run's metrics.
EvaluationMetrics each_second_difference(
    const CourseRun& r, const std::function<glm::dvec3(const EvaluationFrame&)>& at,
    const std::function<void(const EvaluationFrame&, double)>& each) {
  int frames = 0;
  glm::dvec3 before[2];
  return run(r, [&](const EvaluationFrame& frame) {
    const glm::dvec3 now = at(frame);
    if (frames >= 2) each(frame, glm::length(now - 2.0 * before[1] + before[0]));
    before[0] = before[1];
    before[1] = now;
    ++frames;
  });
}

// How many updates the root's horizontal step changed by more than `jump` (m) from the update
// before.
int root_jerks(const CourseRun& r, float jump) {
  int jerks = 0;
  each_second_difference(
      r,
      [](const EvaluationFrame& frame) {
        return glm::dvec3(frame.root_position.x, 0.0, frame.root_position.z);
      },
      [&](const EvaluationFrame&, double d) { jerks += d > jump ? 1 : 0; });
  return jerks;
}

// Beside a ledge's edge (the second course's ramp_15, its side a drop to the floor, circled) and
// along a wall (wall_60, strafed along): the root's own moves met the edge or the wall on one
// update and not the next, and its step turned one way and back on alternate updates, a jitter
// of millimetres (on the tests' database 26 and 206 updates whose step changed by more than 2 mm,
// 41 m/s^2 at 1/144 s; 4 on flat ground, at transitions). Held by what they met lately
// (HeldContacts), the steps slide along.
TEST(CourseRuns, BesideALedgesEdgeAndAlongAWallTheRootDoesNotJitter) {
  constexpr float kDt = 1.0f / 144.0f;
  const CourseRun runs[] = {{"data/levels/course2.glb", "circle.txt", {0.8, 2.0}, kDt},
                            {"data/levels/course2.glb", "strafe.txt", {25.8, 2.0}, kDt}};
  const int on_flat = root_jerks({nullptr, "circle.txt", {0.0, 0.0}, kDt}, 0.002f);
  for (const CourseRun& r : runs) EXPECT_LE(root_jerks(r, 0.002f), on_flat + 10) << r.script;
}

// The largest acceleration (m/s^2, second differences of its position) of `joint` between t0 and
// t1 (s) of a run; the run's metrics in `metrics` if given.
float largest_acceleration(const CourseRun& r, int joint, float t0, float t1,
                           EvaluationMetrics* metrics = nullptr) {
  double largest = 0.0;
  const EvaluationMetrics m = each_second_difference(
      r,
      [joint](const EvaluationFrame& frame) {
        return frame.origin + glm::dvec3(frame.joints[static_cast<size_t>(joint)]);
      },
      [&](const EvaluationFrame& frame, double d) {
        if (frame.t >= t0 && frame.t <= t1) largest = std::max(largest, d);
      });
  if (metrics) *metrics = m;
  return static_cast<float>(largest / (double(r.dt) * r.dt));
}

// Running diagonally into the corner of the second course's floor (two ledge edges): the body was
// kept off the obstacle the simulation object stands against by a push along its normal, and in
// the corner that obstacle was one edge, then the other, from one update to the next: the whole
// body was thrown 4 to 6 cm sideways and back (every joint over 240 m/s^2; random-long from
// x = 0.8 at 1/60 s on the tests' database, 86.15 s). The push is one offset now, out of every
// wall and edge at once.
TEST(CourseRuns, IntoACornerTheBodyIsKeptOffBothWallsWithoutAJump) {
  const int hips = test::normal_controller_database()->database().roles().hips;
  constexpr const char* kIntoTheCorner =
      "0 0 0 0 0\n"
      "0.5 0.707 0.707 0 0 run\n"  // toward world -X and +Z
      "5 0.707 0.707 0 0 run\n";
  // Two starts that reach the corner with the hands at each wall in turn; on flat ground the
  // hips' largest acceleration in this script is about 20 m/s^2, pushed off the walls about 60-75.
  for (const glm::dvec2& start : {glm::dvec2(0.0, 13.5), glm::dvec2(-1.2, 14.0)}) {
    const CourseRun r{"data/levels/course2.glb", kIntoTheCorner, start, 1.0f / 60.0f};
    EXPECT_LT(largest_acceleration(r, hips, 0.0f, 8.0f), 150.0f) << start.x << ", " << start.y;
  }
}

// Walking past the end of the second course's corner wall (stand-turns from x = 31.6 at 1/144
// s): a hand swinging past the wall's end is found a hand's depth inside it at once, and the
// body's push took all of it in the update it was found: the whole body jumped sideways (the hips
// 234 m/s^2 at 42.23 s on the tests' database). The body follows what an arm's depth asks for
// with a bounded acceleration, the arm's swing out of the wall taking the rest meanwhile; the
// hips' own accelerations around it are under 30 m/s^2, and no joint goes into the wall.
TEST(CourseRuns, AHandPastAWallsEndDoesNotThrowTheBody) {
  const int hips = test::normal_controller_database()->database().roles().hips;
  // The time step as `mm eval --dt 0.00694444` reads it, the run measured.
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {31.6, 2.0}, 0.00694444f};
  EvaluationMetrics m;
  EXPECT_LT(largest_acceleration(r, hips, 42.1f, 42.4f, &m), 80.0f);
  EXPECT_LE(m.ground.wall_depth_cm_max, 2.0);
}

// Strafing into the second course's corridor (strafe from x = 33.75 at 1/144 s on the tests'
// database): the simulation object met the end of the corridor's wall, and the plane of that
// end face, which goes on past the wall, pushed what was in it out: a toe stepping into the
// corridor beside the wall was pulled back 1.5 m in a few updates (9,660 m/s^2 at 9.19 s), the
// hips 5 cm in an update (1,169 m/s^2 at 8.85 s). A toe or the trunk in that plane is swept out
// to and kept out only of a face found there; here every leg end and the hips stay under 170.
TEST(CourseRuns, BesideAWallsEndNeitherAFootNorTheBodyIsPushedOutOfItsPlane) {
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const CourseRun r{"data/levels/course2.glb", "strafe.txt", {33.75, 2.0}, 0.00694444f};
  EvaluationMetrics m;
  EXPECT_LT(largest_acceleration(r, roles.hips, 8.0f, 9.6f, &m), 300.0f);
  EXPECT_LE(m.ground.wall_depth_cm_max, 2.0);
  for (const int toe : {roles.left_toe, roles.right_toe}) {
    EXPECT_LT(largest_acceleration(r, toe, 8.0f, 9.6f), 300.0f) << toe;
  }
}

// Circling off the side of the second course's stairs_12_35 (circle from x = 8.7 at 1/144 s on
// the tests' database): a toe held on the fourth tread (48 cm up) while the body went down beside
// the stairs stood, when let go, 38 cm above the body's ground, and the sweep from the root out
// to it a step above the body's ground met the riser under that tread: the toe was pushed 19 cm
// back in an update (the left leg's joints 2,500-3,900 m/s^2 at 4.58 s; under 40 now). A toe on
// ground higher than that sweep goes on with the animation.
TEST(CourseRuns, AToeLeftOnATreadTheBodyWentDownBesideIsNotPushedOffIt) {
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const CourseRun r{"data/levels/course2.glb", "circle.txt", {8.7, 2.0}, 0.00694444f};
  for (const int joint : {roles.left_lower_leg, roles.left_toe}) {
    EXPECT_LT(largest_acceleration(r, joint, 4.5f, 4.7f), 100.0f) << joint;
  }
}

// Strafing along the second course's corner's far wall (its face z = 7, x 29.3 to 32.05, 25 cm
// thick) past its end and back (strafe-run from x = 31.05, z = 1.5, on the tests' database): the
// character went round the wall's end while the simulation object gave way toward it in a
// straight line, into the wall's corner, up to 2.3 cm deep at 1/60 and 1/30 s (on the default
// database at 1/144 s right through, to the wall's back; the legs thrown about, 4,278 m/s^2).
// The give is swept with the object's next step.
TEST(CourseRuns, TheSimulationObjectGivingWayToTheCharacterStaysOutOfAWallsCorner) {
  constexpr float kWallX[2] = {29.3f, 32.05f}, kWallZ[2] = {7.0f, 7.25f};
  const float radius = ControllerSettings{}.character_radius;
  for (const float dt : {1.0f / 60.0f, 1.0f / 30.0f}) {
    const CourseRun r{"data/levels/course2.glb", "strafe-run.txt", {31.05, 1.5}, dt};
    float deepest = 0.0f;
    run(r, [&](const EvaluationFrame& frame) {
      const glm::dvec3 p = frame.origin + glm::dvec3(frame.sim_position);
      const double dx = p.x - std::clamp(p.x, double(kWallX[0]), double(kWallX[1]));
      const double dz = p.z - std::clamp(p.z, double(kWallZ[0]), double(kWallZ[1]));
      deepest = std::max(deepest, radius - static_cast<float>(std::hypot(dx, dz)));
    });
    EXPECT_LT(deepest, 0.005f) << dt;
  }
}

// Stopping at the top of the second course's stairs_20_25 (stand-turns from x = 11.5 at 1/30 s on
// the tests' database): a settling step onto the landing, the toe 12 cm short of the tread's
// height, rose only when its look-ahead met the riser, an update before the toe did, at 40
// m/s^2 while the toe waited there (the right leg's joints 46-53 m/s^2 at 43.3-43.43 s, the run's
// transition ratio 0.924). A foot landing a step up rises toward its landing from the start of
// its swing, here at about half that.
TEST(CourseRuns, AFootLandingAStepUpRisesFromTheStartOfItsSwing) {
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 0.0333333f};
  for (const int joint : {roles.right_lower_leg, roles.right_foot, roles.right_toe}) {
    EXPECT_LT(largest_acceleration(r, joint, 42.9f, 43.6f), 35.0f) << joint;
  }
}

// Up the second course's stairs_20_25 (stop-and-go from x = 11.5 at 1/30 s on the tests'
// database): a foot landing on the first tread 6 cm before the next riser had its ground raised
// toward the next tread by the probes' look-ahead, and its contact label came on with the toe
// 25 cm above its tread: locked there, it stood in the air until its ground came back down (13
// updates over 15 cm up). A lock begins only on a toe near the ground under it now.
TEST(CourseRuns, AFootLandingShortOfAStepIsNotLockedInTheAir) {
  const CourseRun r{"data/levels/course2.glb", "stop-and-go.txt", {11.5, 2.0}, 1.0f / 30.0f};
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const int toes[2] = {roles.left_toe, roles.right_toe};
  int in_the_air = 0;
  run(r, [&](const EvaluationFrame& frame) {
    for (int side = 0; side < 2; ++side) {
      const float under = std::max(frame.toe_ground[side], frame.toe_support[side]);
      const float height = frame.joints[static_cast<size_t>(toes[side])].y - under;
      in_the_air += frame.locked[side] && height > 0.15f ? 1 : 0;
    }
  });
  EXPECT_LE(in_the_air, 3);
}

// Stopping before the second course's box_35 (stop-and-go from x = 39.05, on the tests'
// database): the probes' look-ahead (the body's velocity 0.2 s ahead) saw the box top beyond a
// foot that lands 7 cm short of it, and raised that foot's ground toward it (33 cm at 1/60 s)
// until the foot came down onto the floor, rising and sinking in the air. A toe about to land
// looks no farther than a little past where the playing clip puts it down
// (FootPlacement::kPastLanding). Counted: a foot whose ground rose more than 20 cm over the
// ground under its toe and which then locked lower, its toe never over the raised ground: 2 with
// the look-aheads not cut at the landing; 1 with the cut alone (a toe cutting the box's corner at
// 1/30 s), none since session 29's rules (docs/world.md).
TEST(CourseRuns, AFootStoppingShortOfABoxIsNotRaisedTowardItsTop) {
  int raised_short = 0;
  for (const float dt : {1.0f / 60.0f, 1.0f / 30.0f}) {
    const CourseRun r{"data/levels/course2.glb", "stop-and-go.txt", {39.05, 2.0}, dt};
    float highest[2] = {0.0f, 0.0f};
    bool over_it[2] = {false, false};
    run(r, [&](const EvaluationFrame& frame) {
      for (int side = 0; side < 2; ++side) {
        const float placed = frame.placed_toe_ground[side];
        if (!frame.locked[side]) {
          if (placed - frame.toe_ground[side] > 0.2f)
            highest[side] = std::max(highest[side], placed);
          over_it[side] |= highest[side] > 0.0f && frame.toe_ground[side] > highest[side] - 0.05f;
          continue;
        }
        raised_short += highest[side] > 0.0f && !over_it[side] && placed < highest[side] - 0.05f;
        highest[side] = 0.0f;
        over_it[side] = false;
      }
    });
  }
  EXPECT_EQ(raised_short, 0);
}

// Stop-and-go from x = 39.05 on the tests' database at 1/30 s: the character turns to walk along
// box_35's front face, and a foot swinging along it to land beside the box had its look-ahead
// (the toe's own velocity) reach over the face: its ground rose to the box's top, the foot 47 cm
// over the floor it came down on, its toe swung over the face's edge on the way. A foot in the
// air looks by its own motion no higher than where it lands or the body goes
// (FootPlacement::keep_own_lookahead_to_landings). Counted:
// updates with a toe in the air whose ground is raised more than 25 cm over the ground under it.
TEST(CourseRuns, AFootSwingingAlongABoxToLandBesideItIsNotRaisedOntoItsTop) {
  const CourseRun r{"data/levels/course2.glb", "stop-and-go.txt", {39.05, 2.0}, 0.0333333f};
  int raised = 0;
  run(r, [&](const EvaluationFrame& frame) {
    for (int side = 0; side < 2; ++side) {
      raised +=
          !frame.locked[side] && frame.placed_toe_ground[side] - frame.toe_ground[side] > 0.25f;
    }
  });
  EXPECT_EQ(raised, 0);
}

// Turning on the spot on the second course's stairs_20_25 at 1/144 s: a toe creeping toward the
// landing's riser (its offset decaying toward the animation, half a metre a second) was swept for
// the riser from where it was shown to where the placement had it, a step of the decay behind and
// pointing away from the riser: never held there, its footprint reached the landing's edge and
// the ground under it jumped to the landing's top, 9.6 cm in one update. Swept to where the foot
// lock will show it, from a radius behind (a sphere starting in contact finds nothing), it waits
// at the riser while its ground rises.
TEST(CourseRuns, AToeCreepingToARiserWaitsThereInsteadOfJumpingOntoTheStep) {
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 0.00694444f};
  float previous[2] = {0.0f, 0.0f}, largest = 0.0f;
  bool first = true;
  run(r, [&](const EvaluationFrame& frame) {
    for (int side = 0; side < 2; ++side) {
      if (!first) largest = std::max(largest, frame.placed_toe_ground[side] - previous[side]);
      previous[side] = frame.placed_toe_ground[side];
    }
    first = false;
  });
  EXPECT_LT(largest, 0.05f);
}

// Walking back and forth by stairs_down on the tests' database at 1/30 s: a toe at the tread's
// riser, its ground rising, was locked with its footprint on the tread's edge, 3.6 cm above the
// tread in front of it; its ground fell back the next update and the toe, let go, swung
// over the tread 0.33 cm above it. A lock begins only on a toe whose ground is not rising.
TEST(CourseRuns, AToeIsNotLockedWhileItsGroundRisesOntoAStep) {
  // The time step offlane.sh gives mm eval: at 1/30 s exactly the run takes another way there.
  const CourseRun r{"data/levels/course2.glb", "reversals.txt", {17.45, 2.0}, 0.0333333f};
  const EvaluationMetrics m = run(r);
  EXPECT_GE(m.ground.toe_clearance_cm_min, 1.0);
  EXPECT_EQ(m.ground.foot_penetration_cm_max, 0.0);
}

// Turning on the spot on stairs_20_25's landing at 1/60 s, tests' database: a toe waiting at the
// landing's riser, its ground rising toward the top, had its footprint reach the landing's edge
// for one update: its ground was lifted 4.3 cm onto what was under it, a lift its follower
// answers from rest, so the follower's velocity said the ground was not rising and a lock began 3
// cm below the landing's top (Toes_L 144 m/s^2). The rise that keeps a lock from beginning is
// the ground's whole change over the update. Counted: locks beginning on an update whose toe's
// ground rose more than a centimetre.
TEST(CourseRuns, NoLockBeginsOnTheUpdateAToesGroundIsLiftedOntoAStep) {
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 0.0166667f};
  int lifted_locks = 0;
  bool was_locked[2] = {false, false}, first = true;
  float previous[2] = {0.0f, 0.0f};
  run(r, [&](const EvaluationFrame& frame) {
    for (int side = 0; side < 2; ++side) {
      const float rise = frame.placed_toe_ground[side] - previous[side];
      lifted_locks += !first && frame.locked[side] && !was_locked[side] && rise > 0.01f;
      was_locked[side] = frame.locked[side];
      previous[side] = frame.placed_toe_ground[side];
    }
    first = false;
  });
  EXPECT_EQ(lifted_locks, 0);
}

// The largest horizontal acceleration (m/s^2) of the simulation object over a run.
float largest_simulation_acceleration(const CourseRun& r) {
  double largest = 0.0;
  each_second_difference(
      r,
      [](const EvaluationFrame& frame) {
        return glm::dvec3(frame.origin.x + frame.sim_position.x, 0.0,
                          frame.origin.z + frame.sim_position.z);
      },
      [&](const EvaluationFrame&, double d) { largest = std::max(largest, d); });
  return static_cast<float>(largest / (double(r.dt) * r.dt));
}

// Walking up the first course's stairs and on to its landing's far edge (a ledge), the
// simulation object went on at the stick's speed until the world stopped it, within an update
// (62 m/s^2 at 1/30 s; the root and the swinging toe with it, 110 m/s^2). Where the predicted
// trajectory is blocked it slows down (obstacle_brake.hpp): no harder than it stops on the flat
// plane when the stick is let go.
TEST(CourseRuns, BeforeALedgesEdgeTheCharacterSlowsDownAsOnTheFlat) {
  constexpr float kDt = 1.0f / 30.0f;
  const float on_flat = largest_simulation_acceleration({nullptr, "stop-and-go.txt", {}, kDt});
  const CourseRun r{"data/levels/course.glb", "stop-and-go.txt", {10.0, 3.0}, kDt};
  EXPECT_LT(largest_simulation_acceleration(r), 1.2f * on_flat);
  CourseRun unbraked = r;
  unbraked.settings.obstacle_deceleration = 0.0f;
  EXPECT_GT(largest_simulation_acceleration(unbraked), 3.0f * on_flat);
}

// Strafing across the first course's 20-degree ramp at 1/144 s: a foot locked (planted by its
// height and speed) where the softened leg fell short of its toe, and the heel rose at once to
// the whole lift the held toe needed, 0.43 rad in an update: the ankle swung 4.7 cm about the toe
// (Foot_L 944 m/s^2 at 18.91 s on the tests' database). Beyond kHeelRiseAtOnce the lift a lock
// needs as it begins is taken up with a bounded acceleration.
TEST(CourseRuns, ALockBegunOutOfReachLiftsItsHeelWithoutAJump) {
  const int foot = test::normal_controller_database()->database().roles().left_foot;
  const CourseRun r{"data/levels/course.glb", "strafe.txt", {4.0, 3.0}, 1.0f / 144.0f};
  EXPECT_LT(largest_acceleration(r, foot, 18.8f, 19.0f), 300.0f);
}

// Standing after a stop, a foot the idle clip puts elsewhere steps there (a settling step), and
// the blend into the idle carries it: its lift followed only the lock's offset left to decay,
// millimetres, and the toe slid along the ground at up to 0.5 m/s (reversals from x = 11.5 on
// the second course at 1/144 s: geometric skating 1.12 cm/s against the data's 1.01). It is
// lifted by the way left to where the idle clip puts it now; on the flat plane the showcase at
// 1/144 s skated 0.54 cm/s on the tests' database, now 0.21.
TEST(CourseRuns, ASettlingStepIsLiftedNotSlidAlongTheGround) {
  const EvaluationMetrics m = run({nullptr, "showcase.txt", {}, 1.0f / 144.0f});
  EXPECT_LT(m.ground.foot_skate_geom_cm_s_mean, 0.35);
}

// Running off the second course's ramp_15 onto the floor: each update's foot IK was skipped where
// the toe's target came within 10 micrometres of the animated toe (its ground offset decaying to
// the floor's), and with it the softening of the leg the run stretches near straight: the knee
// dropped 2 cm for an update and came back (569 m/s^2 at 6.91 s on the tests' database, 1,659 on
// the default one). The legs are reached every update.
TEST(CourseRuns, ARunningLegStaysSoftenedAsItsGroundOffsetFades) {
  const int knee = test::normal_controller_database()->database().skeleton().parent(
      test::normal_controller_database()->database().roles().right_foot);
  // The time step as `mm eval --dt 0.00694444` reads it, the run measured.
  const CourseRun r{"data/levels/course2.glb", "walk-run.txt", {0.8, 2.0}, 0.00694444f};
  // The knee's own accelerations around it are about 50 m/s^2.
  EXPECT_LT(largest_acceleration(r, knee, 6.8f, 7.0f), 200.0f);
}

// Walking back and forth over stairs_20_25's landing (0.8 m), a toe the landing's side kept out
// while it stood 0.36 m over the body's ground (a wall: higher than a step) went onto it in one
// update when the body rose a centimetre and it became a step: 11 cm forward (2,441 m/s^2 at
// 9.08 s on the tests' database). What walls push a toe out by now comes back onto the
// animation on a spring, its ground probed where the eased toe is.
TEST(CourseRuns, AToeAWallLetsGoComesBackOnASpring) {
  const int toe = test::normal_controller_database()->database().roles().left_toe;
  const CourseRun r{"data/levels/course2.glb", "reversals.txt", {11.5, 2.0}, 0.00694444f};
  EXPECT_LT(largest_acceleration(r, toe, 8.8f, 9.4f), 600.0f);
}

// Standing before stairs_20_25 with the right foot on its first tread, then walking up: the left
// toe, lifting off a centimetre before the first riser, went on into it and was lifted onto the
// tread in the update it got there (20 cm; 224 m/s^2 at 41.53 s on the tests' database, 176 on
// the default one), after its ground had jumped to the body's, which had climbed more than a
// step above the floor the foot still stood on. The toe now waits at the riser while its ground
// rises, and that floor stays the foot's.
TEST(CourseRuns, AToeLiftingOffBeforeARiserWaitsAtItWhileItRises) {
  const int toe = test::normal_controller_database()->database().roles().left_toe;
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 1.0f / 30.0f};
  EXPECT_LT(largest_acceleration(r, toe, 41.4f, 41.7f), 150.0f);
}

// The same start at 1/60 s: the left toe, released at the riser with its ground already rising
// to the look-ahead's tread, was held again a few centimetres up by the geometric plant (low over
// that raised ground) and came down with it (the knee 232 m/s^2 at 41.38 s on the tests'
// database), then rose on the quick spring of a toe that meets its step at once and was lifted
// the rest of the way onto the tread where the riser's top edge let it go (the toe 210 m/s^2).
// The plant is judged over the ground under the toe now, every toe rises at the bounded
// acceleration, and a toe in the air is lifted only as far as the data's lowest above the tread.
// Let go by the riser, the toe went on with the animation's speed at once (92 m/s^2 at 41.45 s):
// the wall's push, held at rest while it grew, now goes on growing at the rate it did and eases
// back from there.
TEST(CourseRuns, ALegLeavingTheFloorUpStairsRisesWithoutAPop) {
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const int knee =
      test::normal_controller_database()->database().skeleton().parent(roles.left_foot);
  const CourseRun r{"data/levels/course2.glb", "stand-turns.txt", {11.5, 2.0}, 1.0f / 60.0f};
  // The flat data's locomotion p99 at 1/60 s is about 60 m/s^2.
  EXPECT_LT(largest_acceleration(r, knee, 41.2f, 41.7f), 100.0f);
  EXPECT_LT(largest_acceleration(r, roles.left_toe, 41.2f, 41.7f), 80.0f);
}

// Stopping on the first course's stairs landing near its side, the left toe swings out over the
// drop just as the simulation object stops at the edge: the edge kept the toe out as a wall's
// face does, at once, and it moved back 17 cm in an update (450 m/s^2 at 15.0 s on the tests'
// database). It comes back over the edge with a bounded acceleration now; the animation's own
// swing back there is about 100 m/s^2.
TEST(CourseRuns, AToeOutOverALedgesEdgeComesBackWithoutAJump) {
  const JointRoleIndices& roles = test::normal_controller_database()->database().roles();
  const CourseRun r{"data/levels/course.glb", "stop-and-go.txt", {10.0, 3.0}, 1.0f / 60.0f};
  EXPECT_LT(largest_acceleration(r, roles.left_toe, 14.8f, 15.3f), 150.0f);
}

// Walking up the second course's stairs_20_25 (20 cm risers, 25 cm treads, a landing 0.8 m up)
// from standing at its foot, for `seconds`: the steepest the predicted trajectory ever rose
// ahead of the simulation object (m), the lowest playback rate, the time the simulation object
// took to climb from 5 cm to 75 cm, and the rate after standing still on the landing a while.
struct StairClimb {
  float trajectory_rise = 0.0f;
  float lowest_rate = 1.0f;
  float climb_s = 0.0f;
  float rate_standing = 0.0f;
};

StairClimb climb_stairs(const ControllerSettings& settings) {
  constexpr float kDt = 1.0f / 60.0f;
  const BulletWorld world =
      test::course_world(std::filesystem::path(MM_SOURCE_DIR) / "data/levels/course2.glb");
  Controller c = test::make_controller(settings);
  c.set_world(&world);
  c.teleport_world(glm::dvec3(11.5, 0.0, 2.0), 0.0f);
  StairClimb out;
  float started = -1.0f, t = 0.0f;
  for (int f = 0; f < static_cast<int>(4.0f / kDt); ++f, t += kDt) {
    c.update(kDt, test::push_toward(0.0f));
    const ControllerDebug& d = c.debug();
    const float y = d.simulation_position.y;
    if (d.trajectory_count > 0) {
      out.trajectory_rise =
          std::max(out.trajectory_rise,
                   d.predicted_positions[static_cast<size_t>(d.trajectory_count - 1)].y - y);
    }
    out.lowest_rate = std::min(out.lowest_rate, d.playback_rate);
    if (started < 0.0f && y > 0.05f) started = t;
    if (started >= 0.0f && out.climb_s == 0.0f && y > 0.75f) out.climb_s = t - started;
  }
  for (int f = 0; f < static_cast<int>(2.0f / kDt); ++f) c.update(kDt, ControllerInput{});
  out.rate_standing = c.debug().playback_rate;
  return out;
}

// A sample's move through the world climbs one step at most (the capsule is swept lifted by
// step_height), so up a stair the predicted trajectory stopped at the second riser, a tread or
// two ahead: the search matched a stop on every stair. Each move now goes on from the step that
// stopped it (Controller::climb_trajectory). And a stair climbed in the data's flat strides took
// three risers a step, the swinging foot lifted half a metre in a third of a second: up steep
// ground the clip plays slower and the character walks slower by the same rate
// (climb_pace.hpp), no slower than min_playback_rate.
TEST(CourseRuns, UpAStairTheTrajectoryClimbsAndThePaceSlows) {
  const ControllerSettings defaults;
  const StairClimb paced = climb_stairs(defaults);
  // Past the second riser: more than a step above the simulation object.
  EXPECT_GT(paced.trajectory_rise, defaults.step_height);
  EXPECT_NEAR(paced.lowest_rate, defaults.min_playback_rate, 0.05f);
  EXPECT_GT(paced.climb_s, 0.0f);  // the flight climbed
  EXPECT_GT(paced.rate_standing, 0.99f);

  ControllerSettings unpaced = defaults;
  unpaced.max_climb_speed = 0.0f;  // no limit
  const StairClimb fast = climb_stairs(unpaced);
  EXPECT_EQ(fast.lowest_rate, 1.0f);
  EXPECT_GT(fast.trajectory_rise, defaults.step_height);
  ASSERT_GT(fast.climb_s, 0.0f);
  EXPECT_GT(paced.climb_s, 1.5f * fast.climb_s);
}

}  // namespace
}  // namespace mm
