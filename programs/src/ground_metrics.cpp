// Feet and body against the ground (definitions in ground_metrics.hpp).

#include "mm/programs/ground_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "mm/database/sampling.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/pose.hpp"
#include "statistics.hpp"

namespace mm {

using detail::LinearHistogram;
using detail::PercentileHistogram;
using detail::RunningMean;

namespace {

// A toe planted by geometry on two consecutive frames (ground_metrics.hpp), and its speed.
struct GeomPlant {
  bool low_and_slow[2] = {false, false};  // on the previous frame
  RunningMean speed_cm_s;

  // `height` above its ground now, `speed` horizontally (m/s) from the previous frame.
  void add(int side, float height, float speed) {
    const bool now = height < kGeomPlantedHeight && speed < kGeomPlantedSpeed;
    if (now && low_and_slow[side]) speed_cm_s.add(100.0 * speed);
    low_and_slow[side] = now;
  }
};

float horizontal_speed(const glm::vec3& now, const glm::vec3& before, float dt) {
  return std::hypot(now.x - before.x, now.z - before.z) / dt;
}

// The knee's angle away from straight (degrees): 180 minus the angle at the knee between the
// thigh and the shin.
double knee_bend_deg(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle) {
  const glm::vec3 thigh = hip - knee, shin = ankle - knee;
  const float lengths = glm::length(thigh) * glm::length(shin);
  if (lengths <= 0.0f) return 180.0;
  const double cosine = std::clamp(glm::dot(thigh, shin) / lengths, -1.0f, 1.0f);
  return 180.0 - glm::degrees(std::acos(cosine));
}

}  // namespace

float foot_support_height(float toe_ground, const GroundHit& under,
                          std::span<const GroundHit> along, float toe_y) {
  const bool plane =
      under.hit && finite(under.point) && finite(under.normal) && under.normal.y > 0.1f;
  const glm::vec3 n = plane ? under.normal : glm::vec3(0.0f, 1.0f, 0.0f);
  const glm::vec3 at = plane ? under.point : glm::vec3(0.0f, toe_ground, 0.0f);
  float support = toe_ground;
  for (const GroundHit& hit : along) {
    if (!hit.hit || !finite(hit.point)) continue;
    const glm::vec3 d = hit.point - at;
    // Without the plane's point (a miss under the toe) only the height counts: level ground.
    const float on_plane = plane ? at.y - (n.x * d.x + n.z * d.z) / n.y : toe_ground;
    if (hit.point.y > on_plane + kFootEdgeRise && hit.point.y <= toe_y) {
      support = std::max(support, hit.point.y);
    }
  }
  return support;
}

std::array<glm::vec3, kFootSupportProbes> foot_support_points(const glm::vec3& toe,
                                                              const glm::vec3& heel) {
  std::array<glm::vec3, kFootSupportProbes> points;
  for (int k = 0; k < kFootSupportSamples; ++k) {
    points[static_cast<size_t>(k)] =
        glm::mix(toe, heel, static_cast<float>(k + 1) / kFootSupportSamples);
  }
  const glm::vec2 forward(toe.x - heel.x, toe.z - heel.z);
  const float length = glm::length(forward);
  const glm::vec2 across =
      length > 1e-4f ? glm::vec2(-forward.y, forward.x) / length : glm::vec2(1.0f, 0.0f);
  const glm::vec3 side = kFootHalfWidth * glm::vec3(across.x, 0.0f, across.y);
  points[kFootSupportSamples] = toe + side;
  points[kFootSupportSamples + 1] = toe - side;
  const glm::vec2 ahead = length > 1e-4f ? forward / length * kToeReach : glm::vec2(0.0f);
  points[kFootSupportSamples + 2] = toe + glm::vec3(ahead.x, 0.0f, ahead.y);
  return points;
}

struct GroundAccumulator::State {
  JointRoleIndices roles;
  float dt = 0.0f;
  int toes[2] = {-1, -1};
  int frames = 0;
  std::vector<glm::vec3> previous_toes = std::vector<glm::vec3>(2);
  float hips_heights[2] = {0.0f, 0.0f};  // the hips' world y, two and one frames back

