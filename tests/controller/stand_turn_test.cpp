// Turning on the spot (issue 17): the stick released, the facing set by the right stick while
// strafing. The hips turn at a natural rate, the turn finishes on the requested facing in about
// the time a person takes, and the feet step (lift and land) rather than pivot on the ground.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"

namespace mm {
namespace {

using test::hips_yaw;
using test::normal_controller_database;
using test::push_toward;

float yaw_error_degrees(float a, float b) {
  return std::abs(glm::degrees(wrap_angle(a - b)));
}

struct StandTurn {
  float settle_seconds = -1.0f;  // from the request until the hips stay within 5 degrees
  float final_error_degrees = 0.0f;
  float peak_rate_degrees = 0.0f;  // the hips' largest yaw rate, frame to frame
  float lift[2] = {0.0f, 0.0f};    // each toe's highest rise above where it stood (m)
  int stepping_frames = 0;         // frames with a foot out of contact
  // How far each foot ends up turned against the hips, beyond how it stood before the turn
  // (degrees): a foot left planted at its old heading twists the leg above it.
  float foot_twist_degrees[2] = {0.0f, 0.0f};
  // Each leg's hip-to-ankle distance over its length on the last frame: 1 is straight.
  float extension[2] = {0.0f, 0.0f};
};

// The yaw of a foot's foot-to-toe line relative to the hips' yaw.
float foot_yaw_to_hips(const Controller& c, int foot, int toe) {
  const std::span<const Transform> g = c.global_transforms();
  const glm::vec3 along =
      g[static_cast<size_t>(toe)].translation - g[static_cast<size_t>(foot)].translation;
  return wrap_angle(std::atan2(along.x, along.z) - hips_yaw(c));
}

// How a turn on the spot is asked for.
enum class Request { RightStick, Api };

// Stands for a second facing +Z, then asks for the facing `degrees` away (positive: toward +X)
// and holds it for `seconds`.
StandTurn turn_on_the_spot(float degrees, float dt, float seconds = 3.0f,
                           const ControllerSettings& settings = {},
                           Request request = Request::RightStick) {
  Result<Controller> made = Controller::create(normal_controller_database(), settings);
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.message());
  Controller c = std::move(made).value();
  const Database& db = c.controller_database().database();
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  const int feet[2] = {db.roles().left_foot, db.roles().right_foot};
  const int settle_frames = static_cast<int>(std::lround(1.0f / dt));
  for (int i = 0; i < settle_frames; ++i) c.update(dt, ControllerInput{});

  const float goal = glm::radians(degrees);
  ControllerInput input;
  if (request == Request::Api) {
    input.facing_yaw = goal;
  } else {
    input.strafe = true;
    input.right_stick = push_toward(degrees).left_stick;
  }
  StandTurn turn;
  float planted[2];
  float stance[2];
  for (int side = 0; side < 2; ++side) {
    planted[side] = c.global_transforms()[static_cast<size_t>(toes[side])].translation.y;
    stance[side] = foot_yaw_to_hips(c, feet[side], toes[side]);
  }
  float previous_yaw = hips_yaw(c);
  const int frames = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < frames; ++i) {
    c.update(dt, input);
    const float yaw = hips_yaw(c);
    turn.peak_rate_degrees =
        std::max(turn.peak_rate_degrees, yaw_error_degrees(yaw, previous_yaw) / dt);
    previous_yaw = yaw;
    const float error = yaw_error_degrees(yaw, goal);
    if (error > 5.0f) {
      turn.settle_seconds = -1.0f;
    } else if (turn.settle_seconds < 0.0f) {
      turn.settle_seconds = static_cast<float>(i + 1) * dt;
    }
    turn.final_error_degrees = error;
    for (int side = 0; side < 2; ++side) {
      const float height = c.global_transforms()[static_cast<size_t>(toes[side])].translation.y;
      turn.lift[side] = std::max(turn.lift[side], height - planted[side]);
      if (!c.debug().contact[side]) ++turn.stepping_frames;
    }
  }
  for (int side = 0; side < 2; ++side) {
    turn.foot_twist_degrees[side] =
        yaw_error_degrees(foot_yaw_to_hips(c, feet[side], toes[side]), stance[side]);
    const std::span<const Transform> g = c.global_transforms();
    const int knee = db.skeleton().parents()[static_cast<size_t>(feet[side])];
    const int hip = db.skeleton().parents()[static_cast<size_t>(knee)];
    const glm::vec3 h = g[static_cast<size_t>(hip)].translation;
    const glm::vec3 k = g[static_cast<size_t>(knee)].translation;
    const glm::vec3 a = g[static_cast<size_t>(feet[side])].translation;
    turn.extension[side] = glm::length(a - h) / (glm::length(k - h) + glm::length(a - k));
  }
  return turn;
}

void expect_natural_turn(float degrees, float dt, float settle_limit,
                         Request request = Request::RightStick) {
  const StandTurn turn = turn_on_the_spot(degrees, dt, 3.0f, {}, request);
  SCOPED_TRACE(testing::Message() << degrees << " degrees at dt " << dt);
  EXPECT_GT(turn.settle_seconds, 0.0f) << "never settled; final error " << turn.final_error_degrees;
  EXPECT_LE(turn.settle_seconds, settle_limit);
  EXPECT_LE(turn.final_error_degrees, 5.0f);
  EXPECT_LT(turn.peak_rate_degrees, 400.0f);
  // The feet step: each toe rises clear of the ground at least once.
  EXPECT_GT(turn.lift[0], 0.02f);
  EXPECT_GT(turn.lift[1], 0.02f);
  EXPECT_GT(turn.stepping_frames, 0);
  // And they come round with the body: no leg is left twisted (crossed shins) once it stands.
  EXPECT_LT(turn.foot_twist_degrees[0], 20.0f);
  EXPECT_LT(turn.foot_twist_degrees[1], 20.0f);
}

