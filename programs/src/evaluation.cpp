// Scripted evaluation: run, hand every frame to the accumulator, measure (definitions in
// evaluation.hpp).

#include "mm/programs/evaluation.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "mm/runtime/assert.hpp"
#include "statistics.hpp"

#include "mm/database/sampling.hpp"
#include "mm/programs/ground_metrics.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {

using detail::PercentileHistogram;
using detail::RunningMean;

namespace {

float horizontal_distance(const glm::vec3& a, const glm::vec3& b) {
  return std::hypot(a.x - b.x, a.z - b.z);
}

// The absolute angle between two yaws, in degrees, in [0, 180].
double yaw_error_deg(float a, float b) {
  return std::abs(glm::degrees(wrap_angle(a - b)));
}

// The yaw of a horizontal direction, or `fallback` when it has no horizontal length.
float direction_yaw(const glm::vec3& v, float fallback) {
  return std::hypot(v.x, v.z) > 1e-6f ? std::atan2(v.x, v.z) : fallback;
}

// Whole frames covering `seconds` at dt (at least one), so a settle time is compared as a
// frame count without float drift.
int frames_for(float seconds, float dt) {
  return std::max(1, clamped_integer<int>(std::ceil(seconds / dt - 1e-3f)));
}

// Acceleration magnitudes (second differences) of every joint but joint 0 from three
// consecutive frames' joint positions.
double joint_acceleration(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                          std::span<const glm::vec3> c, size_t j, float dt) {
  return glm::length(c[j] - 2.0f * b[j] + a[j]) / (dt * dt);
}

void joint_accelerations(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                         std::span<const glm::vec3> c, float dt, PercentileHistogram& out) {
  for (size_t j = 1; j < b.size(); ++j) out.add(joint_acceleration(a, b, c, j, dt));
}

// The leg joints leg_accel_max reads (knees, ankles, toes; -1 where a role is missing).
std::array<int, 6> leg_joints(const JointRoleIndices& roles) {
  return {roles.left_lower_leg, roles.right_lower_leg, roles.left_foot,
          roles.right_foot,     roles.left_toe,        roles.right_toe};
}

// The largest acceleration among `joints` (ignoring -1) from three consecutive frames.
double largest_acceleration(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                            std::span<const glm::vec3> c, std::span<const int> joints, float dt) {
  double largest = 0.0;
  for (const int j : joints) {
    if (j >= 0)
      largest = std::max(largest, joint_acceleration(a, b, c, static_cast<size_t>(j), dt));
  }
  return largest;
}

// How long a value has stayed within a tolerance of the value it was last held at.
struct HeldValue {
  glm::vec3 anchor{0.0f};
  int frames = 0;
  // `value` this frame, compared with `changed(anchor, value)`.
  template <typename Changed>
  void update(const glm::vec3& value, Changed changed) {
    if (frames == 0 || changed(anchor, value)) {
      anchor = value;
      frames = 0;
    }
    ++frames;  // this frame counts, as the stand time does
  }
};

// One turn on the spot being measured.
struct StandTurn {
  bool open = false;
  int length = 0;         // frames so far
  int settle_frame = -1;  // frames from the start to the first within the settle angle
  double last_error_deg = 0.0;
};

// The sums the turn-on-the-spot metrics are made of.
struct StandTurnSums {
  int events = 0;
  int unsettled = 0;
  double response_s = 0.0;
  double final_error_deg = 0.0;
  double peak_rate_deg_s = 0.0;
  int interrupted = 0;               // ended by a new request before kStandTurnJudgeSeconds
  double final_error_deg_max = 0.0;  // over the others
  void close(const StandTurn& turn, float dt) {
    if (!turn.open) return;
    ++events;
    if (turn.length * static_cast<double>(dt) < kStandTurnJudgeSeconds) {
      ++interrupted;
    } else {
      final_error_deg_max = std::max(final_error_deg_max, turn.last_error_deg);
    }
    unsettled += turn.settle_frame < 0 ? 1 : 0;
    response_s +=
        (turn.settle_frame < 0 ? turn.length : turn.settle_frame) * static_cast<double>(dt);
    final_error_deg += turn.last_error_deg;
  }
};

// A response being timed: the frame it started on and its goal (-1: none open).
struct ResponseEvent {
  int start = -1;
  float from = 0.0f;
  float to = 0.0f;
};

}  // namespace

// Everything the metrics need from earlier frames, and their running sums.
struct EvaluationAccumulator::State {
  // Styles: moving frames with a request and those matching it; the open request.
  int style_frames = 0, style_matches = 0;
  int style_requests = 0;
  int style_request_start = -1;  // frame of the open request, -1 when none is open
  RunningMean style_times;
  double style_time_max = 0.0;
  void measure_style(const EvaluationFrame& r);
  JointRoleIndices roles;
  size_t joint_count = 0;
  float dt = 0.0f;
  int toes[2] = {-1, -1};  // toe role, or the foot when the side has none
  std::array<int, 6> legs{};
  int lookback_frames = 1;
  int stand_settle_frames = 1, idle_settle_frames = 1, strafe_settle_frames = 1;

  int frames = 0;
  EvaluationFrame previous;                  // its joints view `positions[1]`
  std::vector<glm::vec3> positions[2];       // the frame before the previous, the previous
  uint32_t transition_bits = 0;              // bit k: frame n-1-k transitioned
  std::vector<float> desired_speed_history;  // ring over the look-back, by frame
  std::vector<float> desired_yaw_history;

  // Plain metrics.
  PercentileHistogram skate, accelerations, hips_rates;
  // The largest transition accelerations, a min-heap of at most transition_capacity.
  std::vector<TransitionSample> transition_top;
  size_t transition_capacity = 0;
  void keep_largest(const EvaluationFrame& r, int windows);
  RunningMean skate_mean, distance, facing, updates, searches, stand_root, stand_foot;
  double distance_max = 0.0;
  double leg_accel_max = 0.0, leg_accel_max_t = 0.0;
  int transitions = 0;
  ResponseEvent speed_event, heading_event;
  int speed_events = 0, heading_events = 0;
  RunningMean speed_times, heading_times;

