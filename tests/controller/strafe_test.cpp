// Strafing (issue 17): the data has no side steps, so a strafe plays clips whose body faces
// more or less where it walks; the chest still faces the requested facing.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm {
namespace {

// Running strafes in every direction while facing forward, at every rate: the chest's facing
// error (the evaluation's strafe_chest_error_deg_mean) stays small (the clips alone leave it
// near 10 degrees), the root stays with the simulation and the new speed is reached soon.
TEST(StrafeTest, TheChestFacesTheFacingWhileRunningSideways) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/strafe-run.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    EvaluationOptions options;
    options.dt = dt;
    Result<EvaluationResult> run =
        evaluate_script(test::normal_controller_database(), *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    EXPECT_GT(run->metrics.strafe_chest_error_deg_mean, 0.0) << "dt " << dt;  // measured at all
    EXPECT_LT(run->metrics.strafe_chest_error_deg_mean, 5.0) << "dt " << dt;
    EXPECT_LE(run->metrics.root_sim_distance_cm_mean, 8.0) << "dt " << dt;
    EXPECT_LE(run->metrics.speed_response_s, 0.8) << "dt " << dt;
  }
}

// Running backward and to one side while facing forward, the legs turn the other way from the
// travel, toward straight backward, not toward the travel. The root then stays with the
// simulation; with the legs unturned it trails by a quarter of a metre.
struct BackDiagonal {
  float root_distance = 0.0f;  // m, mean over the last 4 s
  float sim_yaw = 0.0f;        // the simulation's facing at the end
  float travel_yaw = 0.0f;     // the desired velocity's direction
};

BackDiagonal run_back_diagonal(const ControllerSettings& settings) {
  Controller c = test::make_controller(settings);
  const float dt = 1.0f / 60.0f;
  ControllerInput input = test::push_toward(0.0f, true);
  input.facing_yaw = 0.0f;  // facing +Z throughout
  for (int i = 0; i < 120; ++i) c.update(dt, input);
  input.left_stick = test::push_toward(135.0f, true).left_stick;  // back and to one side
  BackDiagonal out;
  for (int i = 0; i < 300; ++i) {
    c.update(dt, input);
    const glm::vec3 away = c.root_transform().translation - c.debug().simulation_position;
    if (i >= 60) out.root_distance += std::hypot(away.x, away.z) / 240.0f;
  }
  out.sim_yaw = quat_yaw(c.debug().simulation_rotation);
  out.travel_yaw = std::atan2(c.debug().desired_velocity.x, c.debug().desired_velocity.z);
  return out;
}

TEST(StrafeTest, BackwardDiagonalsTurnTheLegsTowardStraightBack) {
  const ControllerSettings defaults;
  const BackDiagonal warped = run_back_diagonal(defaults);
  ASSERT_GT(std::abs(warped.travel_yaw), glm::radians(120.0f));
  const float straight_back = wrap_angle(warped.travel_yaw + glm::pi<float>());
  EXPECT_NEAR(wrap_angle(warped.sim_yaw),
              std::clamp(straight_back, -defaults.strafe_warp_max, defaults.strafe_warp_max),
              glm::radians(2.0f));
  EXPECT_LT(warped.root_distance, 0.05f);
  ControllerSettings off;
  off.strafe_warp_max = 0.0f;
  const BackDiagonal unwarped = run_back_diagonal(off);
  EXPECT_NEAR(wrap_angle(unwarped.sim_yaw), 0.0f, glm::radians(2.0f));
  EXPECT_GT(unwarped.root_distance, 0.15f);
}

// Standing, the simulation object comes to where the character stopped. The data has no stops:
// after a running strafe the character stands well away from where the simulation did, and a
// standing character is never slid toward it.
float distance_after_stopping(const ControllerSettings& settings) {
  Controller c = test::make_controller(settings);
  ControllerInput input = test::push_toward(180.0f, true);  // run backward
  input.facing_yaw = 0.0f;
  const float dt = 1.0f / 60.0f;
  for (int i = 0; i < 120; ++i) c.update(dt, input);
  for (int i = 0; i < 180; ++i) c.update(dt, ControllerInput{});
  const glm::vec3 away = c.root_transform().translation - c.debug().simulation_position;
  return std::hypot(away.x, away.z);
}