  GeomPlant plant;
  float clearance_min = INFINITY;
  LinearHistogram clearance{-100.0, 100.0, 4000};  // cm: 0.5 mm bins over +-1 m
  RunningMean penetration, floating, floating_data, hips_height;
  double penetration_max = 0.0;
  double hips_height_squares = 0.0;
  PercentileHistogram hips_accelerations;
  int straight_knees = 0;
  double wall_depth_max = 0.0;
  int stuck_frames = 0;
};

GroundAccumulator::GroundAccumulator(const JointRoleIndices& roles, float dt)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.roles = roles;
  s.dt = dt;
  s.toes[0] = roles.left_toe >= 0 ? roles.left_toe : roles.left_foot;
  s.toes[1] = roles.right_toe >= 0 ? roles.right_toe : roles.right_foot;
}

GroundAccumulator::~GroundAccumulator() = default;

void GroundAccumulator::shift(const glm::vec3& by) {
  for (glm::vec3& toe : state_->previous_toes) toe -= by;
}

int GroundAccumulator::toe(int side) const {
  return state_->toes[side != 0 ? 1 : 0];
}

void GroundAccumulator::add(const GroundFrame& r) {
  State& s = *state_;
  float lowest = INFINITY;
  for (int side = 0; side < 2; ++side) {
    if (s.toes[side] < 0) continue;
    const glm::vec3& toe = r.joints[static_cast<size_t>(s.toes[side])];
    const float height = toe.y - r.toe_ground[side];
    lowest = std::min(lowest, height);
    s.penetration.add(100.0 * std::max(0.0f, -height));
    s.penetration_max = std::max(s.penetration_max, 100.0 * std::max(0.0f, -height));
    if (r.contact[side]) {
      const float support = std::max(r.toe_ground[side], r.toe_support[side]);
      s.floating.add(100.0 * std::max(0.0f, toe.y - support));
      if (std::isfinite(r.played_toe[side])) {
        s.floating_data.add(100.0 * std::max(0.0f, r.played_toe[side]));
      }
    }
    if (s.frames > 0) s.plant.add(side, height, horizontal_speed(toe, s.previous_toes[side], s.dt));
    s.previous_toes[side] = toe;
  }
  if (std::isfinite(lowest)) {
    s.clearance_min = std::min(s.clearance_min, lowest);
    s.clearance.add(100.0 * lowest);
  }
  const JointRoleIndices& roles = s.roles;
  if (roles.hips >= 0) {
    const float y = r.joints[static_cast<size_t>(roles.hips)].y;
    const double height = 100.0 * (y - r.hips_ground);
    s.hips_height.add(height);
    s.hips_height_squares += height * height;
    if (s.frames >= 2) {
      s.hips_accelerations.add(std::abs(y - 2.0f * s.hips_heights[1] + s.hips_heights[0]) /
                               (s.dt * s.dt));
    }
    s.hips_heights[0] = s.hips_heights[1];
    s.hips_heights[1] = y;
  }
  const int legs[2][3] = {{roles.left_upper_leg, roles.left_lower_leg, roles.left_foot},
                          {roles.right_upper_leg, roles.right_lower_leg, roles.right_foot}};
  bool straight = false;
  for (const auto& leg : legs) {
    if (leg[0] < 0 || leg[1] < 0 || leg[2] < 0) continue;
    straight =
        straight ||
        knee_bend_deg(r.joints[static_cast<size_t>(leg[0])], r.joints[static_cast<size_t>(leg[1])],
                      r.joints[static_cast<size_t>(leg[2])]) < kStraightKneeDegrees;
  }
  s.straight_knees += straight ? 1 : 0;
  s.wall_depth_max = std::max(s.wall_depth_max, 100.0 * r.wall_depth);
  s.stuck_frames += r.stuck ? 1 : 0;
  ++s.frames;
}