  // Held values.
  int standing_frames = 0;  // consecutive frames with desired speed zero
  HeldValue facing_held, velocity_held;

  // Body metrics.
  float hips_yaw = 0.0f, chest_yaw = 0.0f;
  float pivot_yaw[2] = {0.0f, 0.0f};
  bool pivot_ok[2] = {false, false};  // the toe was low and slow on the previous frame
  RunningMean pivot, strafe_chest, idle_head;
  bool stand_turn_condition = false;  // held on the previous frame
  StandTurn stand_turn;
  StandTurnSums stand_turn_sums;
  float toe_height_min = std::numeric_limits<float>::infinity();
  std::unique_ptr<GroundAccumulator> ground;

  bool has_pair(int left, int right) const { return left >= 0 && right >= 0; }
  bool has_hips() const { return has_pair(roles.left_upper_leg, roles.right_upper_leg); }
  bool has_chest() const { return has_pair(roles.left_upper_arm, roles.right_upper_arm); }

  void follow_origin(const EvaluationFrame& r);
  void measure_plain(const EvaluationFrame& r);
  void measure_responses(const EvaluationFrame& r);
  void update_held(const EvaluationFrame& r);
  void measure_feet(const EvaluationFrame& r);
  void measure_pivot(const EvaluationFrame& r, int side, float toe_speed);
  float measure_hips(const EvaluationFrame& r);
  void measure_stand_turn(const EvaluationFrame& r, float hips_rate);
  void measure_chest_and_head(const EvaluationFrame& r);
  void measure_transition_accel(const EvaluationFrame& r);
  void remember(const EvaluationFrame& r);
};

EvaluationAccumulator::EvaluationAccumulator(const JointRoleIndices& roles, size_t joint_count,
                                             float dt)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.roles = roles;
  s.joint_count = joint_count;
  s.dt = dt;
  s.toes[0] = roles.left_toe >= 0 ? roles.left_toe : roles.left_foot;
  s.toes[1] = roles.right_toe >= 0 ? roles.right_toe : roles.right_foot;
  s.legs = leg_joints(roles);
  s.lookback_frames = std::max(1, clamped_integer<int>(std::round(kStandTurnLookback / dt)));
  s.stand_settle_frames = frames_for(kStandSettleSeconds, dt);
  s.idle_settle_frames = frames_for(kIdleSettleSeconds, dt);
  s.strafe_settle_frames = frames_for(kStrafeSettleSeconds, dt);
  for (std::vector<glm::vec3>& p : s.positions) p.assign(joint_count, glm::vec3(0.0f));
  s.desired_speed_history.assign(static_cast<size_t>(s.lookback_frames) + 1, 0.0f);
  s.desired_yaw_history.assign(static_cast<size_t>(s.lookback_frames) + 1, 0.0f);
  s.ground = std::make_unique<GroundAccumulator>(roles, dt);
}

EvaluationAccumulator::~EvaluationAccumulator() = default;

void EvaluationAccumulator::add(const EvaluationFrame& frame) {
  State& s = *state_;
  MM_ASSERT(frame.joints.size() == s.joint_count);
  s.follow_origin(frame);
  s.measure_plain(frame);
  s.update_held(frame);
  s.measure_feet(frame);
  const float hips_rate = s.measure_hips(frame);
  s.measure_stand_turn(frame, hips_rate);
  s.measure_chest_and_head(frame);
  s.measure_transition_accel(frame);
  s.measure_style(frame);
  GroundFrame ground;
  ground.joints = frame.joints;
  std::copy(std::begin(frame.toe_ground), std::end(frame.toe_ground), ground.toe_ground);
  std::copy(std::begin(frame.toe_support), std::end(frame.toe_support), ground.toe_support);
  ground.hips_ground = frame.hips_ground;
  std::copy(std::begin(frame.contact), std::end(frame.contact), ground.contact);
  std::copy(std::begin(frame.played_toe), std::end(frame.played_toe), ground.played_toe);
  ground.wall_depth = frame.wall_depth;
  ground.stuck = frame.stuck;
  s.ground->add(ground);
  s.remember(frame);
}

void EvaluationAccumulator::State::measure_style(const EvaluationFrame& r) {
  const bool requested = r.requested_style >= 0;
  if (requested && (frames == 0 || r.requested_style != previous.requested_style)) {
    ++style_requests;
    style_request_start = frames;
  } else if (!requested) {
    style_request_start = -1;
  }
  const bool match = requested && r.clip_style == r.requested_style;
  if (match && style_request_start >= 0) {
    const double response = static_cast<double>(frames - style_request_start) * dt;
    style_times.add(response);
    style_time_max = std::max(style_time_max, response);
    style_request_start = -1;
  }
  if (requested && glm::length(r.desired_velocity) > kStyleMovingSpeed) {
    ++style_frames;
    style_matches += match ? 1 : 0;
  }
}

// The earlier frames' positions shifted into this frame's origin (a whole number of metres,
// local_origin.hpp): positions near the character move by at most a float step there.
void EvaluationAccumulator::State::follow_origin(const EvaluationFrame& r) {
  if (frames == 0 || r.origin == previous.origin) return;
  const glm::vec3 shift(r.origin - previous.origin);
  for (std::vector<glm::vec3>& frame : positions) {
    for (glm::vec3& p : frame) p -= shift;
  }
  previous.root_position -= shift;
  previous.sim_position -= shift;
  previous.origin = r.origin;
  ground->shift(shift);
}

