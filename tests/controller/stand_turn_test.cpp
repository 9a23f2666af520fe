// Turning on the spot (issue 17): the stick released, the facing set by the right stick while
// strafing. The hips turn at a natural rate, the turn finishes on the requested facing in about
// the time a person takes, and the feet step (lift and land) rather than pivot on the ground.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"

namespace mm {
namespace {

using test::normal_controller_database;
using test::push_toward;

// The hips' yaw as the evaluation reads it: that of (L - R) x up for the upper legs.
float hips_yaw(const Controller& c) {
  const Database& db = c.controller_database().database();
  const glm::vec3 across =
      c.global_transforms()[static_cast<size_t>(db.roles.left_upper_leg)].translation -
      c.global_transforms()[static_cast<size_t>(db.roles.right_upper_leg)].translation;
  return std::atan2(-across.z, across.x);
}

float yaw_error_degrees(float a, float b) {
  return std::abs(glm::degrees(wrap_angle(a - b)));
}

struct StandTurn {
  float settle_seconds = -1.0f;  // from the request until the hips stay within 5 degrees
  float final_error_degrees = 0.0f;
  float peak_rate_degrees = 0.0f;  // the hips' largest yaw rate, frame to frame
  float lift[2] = {0.0f, 0.0f};    // each toe's highest rise above where it stood (m)
  int stepping_frames = 0;         // frames with a foot out of contact
};

// Stands for a second facing +Z, then asks for the facing `degrees` away (positive: toward +X)
// and holds it for `seconds`.
StandTurn turn_on_the_spot(float degrees, float dt, float seconds = 3.0f,
                           const ControllerSettings& settings = {}) {
  Result<Controller> made = Controller::create(normal_controller_database(), settings);
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.message());
  Controller c = std::move(made).value();
  const Database& db = c.controller_database().database();
  const int toes[2] = {db.roles.left_toe, db.roles.right_toe};
  const int settle_frames = static_cast<int>(std::lround(1.0f / dt));
  for (int i = 0; i < settle_frames; ++i) c.update(dt, ControllerInput{});

  ControllerInput input;
  input.strafe = true;
  input.right_stick = push_toward(degrees).left_stick;
  const float goal = glm::radians(degrees);
  StandTurn turn;
  float planted[2];
  for (int side = 0; side < 2; ++side) {
    planted[side] = c.global_transforms()[static_cast<size_t>(toes[side])].translation.y;
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
  return turn;
}

void expect_natural_turn(float degrees, float dt, float settle_limit) {
  const StandTurn turn = turn_on_the_spot(degrees, dt);
  SCOPED_TRACE(testing::Message() << degrees << " degrees at dt " << dt);
  EXPECT_GT(turn.settle_seconds, 0.0f) << "never settled; final error " << turn.final_error_degrees;
  EXPECT_LE(turn.settle_seconds, settle_limit);
  EXPECT_LE(turn.final_error_degrees, 5.0f);
  EXPECT_LT(turn.peak_rate_degrees, 400.0f);
  // The feet step: each toe rises clear of the ground at least once.
  EXPECT_GT(turn.lift[0], 0.02f);
  EXPECT_GT(turn.lift[1], 0.02f);
  EXPECT_GT(turn.stepping_frames, 0);
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

// The limit is what keeps the hips natural: without it the same turn is too fast, so the test
// above can tell.
TEST(StandTurnTest, AnUnboundedTurnIsTooFast) {
  ControllerSettings fast;
  fast.stand_turn_max_rate = 100.0f;
  fast.stand_turn_acceleration = 1000.0f;
  EXPECT_GT(turn_on_the_spot(90.0f, 1.0f / 60.0f, 3.0f, fast).peak_rate_degrees, 400.0f);
}

}  // namespace
}  // namespace mm