GroundMetrics GroundAccumulator::metrics() const {
  const State& s = *state_;
  GroundMetrics m;
  m.foot_skate_geom_cm_s_mean = s.plant.speed_cm_s.value();
  m.foot_skate_geom_frames = s.plant.speed_cm_s.count;
  m.toe_clearance_cm_min = std::isfinite(s.clearance_min) ? 100.0 * s.clearance_min : 0.0;
  m.toe_clearance_cm_p1 = s.clearance.percentile(1.0);
  m.foot_penetration_cm_mean = s.penetration.value();
  m.foot_penetration_cm_max = s.penetration_max;
  m.foot_float_cm_mean = s.floating.value();
  m.foot_float_data_cm_mean = s.floating_data.value();
  m.hips_height_cm_mean = s.hips_height.value();
  if (s.hips_height.count > 0) {
    const double mean = s.hips_height.value();
    m.hips_height_cm_std =
        std::sqrt(std::max(0.0, s.hips_height_squares / s.hips_height.count - mean * mean));
  }
  m.hips_vertical_accel_p99_m_s2 = s.hips_accelerations.percentile(99.0);
  m.knee_overextension_frames = s.straight_knees;
  m.wall_depth_cm_max = s.wall_depth_max;
  m.stuck_s = s.stuck_frames * static_cast<double>(s.dt);
  return m;
}

WallDepthReader::WallDepthReader(size_t joints)
    : sweeps_(joints),
      sweep_hits_(joints),
      probes_(joints),
      probe_hits_(joints),
      depth_(joints),
      joint_(joints) {}

float WallDepthReader::read(const WorldQueries& world, const glm::dvec3& origin,
                            const glm::vec3& root, std::span<const glm::vec3> joints, float above,
                            int* deepest) {
  if (deepest) *deepest = -1;
  size_t count = 0;
  for (size_t j = 0; j < joints.size() && count < sweeps_.size(); ++j) {
    const glm::vec3& p = joints[j];
    if (p.y < above || std::hypot(p.x - root.x, p.z - root.z) < 1e-4f) continue;
    // The sphere's centre at the joint's height (a sweep's shape stands on its `from`).
    const float bottom = p.y - kWallProbeRadius;
    sweeps_[count] = ShapeSweep{glm::vec3(root.x, bottom, root.z), glm::vec3(p.x, bottom, p.z),
                                kWallProbeRadius, 2.0f * kWallProbeRadius};
    joint_[count++] = static_cast<int>(j);
  }
  if (count == 0) return 0.0f;
  world.sweep(origin, std::span(sweeps_).first(count), std::span(sweep_hits_).first(count));
  // Only the joints past a face need their top.
  size_t behind = 0;
  for (size_t k = 0; k < count; ++k) {
    const SweepHit& hit = sweep_hits_[k];
    const glm::vec3 n(hit.normal.x, 0.0f, hit.normal.z);
    if (!hit.hit || !std::isfinite(hit.fraction) || !(glm::length(n) > 1e-3f)) continue;
    const ShapeSweep& sweep = sweeps_[k];
    const float fraction = std::clamp(hit.fraction, 0.0f, 1.0f);
    const glm::vec3 centre = glm::mix(sweep.from, sweep.to, fraction);
    // A sweep met at its start began inside or against the wall: where its face is, is unknown,
    // and the whole way out to the joint is inside.
    const float depth = fraction > 0.0f
                            ? glm::dot(centre - sweep.to, glm::normalize(n)) - kWallProbeRadius
                            : glm::distance(sweep.from, sweep.to);
    if (!(depth > 0.0f)) continue;
    const glm::vec3& p = joints[static_cast<size_t>(joint_[k])];
    probes_[behind] =
        GroundProbe{p + glm::vec3(0.0f, kTopProbeHeight, 0.0f), kTopProbeHeight + 1.0f, 0.0f};
    depth_[behind] = depth;
    joint_[behind++] = joint_[k];
  }
  if (behind == 0) return 0.0f;
  world.probe_ground(origin, std::span(probes_).first(behind),
                     std::span(probe_hits_).first(behind));
  float deepest_depth = 0.0f;
  for (size_t k = 0; k < behind; ++k) {
    float depth = depth_[k];
    const GroundHit& top = probe_hits_[k];
    if (top.hit && std::isfinite(top.point.y)) {
      depth = std::min(depth, top.point.y - joints[static_cast<size_t>(joint_[k])].y);
    }
    if (depth > deepest_depth) {
      deepest_depth = depth;
      if (deepest) *deepest = joint_[k];
    }
  }
  return deepest_depth;
}