// Distance and facing to the simulation, timings, transitions, the responses.
void EvaluationAccumulator::State::measure_plain(const EvaluationFrame& r) {
  const double d = 100.0 * horizontal_distance(r.root_position, r.sim_position);
  distance.add(d);
  distance_max = std::max(distance_max, d);
  facing.add(yaw_error_deg(r.root_yaw, r.sim_yaw));
  updates.add(r.update_seconds * 1e6);
  if (r.searched) searches.add(r.search_seconds * 1e6);
  transitions += r.transition ? 1 : 0;
  if (frames > 0) measure_responses(r);
}

// Speed: events where the desired speed jumps, done when the root speed is close to it.
// Heading: events where the desired facing jumps, done when the root faces it.
void EvaluationAccumulator::State::measure_responses(const EvaluationFrame& r) {
  const float desired = glm::length(r.desired_velocity);
  const float previous_desired = glm::length(previous.desired_velocity);
  if (std::abs(desired - previous_desired) >= kSpeedEventChange) {
    if (speed_event.start >= 0) ++speed_events;
    speed_event = {frames, previous_desired, desired};
  }
  if (speed_event.start >= 0) {
    const float speed = horizontal_distance(r.root_position, previous.root_position) / dt;
    if (std::abs(speed - speed_event.to) <= 0.1f * std::abs(speed_event.to - speed_event.from)) {
      speed_times.add((static_cast<double>(frames) - speed_event.start) * dt);
      ++speed_events;
      speed_event.start = -1;
    }
  }
  if (std::abs(wrap_angle(r.desired_yaw - previous.desired_yaw)) >= kHeadingEventAngle) {
    if (heading_event.start >= 0) ++heading_events;
    heading_event.start = frames;
  }
  if (heading_event.start >= 0) {
    // A turn that keeps going is followed to its end.
    if (yaw_error_deg(r.root_yaw, r.desired_yaw) <= kSettleAngleDegrees) {
      heading_times.add((static_cast<double>(frames) - heading_event.start) * dt);
      ++heading_events;
      heading_event.start = -1;
    }
  }
}

// How long the stick has been released and the desired facing and velocity held.
void EvaluationAccumulator::State::update_held(const EvaluationFrame& r) {
  standing_frames = glm::length(r.desired_velocity) == 0.0f ? standing_frames + 1 : 0;
  const float facing_tolerance = glm::radians(kFacingToleranceDegrees);
  facing_held.update(glm::vec3(r.desired_yaw, 0.0f, 0.0f), [&](glm::vec3 a, glm::vec3 b) {
    return std::abs(wrap_angle(a.x - b.x)) > facing_tolerance;
  });
  velocity_held.update(r.desired_velocity, [](glm::vec3 a, glm::vec3 b) {
    return glm::length(a - b) > kVelocityTolerance;
  });
}

// Foot skating, standing feet, pivots, the lowest toe.
void EvaluationAccumulator::State::measure_feet(const EvaluationFrame& r) {
  const bool standing =
      standing_frames >= stand_settle_frames && facing_held.frames >= stand_settle_frames;
  for (int side = 0; side < 2; ++side) {
    if (toes[side] < 0) continue;
    const glm::vec3& toe = r.joints[static_cast<size_t>(toes[side])];
    toe_height_min = std::min(toe_height_min, toe.y);
    if (frames == 0) continue;
    const float moved = horizontal_distance(toe, previous.joints[static_cast<size_t>(toes[side])]);
    const double speed_cm = 100.0 * moved / dt;
    if (r.contact[side] && previous.contact[side]) {
      skate.add(speed_cm);
      skate_mean.add(speed_cm);
    }
    if (standing) stand_foot.add(speed_cm);
    measure_pivot(r, side,
                  glm::distance(toe, previous.joints[static_cast<size_t>(toes[side])]) / dt);
  }
  if (standing && frames > 0) {
    stand_root.add(100.0 * horizontal_distance(r.root_position, previous.root_position) / dt);
  }
}

// The foot-to-toe vector's yaw rate while the toe is low and slow now and on the previous frame.
void EvaluationAccumulator::State::measure_pivot(const EvaluationFrame& r, int side,
                                                 float toe_speed) {
  const int foot = side == 0 ? roles.left_foot : roles.right_foot;
  const int toe = side == 0 ? roles.left_toe : roles.right_toe;
  if (foot < 0 || toe < 0) return;
  const glm::vec3& toe_position = r.joints[static_cast<size_t>(toe)];
  const glm::vec3 foot_to_toe = toe_position - r.joints[static_cast<size_t>(foot)];
  const float yaw = direction_yaw(foot_to_toe, pivot_yaw[side]);
  const float level = std::hypot(foot_to_toe.x, foot_to_toe.z);
  const bool flat_enough =
      level >= std::cos(glm::radians(kPivotMaxFootPitchDegrees)) * glm::length(foot_to_toe);
  const bool ok = toe_position.y < kPivotToeHeight && toe_speed < kPivotToeSpeed && flat_enough;
  if (ok && pivot_ok[side]) pivot.add(yaw_error_deg(yaw, pivot_yaw[side]) / dt);
  pivot_ok[side] = ok;
  pivot_yaw[side] = yaw;
}

// The hips' yaw and its rate this frame (deg/s; 0 on the first frame or without hips).
float EvaluationAccumulator::State::measure_hips(const EvaluationFrame& r) {
  if (!has_hips()) return 0.0f;
  const float yaw = pair_yaw(r.joints[static_cast<size_t>(roles.left_upper_leg)],
                             r.joints[static_cast<size_t>(roles.right_upper_leg)], hips_yaw);
  float rate = 0.0f;
  if (frames > 0) {
    rate = static_cast<float>(yaw_error_deg(yaw, hips_yaw) / dt);
    hips_rates.add(rate);
  }
  hips_yaw = yaw;
  return rate;
}

