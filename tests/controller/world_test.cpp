// The controller in a world (issue 28; world.hpp, controller_world.cpp): walls stop and slide the
// simulation object, its trajectory and the root; the body follows ramps and stairs; a flat
// world changes nothing; garbage answers never poison the state. On the Bandai normal database,
// with the analytic test world (tests/support/analytic_world.hpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "analytic_world.hpp"
#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/runtime/finite.hpp"

namespace mm {
namespace {

using test::AnalyticBox;
using test::AnalyticWorld;
using test::make_controller;
using test::push_toward;

constexpr float kDt = 1.0f / 60.0f;

// A tall wall whose near face is the plane z = `face`.
AnalyticBox wall_across_z(float face) {
  return AnalyticBox{glm::vec2(0.0f, face + 0.2f), glm::vec2(30.0f, 0.2f), 0.0f, 3.0f};
}

float hips_height(const Controller& c) {
  const Database& db = c.controller_database().database();
  return c.global_transforms()[static_cast<size_t>(db.roles().hips)].translation.y;
}

// Whether the controller plays a clip tagged idle.
bool playing_idle(const Controller& c) {
  const Database& db = c.controller_database().database();
  const std::string idle[] = {"idle"};
  return c.debug().clip >= 0 &&
         (db.clips()[static_cast<size_t>(c.debug().clip)].tags & db.tag_mask(idle)) != 0;
}

TEST(ControllerWorld, AFlatWorldMovesTheCharacterExactlyAsNoWorld) {
  AnalyticWorld flat;
  Controller plain = make_controller();
  Controller in_world = make_controller();
  in_world.set_world(&flat);
  for (int f = 0; f < 600; ++f) {
    const ControllerInput input = push_toward(f < 300 ? 0.0f : 120.0f, f > 400);
    plain.update(kDt, input);
    in_world.update(kDt, input);
  }
  const auto a = plain.global_transforms();
  const auto b = in_world.global_transforms();
  for (size_t j = 0; j < a.size(); ++j) {
    EXPECT_EQ(a[j].translation, b[j].translation) << j;
    EXPECT_EQ(a[j].rotation, b[j].rotation) << j;
  }
  EXPECT_GT(flat.probe_calls.load(), 0);
  EXPECT_LE(flat.probe_calls.load() + flat.sweep_calls.load(), 600 * kMaxWorldCallsPerUpdate);
}

// The debug drawing's landing (ControllerDebug::foot_landing): walking on, each foot in the air
// shows where the playing clip puts it down, and the lock that holds it there begins within 10 cm
// of the last one shown; a held foot shows none.
TEST(ControllerWorld, AFootInTheAirShowsWhereItLands) {
  AnalyticWorld flat;
  Controller c = make_controller();
  c.set_world(&flat);
  glm::vec3 shown[2] = {};
  bool any_shown[2] = {false, false}, was_locked[2] = {false, false};
  int locks = 0, near = 0;
  for (int f = 0; f < 6 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    const ControllerDebug& d = c.debug();
    for (int side = 0; side < 2; ++side) {
      // Held since the update before (the placement runs before this update's lock).
      if (d.locked[side] && was_locked[side]) {
        EXPECT_FALSE(d.foot_lands[side]) << f;
      }
      if (d.locked[side] && !was_locked[side] && any_shown[side] && f > 60) {
        ++locks;
        const glm::vec3 held = d.lock_position[side];
        near += std::hypot(held.x - shown[side].x, held.z - shown[side].z) < 0.1f ? 1 : 0;
      }
      was_locked[side] = d.locked[side];
      if (d.foot_lands[side]) shown[side] = d.foot_landing[side];
      any_shown[side] |= d.foot_lands[side];
    }
  }
  EXPECT_GE(locks, 6);
  EXPECT_GE(near, locks - 1) << near << " of " << locks;
}

TEST(ControllerWorld, HeadOnIntoAWallTheCharacterStopsBeforeItAndStands) {
  AnalyticWorld world;
  world.boxes.push_back(wall_across_z(4.0f));
  Controller c = make_controller();
  c.set_world(&world);
  const float limit = 4.0f - c.settings().character_radius + 1e-3f;
  std::vector<float> root_z;
  for (int f = 0; f < 8 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    const ControllerDebug& d = c.debug();
    ASSERT_LE(d.simulation_position.z, limit) << f;
    ASSERT_LE(c.root_transform().translation.z, limit) << f;
    for (int i = 0; i < d.trajectory_count; ++i) ASSERT_LE(d.predicted_positions[i].z, limit) << f;
    root_z.push_back(c.root_transform().translation.z);
  }
  // It got to the wall, and for the last two seconds has stood there, the stick still pushing,
  // playing the idle: not a walk's first steps over and over.
  EXPECT_GT(root_z.back(), limit - 0.3f);
  const auto last = root_z.end() - 120;
  EXPECT_LT(*std::max_element(last, root_z.end()) - *std::min_element(last, root_z.end()), 0.05f);
  EXPECT_TRUE(playing_idle(c));
}

// Standing at a wall is for a stick held head-on into it: turned along the wall, the character
// walks along it at once; swept to and fro across the wall's normal (a circle passing a wall),
// it never stands (standing at once, the circle script flickered into the idle for 4 frames).
TEST(ControllerWorld, AtAWallTheCharacterStandsOnlyWhileTheStickHoldsItHeadOn) {
  AnalyticWorld world;
  world.boxes.push_back(wall_across_z(2.0f));
  Controller c = make_controller();
  c.set_world(&world);
  for (int f = 0; f < 4 * 60; ++f) c.update(kDt, push_toward(0.0f));
  ASSERT_TRUE(playing_idle(c));
  // Along the wall: walking within a second, and 2 s on, a metre along.
  const float x = c.root_transform().translation.x;
  int idle_after_a_second = 0;
  for (int f = 0; f < 3 * 60; ++f) {
    c.update(kDt, push_toward(80.0f));
    if (f >= 60 && playing_idle(c)) ++idle_after_a_second;
  }
  EXPECT_EQ(idle_after_a_second, 0);
  EXPECT_GT(std::abs(c.root_transform().translation.x - x), 1.0f);
  // To and fro across the wall's normal, 60 degrees either side at 240 degrees a second.
  int idle = 0;
  for (int f = 0; f < 4 * 60; ++f) {
    const float phase = std::fmod(f * kDt * 240.0f, 240.0f);
    c.update(kDt, push_toward(phase < 120.0f ? phase - 60.0f : 180.0f - phase));
    if (playing_idle(c)) ++idle;
  }
  EXPECT_EQ(idle, 0);
}

// The capsule keeps the root a radius from the wall, but the arms swing and an idle's hands may
// hang farther forward: the upper body is kept out of the wall, at every rate.
TEST(ControllerWorld, HeadOnAtAWallNoJointAboveTheHipsGoesIntoIt) {
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    AnalyticWorld world;
    world.boxes.push_back(wall_across_z(4.0f));
    Controller c = make_controller();
    // A thin capsule, so that the arms surely reach the wall (the legs are the capsule's to
    // keep out).
    ControllerSettings settings = c.settings();
    settings.character_radius = 0.15f;
    ASSERT_TRUE(c.set_settings(settings).ok());
    c.set_world(&world);
    const int frames = static_cast<int>(7.0f / dt);
    float deepest = -1.0f;
    for (int f = 0; f < frames; ++f) {
      // Walking into it, then standing there.
      c.update(dt, f * dt < 4.0f ? push_toward(0.0f) : ControllerInput{});
      const float hips = hips_height(c);
      for (const Transform& joint : c.global_transforms()) {
        if (joint.translation.y > hips) deepest = std::max(deepest, joint.translation.z - 4.0f);
      }
    }
    EXPECT_LT(deepest, 0.005f) << "dt " << dt;
    // It did come close: a hand within 15 cm of the wall.
    EXPECT_GT(deepest, -0.15f) << "dt " << dt;
  }
}

TEST(ControllerWorld, DiagonallyIntoAWallTheCharacterWalksAlongIt) {
  AnalyticWorld world;
  const float yaw = glm::radians(30.0f);
  // A wall 30 degrees off +Z, 1 m to the right of the start: pushing along +Z meets it.
  world.boxes.push_back(AnalyticBox{glm::vec2(-1.2f, 0.0f), glm::vec2(0.2f, 40.0f), yaw, 3.0f});
  Controller c = make_controller();
  c.set_world(&world);
  const glm::vec3 tangent(std::sin(yaw), 0.0f, std::cos(yaw));
  const glm::vec3 start = c.root_transform().translation;
  int blocked = 0;
  glm::vec3 facing(0.0f);  // summed over the last 2 s: a stride swings it a few degrees
  for (int f = 0; f < 10 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    blocked += c.debug().simulation_blocked ? 1 : 0;
    if (f >= 8 * 60) facing += c.root_transform().rotation * glm::vec3(0.0f, 0.0f, 1.0f);
  }
  // It met the wall (and, walking along it, kept meeting it now and then) and kept walking
  // along it: about 10 s at walking speed times cos(30).
  EXPECT_GT(blocked, 20);
  const float along = glm::dot(c.root_transform().translation - start, tangent);
  EXPECT_GT(along, 6.0f);
  // Facing along the wall, not into it: the stick's facing would put the leading arm through
  // the wall at every swing.
  EXPECT_GT(glm::dot(glm::normalize(glm::vec3(facing.x, 0.0f, facing.z)), tangent),
            std::cos(glm::radians(8.0f)));
}

TEST(ControllerWorld, UpARampTheBodyStandsOnTheSurface) {
  AnalyticWorld world;
  const double slope = std::tan(glm::radians(15.0));
  world.height = [=](double, double z) { return std::clamp(z - 2.0, 0.0, 6.0) * slope; };
  Controller c = make_controller();
  c.set_world(&world);
  Controller flat = make_controller();
  float worst = 0.0f;
  // 11 s: up a 15 degree ramp the walk slows to climb at max_climb_speed (climb_pace.hpp).
  for (int f = 0; f < 11 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    flat.update(kDt, push_toward(0.0f));
    const glm::vec3 root = c.root_transform().translation;
    const float surface = static_cast<float>(world.surface(root.x, root.z));
    if (f > 60) worst = std::max(worst, std::abs(c.debug().ground_height - surface));
  }
  // The ground height under the root on its spring lags the slope by a few centimetres at most.
  EXPECT_LT(worst, 0.05f);
  const glm::vec3 root = c.root_transform().translation;
  EXPECT_GT(root.z, 8.0f);  // up on the plateau
  EXPECT_NEAR(root.y, 6.0 * slope, 0.02);
  // The hips stand as high above the plateau as they do above the flat ground.
  EXPECT_NEAR(hips_height(c) - root.y, hips_height(flat), 0.1f);
}

TEST(ControllerWorld, UpStairsTheHipsRiseWithoutPopping) {
  AnalyticWorld world;
  // 12 steps of 17 cm risers and 30 cm treads from z = 2.
  for (int i = 0; i < 12; ++i) {
    world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 2.0f + 0.3f * i + 4.0f),
                                      glm::vec2(3.0f, 4.0f), 0.0f, 0.17f * (i + 1)});
  }
  Controller c = make_controller();
  c.set_world(&world);
  std::vector<float> heights;
  // 16 s: 6 m to the stair, and up it at the climbing pace (climb_pace.hpp).
  for (int f = 0; f < 16 * 60; ++f) {
    c.update(kDt, push_toward(0.0f));
    heights.push_back(hips_height(c));
  }
  // At the top (12 x 17 cm), and every frame's rise no more than a spring allows: a snap of one
  // riser would be 17 cm in a frame.
  EXPECT_NEAR(c.debug().ground_height, 12 * 0.17f, 0.02f);
  float largest_step = 0.0f;
  for (size_t f = 1; f < heights.size(); ++f) {
    largest_step = std::max(largest_step, std::abs(heights[f] - heights[f - 1]));
  }
  EXPECT_LT(largest_step, 0.05f);
}

