#pragma once
// Scripted evaluation (`mm eval`): one controller runs a script at a fixed dt, headless, and
// the run is measured. Every metric is defined here once; `mm eval` prints and writes them.
//
// Metrics (speeds are horizontal, from positions one frame apart):
// - foot_skate_cm_s_mean / _p95: the toe's speed on frames where that foot is in contact (the
//   contact the controller holds: the playing database frame's), over both feet;
// - root_sim_distance_cm_mean / _max: distance between the character's root and the simulation
//   object; facing_error_deg_mean: the angle between their facings;
// - speed_response_s: after the desired speed changes by at least kSpeedEventChange, the time
//   until the root's speed is within 10 % of the change from the new desired speed (mean over
//   the changes that got there before the next change);
// - heading_response_s: after the desired facing turns by at least kHeadingEventAngle in one
//   step, the time until the root's facing is within 10 degrees of it (mean, likewise);
// - stand_root_speed_cm_s_mean / stand_foot_speed_cm_s_mean: root and toe speed on frames where
//   the desired speed has been zero for at least kStandSettleSeconds;
// - transitions_per_s: jumps to a new database frame per second of script;
// - transition_accel_ratio: the 99th percentile of joint acceleration (second differences of
//   global joint positions, every joint but the simulation root) over the 10 frames from each
//   transition, divided by the same percentile over the database's locomotion clips (those the
//   controller plays when no tag is requested: not "action", not "idle") played straight
//   through at the same dt with linear interpolation between frames; the controller plays with
//   cubic Hermite sampling by default, which is smoother than that, so the same ratio against
//   the data played with the controller's own sampling is reported beside it
//   (transition_accel_ratio_same_sampling);
// - search_us_mean: wall time per search; update_us_mean: wall time per update() (the only
//   figures that vary from run to run).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// A desired speed change at least this large (m/s) starts a speed-response measurement.
inline constexpr float kSpeedEventChange = 0.5f;
// A desired facing turn at least this large (radians) in one frame starts a heading measurement.
inline constexpr float kHeadingEventAngle = 0.5f;
// Standing metrics count frames whose desired speed has been zero this long (s).
inline constexpr float kStandSettleSeconds = 1.0f;

struct EvaluationMetrics {
  double foot_skate_cm_s_mean = 0.0;
  double foot_skate_cm_s_p95 = 0.0;
  double root_sim_distance_cm_mean = 0.0;
  double root_sim_distance_cm_max = 0.0;
  double facing_error_deg_mean = 0.0;
  double speed_response_s = 0.0;
  int speed_events = 0;          // changes measured
  int speed_events_reached = 0;  // of which reached before the next change
  double heading_response_s = 0.0;
  int heading_events = 0;
  int heading_events_reached = 0;
  double stand_root_speed_cm_s_mean = 0.0;
  double stand_foot_speed_cm_s_mean = 0.0;
  int stand_frames = 0;
  double transitions_per_s = 0.0;
  double transition_accel_ratio = 0.0;
  double transition_accel_p99 = 0.0;              // m/s^2
  double database_accel_p99 = 0.0;                // m/s^2, linear interpolation
  double database_accel_p99_same_sampling = 0.0;  // m/s^2, the controller's sampling
  double transition_accel_ratio_same_sampling = 0.0;
  double search_us_mean = 0.0;
  double update_us_mean = 0.0;
  int frames = 0;
  double seconds = 0.0;
};

struct EvaluationOptions {
  float dt = 1.0f / 60.0f;  // seconds per update
  // Seconds to run; 0: the script's duration plus 2 s (so its last line is seen through).
  float seconds = 0.0f;
  ControllerSettings settings;
  bool keep_frames = false;  // fill EvaluationResult::csv_rows for --dump
};

struct EvaluationResult {
  EvaluationMetrics metrics;
  std::string csv_header;             // the --dump header (no newline)
  std::vector<std::string> csv_rows;  // one per frame when keep_frames
};

// The database's own joint acceleration, 99th percentile (m/s^2): every clip that carries none
// of `excluded_tags` played straight through at dt with linear interpolation between frames
// (the baseline of transition_accel_ratio), or with cubic Hermite sampling when `cubic`.
double database_acceleration_p99(const Database& db, float dt, uint64_t excluded_tags = 0,
                                 bool cubic = false);

// Runs the script and measures it. Fails on invalid options or settings.
Result<EvaluationResult> evaluate_script(std::shared_ptr<const ControllerDatabase> database,
                                         const InputScript& script,
                                         const EvaluationOptions& options);

}  // namespace mm
