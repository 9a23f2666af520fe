// Scripted evaluation: run, record every frame, then measure (definitions in evaluation.hpp).

#include "mm/controller/evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose.hpp"
#include "playback.hpp"

namespace mm {

namespace {

float horizontal_distance(const glm::vec3& a, const glm::vec3& b) {
  return std::hypot(a.x - b.x, a.z - b.z);
}

// The p-th percentile (0..100) by nearest rank; 0 for no values. Reorders `values`.
double percentile(std::vector<double>& values, double p) {
  if (values.empty()) return 0.0;
  const size_t rank =
      std::min(values.size() - 1,
               static_cast<size_t>(std::ceil(p / 100.0 * values.size())) - (p > 0.0 ? 1 : 0));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank),
                   values.end());
  return values[rank];
}

double mean(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

// What one frame of the run leaves behind.
struct FrameRecord {
  float t = 0.0f;
  glm::vec3 sim_position{0.0f};
  float sim_yaw = 0.0f;
  glm::vec3 root_position{0.0f};
  float root_yaw = 0.0f;
  glm::vec3 desired_velocity{0.0f};
  float desired_yaw = 0.0f;
  bool transition = false;
  bool contact[2] = {false, false};
  double update_seconds = 0.0;
  bool searched = false;
  double search_seconds = 0.0;
};

// Acceleration magnitudes (second differences) of every joint but joint 0 at frame f of a run
// whose joint positions are `positions` (frames x joints).
void joint_accelerations(const std::vector<glm::vec3>& positions, size_t joints, size_t f, float dt,
                         std::vector<double>& out) {
  const glm::vec3* a = positions.data() + (f - 1) * joints;
  const glm::vec3* b = positions.data() + f * joints;
  const glm::vec3* c = positions.data() + (f + 1) * joints;
  for (size_t j = 1; j < joints; ++j) {
    out.push_back(glm::length(c[j] - 2.0f * b[j] + a[j]) / (dt * dt));
  }
}

void measure_responses(const std::vector<FrameRecord>& frames, float dt, EvaluationMetrics& m) {
  // Speed: events where the desired speed jumps; done when the root speed is close to it.
  std::vector<double> speed_times, heading_times;
  int speed_start = -1, heading_start = -1;
  float speed_from = 0.0f, speed_to = 0.0f, heading_to = 0.0f;
  for (size_t f = 1; f < frames.size(); ++f) {
    const FrameRecord& r = frames[f];
    const float desired = glm::length(r.desired_velocity);
    const float previous = glm::length(frames[f - 1].desired_velocity);
    if (std::abs(desired - previous) >= kSpeedEventChange) {
      if (speed_start >= 0) ++m.speed_events;
      speed_start = static_cast<int>(f);
      speed_from = previous;
      speed_to = desired;
    }
    if (speed_start >= 0) {
      const float speed = horizontal_distance(r.root_position, frames[f - 1].root_position) / dt;
      if (std::abs(speed - speed_to) <= 0.1f * std::abs(speed_to - speed_from)) {
        speed_times.push_back((static_cast<double>(f) - speed_start) * dt);
        ++m.speed_events;
        speed_start = -1;
      }
    }
    if (std::abs(wrap_angle(r.desired_yaw - frames[f - 1].desired_yaw)) >= kHeadingEventAngle) {
      if (heading_start >= 0) ++m.heading_events;
      heading_start = static_cast<int>(f);
      heading_to = r.desired_yaw;
    }
    if (heading_start >= 0) {
      heading_to = r.desired_yaw;  // a turn that keeps going is followed to its end
      if (std::abs(wrap_angle(r.root_yaw - heading_to)) <= glm::radians(10.0f)) {
        heading_times.push_back((static_cast<double>(f) - heading_start) * dt);
        ++m.heading_events;
        heading_start = -1;
      }
    }
  }
  if (speed_start >= 0) ++m.speed_events;
  if (heading_start >= 0) ++m.heading_events;
  m.speed_events_reached = static_cast<int>(speed_times.size());
  m.heading_events_reached = static_cast<int>(heading_times.size());
  m.speed_response_s = mean(speed_times);
  m.heading_response_s = mean(heading_times);
}

std::string csv_header(const Database& db) {
  std::string h =
      "t,sim_x,sim_z,sim_yaw_deg,root_x,root_z,root_yaw_deg,desired_vx,desired_vz,"
      "desired_yaw_deg,transition,contact_l,contact_r";
  for (const std::string& name : db.skeleton.names()) {
    h.append(",").append(name).append("_x,").append(name).append("_y,").append(name).append("_z");
  }
  return h;
}

std::string csv_row(const FrameRecord& r, const glm::vec3* joints, size_t joint_count) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%.6f,%.6f,%.6f,%.4f,%.6f,%.6f,%.4f,%.6f,%.6f,%.4f,%d,%d,%d",
                r.t, r.sim_position.x, r.sim_position.z, glm::degrees(r.sim_yaw), r.root_position.x,
                r.root_position.z, glm::degrees(r.root_yaw), r.desired_velocity.x,
                r.desired_velocity.z, glm::degrees(r.desired_yaw), r.transition ? 1 : 0,
                r.contact[0] ? 1 : 0, r.contact[1] ? 1 : 0);
  std::string row = buffer;
  for (size_t j = 0; j < joint_count; ++j) {
    std::snprintf(buffer, sizeof buffer, ",%.6f,%.6f,%.6f", joints[j].x, joints[j].y, joints[j].z);
    row += buffer;
  }
  return row;
}

}  // namespace