// Turning on the spot: start, follow and close events (see the header).
void EvaluationAccumulator::State::measure_stand_turn(const EvaluationFrame& r, float hips_rate) {
  const size_t ring = desired_speed_history.size();
  const size_t now = static_cast<size_t>(frames) % ring;
  const float speed = glm::length(r.desired_velocity);
  desired_speed_history[now] = speed;
  desired_yaw_history[now] = r.desired_yaw;
  if (!has_hips()) return;
  bool condition = false;
  if (frames >= lookback_frames) {
    const size_t then = static_cast<size_t>(frames - lookback_frames) % ring;
    condition = speed < kStandTurnSpeed && desired_speed_history[then] < kStandTurnSpeed &&
                yaw_error_deg(r.desired_yaw, desired_yaw_history[then]) >= kStandTurnAngleDegrees;
  }
  const bool starts = condition && !stand_turn_condition;
  stand_turn_condition = condition;
  if (starts || speed >= kStandTurnSpeed) {
    stand_turn_sums.close(stand_turn, dt);
    stand_turn = StandTurn{};
    stand_turn.open = starts;
  }
  if (!stand_turn.open) return;
  const double error = yaw_error_deg(hips_yaw, r.desired_yaw);
  if (stand_turn.settle_frame < 0 && error <= kSettleAngleDegrees) {
    stand_turn.settle_frame = stand_turn.length;
  }
  ++stand_turn.length;
  stand_turn.last_error_deg = error;
  stand_turn_sums.peak_rate_deg_s = std::max<double>(stand_turn_sums.peak_rate_deg_s, hips_rate);
}

// The chest's yaw error while strafing, the head's speed while idle.
void EvaluationAccumulator::State::measure_chest_and_head(const EvaluationFrame& r) {
  if (has_chest()) {
    chest_yaw = pair_yaw(r.joints[static_cast<size_t>(roles.left_upper_arm)],
                         r.joints[static_cast<size_t>(roles.right_upper_arm)], chest_yaw);
    const float speed = glm::length(r.desired_velocity);
    const bool strafing = speed >= kStrafeMinSpeed &&
                          yaw_error_deg(direction_yaw(r.desired_velocity, r.desired_yaw),
                                        r.desired_yaw) >= kStrafeMinAngleDegrees &&
                          facing_held.frames >= strafe_settle_frames &&
                          velocity_held.frames >= strafe_settle_frames;
    if (strafing) strafe_chest.add(yaw_error_deg(chest_yaw, r.desired_yaw));
  }
  if (roles.head >= 0 && frames > 0 && standing_frames >= idle_settle_frames) {
    const size_t head = static_cast<size_t>(roles.head);
    idle_head.add(100.0 * glm::length(r.joints[head] - previous.joints[head]) / dt);
  }
}

// Joint acceleration at the previous frame (it needs this one), counted once for every
// transition among the 10 frames up to it.
void EvaluationAccumulator::State::measure_transition_accel(const EvaluationFrame& r) {
  if (frames >= 2) {
    const int count = std::popcount(transition_bits & 0x3ffu);
    for (int i = 0; i < count; ++i) {
      joint_accelerations(positions[0], positions[1], r.joints, dt, accelerations);
    }
    if (count > 0 && transition_capacity > 0) keep_largest(r, count);
    // Not where the sample's third frame is itself a transition: that jump is the transition's.
    if (count == 0 && !r.transition) {
      const double leg = largest_acceleration(positions[0], positions[1], r.joints, legs, dt);
      if (leg > leg_accel_max) {
        leg_accel_max = leg;
        leg_accel_max_t = previous.t;
      }
    }
  }
  transition_bits = (transition_bits << 1) | (r.transition ? 1u : 0u);
}

// The previous frame's joint accelerations (as measure_transition_accel takes them) into the
// largest kept, each counted in `windows` transitions' windows.
void EvaluationAccumulator::State::keep_largest(const EvaluationFrame& r, int windows) {
  const auto larger = [](const TransitionSample& a, const TransitionSample& b) {
    return a.acceleration > b.acceleration;
  };
  for (size_t j = 1; j < r.joints.size(); ++j) {
    const double a = joint_acceleration(positions[0], positions[1], r.joints, j, dt);
    if (transition_top.size() == transition_capacity) {
      if (!(a > transition_top.front().acceleration)) continue;
      std::pop_heap(transition_top.begin(), transition_top.end(), larger);
      transition_top.pop_back();
    }
    transition_top.push_back(
        {a, previous.t, static_cast<int>(j), windows, previous.clip, previous.frame});
    std::push_heap(transition_top.begin(), transition_top.end(), larger);
  }
}

// This frame becomes the previous one: its scalars and a copy of its joints.
void EvaluationAccumulator::State::remember(const EvaluationFrame& r) {
  std::swap(positions[0], positions[1]);
  std::copy(r.joints.begin(), r.joints.end(), positions[1].begin());
  previous = r;
  previous.joints = positions[1];
  ++frames;
}

void EvaluationAccumulator::keep_transition_samples(int count) {
  State& s = *state_;
  s.transition_capacity = static_cast<size_t>(std::max(count, 0));
  s.transition_top.clear();
  s.transition_top.reserve(s.transition_capacity);
}

std::vector<TransitionSample> EvaluationAccumulator::transition_samples() const {
  std::vector<TransitionSample> sorted = state_->transition_top;
  std::sort(sorted.begin(), sorted.end(), [](const TransitionSample& a, const TransitionSample& b) {
    return a.acceleration > b.acceleration;
  });
  return sorted;
}

