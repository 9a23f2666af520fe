// Reversals (issue 17): walking or running one way, then the stick pushed the other way or
// across. The simulation turns no faster than simulation_max_turn_rate, the body (the hips'
// facing across the upper legs) no faster than body_max_turn_rate, and the facing still arrives.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm {
namespace {

using test::hips_yaw;
using test::make_controller;
using test::push_toward;

struct Reversal {
  float peak_body_rate = 0.0f;        // rad/s, frame to frame
  float peak_simulation_rate = 0.0f;  // rad/s, frame to frame
  float arrival_seconds = -1.0f;      // until the root faces the new way within 10 degrees
};

// Two seconds toward `from` (degrees of world yaw), then three toward `to`.
Reversal reverse(float from, float to, bool run, float dt,
                 const ControllerSettings& settings = {}) {
  Controller c = make_controller(settings);
  const int lead = static_cast<int>(std::lround(2.0f / dt));
  for (int i = 0; i < lead; ++i) c.update(dt, push_toward(from, run));
  Reversal r;
  float body = hips_yaw(c);
  float simulation = quat_yaw(c.debug().simulation_rotation);
  const int frames = static_cast<int>(std::lround(3.0f / dt));
  for (int i = 0; i < frames; ++i) {
    c.update(dt, push_toward(to, run));
    const float next_body = hips_yaw(c);
    const float next_simulation = quat_yaw(c.debug().simulation_rotation);
    r.peak_body_rate = std::max(r.peak_body_rate, std::abs(wrap_angle(next_body - body)) / dt);
    r.peak_simulation_rate =
        std::max(r.peak_simulation_rate, std::abs(wrap_angle(next_simulation - simulation)) / dt);
    body = next_body;
    simulation = next_simulation;
    const float error = wrap_angle(quat_yaw(c.root_transform().rotation) - glm::radians(to));
    if (r.arrival_seconds < 0.0f && std::abs(error) <= glm::radians(10.0f)) {
      r.arrival_seconds = static_cast<float>(i + 1) * dt;
    }
  }
  return r;
}

// Within the limits at every rate and both gaits, and facing the new way in well under a
// second and a half. (A reversal of exactly 180 degrees may turn either way; 178 does not.)
TEST(ReversalTest, HalfAndQuarterTurnsStayWithinTheTurnRatesAndArrive) {
  const ControllerSettings defaults;
  // Float rounding of the yaws read back from the world transforms.
  const float slack = 0.02f;
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    for (const bool run : {false, true}) {
      for (const float to : {178.0f, -90.0f}) {
        SCOPED_TRACE(testing::Message() << "dt " << dt << (run ? " run" : " walk") << " to " << to);
        const Reversal r = reverse(0.0f, to, run, dt);
        EXPECT_LE(r.peak_body_rate, defaults.body_max_turn_rate + slack);
        EXPECT_LE(r.peak_simulation_rate, defaults.simulation_max_turn_rate + slack);
        EXPECT_GT(r.arrival_seconds, 0.0f);
        EXPECT_LE(r.arrival_seconds, 1.3f);
      }
    }
  }
}

// The body limit is what holds the body: without it a running reversal spins the hips faster
// (the clip's own turning, a transition's offsets and the pull toward the simulation add up).
// (By a margin far above the rounding slack above; the transitions' own smoothing keeps it from
// being more.)
TEST(ReversalTest, WithoutTheBodyLimitARunningReversalSpinsFaster) {
  ControllerSettings unlimited;
  unlimited.body_max_turn_rate = 0.0f;
  const Reversal r = reverse(0.0f, 178.0f, true, 1.0f / 60.0f, unlimited);
  EXPECT_GT(r.peak_body_rate, ControllerSettings{}.body_max_turn_rate * 1.05f);
}

// The transition modes on the shipped reversals, IK on, at the coarsest and the usual rate:
// dead blending's transitions (the default) are the smoother, by the evaluation's measure.
TEST(ReversalTest, DeadBlendingTransitionsAreSmootherThanInertialization) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/reversals.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f}) {
    double ratio[2] = {0.0, 0.0};
    for (const TransitionMode mode :
         {TransitionMode::DeadBlending, TransitionMode::Inertialization}) {
      EvaluationOptions options;
      options.dt = dt;
      options.settings.transition_mode = mode;
      Result<EvaluationResult> run =
          evaluate_script(test::normal_controller_database(), *script, options);
      ASSERT_TRUE(run.ok()) << run.message();
      ratio[static_cast<int>(mode)] = run->metrics.transition_accel_ratio;
    }
    EXPECT_LT(ratio[0], 0.9 * ratio[1]) << "dt " << dt;
  }
}

// transition_accel_ratio_played judges a transition against the clips it plays, at the same
// moments: a cut (no cross-fade) jumps far harder than the clips move there, the default blend
// does not. Against the whole database the same runs would also be judged by how much they run.
TEST(ReversalTest, ACutShowsAgainstTheClipsItPlaysAndTheBlendDoesNot) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/reversals.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  double ratio[2] = {0.0, 0.0};
  for (const bool cut : {false, true}) {
    EvaluationOptions options;
    options.dt = 1.0f / 30.0f;
    if (cut) options.settings.dead_blend_time = 0.0f;
    Result<EvaluationResult> run =
        evaluate_script(test::normal_controller_database(), *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    EXPECT_GT(run->metrics.played_accel_p99, 0.0);
    ratio[cut ? 1 : 0] = run->metrics.transition_accel_ratio_played;
  }
  EXPECT_LT(ratio[0], 1.0);
  EXPECT_GT(ratio[1], 2.0);
  EXPECT_GT(ratio[1], 2.0 * ratio[0]);
}

}  // namespace
}  // namespace mm