double database_acceleration_p99(const Database& db, float dt, uint64_t excluded_tags, bool cubic) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  std::vector<double> accelerations;
  std::vector<Transform> local(joints), global(joints);
  std::vector<glm::vec3> positions;
  for (const ClipRange& clip : db.clips) {
    if (clip.tags & excluded_tags) continue;
    const float duration = static_cast<float>(clip.frame_count() - 1) * db.frame_time;
    const int steps = static_cast<int>(std::floor(duration / dt)) + 1;
    if (steps < 3) continue;
    positions.assign(static_cast<size_t>(steps) * joints, glm::vec3(0.0f));
    for (int s = 0; s < steps; ++s) {
      const float x = static_cast<float>(s) * dt / db.frame_time;
      const int i0 = std::min(static_cast<int>(std::floor(x)), clip.frame_count() - 1);
      const int i1 = std::min(i0 + 1, clip.frame_count() - 1);
      const float a = x - static_cast<float>(i0);
      for (size_t j = 0; j < joints; ++j) {
        local[j] = detail::sample_database_joint(db, clip.start + i0, clip.start + i1, a, j, cubic,
                                                 InterpolationMethod::Nlerp);
      }
      forward_kinematics(db.skeleton.parents(), local, global);
      for (size_t j = 0; j < joints; ++j) {
        positions[static_cast<size_t>(s) * joints + j] = global[j].translation;
      }
    }
    for (int s = 1; s + 1 < steps; ++s) {
      joint_accelerations(positions, joints, static_cast<size_t>(s), dt, accelerations);
    }
  }
  return percentile(accelerations, 99.0);
}