EvaluationMetrics EvaluationAccumulator::metrics() const {
  const State& s = *state_;
  EvaluationMetrics m;
  m.frames = s.frames;
  m.seconds = static_cast<double>(s.frames) * s.dt;
  m.foot_skate_cm_s_mean = s.skate_mean.value();
  m.foot_skate_cm_s_p95 = s.skate.percentile(95.0);
  m.root_sim_distance_cm_mean = s.distance.value();
  m.root_sim_distance_cm_max = s.distance_max;
  m.facing_error_deg_mean = s.facing.value();
  m.speed_events = s.speed_events + (s.speed_event.start >= 0 ? 1 : 0);
  m.heading_events = s.heading_events + (s.heading_event.start >= 0 ? 1 : 0);
  m.speed_events_reached = s.speed_times.count;
  m.heading_events_reached = s.heading_times.count;
  m.speed_response_s = s.speed_times.value();
  m.heading_response_s = s.heading_times.value();
  m.stand_root_speed_cm_s_mean = s.stand_root.value();
  m.stand_foot_speed_cm_s_mean = s.stand_foot.value();
  m.stand_frames = s.stand_root.count;
  m.transitions_per_s = m.seconds > 0.0 ? s.transitions / m.seconds : 0.0;
  m.style_frames = s.style_frames;
  m.style_match = s.style_frames > 0 ? static_cast<double>(s.style_matches) / s.style_frames : -1.0;
  m.style_requests = s.style_requests;
  m.style_requests_reached = static_cast<int>(s.style_times.count);
  m.style_response_s = s.style_times.value();
  m.style_response_s_max = s.style_time_max;
  m.search_us_mean = s.searches.value();
  m.update_us_mean = s.updates.value();
  m.transition_accel_p99 = s.accelerations.percentile(99.0);
  m.leg_accel_max = s.leg_accel_max;
  m.leg_accel_max_t = s.leg_accel_max_t;

  m.body_turn_rate_deg_s_max = s.hips_rates.max();
  m.body_turn_rate_deg_s_p99 = s.hips_rates.percentile(99.0);
  m.foot_pivot_deg_s_mean = s.pivot.value();
  m.foot_pivot_frames = s.pivot.count;
  StandTurnSums turns = s.stand_turn_sums;
  turns.close(s.stand_turn, s.dt);
  m.stand_turns = turns.events;
  m.stand_turn_unsettled = turns.unsettled;
  m.stand_turn_interrupted = turns.interrupted;
  m.stand_turn_final_error_deg_max = turns.final_error_deg_max;
  m.stand_turn_response_s = turns.events > 0 ? turns.response_s / turns.events : 0.0;
  m.stand_turn_final_error_deg_mean = turns.events > 0 ? turns.final_error_deg / turns.events : 0.0;
  m.stand_turn_peak_rate_deg_s_max = turns.peak_rate_deg_s;
  m.strafe_chest_error_deg_mean = s.strafe_chest.value();
  m.strafe_chest_frames = s.strafe_chest.count;
  m.idle_head_speed_cm_s_mean = s.idle_head.value();
  m.idle_head_frames = s.idle_head.count;
  m.toe_height_min_cm = std::isfinite(s.toe_height_min) ? 100.0 * s.toe_height_min : 0.0;
  m.ground = s.ground->metrics();
  return m;
}

namespace {

std::string csv_header(const Database& db) {
  std::string h =
      "t,sim_x,sim_z,sim_yaw_deg,root_x,root_z,root_yaw_deg,desired_vx,desired_vz,"
      "desired_yaw_deg,transition,contact_l,contact_r,clip,frame";
  for (const std::string& name : db.skeleton().names()) {
    h.append(",").append(name).append("_x,").append(name).append("_y,").append(name).append("_z");
  }
  h.append(",toe_ground_l,toe_ground_r,hips_ground,wall_depth,stuck,locked_l,locked_r");
  h.append(",toe_support_l,toe_support_r");
  h.append(",body_ground,placed_toe_ground_l,placed_toe_ground_r,pelvis_drop,playback_rate");
  return h;
}

// Positions in the world: the frame's origin plus its relative positions, summed in double.
std::string csv_row(const EvaluationFrame& r) {
  char buffer[256];
  const glm::dvec3 sim = to_world(r.origin, r.sim_position);
  const glm::dvec3 root = to_world(r.origin, r.root_position);
  std::snprintf(buffer, sizeof buffer,
                "%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%.4f,%.6f,%.6f,%.4f,%d,%d,%d,%d,%d", r.t, sim.x,
                sim.z, glm::degrees(r.sim_yaw), root.x, root.z, glm::degrees(r.root_yaw),
                r.desired_velocity.x, r.desired_velocity.z, glm::degrees(r.desired_yaw),
                r.transition ? 1 : 0, r.contact[0] ? 1 : 0, r.contact[1] ? 1 : 0, r.clip, r.frame);
  std::string row = buffer;
  for (const glm::vec3& joint : r.joints) {
    const glm::dvec3 p = to_world(r.origin, joint);
    std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f,%.6f", p.x, p.y, p.z);
    row += buffer;
  }
  std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f,%.6f,%.6f,%d,%d,%d", r.toe_ground[0],
                r.toe_ground[1], r.hips_ground, r.wall_depth, r.stuck ? 1 : 0, r.locked[0] ? 1 : 0,
                r.locked[1] ? 1 : 0);
  row += buffer;
  std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f",
                std::max(r.toe_ground[0], r.toe_support[0]),
                std::max(r.toe_ground[1], r.toe_support[1]), r.body_ground, r.placed_toe_ground[0],
                r.placed_toe_ground[1], r.pelvis_drop, r.playback_rate);
  row += buffer;
  return row;
}