// A quarter turn in about 0.8 s and a half turn in about 1.2 s, both ways (a half turn of
// exactly 180 degrees may go either way, so the half turns stop a degree short of it).
TEST(StandTurnTest, QuarterTurnsBothWays) {
  expect_natural_turn(90.0f, 1.0f / 60.0f, 1.0f);
  expect_natural_turn(-90.0f, 1.0f / 60.0f, 1.0f);
}

TEST(StandTurnTest, HalfTurnsBothWays) {
  expect_natural_turn(179.0f, 1.0f / 60.0f, 1.4f);
  expect_natural_turn(-179.0f, 1.0f / 60.0f, 1.4f);
}

TEST(StandTurnTest, FrameRateDoesNotChangeTheTurn) {
  expect_natural_turn(179.0f, 1.0f / 30.0f, 1.4f);
  expect_natural_turn(-90.0f, 1.0f / 144.0f, 1.0f);
}

// ControllerInput::facing_yaw asks for the same turn without the sticks.
TEST(StandTurnTest, AFacingGivenThroughTheApiTurnsTheSameWay) {
  expect_natural_turn(90.0f, 1.0f / 60.0f, 1.0f, Request::Api);
  expect_natural_turn(-179.0f, 1.0f / 60.0f, 1.4f, Request::Api);
}

TEST(StandTurnTest, SettingsAreValidatedAndSetByName) {
  ControllerSettings s;
  EXPECT_TRUE(set_controller_setting(s, "stand_turn_max_rate", "4").ok());
  EXPECT_FLOAT_EQ(s.stand_turn_max_rate, 4.0f);
  EXPECT_TRUE(set_controller_setting(s, "stand_turn_acceleration", "12.5").ok());
  EXPECT_FLOAT_EQ(s.stand_turn_acceleration, 12.5f);
  EXPECT_TRUE(s.validate().ok());
  s.stand_turn_acceleration = 0.0f;
  EXPECT_NE(s.validate().message().find("stand_turn_acceleration"), std::string::npos);
  s = {};
  s.stand_turn_max_rate = std::nanf("");
  EXPECT_NE(s.validate().message().find("stand_turn_max_rate"), std::string::npos);
}

// Standing after the turn, the feet are planted where the idle pose puts them (within a step's
// threshold), so the legs keep the pose's own extension: foot IK must not bend knees the data
// holds straight (both knees bent forward read as crossed shins).
TEST(StandTurnTest, StandingLegsKeepThePosesExtension) {
  ControllerSettings no_ik;
  no_ik.ik_enabled = false;
  const float dt = 1.0f / 60.0f;
  for (const float degrees : {179.0f, -90.0f}) {
    const StandTurn with_ik = turn_on_the_spot(degrees, dt);
    const StandTurn animated = turn_on_the_spot(degrees, dt, 3.0f, no_ik);
    for (int side = 0; side < 2; ++side) {
      SCOPED_TRACE(testing::Message() << degrees << " degrees, side " << side);
      EXPECT_NEAR(with_ik.extension[side], animated.extension[side], 0.002f);
    }
  }
}

// The limit is what keeps the hips natural: without it the same turn is too fast, so the test
// above can tell.
TEST(StandTurnTest, AnUnboundedTurnIsTooFast) {
  ControllerSettings fast;
  fast.stand_turn_max_rate = 100.0f;
  fast.stand_turn_acceleration = 1000.0f;
  fast.body_max_turn_rate = 0.0f;  // no limit: the body would hold the turn to its own
  EXPECT_GT(turn_on_the_spot(90.0f, 1.0f / 60.0f, 3.0f, fast).peak_rate_degrees, 400.0f);
}

// Under any input (issue 29): the shipped scripts of turns on the spot, one calm and one whose
// facing jumps every 0.3 to 1.5 s, sometimes right after a walk, at every rate. Every turn given
// time to finish ends within 5 degrees of its facing (the idle's hips may stand a few degrees off
// its root for seconds), the planted feet pivot at most 25 degrees/s, and the body turns at
// most 300 degrees/s (p99).
TEST(StandTurnTest, ShippedTurnScriptsEndOnTheirFacingAtEveryRate) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  for (const char* name : {"stand-turns.txt", "chaos-turns.txt"}) {
    Result<InputScript> script =
        load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input" / name);
    ASSERT_TRUE(script.ok()) << script.message();
    for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
      EvaluationOptions options;
      options.dt = dt;
      Result<EvaluationResult> run = evaluate_script(shared, *script, options);
      ASSERT_TRUE(run.ok()) << run.message();
      const EvaluationMetrics& m = run->metrics;
      EXPECT_GT(m.stand_turns, m.stand_turn_interrupted) << name << " dt " << dt;
      EXPECT_LE(m.stand_turn_final_error_deg_max, 5.0) << name << " dt " << dt;
      EXPECT_LE(m.foot_pivot_deg_s_mean, 25.0) << name << " dt " << dt;
      EXPECT_LE(m.body_turn_rate_deg_s_p99, 300.0) << name << " dt " << dt;
    }
  }
}

}  // namespace
}  // namespace mm