Result<EvaluationResult> evaluate_script(std::shared_ptr<const ControllerDatabase> database,
                                         const InputScript& script,
                                         const EvaluationOptions& options) {
  if (!(options.dt > 0.0f) || !(options.dt <= 1.0f)) {
    return Error{"evaluation: dt must be in (0, 1] seconds"};
  }
  if (!std::isfinite(options.seconds) || options.seconds < 0.0f) {
    return Error{"evaluation: seconds must be >= 0"};
  }
  if (!database) return Error{"evaluation: no database"};
  Result<Controller> made = Controller::create(database, options.settings);
  if (!made) return Error{made.message()};
  Controller& controller = *made;
  const Database& db = database->database();
  const float dt = options.dt;
  const float seconds = options.seconds > 0.0f ? options.seconds : script.duration() + 2.0f;
  const size_t frame_count = static_cast<size_t>(std::ceil(seconds / dt));
  const size_t joints = static_cast<size_t>(db.joint_count());

  std::vector<FrameRecord> frames(frame_count);
  std::vector<glm::vec3> positions(frame_count * joints);
  using Clock = std::chrono::steady_clock;
  for (size_t f = 0; f < frame_count; ++f) {
    const float t = static_cast<float>(f + 1) * dt;
    const ControllerInput input = script.at(t);
    const Clock::time_point start = Clock::now();
    controller.update(dt, input);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const ControllerDebug& d = controller.debug();
    FrameRecord& r = frames[f];
    r.t = t;
    r.sim_position = d.simulation_position;
    r.sim_yaw = quat_yaw(d.simulation_rotation);
    r.root_position = controller.root_transform().translation;
    r.root_yaw = quat_yaw(controller.root_transform().rotation);
    r.desired_velocity = d.desired_velocity;
    r.desired_yaw = quat_yaw(d.desired_rotation);
    r.transition = d.transitioned;
    r.contact[0] = d.contact[0];
    r.contact[1] = d.contact[1];
    r.update_seconds = elapsed;
    r.searched = d.searched;
    r.search_seconds = d.search_seconds;
    const std::span<const Transform> globals = controller.global_transforms();
    for (size_t j = 0; j < joints; ++j) positions[f * joints + j] = globals[j].translation;
  }

  EvaluationResult result;
  EvaluationMetrics& m = result.metrics;
  m.frames = static_cast<int>(frame_count);
  m.seconds = static_cast<double>(frame_count) * dt;
  const int toes[2] = {db.roles.left_toe >= 0 ? db.roles.left_toe : db.roles.left_foot,
                       db.roles.right_toe >= 0 ? db.roles.right_toe : db.roles.right_foot};
  std::vector<double> skate, distance, facing, stand_root, stand_foot, updates, searches;
  float stand_time = 0.0f;
  int transitions = 0;
  for (size_t f = 0; f < frame_count; ++f) {
    const FrameRecord& r = frames[f];
    distance.push_back(100.0 * horizontal_distance(r.root_position, r.sim_position));
    facing.push_back(std::abs(glm::degrees(wrap_angle(r.root_yaw - r.sim_yaw))));
    updates.push_back(r.update_seconds * 1e6);
    if (r.searched) searches.push_back(r.search_seconds * 1e6);
    transitions += r.transition ? 1 : 0;
    stand_time = glm::length(r.desired_velocity) == 0.0f ? stand_time + dt : 0.0f;
    if (f == 0) continue;
    for (int side = 0; side < 2; ++side) {
      const size_t toe = static_cast<size_t>(toes[side]);
      const double speed =
          100.0 *
          horizontal_distance(positions[f * joints + toe], positions[(f - 1) * joints + toe]) / dt;
      if (r.contact[side] && frames[f - 1].contact[side]) skate.push_back(speed);
      if (stand_time >= kStandSettleSeconds) stand_foot.push_back(speed);
    }
    if (stand_time >= kStandSettleSeconds) {
      stand_root.push_back(100.0 *
                           horizontal_distance(r.root_position, frames[f - 1].root_position) / dt);
    }
  }
  m.foot_skate_cm_s_mean = mean(skate);
  m.foot_skate_cm_s_p95 = percentile(skate, 95.0);
  m.root_sim_distance_cm_mean = mean(distance);
  m.root_sim_distance_cm_max =
      distance.empty() ? 0.0 : *std::max_element(distance.begin(), distance.end());
  m.facing_error_deg_mean = mean(facing);
  m.stand_root_speed_cm_s_mean = mean(stand_root);
  m.stand_foot_speed_cm_s_mean = mean(stand_foot);
  m.stand_frames = static_cast<int>(stand_root.size());
  m.transitions_per_s = transitions / m.seconds;
  m.search_us_mean = mean(searches);
  m.update_us_mean = mean(updates);
  measure_responses(frames, dt, m);

  // Joint acceleration over the 10 frames from each transition, against the database's own.
  std::vector<double> accelerations;
  for (size_t f = 0; f < frame_count; ++f) {
    if (!frames[f].transition) continue;
    for (size_t g = std::max<size_t>(f, 1); g < std::min(f + 10, frame_count - 1); ++g) {
      joint_accelerations(positions, joints, g, dt, accelerations);
    }
  }
  m.transition_accel_p99 = percentile(accelerations, 99.0);
  m.database_accel_p99 =
      database_acceleration_p99(db, dt, database->action_tags() | database->idle_tags());
  m.transition_accel_ratio =
      m.database_accel_p99 > 0.0 ? m.transition_accel_p99 / m.database_accel_p99 : 0.0;
  m.database_accel_p99_same_sampling =
      options.settings.cubic_playback
          ? database_acceleration_p99(db, dt, database->action_tags() | database->idle_tags(), true)
          : m.database_accel_p99;
  m.transition_accel_ratio_same_sampling =
      m.database_accel_p99_same_sampling > 0.0
          ? m.transition_accel_p99 / m.database_accel_p99_same_sampling
          : 0.0;

  result.csv_header = csv_header(db);
  if (options.keep_frames) {
    result.csv_rows.reserve(frame_count);
    for (size_t f = 0; f < frame_count; ++f) {
      result.csv_rows.push_back(csv_row(frames[f], positions.data() + f * joints, joints));
    }
  }
  return result;
}

}  // namespace mm
