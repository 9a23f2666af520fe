// The controller's update loop. Its phases, in order, are the private member functions named in
// controller.hpp; this file keeps them in that order.

#include "mm/controller/controller.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <numbers>

#include "mm/database/sampling.hpp"
#include "mm/runtime/approach.hpp"
#include "mm/runtime/atan2_polynomial.hpp"
#include "mm/runtime/constraints.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/ik.hpp"
#include "mm/runtime/pose.hpp"
#include "mm/runtime/skinning.hpp"
#include "mm/runtime/spring.hpp"
#include "mm/runtime/transform_sse.hpp"

#include "mm/controller/leg_reach.hpp"
#include "mm/controller/style_search.hpp"

namespace mm {

namespace {

const glm::vec3 kUp(0.0f, 1.0f, 0.0f);
// A foot released during a contact locks again once its easing offset is this small (m).
constexpr float kRelockOffset = 0.01f;
// Strafing, the chest's twist toward the facing (turn_chest_to_facing): at most this (radians),
// and its spring's halflife (s).
constexpr float kMaxChestTwist = 1.0f;
constexpr float kChestTwistReach = 1.75f;
constexpr float kChestTwistHalflife = 0.1f;
// Slower than this (m/s), a strafe has no direction to warp the legs toward; moving farther than
// this (radians) from the facing, it moves backward, and the legs warp toward straight back.
constexpr float kWarpMinSpeed = 0.1f;
constexpr float kWarpMaxTravel = 1.75f;
// A facing farther than this (radians) from the last one is a new facing, reached when the root
// comes within kWarpFacingReached of it.
constexpr float kWarpRefacing = 0.35f;
constexpr float kWarpFacingReached = 0.17f;
// Standing, a held toe farther than this (m) from where the idle pose puts it steps there.
constexpr float kSettleDistance = 0.08f;
// Standing, a held foot turned farther than this (radians) from the idle pose's heading steps
// round to it: a turn on the spot leaves the planted feet behind and twists the legs.
constexpr float kSettleHeading = 0.25f;
// A step lands once its heading too has come this close (radians) to the animation's, so a
// foot never plants with the twist it stepped to undo.
constexpr float kRelockHeading = 0.05f;
// A step lifts the toe by this share of the distance it still has to go, at most kStepHeight
// (m): it rises as it leaves and lands as it arrives.
constexpr float kStepLift = 1.0f;
constexpr float kStepHeight = 0.08f;
// The bound on the lift's acceleration (m/s^2): it starts from rest without a jolt. On a spring
// the lift began at its hardest acceleration, and a standing leg, near straight, turned that into
// a knee snapping forward (docs/controller.md, Legs between transitions).
constexpr float kLiftAcceleration = 10.0f;
// A held toe farther than this share of the leg's length from the hip (through the animated
// foot) steps rather than being dragged: past full length, since soft reach still bends it.
constexpr float kStepReach = 1.03f;
// It steps only if the animated toe on its ground is at least this much nearer the hip (m).
constexpr float kStepReachGain = 0.02f;
// An animated toe lower than this above its ground (m) and horizontally slower than this (m/s)
// is planted, whatever its label says: the skating metric's rule (ground_metrics.hpp).
constexpr float kPlantedHeight = 0.06f;
constexpr float kPlantedSpeed = 0.35f;
// A lock begins only on a toe at most this high (m) above the ground under it now: the data's
// labelled toes stand lower.
constexpr float kLockAboveGround = 0.12f;
// Nor on a toe whose ground still rises faster than this (m/s), on its way onto a step: at
// stairs_down's riser, its ground rising toward the tread, a toe whose footprint had reached the
// tread's edge was locked 3.6 cm above the tread, in front of its edge; its ground fell back the
// next update and the toe, let go, swung on over the tread 0.33 cm above it (docs/world.md,
// session 28).
constexpr float kLockGroundRising = 0.5f;
// A labelled contact whose animated toe moves horizontally faster than this (m/s) is not held:
// planted toes in the data move under 0.3 m/s, and some clips label a toe sweeping in at a
// run's landing or out at its push-off. Held there, the toe stops dead and the leg snaps after
// the animation on release.
constexpr float kLockSpeed = 0.6f;
constexpr float kSweepHalflife = 0.015f;
// A released toe leaves with this share of the animated toe's velocity held back (its offset
// starts moving against it), so that it does not go from rest to the animation's speed in one
// update: at a run's push-off that speed is metres per second.
constexpr float kReleaseHold = 0.5f;
// Bounds how fast a released toe's offset starts accelerating: a long offset (the new clip's foot
// far from the held one) decays on a longer halflife than foot_lock_release_halflife, 2 ln 2
// sqrt(offset / kReleaseMaxAcceleration). A spring of spring.hpp starts from rest at
// (kHalflifeFrequencyFactor / halflife)^2 times its offset, so the bound is
// (kHalflifeFrequencyFactor / 2 ln 2)^2 = 1.47 times this: about 29 m/s^2 (the formula was
// written with the other convention of halflife; kept, as the motion was measured with it).
constexpr float kReleaseMaxAcceleration = 20.0f;
// The bound on the angular acceleration (rad/s^2) with which a heel takes up the lift a lock
// needed as it began: taken at once, the ankle swung about the toe in one update.
constexpr float kHeelLagAcceleration = 200.0f;
// How much of that lift (radians) is taken at once all the same: eased, the toe slid for the
// few updates the heel took to rise, and a lock begins a little out of reach at most steps.
constexpr float kHeelRiseAtOnce = 0.05f;
// Standing, a held toe's heel is lifted this much (radians) beyond what the toe needs, the margin
// fading in from no lift (lifted_heel): lifted exactly as far as needed, the ankle sat at the edge
// of the softened reach, and the leg went from clamped to free as the heel came down after a
// release, a kink the knee, standing near straight, turned into a snap. Not in motion, where the
// legs are bent: there the margin only lifted the heels higher (on the second course's stairs,
// the walk's transitions read rougher).
constexpr float kHeelMargin = 0.02f;
// A held toe whose animated toe rises faster than this (m/s) is lifting off: released, it
// follows the animation's own lift rather than stepping with a lift of its own.
constexpr float kLiftOffSpeed = 0.2f;
const glm::vec3 kForward(0.0f, 0.0f, 1.0f);

// A rotation a game may hand in: finite and not far from unit length (it is normalized).
bool usable_rotation(const glm::quat& q) {
  return finite(q) && glm::length(q) > 0.5f;
}

glm::quat yaw_rotation(float yaw) {
  return glm::angleAxis(yaw, kUp);
}

// A stick with non-finite axes zeroed, scaled back onto the unit disc, and zero inside the
// dead zone (outside it the magnitude is rescaled so it still reaches 1).
glm::vec2 sanitize_stick(glm::vec2 s, float deadzone) {
  if (!std::isfinite(s.x)) s.x = 0.0f;
  if (!std::isfinite(s.y)) s.y = 0.0f;
  // Bring huge values into range before squaring them.
  const float largest = std::max(std::abs(s.x), std::abs(s.y));
  if (largest > 1.0f) s /= largest;
  const float length = glm::length(s);
  if (length <= deadzone || length < 1e-6f) return glm::vec2(0.0f);
  const float magnitude = std::min(1.0f, (length - deadzone) / (1.0f - deadzone));
  return s * (magnitude / length);
}

// A stick's direction in the world: the camera looks along (sin yaw, 0, cos yaw) and its right
// is forward x up, so stick +x is the camera's right and +y its forward.
glm::vec3 stick_to_world(const glm::vec2& stick, const glm::quat& camera) {
  return camera * glm::vec3(-stick.x, 0.0f, stick.y);
}

// How far (m) a foot's ground lies below the body's before its leg falls short by its height
// alone (reach, reach_down).
constexpr float kShortBelowDepth = 0.05f;
// The most (radians) the root turns to bring a standing pose's hips onto the facing, and the
// halflife (s) over which it follows their offset: short beside the adjustment's own halflife,
// because the two lags add, and a weight shift after a transition inside the idle turns the
// hips by ten degrees in under half a second.
constexpr float kMaxHipsAlign = 0.2f;
constexpr float kHipsAlignHalflife = 0.05f;
// Halflife (s) of the easing between keeping the animation's extension (standing) and not.
constexpr float kStandingReachHalflife = 0.1f;
// The width (m) of the smooth maximum that keeps a toe target above the data's lowest toe: the
// target is raised by at most half of it where it meets the floor, and less above.
constexpr float kFloorSoftness = 0.005f;

// How far forward (m) the knee's pole leans, on top of the knee's own offset from the hip-ankle
// line: enough to decide for a straight leg, small beside the bend of a walking knee.
constexpr float kKneeForwardBias = 0.05f;

// GLM's quaternion product, normalization and rotation of a vector, always inlined: reach's
// products were out-of-line calls, or not, as the inliner's budget for this file fell, and its
// register use changed with each. With SSE2 in registers (transform_sse.hpp: the same bits).
#if defined(__SSE2__)
[[gnu::always_inline]] inline glm::quat product(const glm::quat& p, const glm::quat& q) {
  return sse::to_quat(sse::product(sse::load(p), sse::load(q)));
}
[[gnu::always_inline]] inline glm::quat normalized(const glm::quat& q) {
  return sse::to_quat(sse::normalize(sse::load(q)));
}
[[gnu::always_inline]] inline glm::vec3 rotated(const glm::quat& q, const glm::vec3& v) {
  return sse::to_vec3(sse::rotate(sse::load(q), sse::load(v)));
}
#else
[[gnu::always_inline]] inline glm::quat product(const glm::quat& p, const glm::quat& q) {
  return glm::quat(
      p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
      p.w * q.y + p.y * q.w + p.z * q.x - p.x * q.z, p.w * q.z + p.z * q.w + p.x * q.y - p.y * q.x);
}
inline glm::quat normalized(const glm::quat& q) {
  return glm::normalize(q);
}
inline glm::vec3 rotated(const glm::quat& q, const glm::vec3& v) {
  return q * v;
}
#endif

// The turn (radians, at most FootPlacement::kMaxHeelRise) about the held toe that brings the ankle
// to `distance` from the hip, turning the toe-to-ankle line toward the toe-to-hip line about `axis`
// so that the heel lifts; 0 where the ankle is already that close. `axis` is left as it was where
// the lines give none (a turn easing out keeps its last axis).
float heel_rise_angle(const glm::vec3& toe, const glm::vec3& ankle, const glm::vec3& hip,
                      float distance, glm::vec3& axis) {
  const glm::vec3 a = ankle - toe, h = hip - toe;
  const float foot = glm::length(a), to_hip = glm::length(h);
  const glm::vec3 normal = glm::cross(a, h);
  const float normal_length = glm::length(normal);
  if (foot < 1e-4f || to_hip < 1e-4f || normal_length < 1e-6f * foot * to_hip) return 0.0f;
  axis = normal / normal_length;
  if (glm::length(ankle - hip) <= distance) return 0.0f;
  // The angle between the two lines now, as its cosine and sine (dot and cross products), and
  // the one at which the ankle is `distance` from the hip (law of cosines; pointing straight at
  // the hip where even that falls short). Only their difference is an angle: one atan2 of the
  // difference formulas instead of two arccosines.
  const float scale = 1.0f / (foot * to_hip);
  const float now_cos = glm::dot(a, h) * scale, now_sin = normal_length * scale;
  const float wanted_cos = std::clamp(
      (foot * foot + to_hip * to_hip - distance * distance) * (0.5f * scale), -1.0f, 1.0f);
  const float wanted_sin = std::sqrt(1.0f - wanted_cos * wanted_cos);
  const float turn_cos = now_cos * wanted_cos + now_sin * wanted_sin;
  const float turn_sin = now_sin * wanted_cos - now_cos * wanted_sin;
  // A turn that would lower the heel (the hip below the foot) is no heel rise: the axis is
  // perpendicular to a, so a turns to a cos + (axis x a) sin.
  if (a.y * turn_cos + glm::cross(axis, a).y * turn_sin <= a.y) return 0.0f;
  return std::clamp(atan2_polynomial(turn_sin, turn_cos), 0.0f, FootPlacement::kMaxHeelRise);
}

// The heel's lift for a held toe that needs `needed` (heel_rise_angle): `margin` more, fading
// in smoothly from no lift (it never jumps), no more than the heel's limit.
float lifted_heel(float needed, float margin) {
  if (!(needed > 0.0f)) return 0.0f;
  if (!(margin > 0.0f)) return std::min(needed, FootPlacement::kMaxHeelRise);
  return std::min(needed + margin * (1.0f - std::exp(-needed / margin)),
                  FootPlacement::kMaxHeelRise);
}

// The root (joint 0) and the body (joints 1..) of a pose and its velocities: transitions treat
// them apart.
PoseMotion root_part(const std::vector<Transform>& pose, const std::vector<glm::vec3>& velocities,
                     const std::vector<glm::vec3>& angular_velocities) {
  return {std::span(pose).first(1), std::span(velocities).first(1),
          std::span(angular_velocities).first(1)};
}
PoseMotion body_part(const std::vector<Transform>& pose, const std::vector<glm::vec3>& velocities,
                     const std::vector<glm::vec3>& angular_velocities) {
  return {std::span(pose).subspan(1), std::span(velocities).subspan(1),
          std::span(angular_velocities).subspan(1)};
}

}  // namespace

float Controller::PullFractionCache::of(float halflife, float dt) {
  if (key_.changed(halflife, dt)) fraction_ = pull_fraction(halflife, dt);
  return fraction_;
}

std::string_view sync_mode_name(SyncMode mode) {
  switch (mode) {
    case SyncMode::CharacterFollowsSimulation:
      return "character";
    case SyncMode::SimulationFollowsCharacter:
      return "simulation";
    case SyncMode::None:
      return "none";
  }
  return "none";
}

bool parse_sync_mode(std::string_view name, SyncMode& mode) {
  for (SyncMode m : {SyncMode::CharacterFollowsSimulation, SyncMode::SimulationFollowsCharacter,
                     SyncMode::None}) {
    if (sync_mode_name(m) == name) {
      mode = m;
      return true;
    }
  }
  return false;
}

// ---- Creation --------------------------------------------------------------------------------

Result<Controller> Controller::create(std::shared_ptr<const ControllerDatabase> database,
                                      const ControllerSettings& settings) {
  if (!database) return Error{"controller: no controller database given"};
  Controller c;
  c.shared_ = std::move(database);
  c.db_ = &c.shared_->database();
  if (Status s = c.set_settings(settings); !s) return Error{s.message()};
  if (Status s = c.resolve_schema(); !s) return Error{s.message()};
  if (Status s = c.resolve_joints(); !s) return Error{s.message()};
  c.size_buffers();
  c.start_standing();
  return c;
}

// The trajectory channels' times and where their columns are.
Status Controller::resolve_schema() {
  const FeatureSchema& schema = db_->schema();
  if (schema.channels.size() > static_cast<size_t>(kMaxDebugChannels)) {
    return Error{"controller: the schema has more than " + std::to_string(kMaxDebugChannels) +
                 " channels"};
  }
  for (size_t i = 0; i < schema.channels.size(); ++i) {
    const FeatureChannel& channel = schema.channels[i];
    const bool direction = channel.kind == FeatureKind::TrajectoryDirection;
    if (channel.kind != FeatureKind::TrajectoryPosition && !direction) continue;
    int column = schema.offset(static_cast<int>(i));
    for (float t : channel.times) {
      auto it = std::find(trajectory_times_.begin(), trajectory_times_.end(), t);
      if (it == trajectory_times_.end()) {
        if (trajectory_times_.size() >= ControllerDebug::kMaxTrajectoryPoints) {
          return Error{"controller: the schema has more than " +
                       std::to_string(ControllerDebug::kMaxTrajectoryPoints) +
                       " distinct trajectory times"};
        }
        trajectory_times_.push_back(t);
        it = trajectory_times_.end() - 1;
      }
      trajectory_columns_.push_back(
          {column, static_cast<int>(it - trajectory_times_.begin()), direction});
      column += 2;
    }
  }
  debug_.channel_count = static_cast<int>(schema.channels.size());
  debug_.trajectory_count = static_cast<int>(trajectory_times_.size());
  std::copy(trajectory_times_.begin(), trajectory_times_.end(), debug_.trajectory_times);
  return Status::success();
}

// The legs (upper leg, lower leg, foot, toe; without a toe the foot is held) and the source
// roots to fold (see sample_playback).
Status Controller::resolve_joints() {
  const Database& db = *db_;
  const int feet[2] = {db.roles().left_foot, db.roles().right_foot};
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  for (int side = 0; side < 2; ++side) {
    const int foot = feet[side];
    const int knee = db.skeleton().parent(foot);
    const int hip = knee >= 0 ? db.skeleton().parent(knee) : -1;
    if (hip <= 0) {
      return Error{"controller: the foot '" + db.skeleton().name(foot) +
                   "' does not hang from a two-bone leg"};
    }
    const int toe = toes[side] >= 0 && db.skeleton().parent(toes[side]) == foot ? toes[side] : -1;
    leg_joints_[side] = {hip, knee, foot, toe};
  }
  for (int j = 1; j < db.joint_count(); ++j) {
    if (db.skeleton().parent(j) == 0 && db.skeleton().subtree_size(j) > 1 && j != db.roles().hips) {
      folded_joints_.push_back(j);
      // Its children, found once here: sample_playback folds it into them in every update.
      for (int c = j + 1; c < j + db.skeleton().subtree_size(j); ++c) {
        if (db.skeleton().parent(c) == j) folded_children_.push_back({j, c});
      }
    }
  }
  return Status::success();
}

// Every per-joint buffer update() uses, and the inverse bind matrices of the rest pose.
void Controller::size_buffers() {
  const Database& db = *db_;
  const size_t n = static_cast<size_t>(db.joint_count());
  root_offsets_.resize(1);
  body_offsets_.resize(db.joint_count() - 1);
  body_blend_.resize(db.joint_count() - 1);
  for (auto* v : {&sampled_, &other_, &locals_, &globals_, &world_globals_}) v->resize(n);
  for (auto* v : {&sampled_velocities_, &sampled_angular_velocities_, &other_velocities_,
                  &other_angular_velocities_}) {
    v->assign(n, glm::vec3(0.0f));
  }
  skinning_.assign(n, glm::mat4(1.0f));
  fk_plan_ = ForwardKinematicsPlan(db.skeleton().parents());
  query_.assign(static_cast<size_t>(db.feature_dims()), 0.0f);
  std::vector<Transform> bind(n), inverse_bind(n);
  forward_kinematics(db.skeleton().parents(), db.skeleton().rest(), bind);
  inverse_bind_transforms(bind, inverse_bind);
  inverse_bind_.resize(n);
  for (size_t j = 0; j < n; ++j) inverse_bind_[j] = to_matrix(inverse_bind[j]);
}

// At the origin facing +Z, on the idle clip when there is one, else on the first candidate.
void Controller::start_standing() {
  const std::span<const uint8_t> candidates = shared_->candidates();
  int start = -1;
  for (const ClipRange& clip : db_->clips()) {
    if (!(clip.tags & shared_->idle_tags())) continue;
    for (int f = clip.start; f < clip.end && start < 0; ++f) {
      if (candidates[static_cast<size_t>(f)]) start = f;
    }
  }
  if (start < 0) {
    start =
        static_cast<int>(std::find(candidates.begin(), candidates.end(), 1) - candidates.begin());
  }
  teleport(glm::vec3(0.0f), 0.0f);
  transition_to(start);
  clear_transitions();
  std::copy(sampled_.begin(), sampled_.end(), locals_.begin());
  displayed_velocity_ = sampled_velocities_[0];
  predict();
  refresh_outputs(0.0f);
}

Status Controller::set_settings(const ControllerSettings& settings) {
  if (Status s = settings.validate(); !s) return s;
  Result<const Searcher*> searcher = shared_->searcher(settings.search_method);
  if (!searcher) return Error{"controller: " + searcher.message()};
  searcher_ = *searcher;
  // The body's transition state of one mode means nothing to the other.
  if (settings.transition_mode != settings_.transition_mode) {
    body_offsets_.clear();
    body_blend_.clear();
  }
  settings_ = settings;
  const ControllerDatabase::Speeds& measured = shared_->speeds();
  auto pick = [](float setting, float fallback) { return setting > 0.0f ? setting : fallback; };
  speeds_.walk_forward = pick(settings.walk_speed_forward, measured.walk_forward);
  speeds_.walk_sideways = pick(settings.walk_speed_sideways, measured.walk_sideways);
  speeds_.walk_backward = pick(settings.walk_speed_backward, measured.walk_backward);
  speeds_.run_forward = pick(settings.run_speed_forward, measured.run_forward);
  speeds_.run_sideways = pick(settings.run_speed_sideways, measured.run_sideways);
  speeds_.run_backward = pick(settings.run_speed_backward, measured.run_backward);
  force_search_ = true;
  return Status::success();
}

// teleport() relative to the origin (teleport_world() picks the origin first).
void Controller::place(const glm::vec3& position, float yaw) {
  // On the flat plane the ground is y = 0; in a world, the ground is searched from the given
  // height (settle_on_ground).
  const glm::vec3 ground(position.x, world_ ? position.y : 0.0f, position.z);
  const glm::quat rotation = yaw_rotation(std::isfinite(yaw) ? yaw : 0.0f);
  sim_position_ = finite(ground) ? ground : glm::vec3(0.0f);
  if (world_) settle_on_ground();
  sim_velocity_ = sim_acceleration_ = sim_angular_velocity_ = glm::vec3(0.0f);
  sim_rotation_ = desired_rotation_ = simulation_goal_rotation_ = warp_facing_ = rotation;
  warp_facing_reached_ = true;
  desired_velocity_ = glm::vec3(0.0f);
  climb_pace_.reset();
  clear_transitions();
  for (FootLock& f : feet_) f = FootLock{};
  standing_reach_ = 0.0f;
  body_yaw_known_ = false;
  hips_align_ = 0.0f;
  chest_twist_ = chest_twist_velocity_ = 0.0f;
  if (clip_ >= 0) {
    // Without offsets the displayed pose is the played one, then placed.
    sampled_at_ = playback_point();
    sample_playback(sampled_at_, sampled_, sampled_velocities_, sampled_angular_velocities_, true);
    sampled_body_velocities_ = true;
    std::copy(sampled_.begin(), sampled_.end(), locals_.begin());
    move_root(glm::vec3(sim_position_.x, 0.0f, sim_position_.z), rotation);
    if (world_ || game_capsule_) locals_[0].translation.y += ground_height_;
    predict();
    refresh_outputs(0.0f);
  } else {
    transition_src_position_ = sim_position_;
    transition_src_rotation_ = rotation;
  }
  force_search_ = true;
}

// ---- Update ----------------------------------------------------------------------------------

void Controller::update(float dt, const ControllerInput& input) {
  if (!(dt > 0.0f) || !std::isfinite(dt)) return;
  settle_carried_pose();  // after update_move_only(): the pose the update goes on from
  dt = std::min(dt, settings_.max_dt);
  follow_character();
  debug_.searched = debug_.transitioned = false;
  debug_.search_seconds = 0.0f;

  desired_motion(input);
  if (world_) pace_to_ground(dt);
  search_timer_ += dt;
  since_transition_ += dt;
  if (should_search()) {
    // The last update's prediction heads where the stick pointed then: a search for a changed
    // stick matched against it would pick a frame for the old request (a walk backwards to
    // start a run from standing) and keep it until the next search.
    if (prediction_stale()) predict();
    search();
  }
  advance_playback(dt);
  sampled_at_ = playback_point();
  sample_playback(sampled_at_, sampled_, sampled_velocities_, sampled_angular_velocities_, false);
  sampled_body_velocities_ = false;
  show_transitions(dt);
  // Only the root's displayed motion is needed (by the synchronization): the playing root's
  // plus its offsets' rates.
  displayed_velocity_ = sampled_velocities_[0] + root_offsets_.velocities[0];
  displayed_angular_velocity_ = sampled_angular_velocities_[0] +
                                rotation_vector_rate_to_angular_velocity(
                                    root_offsets_.rotations[0], root_offsets_.rotation_rates[0]);
  simulate(dt);
  if (world_) {
    track_held_by_obstacle(dt);
    collide_root_motion(dt);
  }
  synchronize(dt);
  limit_body_turn(dt);
  turn_chest_to_facing(dt);
  if (world_ || game_capsule_) lift_to_ground(dt);
  predict();
  refresh_outputs(dt);
}

// Forward kinematics, the feet, the skinning matrices: everything read back after an update
// (or a teleport or adjustment) from the local pose.
void Controller::refresh_outputs(float dt) {
  pose_carried_ = false;  // forward kinematics places every joint
  finish_pose();
  if (world_) {
    place_feet(dt);
    keep_body_off_walls(dt);
  }
  foot_lock(dt);
  publish_world_transforms();
  skinning_stale_ = settings_.compute_skinning;
}

std::span<const glm::mat4> Controller::skinning_matrices() const {
  if (skinning_stale_) {
    mm::skinning_matrices(global_transforms(), inverse_bind_, skinning_);
    skinning_stale_ = false;
  }
  return skinning_;
}

// The stick, relative to the camera, becomes a desired velocity (with separate forward,
// sideways and backward speeds in the desired facing's frame) and a desired facing.
void Controller::desired_motion(const ControllerInput& input) {
  const glm::vec2 move = sanitize_stick(input.left_stick, settings_.stick_deadzone);
  const glm::vec2 face = sanitize_stick(input.right_stick, settings_.stick_deadzone);
  const float yaw = std::isfinite(input.camera_yaw) ? wrap_angle(input.camera_yaw) : 0.0f;
  const glm::quat camera = yaw_rotation(yaw);
  const glm::vec3 move_world = stick_to_world(move, camera);

  const bool facing_given = std::isfinite(input.facing_yaw);
  if (facing_given) {
    desired_rotation_ = yaw_rotation(wrap_angle(input.facing_yaw));
  } else if (input.strafe) {
    if (glm::length(face) > 0.0f) {
      const glm::vec3 d = stick_to_world(face, camera);
      desired_rotation_ = yaw_rotation(std::atan2(d.x, d.z));
    }
  } else if (glm::length(move) > 0.0f) {
    desired_rotation_ = yaw_rotation(std::atan2(move_world.x, move_world.z));
  }

  const glm::vec3 local = glm::conjugate(desired_rotation_) * move_world;
  const bool run = input.run;
  const float forward = run ? speeds_.run_forward : speeds_.walk_forward;
  const float sideways = run ? speeds_.run_sideways : speeds_.walk_sideways;
  const float backward = run ? speeds_.run_backward : speeds_.walk_backward;
  const glm::vec3 scaled(local.x * sideways, 0.0f, local.z * (local.z > 0.0f ? forward : backward));
  desired_velocity_ = desired_rotation_ * scaled;
  if (world_ && !input.strafe && !facing_given) face_along_obstacle();
  // Standing at an obstacle the stick pushes into, nothing of its velocity is asked for: the
  // prediction (and the body's ground taken from it) is of standing.
  stick_velocity_ = desired_velocity_;
  if (standing_at_obstacle()) desired_velocity_ = glm::vec3(0.0f);

  tag_bits_ = input.tag_bits ? *input.tag_bits : shared_->tag_bits(input.tag);
  style_ = input.style >= 0 && input.style < shared_->style_count() ? input.style : -1;
  debug_.requested_style = style_;
  const bool released = glm::length(move) == 0.0f;
  stopping_ = (released || standing_at_obstacle()) && shared_->idle_tags() != 0 && tag_bits_ == 0 &&
              glm::length(sim_velocity_) < settings_.stop_speed;
  debug_.desired_velocity = desired_velocity_;
  debug_.desired_rotation = desired_rotation_;
  debug_.standing = released;
  strafing_ = (input.strafe || facing_given) && !released;
  // A new facing is turned to before the legs warp away from it (see warped_facing).
  if (quat_angle_between(desired_rotation_, warp_facing_) > kWarpRefacing) {
    warp_facing_ = desired_rotation_;
    warp_facing_reached_ = false;
  }
  if (clip_ >= 0 && std::abs(wrap_angle(root_yaw_.of(locals_[0].rotation) -
                                        desired_yaw_.of(desired_rotation_))) < kWarpFacingReached) {
    warp_facing_reached_ = true;
  }
  simulation_goal_rotation_ = warped_facing();
}

// Steep ground ahead slows the clip and the desired velocity alike (climb_pace.hpp). The grade is
// read off the last update's prediction, collided with the world: the ground the character is
// about to walk on, found before it gets there.
void Controller::pace_to_ground(float dt) {
  const std::span<const glm::vec3> ahead(debug_.predicted_positions,
                                         static_cast<size_t>(debug_.trajectory_count));
  const float speed = std::hypot(desired_velocity_.x, desired_velocity_.z);
  climb_pace_.update(grade_ahead(sim_position_, ahead), speed, settings_.max_climb_speed,
                     settings_.min_playback_rate, dt);
  desired_velocity_ *= climb_pace_.rate();
  debug_.desired_velocity = desired_velocity_;
  debug_.playback_rate = climb_pace_.rate();
}

bool Controller::should_search() const {
  if (force_search_) return true;
  // Periodic searches wait a little after a transition: the query keeps drifting while the
  // simulation settles, and a jump every interval would make every transition chain into the
  // next before its offsets have decayed.
  if (search_timer_ >= settings_.search_interval &&
      since_transition_ >= settings_.transition_cooldown && !playing_idle_through()) {
    return true;
  }
  if (tag_bits_ != tag_bits_at_search_ || stopping_ != stopping_at_search_ ||
      style_ != style_at_search_) {
    return true;
  }
  if (glm::length(desired_velocity_ - desired_velocity_at_search_) >
      settings_.replan_velocity_change) {
    return true;
  }
  if (quat_angle_between(desired_rotation_, desired_rotation_at_search_) >
      settings_.replan_facing_change) {
    return true;
  }
  return clip_duration() - clip_time_ < settings_.clip_end_lookahead;
}

bool Controller::on_idle_clip() const {
  return stopping_ && clip_ >= 0 &&
         (db_->clips()[static_cast<size_t>(clip_)].tags & shared_->idle_tags()) != 0;
}

// Standing on an idle clip whose next frame may still be matched: nothing to search for.
bool Controller::playing_idle_through() const {
  return on_idle_clip() && shared_->candidates()[static_cast<size_t>(playback_point().frame1)] != 0;
}

// The query: the playing frame's own pose features (interpolated between its two frames), with
// the trajectory columns replaced by the simulation object's predicted trajectory, expressed in
// the displayed character root's frame and normalized like the database.
void Controller::build_query() {
  const Database& db = *db_;
  const size_t dims = static_cast<size_t>(db.feature_dims());
  const PlaybackPoint at = playback_point();
  const float* r0 = db.features().data() + static_cast<size_t>(at.frame0) * dims;
  const float* r1 = db.features().data() + static_cast<size_t>(at.frame1) * dims;
  for (size_t c = 0; c < dims; ++c) query_[c] = r0[c] + at.weight * (r1[c] - r0[c]);

  const Transform& root = globals_[0];
  const glm::quat inverse = glm::conjugate(root.rotation);
  for (const TrajectoryColumn& t : trajectory_columns_) {
    glm::vec3 v;
    if (t.direction) {
      v = inverse * (debug_.predicted_rotations[t.time_index] * kForward);
    } else {
      // At the clip's slowed rate it covers the prediction's ground in as many clip seconds as
      // the stick's own speed would: the search matches the gait asked for.
      v = inverse * (debug_.predicted_positions[t.time_index] - root.translation) /
          climb_pace_.rate();
    }
    const size_t c = static_cast<size_t>(t.column);
    query_[c] = (v.x - db.feature_offset()[c]) / db.feature_scale()[c];
    query_[c + 1] = (v.z - db.feature_offset()[c + 1]) / db.feature_scale()[c + 1];
  }
}

void Controller::search() {
  const auto start = std::chrono::steady_clock::now();
  build_query();
  const SearchResult best = search_candidates();
  // The update samples the playing clip again right after the search, and nothing reads the
  // incoming body before: only inertialization's start reads it at the jump.
  if (best.frame >= 0 && !best.continuation) {
    transition_to(best.frame, settings_.transition_mode == TransitionMode::Inertialization);
  }

  force_search_ = false;
  search_timer_ = 0.0f;
  desired_velocity_at_search_ = desired_velocity_;
  desired_rotation_at_search_ = desired_rotation_;
  tag_bits_at_search_ = tag_bits_;
  style_at_search_ = style_;
  stopping_at_search_ = stopping_;
  record_search(best);
  debug_.search_seconds =
      std::chrono::duration<float>(std::chrono::steady_clock::now() - start).count();
}

// The best frame for the query among the candidates the moment allows: clips carrying a
// requested tag, the idle clip while stopping, locomotion otherwise.
SearchResult Controller::search_candidates() const {
  const Database& db = *db_;
  SearchConstraints constraints;
  constraints.current_frame = playback_point().frame0;
  const float window = on_idle_clip() ? settings_.idle_ignore_window : settings_.ignore_window;
  constraints.window_frames = clamped_integer<int>(std::round(window / db.frame_time()));
  constraints.transition_cost = settings_.transition_cost;
  if (tag_bits_ == 0) {
    if (stopping_) {
      constraints.include_tags = shared_->idle_tags();
      return searcher_->search(query_, constraints);
    }
    constraints.exclude_tags = shared_->action_tags() | shared_->idle_tags();
    return search_in_style(
        *searcher_, query_, constraints,
        style_tiers(*shared_, style_, settings_.style_cost, settings_.style_fallback_step));
  }
  // Any of the requested tags will do: one search per tag, the cheapest wins.
  SearchResult best;
  for (int bit = 0; bit < 64; ++bit) {
    if (!(tag_bits_ & (uint64_t{1} << bit))) continue;
    constraints.include_tags = uint64_t{1} << bit;
    const SearchResult r = searcher_->search(query_, constraints);
    if (r.frame >= 0 && (r.cost < best.cost || (r.cost == best.cost && r.continuation))) best = r;
  }
  return best;
}

// The search's answer in the debug state: the query, the cost and its per-channel breakdown.
void Controller::record_search(const SearchResult& best) {
  const Database& db = *db_;
  ++debug_.searches;
  debug_.searched = true;
  debug_.last_best_frame = best.frame;
  debug_.last_cost = best.cost;
  const int shown = std::min(static_cast<int>(query_.size()), ControllerDebug::kMaxQueryDims);
  debug_.query_dims = shown;
  std::copy(query_.begin(), query_.begin() + shown, debug_.last_query);
  if (best.frame < 0) return;
  const float* row = db.features().data() + static_cast<size_t>(best.frame) * query_.size();
  for (size_t ch = 0; ch < db.schema().channels.size(); ++ch) {
    const int first = db.schema().offset(static_cast<int>(ch));
    const int count = db.schema().channels[ch].dims();
    float sum = 0.0f;
    for (int k = first; k < first + count; ++k) {
      const float d = query_[static_cast<size_t>(k)] - row[k];
      sum += d * d;
    }
    debug_.last_channel_costs[ch] = sum;
  }
}

// Jumps to a database frame. The outgoing pose is what plays now (sampled_); the incoming one is
// the new frame, its root mapped so that it starts exactly where the outgoing root is (the new
// transition source) with the database root of the new frame as the destination.
void Controller::transition_to(int frame, bool incoming_body) {
  const Database& db = *db_;
  const int clip = db.frame_clip()[static_cast<size_t>(frame)];
  const ClipRange& range = db.clips()[static_cast<size_t>(clip)];
  const bool had_clip = clip_ >= 0;
  if (had_clip) {
    transition_src_position_ = sampled_[0].translation;
    transition_src_rotation_ = sampled_[0].rotation;
    // The outgoing body's velocities, where the update sampled it (start_transition reads them).
    if (!sampled_body_velocities_) {
      sample_body_velocities(sampled_at_, sampled_velocities_, sampled_angular_velocities_);
    }
  }
  transition_dst_position_ = db.local_position(frame, 0);
  transition_dst_rotation_ = db.local_rotation(frame, 0);
  clip_ = clip;
  clip_time_ = static_cast<float>(frame - range.start) * db.frame_time();
  if (incoming_body) {
    sample_playback(playback_point(), other_, other_velocities_, other_angular_velocities_, true);
  } else {
    sample_playback_root(other_, other_velocities_, other_angular_velocities_);
  }
  if (had_clip) {
    start_transition();
    ++debug_.transitions;
    debug_.transitioned = true;
    since_transition_ = 0.0f;
  }
  std::swap(sampled_, other_);
  std::swap(sampled_velocities_, other_velocities_);
  std::swap(sampled_angular_velocities_, other_angular_velocities_);
  sampled_body_velocities_ = incoming_body;
}

// At a jump, the outgoing clip (sampled_) hands over to the incoming one (other_).
void Controller::start_transition() {
  inertialize_transition(root_offsets_,
                         root_part(sampled_, sampled_velocities_, sampled_angular_velocities_),
                         root_part(other_, other_velocities_, other_angular_velocities_));
  const PoseMotion outgoing = body_part(sampled_, sampled_velocities_, sampled_angular_velocities_);
  switch (settings_.transition_mode) {
    case TransitionMode::Inertialization:
      inertialize_transition(body_offsets_, outgoing,
                             body_part(other_, other_velocities_, other_angular_velocities_));
      return;
    case TransitionMode::DeadBlending:
      dead_blend_transition(body_blend_, outgoing, settings_.dead_blend_time);
      std::copy(std::begin(shown_contact_), std::end(shown_contact_),
                std::begin(blend_source_contact_));
      return;
  }
}

// The playing clip (sampled_, at the new time) through the running transitions into locals_.
void Controller::show_transitions(float dt) {
  const CriticalSpringStep& step = offset_step_.step(settings_.inertialization_halflife, dt);
  inertialize_update(root_offsets_,
                     root_part(sampled_, sampled_velocities_, sampled_angular_velocities_), step,
                     std::span(locals_).first(1), {}, {});
  const PoseMotion incoming = body_part(sampled_, sampled_velocities_, sampled_angular_velocities_);
  switch (settings_.transition_mode) {
    case TransitionMode::Inertialization:
      inertialize_update(body_offsets_, incoming, step, std::span(locals_).subspan(1), {}, {});
      return;
    case TransitionMode::DeadBlending:
      dead_blend_update(body_blend_, incoming, settings_.dead_blend_time,
                        settings_.dead_blend_decay_halflife, dt, std::span(locals_).subspan(1), {},
                        {});
      return;
  }
}

void Controller::clear_transitions() {
  root_offsets_.clear();
  body_offsets_.clear();
  body_blend_.clear();
}

// Seconds from the playing clip's first frame to its last.
float Controller::clip_duration() const {
  const ClipRange& clip = db_->clips()[static_cast<size_t>(clip_)];
  return static_cast<float>(clip.frame_count() - 1) * db_->frame_time();
}

void Controller::advance_playback(float dt) {
  const float end = clip_duration();
  clip_time_ = std::min(clip_time_ + dt * climb_pace_.rate(), end);
  if (clip_time_ >= end) force_search_ = true;
}

Controller::PlaybackPoint Controller::playback_point() const {
  const ClipRange& clip = db_->clips()[static_cast<size_t>(clip_)];
  const float x = clip_time_ / db_->frame_time();
  const int i0 = std::clamp(clamped_integer<int>(std::floor(x)), 0, clip.frame_count() - 1);
  const int i1 = std::min(i0 + 1, clip.frame_count() - 1);
  return {clip.start + i0, clip.start + i1, std::clamp(x - static_cast<float>(i0), 0.0f, 1.0f)};
}

// One joint's local transform at a playback point: cubic Hermite through the two frames' values
// and velocities (no velocity kink where one frame interval meets the next), or the chosen
// two-point interpolation.
Transform Controller::sample_joint(const PlaybackPoint& at, size_t joint) const {
  return sample_database_joint(*db_, at.frame0, at.frame1, at.weight, joint,
                               settings_.cubic_playback, settings_.interpolation);
}

// The database root (joint 0, unmapped) at a playback point: sample_playback's own sample when
// it was taken there the same way (move_root asks for it in the update that sampled it), else
// sampled again. sample_database_pose equals sample_database_joint to the bit, so both give the
// same transform.
Transform Controller::database_root(const PlaybackPoint& at) const {
  const RootSample& s = root_sample_;
  if (s.valid && s.at.frame0 == at.frame0 && s.at.frame1 == at.frame1 &&
      std::bit_cast<uint32_t>(s.at.weight) == std::bit_cast<uint32_t>(at.weight) &&
      s.cubic == settings_.cubic_playback && s.method == settings_.interpolation) {
    return s.root;
  }
  return sample_joint(at, 0);
}

// The playing clip at `at`, interpolated between its two nearest frames, with the root
// (joint 0) mapped into the world through the transition source and destination:
//   root = source * inverse(destination) * database root.
// The root's velocities always; the body's (joints 1..) only when `body_velocities`.
void Controller::sample_playback(const PlaybackPoint& at, std::span<Transform> local,
                                 std::span<glm::vec3> velocities,
                                 std::span<glm::vec3> angular_velocities,
                                 bool body_velocities) const {
  const Database& db = *db_;
  sample_database_pose(db, at.frame0, at.frame1, at.weight, settings_.cubic_playback,
                       settings_.interpolation, local);
  if (body_velocities) sample_body_velocities(at, velocities, angular_velocities);
  // Source roots (such as the Bandai joint_Root, the capture's world origin) are folded into
  // their children so that every joint below the root is relative to the character: their
  // locals relative to the simulation root differ between takes by whole metres, and offsets
  // between such values would swing the body around during a transition.
  // (A folded joint's children are not folded joints: those hang from the root.)
  for (const auto& [j, c] : folded_children_) {
    local[static_cast<size_t>(c)] =
        compose(local[static_cast<size_t>(j)], local[static_cast<size_t>(c)]);
  }
  for (const int j : folded_joints_) local[static_cast<size_t>(j)] = Transform{};
  map_playback_root(at, local, velocities, angular_velocities);
}

// sample_playback's root alone (joint 0 and its velocities, to the same bits: sample_joint equals
// sample_database_pose joint for joint); the rest of `local` and the velocities are left alone.
void Controller::sample_playback_root(std::span<Transform> local, std::span<glm::vec3> velocities,
                                      std::span<glm::vec3> angular_velocities) const {
  const PlaybackPoint at = playback_point();
  local[0] = sample_joint(at, 0);
  map_playback_root(at, local, velocities, angular_velocities);
}

// The sampled database root (local[0]) kept for database_root, its velocities, and all three
// mapped into the world through the transition source and destination.
[[gnu::always_inline]] inline void Controller::map_playback_root(
    const PlaybackPoint& at, std::span<Transform> local, std::span<glm::vec3> velocities,
    std::span<glm::vec3> angular_velocities) const {
  const Database& db = *db_;
  root_sample_ = {at, settings_.cubic_playback, settings_.interpolation, local[0], true};
  velocities[0] =
      glm::mix(db.local_velocity(at.frame0, 0), db.local_velocity(at.frame1, 0), at.weight);
  angular_velocities[0] = glm::mix(db.local_angular_velocity(at.frame0, 0),
                                   db.local_angular_velocity(at.frame1, 0), at.weight);
  const glm::quat map = transition_src_rotation_ * glm::conjugate(transition_dst_rotation_);
  local[0].translation =
      map * (local[0].translation - transition_dst_position_) + transition_src_position_;
  local[0].rotation = glm::normalize(map * local[0].rotation);
  velocities[0] = map * velocities[0] * climb_pace_.rate();
  angular_velocities[0] = map * angular_velocities[0] * climb_pace_.rate();
}

// The body's (joints 1..) velocities at a playback point, folded like sample_playback folds the
// pose.
void Controller::sample_body_velocities(const PlaybackPoint& at, std::span<glm::vec3> velocities,
                                        std::span<glm::vec3> angular_velocities) const {
  const Database& db = *db_;
  const size_t joints = static_cast<size_t>(db.joint_count());
  pose_velocity_mix(db.frame_pose_lanes(at.frame0), db.frame_pose_lanes(at.frame1), at.weight, 1,
                    velocities.first(joints), angular_velocities.first(joints));
  // In the world's time: the clip plays at the climbing pace's rate.
  if (const float rate = climb_pace_.rate(); rate != 1.0f) {
    for (size_t j = 1; j < joints; ++j) {
      velocities[j] *= rate;
      angular_velocities[j] *= rate;
    }
  }
  for (const int j : folded_joints_) {
    const glm::quat folded = sample_joint(at, static_cast<size_t>(j)).rotation;
    const glm::vec3 v = velocities[static_cast<size_t>(j)];
    const glm::vec3 w = angular_velocities[static_cast<size_t>(j)];
    for (const auto& [f, c] : folded_children_) {
      if (f != j) continue;
      const size_t k = static_cast<size_t>(c);
      const glm::vec3 offset = folded * sample_joint(at, k).translation;
      velocities[k] = v + glm::cross(w, offset) + folded * velocities[k];
      angular_velocities[k] = w + folded * angular_velocities[k];
    }
    velocities[static_cast<size_t>(j)] = angular_velocities[static_cast<size_t>(j)] =
        glm::vec3(0.0f);
  }
}

void Controller::simulate(float dt) {
  const glm::vec3 before = sim_position_;
  const glm::vec3 goal = world_ ? braked_velocity(desired_velocity_, sim_position_, obstacle_ahead_,
                                                  settings_.obstacle_deceleration)
                                : desired_velocity_;
  spring_character_update(sim_position_, sim_velocity_, sim_acceleration_, goal,
                          settings_.simulation_velocity_halflife, dt);
  if (stopping_) {
    stand_turn(dt);
  } else {
    const glm::quat before_rotation = sim_rotation_;
    critical_spring_update(sim_rotation_, sim_angular_velocity_, simulation_goal_rotation_,
                           sim_rotation_step_.step(settings_.simulation_rotation_halflife, dt));
    limit_turn_rate(before_rotation, dt);
  }
  if (world_) {
    collide_simulation(before);
  } else if (!game_capsule_) {
    sim_position_.y = 0.0f;
  }
}

// The rotation spring's step, and its rate, cut to simulation_max_turn_rate: a large change of
// facing then turns at that rate until the spring's own rate falls below it.
void Controller::limit_turn_rate(const glm::quat& before, float dt) {
  const float max_rate = settings_.simulation_max_turn_rate;
  // The yaw before first: the last prediction asked for it, the one after is new.
  const float yaw_before = sim_yaw_.of(before);
  const float step = wrap_angle(sim_yaw_.of(sim_rotation_) - yaw_before);
  if (std::abs(step) > max_rate * dt) {
    sim_rotation_ = glm::normalize(yaw_rotation(std::copysign(max_rate * dt, step)) * before);
  }
  sim_angular_velocity_.y = std::clamp(sim_angular_velocity_.y, -max_rate, max_rate);
}

// Standing, the facing turns the way a person turns on the spot: the rotation spring alone
// would swing a still body round faster than any step could follow. The turn rate moves toward
// the fastest rate from which the turn can still stop on the desired facing at the set
// deceleration, bounded by the maximum rate, and changes by at most the set acceleration: it
// eases in, cruises and eases out. A turn that would pass the facing this update lands on it.
void Controller::stand_turn(float dt) {
  const float error = wrap_angle(desired_yaw_.of(desired_rotation_) - sim_yaw_.of(sim_rotation_));
  const float acceleration = settings_.stand_turn_acceleration;
  const float stoppable = std::sqrt(2.0f * acceleration * std::abs(error));
  const float goal = std::copysign(std::min(settings_.stand_turn_max_rate, stoppable), error);
  float rate = sim_angular_velocity_.y;
  rate += std::clamp(goal - rate, -acceleration * dt, acceleration * dt);
  float step = rate * dt;
  if (step * error > 0.0f && std::abs(step) >= std::abs(error)) {
    step = error;
    rate = 0.0f;
  }
  sim_rotation_ = glm::normalize(yaw_rotation(step) * sim_rotation_);
  sim_angular_velocity_ = glm::vec3(0.0f, rate, 0.0f);
}

bool Controller::prediction_stale() const {
  return desired_velocity_ != predicted_velocity_goal_ ||
         simulation_goal_rotation_ != predicted_rotation_goal_ || stopping_ != predicted_stopping_;
}

void Controller::predict() {
  predicted_velocity_goal_ = desired_velocity_;
  predicted_rotation_goal_ = simulation_goal_rotation_;
  predicted_stopping_ = stopping_;
  const size_t n = trajectory_times_.size();
  std::span<glm::vec3> positions(debug_.predicted_positions, n);
  std::span<glm::quat> rotations(debug_.predicted_rotations, n);
  // The coefficients depend only on the halflives and the times: computed again only when
  // one of them changed (the tables check).
  position_springs_.prepare_character(settings_.simulation_velocity_halflife, trajectory_times_);
  rotation_springs_.prepare_critical(settings_.simulation_rotation_halflife, trajectory_times_);
  spring_character_predict(positions, {}, {}, sim_position_, sim_velocity_, sim_acceleration_,
                           desired_velocity_, position_springs_);
  // The predicted yaws change only with the prediction (kept while the facing is held).
  if (rotation_prediction_.predict(rotations, sim_rotation_, sim_angular_velocity_,
                                   simulation_goal_rotation_, rotation_springs_)) {
    for (size_t i = 0; i < n; ++i) predicted_yaws_[i] = quat_yaw(rotations[i]);
  }
  if (world_) collide_trajectory(positions);
  // The turn-rate limit as update applies it, closely enough for the query: no farther from
  // today's facing than the fastest turn reaches in the time.
  const float yaw = sim_yaw_.of(sim_rotation_);
  const float max_rate =
      stopping_ ? settings_.stand_turn_max_rate : settings_.simulation_max_turn_rate;
  for (size_t i = 0; i < n; ++i) {
    const float reach = max_rate * std::max(0.0f, trajectory_times_[i]);
    const float turn = wrap_angle(predicted_yaws_[i] - yaw);
    if (std::abs(turn) > reach) {
      rotations[i] = glm::normalize(yaw_rotation(std::copysign(reach, turn)) * sim_rotation_);
    }
  }
  for (size_t i = 0; i < n; ++i) {
    debug_.desired_positions[i] =
        sim_position_ + desired_velocity_ * std::max(0.0f, trajectory_times_[i]);
  }
  debug_.simulation_position = sim_position_;
  debug_.simulation_velocity = sim_velocity_;
  debug_.simulation_acceleration = sim_acceleration_;
  debug_.simulation_rotation = sim_rotation_;
  debug_.simulation_angular_velocity = sim_angular_velocity_;
}

// Keeps the character and the simulation object together (see SyncMode).
void Controller::synchronize(float dt) {
  const Transform root = locals_[0];
  switch (settings_.sync_mode) {
    case SyncMode::None:
      return;
    case SyncMode::SimulationFollowsCharacter:
      sim_position_ =
          glm::vec3(root.translation.x, world_ ? last_root_.y : 0.0f, root.translation.z);
      sim_rotation_ = yaw_rotation(root_yaw_.of(root.rotation));
      return;
    case SyncMode::CharacterFollowsSimulation:
      break;
  }
  // The simulation object gives way to the character a little (position only), so that the
  // character needs less pulling: pulling a body away from a planted foot is what slides it.
  if (settings_.simulation_yield_halflife > 0.0f) {
    glm::vec3 toward = root.translation - sim_position_;
    toward.y = 0.0f;
    glm::vec3 step = toward * yield_pull_.of(settings_.simulation_yield_halflife, dt);
    const float own_speed = std::hypot(displayed_velocity_.x, displayed_velocity_.z);
    float max_speed = settings_.simulation_yield_max_velocity_ratio * own_speed;
    if (stopping_) max_speed = std::max(max_speed, settings_.simulation_yield_standing_speed);
    const float max_step = max_speed * dt;
    if (glm::length(step) > max_step) step *= max_step / glm::length(step);
    // In a world the give goes no way into a wall: given straight toward a character going round
    // a wall's end, the object went into the wall's corner, and on through to its back
    // (docs/world.md, session 32).
    step = without_slide_back(step, dt);
    if (world_) step = mover_.free_step(*world_, origin_, character_shape(), sim_position_, step);
    sim_position_ += step;
  }
  // Pull the character toward the simulation, no faster than a share of its own motion.
  const glm::vec3 velocity = displayed_velocity_;
  const float speed = std::sqrt(velocity.x * velocity.x + velocity.z * velocity.z);
  const float turn_rate = std::abs(displayed_angular_velocity_.y);
  const float fraction = adjustment_pull_.of(settings_.adjustment_halflife, dt);

  glm::vec3 error = sim_position_ - root.translation;
  error.y = 0.0f;
  glm::vec3 step = error * fraction;
  const float max_step = settings_.adjustment_max_velocity_ratio * speed * dt;
  if (glm::length(step) > max_step) step *= max_step / glm::length(step);
  glm::vec3 position = root.translation + step;

  const float root_yaw = root_yaw_.of(root.rotation);
  align_hips(dt);
  float angle = wrap_angle(sim_yaw_.of(sim_rotation_) - hips_align_ - root_yaw) * fraction;
  // At least as fast as the simulation itself turns: held to the character's own turning, a
  // clip that does not turn would leave the root behind a turning simulation until the clamp
  // dragged it.
  float max_angle = std::max(settings_.adjustment_max_angular_velocity_ratio * turn_rate,
                             std::abs(sim_angular_velocity_.y)) *
                    dt;
  if (stopping_) {
    // The idle pose does not turn by itself, so a standing character turns with the
    // simulation's own (bounded, eased) turning, and catches up on what remains no faster:
    // the ratio to its own turning would hold it, and the clamp drag it, short of the facing.
    angle += sim_angular_velocity_.y * dt;
    max_angle = std::max(max_angle, settings_.stand_turn_max_rate * dt);
  }
  angle = std::clamp(angle, -max_angle, max_angle);
  if (!stopping_) {
    // Moving, the pull never makes the root turn faster than the simulation may: the body
    // would spin at its own turning plus the pull's.
    const float own = displayed_angular_velocity_.y * dt;
    const float limit = std::max(std::abs(own), settings_.simulation_max_turn_rate * dt);
    angle = std::clamp(own + angle, -limit, limit) - own;
  }
  float yaw = root_yaw + angle;

  // Never farther than the clamping limits.
  glm::vec3 away = position - sim_position_;
  away.y = 0.0f;
  const float distance = glm::length(away);
  if (distance > settings_.clamp_max_distance) {
    position = sim_position_ + away * (settings_.clamp_max_distance / distance);
  }
  const float yaw_error = wrap_angle(yaw - sim_yaw_.of(sim_rotation_));
  if (std::abs(yaw_error) > settings_.clamp_max_angle) {
    yaw = sim_yaw_.of(sim_rotation_) + std::copysign(settings_.clamp_max_angle, yaw_error);
  }
  position.y = root.translation.y;
  if (position == root.translation && yaw == root_yaw) return;
  // Only the yaw changes: the root's rotation is about +Y in this data, and a pure yaw delta
  // keeps any tilt it might have.
  const glm::quat delta = yaw_rotation(wrap_angle(yaw - root_yaw));
  move_root(position, glm::normalize(delta * root.rotation));
}

// The body's facing in the displayed pose: the yaw across the upper legs (pair_yaw), from the
// local pose before forward kinematics.
float Controller::body_yaw() const {
  const auto [left, right] = forward_kinematics_positions(db_->skeleton().parents(), locals_,
                                                          leg_joints_[0][0], leg_joints_[1][0]);
  return pair_yaw(left, right, root_yaw_.of(locals_[0].rotation));
}

// The body turns no faster than body_max_turn_rate: the root takes back what the clip's own
// turning, a transition's offsets and the pull toward the simulation would add beyond it (the
// pull makes it up on later updates).
void Controller::limit_body_turn(float dt) {
  if (settings_.sync_mode == SyncMode::None) return;
  float yaw = body_yaw();
  const float limit = settings_.body_max_turn_rate * dt;
  if (body_yaw_known_ && limit > 0.0f) {
    const float turn = wrap_angle(yaw - body_yaw_);
    if (std::abs(turn) > limit) {
      const float back = std::copysign(limit, turn) - turn;
      move_root(locals_[0].translation, glm::normalize(yaw_rotation(back) * locals_[0].rotation));
      yaw = wrap_angle(yaw + back);
    }
  }
  body_yaw_ = yaw;
  body_yaw_known_ = true;
  hips_offset_ = wrap_angle(yaw - root_yaw_.of(locals_[0].rotation));
}

// Standing, the idle pose's hips may face a few degrees off its root for seconds (a weight
// shift), and a turn on the spot would end that far off the facing. The root's facing goal is
// turned the other way by the hips' offset (followed within a few frames, bounded), so the
// hips keep the facing while the rest of the pose sways, and eases back to none once the
// character moves.
void Controller::align_hips(float dt) {
  const float goal =
      stopping_ && body_yaw_known_ ? std::clamp(hips_offset_, -kMaxHipsAlign, kMaxHipsAlign) : 0.0f;
  hips_align_ += (goal - hips_align_) * hips_align_pull_.of(kHipsAlignHalflife, dt);
}

// Orientation warping. The data has no side steps: strafing, the simulation (and with it the
// root and the legs, through the search) faces partly toward where it goes, by at most
// strafe_warp_max, so that clips walking that way serve the move, while turn_chest_to_facing
// turns the chest back to the facing. Moving backward and to one side, the legs turn the other
// way, so that they go straight backward: the data never moves sideways and back at once, and
// turned toward the travel the legs would have to turn more than half round. A new facing (a strafe
// that flips it) is turned to first, the root within kWarpFacingReached of it, and only then do the
// legs warp away.
glm::quat Controller::warped_facing() const {
  const float limit = settings_.strafe_warp_max;
  if (!strafing_ || !warp_facing_reached_ || !(limit > 0.0f) ||
      glm::length(desired_velocity_) < kWarpMinSpeed) {
    return desired_rotation_;
  }
  const float facing = desired_yaw_.of(desired_rotation_);
  const float off = wrap_angle(std::atan2(desired_velocity_.x, desired_velocity_.z) - facing);
  const float warp = std::abs(off) > kWarpMaxTravel ? wrap_angle(off + glm::pi<float>()) : off;
  return yaw_rotation(facing + std::clamp(warp, -limit, limit));
}

// Strafing, the chest faces the desired facing. The data has no side steps: a strafe plays
// clips whose body faces more or less where it walks. A twist about the vertical, half in the
// spine and half in the chest, turns the chest toward the facing; it follows its goal on a
// short spring (a slower one lagged the body coming round and overshot when it arrived, and
// held the chest off the facing longer), and eases out when the strafe ends. (Skeletons without
// spine or chest roles, or without upper arms to measure the chest's facing by, are left as they
// are.)
void Controller::turn_chest_to_facing(float dt) {
  const JointRoleIndices& roles = db_->roles();
  if (roles.left_upper_arm < 0 || roles.right_upper_arm < 0 ||
      (roles.spine < 0 && roles.chest < 0)) {
    return;
  }
  const std::span<const int> parents = db_->skeleton().parents();
  float goal = 0.0f;
  if (strafing_) {
    const auto [left, right] =
        forward_kinematics_positions(parents, locals_, roles.left_upper_arm, roles.right_upper_arm);
    const float chest_yaw = pair_yaw(left, right, root_yaw_.of(locals_[0].rotation));
    const float error = wrap_angle(desired_yaw_.of(desired_rotation_) - chest_yaw);
    // Farther off, the body is still coming round (a strafe that flips the facing): twisting
    // now could pick the other way round from the body's own turn.
    goal = std::abs(error) <= kChestTwistReach ? std::clamp(error, -kMaxChestTwist, kMaxChestTwist)
                                               : 0.0f;
  }
  chest_twist_spring_.update(chest_twist_, chest_twist_velocity_, goal, kChestTwistHalflife, dt);
  const bool both = roles.spine >= 0 && roles.chest >= 0;
  // One turn for both joints: the twist does not change between them, and taken inside the loop
  // its sine and cosine were computed again after each parent walk.
  const glm::quat turn = yaw_rotation(both ? 0.5f * chest_twist_ : chest_twist_);
  for (const int joint : {roles.spine, roles.chest}) {
    if (joint < 0) continue;
    // A turn about the world's vertical, expressed in the joint's parent frame.
    const glm::quat parent =
        forward_kinematics_rotation(parents, locals_, db_->skeleton().parent(joint));
    Transform& local = locals_[static_cast<size_t>(joint)];
    local.rotation =
        normalized(product(product(product(glm::conjugate(parent), turn), parent), local.rotation));
  }
}

// adjust_root() relative to the origin.
void Controller::adjust_root_local(const glm::vec3& position, const glm::quat& rotation) {
  if (!finite(position) || !usable_rotation(rotation) || clip_ < 0) return;
  body_yaw_known_ = false;
  move_displayed_root(position, glm::normalize(rotation));
  // The feet go with the body: held toes would otherwise pull the legs back.
  for (FootLock& f : feet_) f = FootLock{};
  refresh_outputs(0.0f);
}

void Controller::move_root(const glm::vec3& position, const glm::quat& rotation) {
  // The displayed root is the playing root plus the inertialization offsets; find the playing
  // root that displays as requested. (GLM's arithmetic, in registers: product, normalized,
  // rotated.)
  const glm::quat offset = quat_from_scaled_angle_axis(root_offsets_.rotations[0]);
  const glm::vec3 played_position = position - root_offsets_.positions[0];
  const glm::quat played_rotation = normalized(product(glm::conjugate(offset), rotation));
  // The database root relative to the destination: M = inverse(destination) * root(t).
  const Transform root = database_root(playback_point());
  const glm::quat inverse_destination = glm::conjugate(transition_dst_rotation_);
  const glm::quat relative_rotation = product(inverse_destination, root.rotation);
  const glm::vec3 relative_position =
      rotated(inverse_destination, root.translation - transition_dst_position_);
  // The new source: the destination's rotation mapped onto the requested one, then the source
  // position recomputed from it so that the mapped root lands exactly on the request.
  const glm::quat old_map = product(transition_src_rotation_, inverse_destination);
  transition_src_rotation_ =
      normalized(product(played_rotation, glm::conjugate(relative_rotation)));
  transition_src_position_ = played_position - rotated(transition_src_rotation_, relative_position);
  const glm::quat new_map = product(transition_src_rotation_, inverse_destination);
  const glm::quat turn = product(new_map, glm::conjugate(old_map));

  sampled_[0].translation = played_position;
  sampled_[0].rotation = played_rotation;
  sampled_velocities_[0] = rotated(turn, sampled_velocities_[0]);
  sampled_angular_velocities_[0] = rotated(turn, sampled_angular_velocities_[0]);
  locals_[0].translation = position;
  locals_[0].rotation = normalized(rotation);
  displayed_velocity_ = rotated(turn, displayed_velocity_);
}

void Controller::finish_pose() {
  // The pose is sampled from the database, which stores no scales: every scale is one.
  fk_plan_.run_unit_scale(locals_, globals_);
  const Database& db = *db_;
  const ClipRange& clip = db.clips()[static_cast<size_t>(clip_)];
  const int frame =
      std::clamp(clip.start + clamped_integer<int>(std::round(clip_time_ / db.frame_time())),
                 clip.start, clip.end - 1);
  debug_.clip = clip_;
  debug_.frame = frame;
  debug_.clip_time = clip_time_;
  // While a dead blend is under half way, a foot is down only if it is in both poses: what
  // shows is mostly the pose the blend started from, whose foot may be swinging where the
  // incoming clip's is down, while the blend already carries a foot the incoming clip lifts.
  const bool early_blend = in_early_blend();
  for (size_t side = 0; side < 2; ++side) {
    const bool label = db.contacts()[static_cast<size_t>(frame) * 2 + side] != 0;
    shown_contact_[side] = label && (!early_blend || blend_source_contact_[side]);
    debug_.contact[side] = shown_contact_[side];
  }
}

// A dead blend under half way: what shows is still mostly the pose it started from.
bool Controller::in_early_blend() const {
  return settings_.transition_mode == TransitionMode::DeadBlending && body_blend_.active &&
         body_blend_.time < 0.5f * settings_.dead_blend_time;
}

// Foot locking. A foot whose playing frame says "contact" keeps its toe where it was when the
// contact began; the leg reaches it by two-bone IK (hip, knee, ankle; the foot keeps its
// animated global rotation, so the ankle goes where that rotation puts it above the held toe),
// then distance-constraint relaxation restores the leg's bone lengths should the solve have been
// clamped. A lock ends when the contact ends or the animation drags the toe beyond the unlock
// radius; the foot then eases back onto the animation through a decaying offset.
void Controller::foot_lock(float dt) {
  // Standing on the idle clip, feet still held where the last steps left them take a step
  // each, one at a time, into the idle pose.
  const bool settling = on_idle_clip();
  playing_leg_ends_known_ = false;
  standing_reach_ += ((settling ? 1.0f : 0.0f) - standing_reach_) *
                     standing_reach_pull_.of(kStandingReachHalflife, dt);
  for (int side = 0; side < 2; ++side) {
    const int effector = leg_end(side);
    const glm::vec3 animated = globals_[static_cast<size_t>(effector)].translation;
    if (!settings_.ik_enabled || !settings_.foot_lock_enabled) {
      feet_[side] = FootLock{};
      debug_.locked[side] = false;
      debug_.lock_position[side] = debug_.ik_target[side] = animated;
      continue;
    }
    // The feet stay where the animation has them when the body is kept off a wall.
    const glm::vec3 unshifted = animated - body_shift_;
    const glm::vec3 on_ground = unshifted + glm::vec3(0.0f, ground_offset_[side], 0.0f);
    const bool planted = low_and_slow(side, on_ground, dt);
    const bool labelled = contact_label_holds(side);
    const bool contact = labelled || planted;
    const glm::vec3 target = foot_target(side, unshifted, on_ground, contact,
                                         on_its_ground(side, on_ground), settling, dt);
    hold_heading(side, dt);
    debug_.locked[side] = feet_[side].locked;
    debug_.lock_position[side] = feet_[side].position;
    debug_.ik_target[side] = target;
    // A stepping foot is in the air, and a sweeping toe is not down, whatever the playing frame
    // says.
    debug_.contact[side] = labelled && !feet_[side].stepping;
    ease_heel_down(side, dt);
    // Every update, even with the target on the animated toe: the reach softens a leg the
    // animation stretches near straight, and the knee bends forward where the data's stands past
    // straight. Skipped whenever the target came within 10 micrometres of the animated toe, a
    // running leg's knee jumped 2 cm for an update and back.
    reach(side, animated, target, dt);
  }
}

// Where one foot's toe goes this update: the lock point, or the animated toe on its ground
// (`on_ground`: `animated` raised by its ground's offset, foot_placement.hpp; the same without a
// world) plus an offset that decays after a release and keeps the target continuous there. A
// lock starts where the toe is, at once (easing it to rest would be a slide on the ground), when
// a contact begins or once a foot released during one has eased back onto the animation; it
// holds that point in 3-D.
glm::vec3 Controller::foot_target(int side, const glm::vec3& animated, const glm::vec3& on_ground,
                                  bool contact, bool grounded, bool settling, float dt) {
  FootLock& f = feet_[side];
  bool released = false;
  if (!f.has_target) {
    f.target = on_ground;
    f.has_target = true;
  }
  if (contact && grounded && !f.locked && !f.stepping &&
      glm::length(f.target_velocity) < kLockSpeed &&
      (!f.previous_contact || glm::length(f.offset) < kRelockOffset)) {
    f.locked = true;
    f.lock_began = true;
    f.position = f.target;
    f.lock_ground = toe_ground(side);
    f.offset = f.offset_velocity = glm::vec3(0.0f);
    // The target held already has the walls' push in it.
    f.wall_push = f.wall_push_velocity = glm::vec3(0.0f);
  } else if (f.locked) {
    // The lock holds its point, but its height rides on the ground found under it: a foot that
    // swung up toward a step it then landed short of comes down onto the tread it is over.
    const float ground = toe_ground(side);
    f.position.y += ground - f.lock_ground;
    f.lock_ground = ground;
    glm::vec3 drag = animated - f.position;
    drag.y = 0.0f;
    // Standing, a step is due by where the idle clip itself puts the toe, not by where the blend
    // into it has got to: waiting for the blend, the steps came late, long after the stop.
    glm::vec3 settle_drag = drag;
    if (settling) {
      settle_drag = playing_leg_end(side) - f.position;
      settle_drag.y = 0.0f;
    }
    const bool settle =
        settling && !feet_[1 - side].stepping &&
        (glm::length(settle_drag) > kSettleDistance || std::abs(f.heading_offset) > kSettleHeading);
    // Beyond the leg's reach (softened, see soft_reach) the held toe would be dragged along the
    // ground anyway; but not where the animated toe on its ground is hardly nearer (downhill on
    // a slope, the pelvis dropped as far as it goes): the step would land as far out of reach,
    // and the foot, released and locked again over and over, shuffled where it stood.
    const std::vector<int>& leg = leg_joints_[side];
    const glm::vec3 ankle = globals_[static_cast<size_t>(leg[2])].translation;
    const glm::vec3 hip = globals_[static_cast<size_t>(leg[0])].translation;
    const glm::vec3 toe_from_ankle = animated + body_shift_ - ankle;
    const float held_reach = glm::length(f.position - toe_from_ankle - hip);
    const bool out_of_reach =
        held_reach > kStepReach * leg_length(side) &&
        held_reach > glm::length(on_ground - toe_from_ankle - hip) + kStepReachGain;
    const bool dragged = glm::length(drag) > settings_.foot_unlock_radius || out_of_reach;
    if (!contact || dragged || settle) {
      // A foot that has to move while its frame says "contact" steps there rather than slides.
      released = true;
      f.locked = false;
      f.stepping = contact && (settle || dragged) && f.velocity.y < kLiftOffSpeed;
      f.offset = f.target - on_ground;
      f.offset_velocity = -kReleaseHold * f.velocity;
      // A held toe rising with the animation's (a heel-off's toe) goes on rising at its rate:
      // held for the release's update, it stopped for one update, a jolt up the leg.
      f.offset.y += f.target_velocity.y * dt;
      f.offset_velocity.y = f.target_velocity.y - f.velocity.y;
      f.release_halflife = release_halflife(glm::length(f.offset));
    }
  }
  f.previous_contact = contact;
  // The release's first update holds the toe where it was: its offset starts decaying from
  // rest on the next.
  if (!released) decay_offset(side, f.offset, f.offset_velocity, dt);
  glm::vec3 target = on_ground;
  // A held toe keeps its point on the ground, but rises with the animation's: a toe lifting
  // off is no longer planted, and held down it would have that height to catch up on release.
  // Nor is it held up in the air: a toe still coming down as the contact begins (a heel strike)
  // comes down as the animation's own toe does, rather than stopping dead where it was caught and
  // standing there, the foot floating for the whole step. Its own descent, not its ground's (a
  // ground lowered by the look-ahead of a step down does not take a held toe off its tread), and
  // no lower than the data's lowest toe over the ground under it (unbounded, the downhill foot on
  // a ramp went on down out of the leg's reach).
  if (f.locked) {
    const float under = ground_under_toe(side);
    const float lowest = under + shared_->lowest_foot_end(side);
    f.position.y = std::max(f.position.y + std::min(0.0f, f.animated_rise) * dt,
                            std::min(f.position.y, lowest));
    target = glm::vec3(f.position.x, std::max(f.position.y, on_ground.y), f.position.z);
  }
  target += f.offset;
  if (world_) {
    // Out of the walls as place_feet put it (its ground probed there), eased where one let go;
    // a held toe stays at its point, out of the walls already when it was taken.
    if (!f.locked) target += toe_push(side);
    keep_toe_off_wall(side, target);
  }
  // Never lower than the data's own feet go: blends, offsets and locks taken mid-stride would
  // otherwise sink a toe into the ground. A smooth maximum: a hard one would stop a descending
  // toe dead at the floor, a jerk the legs show.
  const float floor = shared_->lowest_foot_end(side) + toe_ground(side);
  const float below = target.y - floor;
  target.y = floor + 0.5f * (below + std::sqrt(below * below + kFloorSoftness * kFloorSoftness));
  // An update of no time (a placement, the root pulled within reach of a game's capsule) keeps
  // the rate: divided by it, the rate was not a number, and a release carried it on.
  if (dt > 0.0f) f.target_velocity = (target - f.target) / dt;
  f.target = target;
  // A stepping foot rises with the distance it still has to go and lands as it arrives (a foot
  // turning round its toe still has its heel's arc to go); the lift itself follows that height
  // with a bounded acceleration, so the foot leaves the ground smoothly.
  float to_go = std::hypot(f.offset.x, f.offset.z) + std::abs(f.heading_offset) * foot_length(side);
  // A settling step goes to where the idle clip itself puts the toe, and the blend into the idle
  // carries the released toe there: lifted only by the offset left, it slid along the ground.
  if (settling && f.stepping) {
    const glm::vec3 way = playing_leg_end(side) - target;
    to_go = std::max(to_go, std::hypot(way.x, way.z));
  }
  const float lift_goal = f.stepping ? std::min(kStepHeight, kStepLift * to_go) : 0.0f;
  approach(f.lift, f.lift_velocity, lift_goal, kLiftAcceleration, dt);
  target.y += f.lift;
  if (f.stepping && glm::length(f.offset) < kRelockOffset && f.lift < kRelockOffset &&
      std::abs(f.heading_offset) < kRelockHeading) {
    f.stepping = false;
  }
  return target;
}

// Whether a lock may begin on a toe placed `on_ground`: near enough the ground under it now, on
// a ground not rising onto a step (kLockGroundRising). A foot whose ground the look-ahead raised
// toward a step it then lands short of (or a box its heel swung over) has its contact label on in
// the air, and locked there it stood on nothing until its ground came back down (docs/world.md,
// session 27). Under the heel counts too: a foot on a tread's edge, its toe out over the tread
// below, stands on the edge. Without a world the toe is on its ground.
bool Controller::on_its_ground(int side, const glm::vec3& on_ground) const {
  if (!world_) return true;
  const float under =
      std::max(foot_placement_.ground_under_toe(side), foot_placement_.ground_under_heel(side));
  const float rising = foot_placement_.toe_ground_rise(side);
  return on_ground.y - under < kLockAboveGround && rising < kLockGroundRising;
}

// A released toe's offset and its rate moved on by one update's decay back to the animation.
void Controller::decay_offset(int side, glm::vec3& offset, glm::vec3& velocity, float dt) {
  const FootLock& f = feet_[side];
  critical_spring_apply(
      offset, velocity, glm::vec3(0.0f),
      foot_springs_[side].offset.step(
          std::max(f.release_halflife, settings_.foot_lock_release_halflife), dt));
}

// Whether the playing frame's contact label holds the toe: not where the animated toe moves
// faster than kLockSpeed (its speed as of the last foot lock).
bool Controller::contact_label_holds(int side) const {
  return debug_.contact[side] && feet_[side].speed < kLockSpeed;
}

// The height of the ground a toe stands on: in a world, the ground under it; on the game's
// capsule, the capsule's height (ground_height_); else the plane y = 0.
float Controller::toe_ground(int side) const {
  if (world_) return foot_placement_.ground(side).toe;
  return game_capsule_ ? ground_height_ : 0.0f;
}

// The ground under a toe now: in a world the probed ground under it, without the look-ahead
// that toe_ground has in it; else toe_ground.
float Controller::ground_under_toe(int side) const {
  return world_ ? foot_placement_.ground_under_toe(side) : toe_ground(side);
}

// Whether the animated toe (on its ground) is planted by geometry, as the skating metric sees
// a toe (ground_metrics.hpp): low and horizontally slow. A blend's pose drags such a toe along
// the ground while neither pose's contact label is on (a dead blend's first half has a foot
// down only where both poses do); held like a labelled contact, it stays where it is. Updates
// of no time keep the last answer.
bool Controller::low_and_slow(int side, const glm::vec3& on_ground, float dt) {
  FootLock& f = feet_[side];
  if (dt > 0.0f && f.has_animated) {
    f.velocity = (on_ground - f.animated) / dt;
    const float speed = std::hypot(f.velocity.x, f.velocity.z);
    // Low over the ground under it now, not over the foot's ground, which the look-ahead raises
    // before a step: a toe released at a riser, its ground already rising, was held again a few
    // centimetres up and came down with the ground as the held foot stopped looking ahead (the
    // knee 391 m/s^2 at 1/60 s, stand-turns.txt from x = 11.5 on the second course).
    const float under = ground_under_toe(side);
    f.low_and_slow = on_ground.y - under < kPlantedHeight && speed < kPlantedSpeed;
    // The animation's own rise, without its ground's (a held toe comes down as the animation's
    // own does, foot_target).
    f.animated_rise = (on_ground.y - ground_offset_[side] - f.animated_height) / dt;
    // Whether a labelled toe sweeps is judged on its speed over about a 1/30 s frame: a blend's
    // jitter over a few milliseconds is no sweep.
    f.speed += (speed - f.speed) * sweep_pull_.of(kSweepHalflife, dt);
  }
  f.animated = on_ground;
  f.animated_height = on_ground.y - ground_offset_[side];
  f.has_animated = true;
  return f.low_and_slow;
}

// Where the playing clip itself (sampled_, not the transition into it) puts a leg's end, under
// the displayed root. Both ends are walked when the first is asked for (reset by foot_lock each
// update): feet settling together ask for both, and the two chains share the walk from the hips
// up (forward_kinematics_positions, each position to the bit of its own walk). Neither sampled_
// nor the root's local changes during the foot lock.
glm::vec3 Controller::playing_leg_end(int side) {
  if (!playing_leg_ends_known_) {
    const auto [left, right] =
        forward_kinematics_positions(db_->skeleton().parents(), sampled_, leg_end(0), leg_end(1));
    const Transform to_displayed = compose(locals_[0], inverse(sampled_[0]));
    playing_leg_ends_ = {transform_point(to_displayed, left), transform_point(to_displayed, right)};
    playing_leg_ends_known_ = true;
  }
  return playing_leg_ends_[static_cast<size_t>(side)];
}

// The end joint of a leg: its toe, or its foot when it has none.
int Controller::leg_end(int side) const {
  const std::vector<int>& leg = leg_joints_[side];
  return leg[3] >= 0 ? leg[3] : leg[2];
}

// A planted foot does not swivel on the ground: while locked it keeps the heading it landed
// with, whatever the body above it does (the leg twists instead), and once released it eases
// back onto the animation's heading. A hold begins with the heading shown at that moment, so
// the foot never jumps. Legs without a toe have no heading to hold.
void Controller::hold_heading(int side, float dt) {
  FootLock& f = feet_[side];
  if (leg_joints_[side][3] < 0) {
    f.heading_offset = f.heading_offset_velocity = 0.0f;
    return;
  }
  const float animated = foot_heading(side);
  // A foot down in the pose a dead blend started from keeps its heading while the fade is
  // under half way, even when its toe is let go: the fade would swivel it on the ground. Not
  // a stepping foot: it is in the air, and held it would never come round to land; nor a toe
  // the blend has lifted off the ground: a foot at push-off turns steep, its heading swings
  // round, and held it would twist the foot about.
  const bool hold = f.locked || (in_early_blend() && blend_source_contact_[side] && !f.stepping &&
                                 f.low_and_slow);
  if (hold) {
    if (!f.heading_held) f.heading = wrap_angle(animated + f.heading_offset);
    f.heading_held = true;
    f.heading_offset = wrap_angle(f.heading - animated);
    f.heading_offset_velocity = 0.0f;
    return;
  }
  // Released, the offset decays on a halflife long enough that the ankle, swung about the toe
  // through the offset's arc, starts with a bounded acceleration (release_halflife), as a
  // released toe's offset does: on the shortest halflife a foot held 80 degrees round started
  // swivelling back at hundreds of m/s^2 at the ankle.
  if (f.heading_held) {
    f.heading_release_halflife = release_halflife(std::abs(f.heading_offset) * foot_length(side));
  }
  f.heading_held = false;
  foot_springs_[side].heading.update(f.heading_offset, f.heading_offset_velocity, 0.0f,
                                     f.heading_release_halflife, dt);
}

// The animated foot's heading: the yaw of its foot-to-toe line (radians).
float Controller::foot_heading(int side) const {
  const std::vector<int>& leg = leg_joints_[side];
  const glm::vec3 along = globals_[static_cast<size_t>(leg[3])].translation -
                          globals_[static_cast<size_t>(leg[2])].translation;
  return atan2_polynomial(along.x, along.z);
}

// Two-bone IK of one leg toward a toe target, the foot turned to its held heading, then the
// bone lengths restored.
void Controller::reach(int side, const glm::vec3& animated, const glm::vec3& target, float dt) {
  const std::span<const int> parents = db_->skeleton().parents();
  const std::vector<int>& leg = leg_joints_[side];
  const int hip = leg[0], knee = leg[1], foot = leg[2];
  // Reach: the ankle goes where the foot's rotation (animated, turned to the held heading, in
  // a world pitched to its ground: foot_placement.hpp) puts it above the target toe.
  glm::quat swivel = yaw_rotation(feet_[side].heading_offset);
  if (world_) {
    const glm::vec3 along =
        rotated(swivel, animated - globals_[static_cast<size_t>(foot)].translation);
    swivel = product(foot_placement_.tilt(side, along, settings_.max_foot_tilt), swivel);
  }
  const glm::quat foot_rotation =
      normalized(product(swivel, globals_[static_cast<size_t>(foot)].rotation));
  const glm::vec3 hip_position = globals_[static_cast<size_t>(hip)].translation;
  glm::vec3 ankle_target =
      target - rotated(swivel, animated - globals_[static_cast<size_t>(foot)].translation);
  const float animated_reach =
      glm::length(globals_[static_cast<size_t>(foot)].translation - hip_position);
  glm::vec3 reached =
      soft_reach(ankle_target - hip_position, animated_reach, standing_reach_, leg_length(side));
  // A foot reaching down to ground lower than the body's (a step down, a ledge's foot) stays over
  // where it reaches for until the pelvis has come down (leg_reach.hpp): shortened along the
  // hip-to-target line instead, a foot behind the body over a box's edge swung back toward the
  // hip, into the box's face (docs/world.md, session 27). Faded in over kShortBelowDepth of the
  // foot's ground below the body's.
  const float reach_down_weight =
      world_ ? (ground_height_ - foot_placement_.ground(side).toe) / kShortBelowDepth : 0.0f;
  if (world_) reached = reach_down(ankle_target - hip_position, reached, reach_down_weight);
  // A held toe the softened leg falls short of is reached by lifting the heel, not by dragging
  // the toe: the leg keeps the softened length, so the knee bends as it would, and the toe
  // stays put (up to the heel's limit).
  // The heel lifts as far as the held toe needs and comes down on a spring (ease_heel_down), not
  // at once, when the need ends or the lock does. A lock that begins needing more than
  // kHeelRiseAtOnce takes up the rest with a bounded acceleration (heel_lag).
  FootLock& f = feet_[side];
  glm::quat heel_rise(1.0f, 0.0f, 0.0f, 0.0f);
  if (leg[3] >= 0 && (f.locked || f.heel_rise > 0.0f)) {
    const float length = glm::length(reached);
    const float needed =
        lifted_heel(heel_rise_angle(target, ankle_target, hip_position, length, f.heel_axis),
                    standing_reach_ * kHeelMargin);
    if (f.lock_began) {
      f.heel_lag = std::max(0.0f, needed - f.heel_rise - kHeelRiseAtOnce);
      f.heel_lag_velocity = 0.0f;
    }
    if (f.locked && needed - f.heel_lag > f.heel_rise) {
      // Raised with the need, the heel keeps the rate it rose at: once the need falls away it
      // comes down on its spring from that rate, not from rest, which was a jolt at the ankle.
      const float rise = needed - f.heel_lag;
      f.heel_rise_velocity =
          f.lock_began || !(dt > 0.0f) ? 0.0f : std::max(0.0f, (rise - f.heel_rise) / dt);
      f.heel_rise = rise;
    }
    if (f.heel_rise > 0.0f) {
      heel_rise = glm::angleAxis(f.heel_rise, f.heel_axis);
      // Cut to the leg's length as the reach itself is: a foot reaching down stays over its
      // point (cut along the hip's line, a foot held behind the body on the tread below, its
      // heel lifting, was taken forward into the riser above it: docs/world.md, session 32).
      reached = reach_at_most(target + rotated(heel_rise, ankle_target - target) - hip_position,
                              length, reach_down_weight);
    }
  }
  f.lock_began = false;
  ankle_target = hip_position + reached;
  // The knee turns about its hinge in the data (ControllerDatabase::knee_hinge), the chain
  // keeping the animation's twist. Without one it bends toward the pole, where it points now; a
  // nearly straight leg has no such direction (its knee lies on the hip-ankle line and the bend
  // plane would flip from frame to frame), so the character's forward breaks the tie. A knee
  // behind that line (a leg straight or overstretched in the data) points nowhere a knee bends:
  // only its sideways part counts, or as it crosses the line the bend would turn over, the knee
  // jumping to the back of the leg.
  // (The pole is kept with a hinge too: the solve falls back on it where the hinge would lie
  // along the thigh.)
  const glm::vec3 hinge = shared_->knee_hinge(side);
  const glm::vec3 forward = rotated(globals_[0].rotation, kForward);
  glm::vec3 bend = globals_[static_cast<size_t>(knee)].translation -
                   0.5f * (hip_position + globals_[static_cast<size_t>(foot)].translation);
  bend -= std::min(0.0f, glm::dot(bend, forward)) * forward;
  const glm::vec3 pole = bend + kKneeForwardBias * forward;
  // The foot's subtree is refreshed once, below, after its rotation is set.
  const TwoBoneIkResult solved = apply_two_bone_ik_above_end(
      parents, db_->skeleton().subtree_sizes(), locals_, globals_, hip, knee, foot, ankle_target,
      pole, rotated(globals_[static_cast<size_t>(knee)].rotation, hinge));
  // A heel on the ground (no lift at all) leaves the foot its turned rotation and the toe its
  // local one: the toe's turn below is then the foot's rotation undone by itself.
  const bool heel_lifted = heel_rise != glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  const glm::quat raised_foot =
      heel_lifted ? normalized(product(heel_rise, foot_rotation)) : foot_rotation;
  locals_[static_cast<size_t>(foot)].rotation = normalized(
      product(glm::conjugate(globals_[static_cast<size_t>(knee)].rotation), raised_foot));
  // The toe stays flat on the ground while the heel rises: it bends at the ball of the foot.
  if (leg[3] >= 0 && heel_lifted) {
    Transform& toe = locals_[static_cast<size_t>(leg[3])];
    toe.rotation =
        normalized(product(product(glm::conjugate(raised_foot), foot_rotation), toe.rotation));
  }
  refresh_subtree(foot);
  // A solve that reached its target unclamped turned the bones only, so their lengths hold and
  // there is nothing to check.
  if (!solved.reached) restore_leg_lengths(side);
}

// Distance-constraint relaxation over the leg's joints with the hip pinned, then each bone
// turned to point at its relaxed child: the leg keeps the bone lengths of the pose being played
// (actors differ, so not the skeleton's rest lengths). After an exact two-bone solve the
// constraints already hold and nothing moves (reach does not call it then); it is the safety net
// for a solve that could not keep them (a degenerate or clamped chain).
void Controller::restore_leg_lengths(int side) {
  const std::vector<int>& leg = leg_joints_[side];
  const int count = leg[3] >= 0 ? 4 : 3;
  const std::span<const int> parents = db_->skeleton().parents();
  glm::vec3 points[4];
  DistanceConstraint constraints[3];
  for (int i = 0; i < count; ++i) points[i] = globals_[static_cast<size_t>(leg[i])].translation;
  for (int i = 0; i + 1 < count; ++i) {
    const float rest = glm::length(locals_[static_cast<size_t>(leg[i + 1])].translation);
    constraints[i] = {i, i + 1, rest, i == 0 ? 0.0f : 1.0f, 1.0f};
  }
  const float before = max_distance_constraint_error({points, static_cast<size_t>(count)},
                                                     {constraints, static_cast<size_t>(count - 1)});
  if (before < 1e-4f || settings_.bone_length_iterations == 0) return;
  relax_distance_constraints({points, static_cast<size_t>(count)},
                             {constraints, static_cast<size_t>(count - 1)},
                             settings_.bone_length_iterations);
  // Turn each bone of the chain toward its child's relaxed position, parents first.
  for (int i = 0; i + 1 < count; ++i) {
    const size_t joint = static_cast<size_t>(leg[i]);
    const size_t child = static_cast<size_t>(leg[i + 1]);
    const glm::vec3 from = globals_[child].translation - globals_[joint].translation;
    const glm::vec3 to = points[i + 1] - globals_[joint].translation;
    const glm::quat swing = quat_between(from, to);
    const glm::quat global = glm::normalize(swing * globals_[joint].rotation);
    const int parent = parents[joint];
    const glm::quat parent_rotation = parent >= 0 ? globals_[static_cast<size_t>(parent)].rotation
                                                  : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    locals_[joint].rotation = glm::normalize(glm::conjugate(parent_rotation) * global);
    refresh_subtree(leg[i]);
  }
}

// The heel's lift decays toward none on a spring; reach raises it again as a held toe needs.
void Controller::ease_heel_down(int side, float dt) {
  FootLock& f = feet_[side];
  approach(f.heel_lag, f.heel_lag_velocity, 0.0f, kHeelLagAcceleration, dt);
  if (f.heel_rise <= 0.0f) return;
  foot_springs_[side].heel.update(f.heel_rise, f.heel_rise_velocity, 0.0f,
                                  settings_.foot_lock_release_halflife, dt);
  if (f.heel_rise < 1e-4f) f.heel_rise = f.heel_rise_velocity = 0.0f;
}

// The halflife on which a released offset of `distance` (m; for a heading, the arc it swings the
// ankle through) decays: foot_lock_release_halflife, or longer, so that a long offset starts
// with a bounded acceleration (kReleaseMaxAcceleration).
float Controller::release_halflife(float distance) const {
  return std::max(
      settings_.foot_lock_release_halflife,
      2.0f * std::numbers::ln2_v<float> * std::sqrt(distance / kReleaseMaxAcceleration));
}

// The foot's length, ankle to toe, in the pose being played (0 without a toe).
float Controller::foot_length(int side) const {
  const int toe = leg_joints_[side][3];
  return toe >= 0 ? glm::length(locals_[static_cast<size_t>(toe)].translation) : 0.0f;
}

// The leg's length in the pose being played (actors' legs differ between takes).
float Controller::leg_length(int side) const {
  const std::vector<int>& leg = leg_joints_[side];
  return glm::length(locals_[static_cast<size_t>(leg[1])].translation) +
         glm::length(locals_[static_cast<size_t>(leg[2])].translation);
}

// The globals of a joint and its descendants from their locals, each compose in SSE registers
// (transform_sse.hpp: the same bits as compose's scalar code, in fewer instructions).
void Controller::refresh_subtree(int joint) {
  const std::span<const int> parents = db_->skeleton().parents();
  const int end = joint + db_->skeleton().subtree_size(joint);
  for (int j = joint; j < end; ++j) {
    const int p = parents[static_cast<size_t>(j)];
    if (p < 0) {
      globals_[static_cast<size_t>(j)] = locals_[static_cast<size_t>(j)];
    } else {
      sse::compose_into(globals_[static_cast<size_t>(p)], locals_[static_cast<size_t>(j)],
                        globals_[static_cast<size_t>(j)]);
    }
  }
}

}  // namespace mm