// The record of the update just made, relative to the controller's origin (as the debug state
// is); `positions` receives the joints it views.
EvaluationFrame frame_record(const Controller& controller, float t, double update_seconds,
                             std::vector<glm::vec3>& positions) {
  const ControllerDebug& d = controller.debug();
  const std::span<const Transform> globals = controller.origin_transforms();
  EvaluationFrame r;
  r.t = t;
  r.origin = controller.origin();
  r.sim_position = d.simulation_position;
  r.sim_yaw = quat_yaw(d.simulation_rotation);
  r.root_position = globals[0].translation;
  r.root_yaw = quat_yaw(globals[0].rotation);
  r.desired_velocity = d.desired_velocity;
  r.desired_yaw = quat_yaw(d.desired_rotation);
  r.transition = d.transitioned;
  r.clip = d.clip;
  r.clip_style =
      d.clip >= 0
          ? controller.controller_database().database().clips()[static_cast<size_t>(d.clip)].style
          : -1;
  r.requested_style = d.requested_style;
  r.frame = d.frame;
  r.contact[0] = d.contact[0];
  r.contact[1] = d.contact[1];
  r.locked[0] = d.locked[0];
  r.locked[1] = d.locked[1];
  r.update_seconds = update_seconds;
  r.searched = d.searched;
  r.search_seconds = d.search_seconds;
  r.body_ground = d.ground_height;
  r.playback_rate = d.playback_rate;
  r.placed_toe_ground[0] = d.foot_ground[0].toe;
  r.placed_toe_ground[1] = d.foot_ground[1].toe;
  r.pelvis_drop = d.pelvis_drop;
  for (size_t j = 0; j < positions.size(); ++j) positions[j] = globals[j].translation;
  r.joints = positions;
  return r;
}

// What the world says about each frame's pose (ground_metrics.hpp): the ground under the toes
// and the hips, the deepest joint inside a wall, whether the simulation object was stuck. Its
// buffers are sized once; without a world it leaves the frame's flat-ground defaults.
class WorldReadings {
 public:
  WorldReadings(const WorldQueries* world, const JointRoleIndices& roles, size_t joints)
      : world_(world), roles_(roles), walls_(joints) {
    toes_[0] = roles.left_toe >= 0 ? roles.left_toe : roles.left_foot;
    toes_[1] = roles.right_toe >= 0 ? roles.right_toe : roles.right_foot;
    heels_[0] = roles.left_foot >= 0 ? roles.left_foot : toes_[0];
    heels_[1] = roles.right_foot >= 0 ? roles.right_foot : toes_[1];
  }

  void read(const Controller& controller, float dt, EvaluationFrame& r) {
    if (!world_) return;
    const ControllerDebug& d = controller.debug();
    read_ground(d, r);
    read_walls(controller, d, r);
    const float moved = horizontal_distance(d.simulation_position, previous_sim_) / dt;
    const glm::vec3 along =
        r.desired_velocity -
        d.simulation_contact * glm::dot(r.desired_velocity, d.simulation_contact);
    r.stuck = held_at_wall(d.simulation_blocked, d.simulation_contact, r.desired_velocity,
                           previous_sim_velocity_, d.simulation_velocity, moved) &&
              can_slide(controller.settings(), d, r.origin, along);
    previous_sim_ = d.simulation_position;
    previous_sim_velocity_ = d.simulation_velocity;
  }

 private:
  // The toes' and hips' ground, probed from a metre above them (a joint with no ground under it
  // within 3 m takes the ground under the root), and the ground under each foot
  // (foot_support_points), for the ground the foot rests on (foot_support_height). One call.
  void read_ground(const ControllerDebug& d, EvaluationFrame& r) {
    constexpr int kJoints = 3, kAlong = kFootSupportProbes;
    const int joints[kJoints] = {toes_[0], toes_[1], roles_.hips};
    std::array<GroundProbe, kJoints + 2 * kAlong> probes;
    std::array<GroundHit, kJoints + 2 * kAlong> hits;
    const auto joint = [&](int j) {
      return j >= 0 ? r.joints[static_cast<size_t>(j)] : r.root_position;
    };
    const auto from_above = [](const glm::vec3& p) {
      return GroundProbe{p + glm::vec3(0.0f, 1.0f, 0.0f), 3.0f, 0.0f};
    };
    for (int k = 0; k < kJoints; ++k) probes[k] = from_above(joint(joints[k]));
    for (int side = 0; side < 2; ++side) {
      const auto points = foot_support_points(joint(toes_[side]), joint(heels_[side]));
      for (int k = 0; k < kAlong; ++k) probes[kJoints + side * kAlong + k] = from_above(points[k]);
    }
    world_->probe_ground(r.origin, probes, hits);
    float* out[kJoints] = {&r.toe_ground[0], &r.toe_ground[1], &r.hips_ground};
    for (int k = 0; k < kJoints; ++k) {
      *out[k] = hits[k].hit && std::isfinite(hits[k].point.y) ? hits[k].point.y : d.ground_height;
    }
    for (int side = 0; side < 2; ++side) {
      r.toe_support[side] = foot_support_height(
          r.toe_ground[side], hits[side], std::span(hits).subspan(kJoints + side * kAlong, kAlong),
          joint(toes_[side]).y);
    }
  }

  // Whether the capsule, as the mover sweeps it (lifted by the step height), can move along the
  // wall it is blocked by: pushed into a concave corner, the slide along one wall meets the other
  // at once, and a character standing there is not stuck where it could have slid. Swept a skin
  // off the wall, so that the wall it rests against is not met again.
  bool can_slide(const ControllerSettings& s, const ControllerDebug& d, const glm::dvec3& origin,
                 const glm::vec3& along) const {
    constexpr float kSkin = 0.01f;   // m off the wall
    constexpr float kProbe = 0.05f;  // m along it: half of it free is a slide
    const glm::vec3 from =
        d.simulation_position + glm::vec3(0.0f, s.step_height, 0.0f) + d.simulation_contact * kSkin;
    const ShapeSweep sweep{from, from + glm::normalize(along) * kProbe, s.character_radius,
                           s.character_height};
    SweepHit hit;
    world_->sweep(origin, std::span(&sweep, 1), std::span(&hit, 1));
    return !hit.hit || !(hit.fraction < 0.5f);
  }