TEST(ControllerWorld, GarbageAnswersNeverPoisonTheController) {
  AnalyticWorld world;
  world.garbage = true;
  Controller c = make_controller();
  c.set_world(&world);
  for (int f = 0; f < 120; ++f) c.update(kDt, push_toward(45.0f));
  for (const Transform& t : c.global_transforms()) {
    ASSERT_TRUE(finite(t.translation));
    ASSERT_TRUE(finite(t.rotation));
  }
  EXPECT_GT(c.debug().world_rejected, 120);
  // With no ground it can stand on, the simulation object stays where it was placed.
  EXPECT_EQ(c.debug().simulation_position, glm::vec3(0.0f));
}

TEST(ControllerWorld, TheWorldSettingsAreCheckedAndSetByName) {
  ControllerSettings settings;
  ASSERT_TRUE(set_controller_setting(settings, "step_height", "0.2").ok());
  EXPECT_EQ(settings.step_height, 0.2f);
  ASSERT_TRUE(set_controller_setting(settings, "character_radius", "1").ok());
  const Status refused = settings.validate();
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.message(),
            "controller settings: character_height must be at least twice character_radius (a "
            "capsule), found 1.700000 and 1.000000");
  settings = ControllerSettings{};
  settings.max_slope = 2.0f;
  EXPECT_EQ(settings.validate().message(),
            "controller settings: max_slope must be a number in [0.000000, 1.500000], found "
            "2.000000");
}

}  // namespace
}  // namespace mm