// Twice kStuckSpeed, at the frame's start and end: a simulation object starting from rest
// beside a wall (the stick turned along it, or back) moves as slowly as it would in the open
// until its spring has built the speed up, and the yield toward the character may take back half
// of a slide along a wall (Controller::without_slide_back); neither is the wall holding it.
bool held_at_wall(bool blocked, const glm::vec3& contact, const glm::vec3& desired_velocity,
                  const glm::vec3& velocity_before, const glm::vec3& velocity_now,
                  float moved_speed) {
  if (!blocked || !(glm::length(contact) > 0.5f) || !(moved_speed < kStuckSpeed)) return false;
  const glm::vec3 along = desired_velocity - contact * glm::dot(desired_velocity, contact);
  const float push = glm::length(along);
  if (!(push >= kStuckAlongSpeed)) return false;
  const glm::vec3 direction = along / push;
  return std::min(glm::dot(velocity_before, direction), glm::dot(velocity_now, direction)) >=
         2.0f * kStuckSpeed;
}

double database_geometric_skate(const Database& db, float dt, uint64_t excluded_tags) {
  if (!(dt > 0.0f)) return 0.0;
  const size_t joints = static_cast<size_t>(db.joint_count());
  const int toes[2] = {db.roles().left_toe >= 0 ? db.roles().left_toe : db.roles().left_foot,
                       db.roles().right_toe >= 0 ? db.roles().right_toe : db.roles().right_foot};
  std::vector<Transform> local(joints), global(joints);
  GeomPlant plant;
  for (const ClipRange& clip : db.clips()) {
    if (clip.tags & excluded_tags) continue;
    const float duration = static_cast<float>(clip.frame_count() - 1) * db.frame_time();
    const int64_t steps = clamped_integer<int64_t>(std::floor(duration / dt)) + 1;
    glm::vec3 previous[2];
    for (int64_t step = 0; step < steps; ++step) {
      const float x = static_cast<float>(step) * dt / db.frame_time();
      const int i0 = std::min(clamped_integer<int>(std::floor(x)), clip.frame_count() - 1);
      const int i1 = std::min(i0 + 1, clip.frame_count() - 1);
      for (size_t j = 0; j < joints; ++j) {
        local[j] =
            sample_database_joint(db, clip.start + i0, clip.start + i1, x - static_cast<float>(i0),
                                  j, false, InterpolationMethod::Nlerp);
      }
      forward_kinematics(db.skeleton().parents(), local, global);
      for (int side = 0; side < 2; ++side) {
        if (toes[side] < 0) continue;
        const glm::vec3 toe = global[static_cast<size_t>(toes[side])].translation;
        // A clip's first step has no previous one: not low and slow, so it starts no sample.
        plant.add(side, step == 0 ? INFINITY : toe.y,
                  step == 0 ? 0.0f : horizontal_speed(toe, previous[side], dt));
        previous[side] = toe;
      }
    }
  }
  return plant.speed_cm_s.value();
}

}  // namespace mm