  // The deepest any joint higher than a step above the ground is inside a wall
  // (WallDepthReader). Lower joints meet the ground's slopes and steps, not walls, and are the
  // penetration metrics' to judge.
  void read_walls(const Controller& controller, const ControllerDebug& d, EvaluationFrame& r) {
    const float above = d.ground_height + controller.settings().step_height;
    r.wall_depth = walls_.read(*world_, r.origin, r.root_position, r.joints.subspan(1), above);
  }

  const WorldQueries* world_;
  JointRoleIndices roles_;
  int toes_[2] = {-1, -1};
  int heels_[2] = {-1, -1};  // the feet (ankles), or the toes where a side has none
  WallDepthReader walls_;
  glm::vec3 previous_sim_{0.0f};
  glm::vec3 previous_sim_velocity_{0.0f};
};

// The playing clips' own poses: a clip's global joint positions at a time, held within the
// clip, sampled as the controller samples them. Buffers sized once.
class ClipPoses {
 public:
  ClipPoses(const Database& db, bool cubic)
      : db_(db),
        cubic_(cubic),
        local_(static_cast<size_t>(db.joint_count())),
        global_(local_.size()) {}

  void pose_at(int clip_index, float time, std::span<glm::vec3> out) {
    const ClipRange& clip = db_.clips()[static_cast<size_t>(clip_index)];
    const float last = static_cast<float>(clip.frame_count() - 1);
    const float x = std::clamp(time / db_.frame_time(), 0.0f, last);
    const int i0 = std::min(clamped_integer<int>(std::floor(x)), clip.frame_count() - 1);
    const int i1 = std::min(i0 + 1, clip.frame_count() - 1);
    for (size_t j = 0; j < local_.size(); ++j) {
      local_[j] =
          sample_database_joint(db_, clip.start + i0, clip.start + i1, x - static_cast<float>(i0),
                                j, cubic_, InterpolationMethod::Nlerp);
    }
    forward_kinematics(db_.skeleton().parents(), local_, global_);
    for (size_t j = 0; j < local_.size(); ++j) out[j] = global_[j].translation;
  }
  size_t joints() const { return local_.size(); }

 private:
  const Database& db_;
  bool cubic_;
  std::vector<Transform> local_, global_;
};

// The acceleration the playing clips have on their own at the moments transition_accel_p99
// samples (the 10 frames from each transition, counted once per transition among them): the
// clip played straight through those moments, with the controller's sampling. What a blend
// adds to a jump shows against this; against the whole database it would also show how much
// more the script runs than the data does.
class PlayedAcceleration {
 public:
  PlayedAcceleration(const Database& db, float dt, bool cubic)
      : dt_(dt), poses_(db, cubic), legs_(leg_joints(db.roles())) {
    for (std::vector<glm::vec3>& step : steps_) step.assign(poses_.joints(), glm::vec3(0.0f));
  }

  void add(const ControllerDebug& d) {
    transition_bits_ = (transition_bits_ << 1) | (d.transitioned ? 1u : 0u);
    const int count = std::popcount(transition_bits_ & 0x3ffu);
    if (d.clip < 0) return;
    for (int k = 0; k < 3; ++k) {
      poses_.pose_at(d.clip, d.clip_time + static_cast<float>(k - 1) * dt_,
                     steps_[static_cast<size_t>(k)]);
    }
    for (int i = 0; i < count; ++i) {
      joint_accelerations(steps_[0], steps_[1], steps_[2], dt_, accelerations_);
    }
    if (count == 0) {
      leg_max_ =
          std::max(leg_max_, largest_acceleration(steps_[0], steps_[1], steps_[2], legs_, dt_));
    }
  }
  double p99() const { return accelerations_.percentile(99.0); }
  // The leg joints' largest acceleration outside the windows (leg_accel_played_max).
  double leg_max() const { return leg_max_; }

 private:
  float dt_;
  ClipPoses poses_;
  std::vector<glm::vec3> steps_[3];
  std::array<int, 6> legs_;
  uint32_t transition_bits_ = 0;
  PercentileHistogram accelerations_;
  double leg_max_ = 0.0;
};

// The playing clip's own toe heights above its flat ground at the playing time
// (EvaluationFrame::played_toe, for foot_float_data_cm_mean).
class PlayedToes {
 public:
  PlayedToes(const Database& db, bool cubic) : poses_(db, cubic), pose_(poses_.joints()) {
    const JointRoleIndices& roles = db.roles();
    toes_[0] = roles.left_toe >= 0 ? roles.left_toe : roles.left_foot;
    toes_[1] = roles.right_toe >= 0 ? roles.right_toe : roles.right_foot;
  }

  void read(const ControllerDebug& d, EvaluationFrame& r) {
    if (d.clip < 0) return;
    poses_.pose_at(d.clip, d.clip_time, pose_);
    for (int side = 0; side < 2; ++side) {
      if (toes_[side] >= 0) r.played_toe[side] = pose_[static_cast<size_t>(toes_[side])].y;
    }
  }

 private:
  ClipPoses poses_;
  std::vector<glm::vec3> pose_;
  int toes_[2] = {-1, -1};
};

// The transition figures against the database's own acceleration at the same dt.
void compare_with_database(const ControllerDatabase& database, const EvaluationOptions& options,
                           EvaluationMetrics& m) {
  const Database& db = database.database();
  const uint64_t excluded = database.action_tags() | database.idle_tags();
  m.database_accel_p99 = database_acceleration_p99(db, options.dt, excluded);
  m.transition_accel_ratio =
      m.database_accel_p99 > 0.0 ? m.transition_accel_p99 / m.database_accel_p99 : 0.0;
  m.database_accel_p99_same_sampling =
      options.settings.cubic_playback ? database_acceleration_p99(db, options.dt, excluded, true)
                                      : m.database_accel_p99;
  m.transition_accel_ratio_same_sampling =
      m.database_accel_p99_same_sampling > 0.0
          ? m.transition_accel_p99 / m.database_accel_p99_same_sampling
          : 0.0;
}