namespace mm {
namespace {

// mm eval's metrics in a world (ground_metrics.hpp): measured against the world's ground, they
// read on a level what they read on the flat plane where the level is flat.
TEST(ControllerWorldEvaluation, TheGroundMetricsReadTheWorldsGround) {
  const auto shared = test::normal_controller_database();
  InputScript script(
      {ScriptEvent{0.0f, push_toward(0.0f), ""}, ScriptEvent{8.0f, ControllerInput{}, ""}});
  EvaluationOptions flat_options;
  flat_options.seconds = 10.0f;
  const Result<EvaluationResult> flat = evaluate_script(shared, script, flat_options);
  ASSERT_TRUE(flat.ok()) << flat.message();

  AnalyticWorld raised;  // the same flat ground, a metre up
  raised.height = [](double, double) { return 1.0; };
  EvaluationOptions options = flat_options;
  options.world = &raised;
  const Result<EvaluationResult> up = evaluate_script(shared, script, options);
  ASSERT_TRUE(up.ok()) << up.message();
  const GroundMetrics& a = flat->metrics.ground;
  const GroundMetrics& b = up->metrics.ground;
  EXPECT_NEAR(b.hips_height_cm_mean, a.hips_height_cm_mean, 0.5);
  EXPECT_NEAR(b.toe_clearance_cm_min, a.toe_clearance_cm_min, 0.5);
  EXPECT_NEAR(b.foot_skate_geom_cm_s_mean, a.foot_skate_geom_cm_s_mean, 0.5);
  EXPECT_GT(a.hips_height_cm_mean, 70.0);
  EXPECT_EQ(b.wall_depth_cm_max, 0.0);
  EXPECT_EQ(b.stuck_s, 0.0);

  AnalyticWorld walled;
  walled.boxes.push_back(wall_across_z(4.0f));
  options.world = &walled;
  const Result<EvaluationResult> wall = evaluate_script(shared, script, options);
  ASSERT_TRUE(wall.ok()) << wall.message();
  // Head-on there is nothing to slide along: never stuck; and no joint more than 2 cm into the
  // wall.
  EXPECT_EQ(wall->metrics.ground.stuck_s, 0.0);
  EXPECT_LT(wall->metrics.ground.wall_depth_cm_max, 2.0);

  // Pushed diagonally into a concave corner (this wall and one whose face is x = 2): the slide
  // along either wall meets the other, so the character standing there is not stuck where it
  // could have slid.
  AnalyticWorld corner;
  corner.boxes.push_back(wall_across_z(4.0f));
  corner.boxes.push_back(AnalyticBox{glm::vec2(2.2f, 0.0f), glm::vec2(0.2f, 30.0f), 0.0f, 3.0f});
  InputScript into_corner(
      {ScriptEvent{0.0f, push_toward(45.0f), ""}, ScriptEvent{8.0f, ControllerInput{}, ""}});
  options.world = &corner;
  const Result<EvaluationResult> cornered = evaluate_script(shared, into_corner, options);
  ASSERT_TRUE(cornered.ok()) << cornered.message();
  // (Creeping into the corner's last centimetres, a frame may be slower than kStuckSpeed with
  // a little room left along the wall: at most a frame or two of the 8 s push.)
  EXPECT_LT(cornered->metrics.ground.stuck_s, 0.05);
  EXPECT_LT(cornered->metrics.ground.wall_depth_cm_max, 2.0);
  // Along the z wall alone (no corner), the same push slides: not stuck either.
  options.world = &walled;
  const Result<EvaluationResult> along = evaluate_script(shared, into_corner, options);
  ASSERT_TRUE(along.ok()) << along.message();
  EXPECT_EQ(along->metrics.ground.stuck_s, 0.0);

  // A wall through the character where it stands (farther in than the body is ever moved back
  // from a wall): the depth is seen.
  AnalyticWorld through;
  through.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 0.2f), glm::vec2(2.0f, 0.3f), 0.0f, 3.0f});
  options.world = &through;
  const Result<EvaluationResult> inside = evaluate_script(shared, script, options);
  ASSERT_TRUE(inside.ok()) << inside.message();
  EXPECT_GT(inside->metrics.ground.wall_depth_cm_max, 2.0);
}