TEST(StrafeTest, StandingTheSimulationComesToTheCharacter) {
  ControllerSettings held;
  held.simulation_yield_standing_speed = 0.0f;
  const float stays = distance_after_stopping(held);
  const float closes = distance_after_stopping({});
  EXPECT_GT(stays, 0.05f);
  EXPECT_LT(closes, 0.01f);
}

// A facing given through the API (ControllerInput::facing_yaw) while walking: the character
// keeps facing it as when strafing, whatever the stick's direction (the chest on it, the legs
// and root warped toward the travel by strafe_warp_max); an absurd but finite yaw is taken
// modulo a turn.
TEST(StrafeTest, AFacingGivenThroughTheApiIsKeptWhileWalking) {
  Controller c = test::make_controller();
  ControllerInput input = test::push_toward(90.0f);  // walk toward +X
  input.facing_yaw = 0.0f;                           // facing +Z
  const float dt = 1.0f / 60.0f;
  for (int i = 0; i < 240; ++i) c.update(dt, input);
  const ControllerSettings defaults;
  EXPECT_NEAR(wrap_angle(quat_yaw(c.root_transform().rotation)), defaults.strafe_warp_max,
              glm::radians(15.0f));
  EXPECT_LT(std::abs(wrap_angle(test::chest_yaw(c))), glm::radians(10.0f));
  EXPECT_GT(c.root_transform().translation.x, 1.0f);  // and it went where the stick said

  input.facing_yaw = 1e30f;
  for (int i = 0; i < 60; ++i) c.update(dt, input);
  for (const Transform& t : c.global_transforms()) {
    ASSERT_TRUE(std::isfinite(t.translation.x + t.translation.y + t.translation.z));
  }
}

// Sideways from standing, with no side steps in the data and no orientation warping to serve
// them from forward walks: the character still gets going. (The simulation object, yielding to
// a character that did not follow at any speed, once held it beside the character, and nothing
// moved.)
float side_step_distance(ControllerSettings settings) {
  settings.strafe_warp_max = 0.0f;
  Controller c = test::make_controller(settings);
  const float dt = 1.0f / 60.0f;
  for (int i = 0; i < 60; ++i) c.update(dt, ControllerInput{});
  ControllerInput input = test::push_toward(90.0f);  // toward +X
  input.facing_yaw = 0.0f;                           // facing +Z
  const float start = c.root_transform().translation.x;
  for (int i = 0; i < 240; ++i) c.update(dt, input);
  return c.root_transform().translation.x - start;
}

TEST(StrafeTest, ASideStepFromStandingGetsGoing) {
  // Of the 2.4 m that 4 s at the data's sideways walking speed would give: it starts slowly and
  // goes at the pace the clamp drags it (see docs/controller.md, Known limits).
  EXPECT_GT(side_step_distance({}), 1.0f);
  ControllerSettings unbounded_yield;
  unbounded_yield.simulation_yield_max_velocity_ratio = 1000.0f;
  EXPECT_LT(side_step_distance(unbounded_yield), 0.5f);
}

// Orientation warping: the shipped strafes reach the new speed sooner and keep the root nearer
// the simulation than without it, and reach it within 0.8 s.
TEST(StrafeTest, OrientationWarpingServesStrafesFromForwardWalks) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/strafe.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  EvaluationMetrics metrics[2];
  for (const bool warp : {true, false}) {
    EvaluationOptions options;
    if (!warp) options.settings.strafe_warp_max = 0.0f;
    Result<EvaluationResult> run =
        evaluate_script(test::normal_controller_database(), *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    metrics[warp ? 0 : 1] = run->metrics;
  }
  EXPECT_LE(metrics[0].speed_response_s, 0.8);
  EXPECT_GT(metrics[1].speed_response_s, metrics[0].speed_response_s);
  EXPECT_LT(metrics[0].root_sim_distance_cm_mean, metrics[1].root_sim_distance_cm_mean);
  EXPECT_LT(metrics[0].strafe_chest_error_deg_mean, 5.0);  // the chest still on the facing
}

}  // namespace
}  // namespace mm