// The database's own geometric skating at the run's dt, over every clip: a run plays
// locomotion, actions and idle alike, and its standing frames count as the data's do.
void compare_skating_with_database(const ControllerDatabase& database, float dt,
                                   EvaluationMetrics& m) {
  m.foot_skate_geom_data_cm_s_mean = database_geometric_skate(database.database(), dt, 0);
}

}  // namespace

double database_acceleration_p99(const Database& db, float dt, uint64_t excluded_tags, bool cubic) {
  if (!(dt > 0.0f)) return 0.0;
  const size_t joints = static_cast<size_t>(db.joint_count());
  PercentileHistogram accelerations;
  std::vector<Transform> local(joints), global(joints);
  // The joint positions of the last three steps, by step modulo 3: the second difference needs
  // no more, so memory does not grow with the clips' length or a small dt.
  std::vector<glm::vec3> recent[3];
  for (std::vector<glm::vec3>& step : recent) step.assign(joints, glm::vec3(0.0f));
  for (const ClipRange& clip : db.clips()) {
    if (clip.tags & excluded_tags) continue;
    const float duration = static_cast<float>(clip.frame_count() - 1) * db.frame_time();
    const int64_t steps = clamped_integer<int64_t>(std::floor(duration / dt)) + 1;
    if (steps < 3) continue;
    for (int64_t s = 0; s < steps; ++s) {
      const float x = static_cast<float>(s) * dt / db.frame_time();
      const int i0 = std::min(clamped_integer<int>(std::floor(x)), clip.frame_count() - 1);
      const int i1 = std::min(i0 + 1, clip.frame_count() - 1);
      const float a = x - static_cast<float>(i0);
      for (size_t j = 0; j < joints; ++j) {
        local[j] = sample_database_joint(db, clip.start + i0, clip.start + i1, a, j, cubic,
                                         InterpolationMethod::Nlerp);
      }
      forward_kinematics(db.skeleton().parents(), local, global);
      std::vector<glm::vec3>& now = recent[s % 3];
      for (size_t j = 0; j < joints; ++j) now[j] = global[j].translation;
      if (s >= 2) {
        joint_accelerations(recent[(s - 2) % 3], recent[(s - 1) % 3], now, dt, accelerations);
      }
    }
  }
  return accelerations.percentile(99.0);
}

Result<EvaluationResult> evaluate_script(std::shared_ptr<const ControllerDatabase> database,
                                         const InputScript& script,
                                         const EvaluationOptions& options) {
  if (!std::isfinite(options.seconds) || options.seconds < 0.0f) {
    return Error{"evaluation: seconds must be >= 0"};
  }
  if (!std::isfinite(options.start.x) || !std::isfinite(options.start.y)) {
    return Error{"evaluation: the start position must be finite"};
  }
  if (options.transition_report < 0 || options.transition_report > kMaxTransitionReport) {
    return Error{"evaluation: transition_report must be in [0, " +
                 std::to_string(kMaxTransitionReport) + "]"};
  }
  const float dt = options.dt;
  const float seconds = options.seconds > 0.0f ? options.seconds : script.duration() + 2.0f;
  const Result<int> frame_count = scripted_run_frames(seconds, dt);
  if (!frame_count) return Error{"evaluation: " + frame_count.message()};
  if (!database) return Error{"evaluation: no database"};
  Result<Controller> made = Controller::create(database, options.settings);
  if (!made) return Error{made.message()};
  Controller& controller = *made;
  controller.set_world(options.world);
  // A controller is created at the world origin; only a start elsewhere is a teleport, so a
  // run from the origin is the same run it always was.
  if (options.start != glm::dvec2(0.0)) {
    controller.teleport_world(glm::dvec3(options.start.x, 0.0, options.start.y), 0.0f);
  }
  const Database& db = database->database();
  const size_t joints = static_cast<size_t>(db.joint_count());

  if (options.dump) *options.dump << csv_header(db) << "\n";
  EvaluationAccumulator accumulator(db.roles(), joints, dt);
  accumulator.keep_transition_samples(options.transition_report);
  std::vector<glm::vec3> positions(joints);
  WorldReadings world(options.world, db.roles(), joints);
  PlayedAcceleration played(db, dt, options.settings.cubic_playback);
  PlayedToes played_toes(db, options.settings.cubic_playback);
  using Clock = std::chrono::steady_clock;
  for (int f = 0; f < *frame_count; ++f) {
    const float t = static_cast<float>(f + 1) * dt;
    const ControllerInput input = script.at(t);
    const Clock::time_point start = Clock::now();
    controller.update(dt, input);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    EvaluationFrame frame = frame_record(controller, t, elapsed, positions);
    world.read(controller, dt, frame);
    played_toes.read(controller.debug(), frame);
    accumulator.add(frame);
    played.add(controller.debug());
    if (options.dump) *options.dump << csv_row(frame) << "\n";
    if (options.on_frame) options.on_frame(frame);
  }
  EvaluationResult result;
  result.metrics = accumulator.metrics();
  result.transition_samples = accumulator.transition_samples();
  compare_with_database(*database, options, result.metrics);
  compare_skating_with_database(*database, dt, result.metrics);
  EvaluationMetrics& m = result.metrics;
  m.played_accel_p99 = played.p99();
  m.transition_accel_ratio_played =
      m.played_accel_p99 > 0.0 ? m.transition_accel_p99 / m.played_accel_p99 : 0.0;
  m.leg_accel_played_max = played.leg_max();
  const double leg_reference = std::max(m.leg_accel_played_max, m.database_accel_p99_same_sampling);
  m.leg_accel_ratio = leg_reference > 0.0 ? m.leg_accel_max / leg_reference : 0.0;
  return result;
}

}  // namespace mm