// stop-and-go beside a wall turned 60 degrees (the second course's wall_60, as in
// data/levels/course2.glb), on a thinner capsule than the default: standing at the wall side on,
// a swinging hand reaches farther past its face than the body is ever moved back (kMaxWallPush).
// The arm is swung out about the upper arm (arm_off_wall.hpp) instead, a centimetre clear of the
// face.
TEST(ControllerWorldEvaluation, BesideATurnedWallTheHandsStayOutOfIt) {
  const auto shared = test::normal_controller_database();
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/stop-and-go.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  // Its face from (24.8, 4) to (28.26, 6), 0.3 m thick behind it.
  const float yaw = glm::radians(60.0f);
  const glm::vec2 along(std::sin(yaw), std::cos(yaw));
  const glm::vec2 normal(std::cos(yaw), -std::sin(yaw));
  AnalyticWorld world;
  world.boxes.push_back(AnalyticBox{glm::vec2(24.8f, 4.0f) + 2.0f * along - 0.15f * normal,
                                    glm::vec2(0.15f, 2.0f), yaw, 2.0f});
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f}) {
    EvaluationOptions options;
    options.dt = dt;
    options.world = &world;
    options.start = glm::dvec2(25.8, 2.0);
    options.settings.character_radius = 0.15f;
    const Result<EvaluationResult> run = evaluate_script(shared, *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    // The metric's sphere (1 cm) reads a joint on the face as 1 cm in.
    EXPECT_LT(run->metrics.ground.wall_depth_cm_max, 1.0) << "dt " << dt;
  }
}

}  // namespace
}  // namespace mm
