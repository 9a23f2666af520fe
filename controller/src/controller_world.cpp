// The controller in the game's world (world.hpp, docs/world.md): the simulation object, its
// predicted trajectory and the animated root are moved through it by one CharacterMover, and
// the body stands on the ground under the root. None of this runs without a world: the flat
// plane is exactly the controller without it.

#include <algorithm>
#include <array>
#include <cmath>

#include "mm/controller/arm_off_wall.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/sweep_start.hpp"
#include "mm/controller/wall_slide.hpp"
#include "mm/runtime/approach.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/spring.hpp"

namespace mm {

namespace {

// A toe this close to its lowest height in the data (m) is about to land or has just lifted:
// its leg's reach counts for the pelvis drop (foot_placement.hpp).
constexpr float kNearGroundHeight = 0.1f;
// Pushing into a wall, the share of the desired speed that must be left along it for the
// character to turn and walk along it rather than stand facing the wall.
constexpr float kSlideFacingShare = 0.3f;
// Held head-on at an obstacle (held_by_obstacle) below this speed (m/s) for this long (s), the
// character stands.
constexpr float kHeldSpeed = 0.1f;
constexpr float kHeldDelay = 0.3f;
// Halflife (s) of the body's return from a wall it was kept out of.
constexpr float kWallPushHalflife = 0.15f;
// The farthest (m) the body is moved back from a wall: farther, the legs could not reach the
// feet, which stay.
constexpr float kMaxWallPush = 0.1f;
// The most the body accelerates (m/s^2, along each horizontal axis) following a push an arm's
// depth asks for (keep_body_off_walls).
constexpr float kArmPushAcceleration = 20.0f;
// The radius (m) of the spheres swept to find walls near the toes and arms, and how far a toe
// joint stays from a wall's face (the toes reach past their joint).
constexpr float kWallProbeRadius = 0.03f;
// The least horizontal share of a face's normal that makes it a riser a toe waits at (a face
// steeper than about 64 degrees).
constexpr float kRiserNormal = 0.9f;
// Halflife (s) of a toe's way back onto the animation when a wall that kept it out lets go:
// 11 cm (a ledge's side that becomes a step) come back in about 0.2 s, at most about 30 m/s^2.
constexpr float kToeWallPushHalflife = 0.08f;
// The most a ledge's edge accelerates a toe it brings back over the ledge (m/s^2, along each
// horizontal axis): 19 cm in about 0.11 s.
constexpr float kLedgePushAcceleration = 60.0f;
// A trajectory sample's move goes on from where a step stopped it at most this many times (a
// second's walk up a stair of 25 cm treads crosses five risers; two or three per move), and
// only where it ended at least this much higher or lower than it started and has at least this
// far still to go (m): a wall leaves it where it was.
constexpr int kTrajectoryClimbs = 4;
constexpr float kClimbMinimum = 0.01f;
// Only a move stopped on level ground (a tread; the up vector's share of its normal at least
// this) goes on: one stopped on a ramp met its own slope, not a step.
constexpr float kTreadNormalY = 0.99f;
// Edges' normals this close (cosine) are one edge.
constexpr float kSameEdge = 0.99f;
// How far in front of a wall's face an arm's joints are swung (a hand exactly on the plane shows
// the skin's thickness through it).
constexpr float kArmMargin = 0.01f;

}  // namespace

void Controller::set_world(const WorldQueries* world) {
  if (world == world_) return;
  world_ = world;
  ground_height_ = ground_velocity_ = 0.0f;
  foot_placement_.reset(0.0f);
  ground_offset_[0] = ground_offset_[1] = 0.0f;
  obstacle_normal_ = edge_normal_ = glm::vec3(0.0f);
  obstacle_ahead_ = ObstacleAhead{};
  obstacle_edge_ = false;
  held_time_ = 0.0f;
  root_contacts_.clear();
  wall_push_ = wall_push_velocity_ = glm::vec3(0.0f);
  arm_push_lag_ = arm_push_lag_velocity_ = glm::vec3(0.0f);
  // Without a world nothing moves the body back, and the foot lock must not keep taking it off.
  body_shift_ = glm::vec3(0.0f);
  if (clip_ >= 0) place(sim_position_, quat_yaw(sim_rotation_));
}

CharacterShape Controller::character_shape() const {
  CharacterShape shape;
  shape.radius = settings_.character_radius;
  shape.height = settings_.character_height;
  shape.step_height = settings_.step_height;
  shape.max_step_down = settings_.max_step_down;
  shape.min_walkable_normal_y = std::cos(settings_.max_slope);
  return shape;
}

// The simulation object's step from `before` to where its spring put it, through the world. What
// an obstacle stops of its velocity is taken away too, so that the spring starts from the motion
// the object really has (and the prediction from it): pushing into a wall stands still, pushing
// along it slides at the speed along it.
void Controller::collide_simulation(const glm::vec3& before) {
  const MoveResult m = mover_.move(*world_, origin_, character_shape(), before, sim_position_);
  sim_position_ = m.position;
  debug_.simulation_blocked = m.blocked || m.no_ground;
  debug_.simulation_contact = m.normal;
  edge_normal_ = m.edge_normal;
  if (m.blocked && glm::length(m.normal) > 0.5f) {
    obstacle_normal_ = m.normal;
    obstacle_point_ = sim_position_;
    obstacle_edge_ = m.edge;
  }
  if (m.no_ground) {
    sim_velocity_ = sim_acceleration_ = glm::vec3(0.0f);
  } else if (m.blocked) {
    sim_velocity_ -= m.normal * std::min(0.0f, glm::dot(sim_velocity_, m.normal));
    sim_acceleration_ -= m.normal * std::min(0.0f, glm::dot(sim_acceleration_, m.normal));
  }
  debug_.world_rejected = mover_.rejected();
}

// Every predicted sample moved from the simulation object toward where the springs put it, in
// one batch: the trajectory the search matches stops at walls and slides along them, so the
// search picks stops and turns before a wall rather than walking into it.
void Controller::collide_trajectory(std::span<glm::vec3> positions) {
  std::array<glm::vec3, CharacterMover::kMaxMoves> starts;
  std::array<MoveResult, CharacterMover::kMaxMoves> moved;
  const size_t n = positions.size();
  std::fill_n(starts.begin(), n, sim_position_);
  std::array<glm::vec3, CharacterMover::kMaxMoves> goals;
  std::copy_n(positions.begin(), n, goals.begin());
  // Beside a ledge's edge (or stopped at one ahead) the samples lose their part toward it, as the
  // simulation object's steps do and as a wall's sweep slides them: the search then matches the
  // slide along the edge the simulation makes (beyond it, a sample found the ground below the
  // drop, and the search kept walking clips while the simulation stood at the edge).
  if (glm::length(edge_normal_) > 0.5f) {
    for (glm::vec3& p : positions) {
      const float into =
          -glm::dot(glm::vec3(p.x - sim_position_.x, 0.0f, p.z - sim_position_.z), edge_normal_);
      if (into > 0.0f) p += edge_normal_ * into;
    }
  }
  mover_.collide(*world_, origin_, character_shape(), std::span(starts).first(n), positions,
                 std::span(moved).first(n));
  climb_trajectory(positions, starts, moved);
  // Where the stick's own way is blocked (before a ledge's edge beside the simulation object took
  // its part toward the edge), and by what: the simulation object slows down toward it
  // (obstacle_brake.hpp).
  std::array<glm::vec3, CharacterMover::kMaxMoves> normals;
  for (size_t i = 0; i < n; ++i) {
    positions[i] = moved[i].position;
    // Not a riser a sample is still climbing (ended a step above or below the simulation
    // object): braked there, the walk up a stair slowed on every tread, on top of the pace.
    const bool climbing = std::abs(moved[i].position.y - sim_position_.y) >= kClimbMinimum;
    normals[i] = moved[i].blocked && !climbing ? moved[i].normal : glm::vec3(0.0f);
    // A move over a ledge's drop is cancelled (the sample stays where it started): the drop is
    // somewhere along it, the way it blocks the move's own unless the edge was found.
    if (moved[i].no_ground) {
      const glm::vec3 back(starts[i].x - goals[i].x, 0.0f, starts[i].z - goals[i].z);
      const float length = glm::length(back);
      normals[i] = glm::length(moved[i].edge_normal) > 0.5f ? moved[i].edge_normal
                   : length > 0.0f                          ? back / length
                                                            : glm::vec3(0.0f);
    }
  }
  obstacle_ahead_ =
      obstacle_ahead(std::span(goals).first(n), positions, std::span(normals).first(n));
  debug_.world_rejected = mover_.rejected();
}

// A sample's move climbs one step at most: the capsule is swept lifted by step_height, and up a
// stair the second riser stands higher than that above where the move started, a wall. The
// trajectory stopped a tread or two ahead, the search matched a stop on every tread, and the
// climbing pace (climb_pace.hpp) read no stair ahead. A sample stopped on a tread higher or
// lower than it started from moves on from there toward its goal, as the simulation object
// itself would over the next updates: a wall (no height gained), a ledge's edge and a ramp's own
// slope still stop it at once, a stair only after the flight.
void Controller::climb_trajectory(std::span<const glm::vec3> goals,
                                  std::span<glm::vec3, CharacterMover::kMaxMoves> starts,
                                  std::span<MoveResult, CharacterMover::kMaxMoves> moved) {
  std::array<glm::vec3, CharacterMover::kMaxMoves> from, to;
  std::array<MoveResult, CharacterMover::kMaxMoves> again;
  std::array<size_t, CharacterMover::kMaxMoves> which;
  for (int pass = 0; pass < kTrajectoryClimbs; ++pass) {
    size_t count = 0;
    for (size_t i = 0; i < goals.size(); ++i) {
      const MoveResult& m = moved[i];
      const glm::vec3 left(goals[i].x - m.position.x, 0.0f, goals[i].z - m.position.z);
      if (!m.blocked || m.edge || m.no_ground || m.ground_normal.y < kTreadNormalY ||
          std::abs(m.position.y - starts[i].y) < kClimbMinimum ||
          glm::length(left) < kClimbMinimum) {
        continue;
      }
      from[count] = m.position;
      to[count] = goals[i];
      which[count++] = i;
    }
    if (count == 0) return;
    mover_.collide(*world_, origin_, character_shape(), std::span(from).first(count),
                   std::span(to).first(count), std::span(again).first(count));
    for (size_t k = 0; k < count; ++k) {
      const MoveResult& m = again[k];
      if (m.no_ground) continue;
      starts[which[k]] = from[k];
      moved[which[k]] = m;
    }
  }
}

// The root's step since the last update, the animation's own displacement, through the world,
// before the synchronization pulls it toward the simulation object: root motion cannot walk
// through a wall either, and the simulation object's yield toward the root (synchronize) moves
// it toward a place the world allows.
void Controller::collide_root_motion(float dt) {
  const Transform root = locals_[0];
  const glm::vec3 goal(root.translation.x, 0.0f, root.translation.z);
  // Held by the walls and edges it met lately too (HeldContacts): met afresh on every update,
  // a wall or an edge stopped the root on one update and not the next. The move reaching deeper
  // toward them only finds them: where the root goes is its goal held by what was found (the
  // mover's own slide of the deeper move along an edge went sideways).
  const bool holding = root_contacts_.count() > 0;
  const MoveResult m =
      mover_.move(*world_, origin_, character_shape(), last_root_, root_contacts_.reach(goal));
  glm::vec3 end = holding && !m.no_ground ? goal : m.position;
  root_contacts_.hold(end, m, dt);
  if (end.x != goal.x || end.z != goal.z) {
    move_root(glm::vec3(end.x, root.translation.y, end.z), root.rotation);
  }
  last_root_.y = m.position.y;
  debug_.world_rejected = mover_.rejected();
}

// The body lifted onto the ground under the root, on a spring: up and down stairs the hips rise
// and fall without popping. The root's own height stays the data's (its plane, y = 0): the
// transition's root mapping never sees the ground; the lift is added to the displayed pose only.
// In a world, the ground is the one found under the root before the synchronization's small
// pull; with the game's capsule, the height the game gave the simulation object.
void Controller::lift_to_ground(float dt) {
  float ground = sim_position_.y;
  if (world_) {
    last_root_ = glm::vec3(locals_[0].translation.x, last_root_.y, locals_[0].translation.z);
    ground = last_root_.y;
    // Halfway to the ground under the trajectory's first sample (the last update's): stairs
    // become the slope they climb rather than a riser to jump at every tread, and the spring's
    // lag up a ramp is made up ahead of time.
    if (debug_.trajectory_count > 0) ground = 0.5f * (ground + debug_.predicted_positions[0].y);
  }
  critical_spring_update(ground_height_, ground_velocity_, ground, settings_.ground_height_halflife,
                         dt);
  locals_[0].translation.y += ground_height_;
  debug_.ground_height = ground_height_;
}

// Pushed into a wall at an angle, the character walks along it, so it faces along it: facing
// the stick's direction, into the wall, the arms and the leading shoulder would swing through
// it. The velocity asked for keeps the stick's direction (the wall slides it); only the facing
// turns, once the simulation object has met the wall and while it stays beside it (a slide
// along a wall does not touch it on every update). Head-on there is nothing to slide along,
// and the facing stays the stick's.
void Controller::face_along_obstacle() {
  const glm::vec3 n = obstacle_normal_;
  if (glm::length(n) < 0.5f || glm::dot(sim_position_ - obstacle_point_, n) > kBesideObstacle) {
    return;
  }
  const float into = glm::dot(desired_velocity_, n);
  if (into >= 0.0f) return;
  const glm::vec3 along = desired_velocity_ - n * into;
  if (glm::length(along) < kSlideFacingShare * glm::length(desired_velocity_)) return;
  desired_rotation_ = glm::angleAxis(std::atan2(along.x, along.z), glm::vec3(0.0f, 1.0f, 0.0f));
}

// Pushed head-on into the wall the simulation object stands against, or toward the edge of the
// ledge it stopped at (less than kSlideFacingShare of the stick's velocity left along it, where
// the facing does not turn along it either): nothing of the stick's velocity moves it.
bool Controller::held_by_obstacle() const {
  if (!world_) return false;
  const auto head_on = [this](const glm::vec3& n) {
    const float into = glm::dot(stick_velocity_, n);
    if (glm::length(n) < 0.5f || into >= 0.0f) return false;
    return glm::length(stick_velocity_ - n * into) <
           kSlideFacingShare * glm::length(stick_velocity_);
  };
  const bool beside =
      glm::dot(sim_position_ - obstacle_point_, obstacle_normal_) <= kBesideObstacle;
  return (beside && head_on(obstacle_normal_)) || head_on(edge_normal_);
}

// How long the simulation object has been held so (held_by_obstacle). Held kHeldDelay, the
// character stands: the search looks among the idle clips, as with the stick released.
// Searched among locomotion, the best match for standing still was a walk's first steps, played
// over and over with the toes shuffling on the spot; standing at once, a stick sweeping past a
// wall (the circle script) flickered into the idle for a few frames.
// Until then the object must also be nearly at rest (kHeldSpeed); standing, only the stick can
// end it (the standing simulation object moves toward the character).
void Controller::track_held_by_obstacle(float dt) {
  const bool held =
      held_by_obstacle() && (standing_at_obstacle() || glm::length(sim_velocity_) < kHeldSpeed);
  held_time_ = held ? held_time_ + dt : 0.0f;
}

bool Controller::standing_at_obstacle() const {
  return held_time_ >= kHeldDelay;
}

void Controller::set_simulation_position_world(const glm::dvec3& position) {
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z)) {
    return;
  }
  set_simulation_position(glm::vec3(position - origin_));
}

// What the game's physics refused of the step asked for (the simulation object's position after
// update()) acts as a wall: its part of the velocity and acceleration goes. Less than a tenth of
// a millimetre is the game's rounding, not a refusal.
void Controller::set_simulation_position(const glm::vec3& position) {
  if (!finite(position)) return;
  if (!game_capsule_) {
    // The first hand-back: the body starts at the game's height rather than rising to it.
    game_capsule_ = true;
    if (!world_) {
      ground_height_ = position.y;
      ground_velocity_ = 0.0f;
      locals_[0].translation.y += ground_height_;
    }
  }
  glm::vec3 refused = sim_position_ - position;
  refused.y = 0.0f;
  const float length = glm::length(refused);
  if (length > 1e-4f) {
    const glm::vec3 normal = -refused / length;
    sim_velocity_ -= normal * std::min(0.0f, glm::dot(sim_velocity_, normal));
    sim_acceleration_ -= normal * std::min(0.0f, glm::dot(sim_acceleration_, normal));
  }
  sim_position_ = position;
  debug_.simulation_position = sim_position_;
  debug_.simulation_velocity = sim_velocity_;
  // The character never farther from the simulation object than the clamp, also after the
  // game moved it: the root's next move starts within reach of the capsule.
  if (clip_ < 0) return;
  const Transform root = locals_[0];
  glm::vec3 away = root.translation - sim_position_;
  away.y = 0.0f;
  const float distance = glm::length(away);
  if (distance > settings_.clamp_max_distance) {
    glm::vec3 clamped = sim_position_ + away * (settings_.clamp_max_distance / distance);
    clamped.y = root.translation.y;
    move_displayed_root(clamped, root.rotation);
    refresh_outputs(0.0f);
  }
}

// Between updates the displayed root is lifted onto the ground (lift_to_ground); move_root()
// takes the root in the data's plane, so the lift comes off before and goes back on after.
void Controller::move_displayed_root(const glm::vec3& position, const glm::quat& rotation) {
  if (!world_ && !game_capsule_) {
    move_root(position, rotation);
    return;
  }
  move_root(position - glm::vec3(0.0f, ground_height_, 0.0f), rotation);
  locals_[0].translation.y += ground_height_;
}

// A placement on the world's ground: the simulation object on the highest walkable ground
// within the capsule's height above its height down to a step below, the body at that height at
// once, nothing moving. Nothing there: it stays at the height it was given.
void Controller::settle_on_ground() {
  GroundHit hit;
  const CharacterShape shape = character_shape();
  if (mover_.ground(*world_, origin_, shape, sim_position_, shape.height, hit)) {
    sim_position_.y = hit.point.y;
  }
  ground_height_ = sim_position_.y;
  ground_velocity_ = 0.0f;
  last_root_ = sim_position_;
  root_contacts_.clear();
  debug_.ground_height = ground_height_;
  foot_placement_.reset(ground_height_);
  obstacle_normal_ = glm::vec3(0.0f);
  obstacle_ahead_ = ObstacleAhead{};
  obstacle_edge_ = false;
  held_time_ = 0.0f;
  std::fill(std::begin(toe_walls_), std::end(toe_walls_), WallHit{});
  std::fill(std::begin(beside_toe_walls_), std::end(beside_toe_walls_), WallHit{});
  std::fill(std::begin(riser_walls_), std::end(riser_walls_), WallHit{});
  std::fill(std::begin(body_walls_), std::end(body_walls_), WallHit{});
  trunk_wall_ = WallHit{};
  wall_push_ = wall_push_velocity_ = glm::vec3(0.0f);
  arm_push_lag_ = arm_push_lag_velocity_ = glm::vec3(0.0f);
}

// The body kept out of walls: the capsule keeps the root a radius away, but an arm swinging
// forward or an idle hand reaches past it. Everything above the root is moved back from each wall
// by as far as its deepest joint is past it: the wall the simulation object stands against (the
// joints higher than a step), and the wall found toward a hand, elbow or the head (find_walls).
// The push is one horizontal offset that covers every wall's depth at once, at most kMaxWallPush
// long, and eases back on a spring once nothing is in. One offset, not a depth along the deepest
// wall's normal: in a corner the wall the simulation object stands against is one side, then the
// other, from one update to the next, and a push that turned with it threw the whole body
// sideways and back (the ledge's edges at the second course's floor corner: the hips 482 m/s^2).
// The feet stay where the animation has them: the foot lock takes the shift (body_shift_) off
// their targets, so the body leans over them rather than sliding them.
// What an arm's depth raises the push by the body follows with a bounded acceleration
// (arm_push_lag_), and the arm's swing out of the wall (keep_arms_off_walls) takes the rest
// meanwhile: a hand swinging past the end of a wall is found a hand's depth in at once, and taken
// at once, the whole body jumped sideways in an update (walking past the end of the second
// course's corner wall; docs/world.md, session 27). The head and the trunk are pushed out at
// once.
void Controller::keep_body_off_walls(float dt) {
  std::array<WallDepth, kMaxWallDepths> walls;
  const std::span<const WallDepth> found = std::span(walls).first(wall_depths(walls));
  critical_spring_update(wall_push_, wall_push_velocity_, glm::vec3(0.0f), kWallPushHalflife, dt);
  // Twice over: where two walls meet at less than a right angle, the push out of one takes some of
  // the push out of the other back.
  for (int pass = 0; pass < 2; ++pass) {
    for (const WallDepth& wall : found) {
      const float short_by = std::min(wall.depth, kMaxWallPush) - glm::dot(wall_push_, wall.normal);
      if (short_by <= 0.0f) continue;
      wall_push_ += wall.normal * short_by;
      wall_push_velocity_ -= wall.normal * glm::dot(wall_push_velocity_, wall.normal);
      if (wall.arm) arm_push_lag_ += wall.normal * short_by;
    }
  }
  const float length = glm::length(wall_push_);
  if (length > kMaxWallPush) wall_push_ *= kMaxWallPush / length;
  follow_arm_push(found, dt);
  if (length < 1e-5f) {
    wall_push_ = wall_push_velocity_ = glm::vec3(0.0f);
    arm_push_lag_ = arm_push_lag_velocity_ = glm::vec3(0.0f);
    body_shift_ = glm::vec3(0.0f);
  } else {
    body_shift_ = wall_push_ - arm_push_lag_;
    for (size_t j = 1; j < globals_.size(); ++j) globals_[j].translation += body_shift_;
  }
  keep_arms_off_walls();
}

// The walls the body is in, into `out`, and how many: the wall found toward the trunk's joint
// deepest in the plane of the one the simulation object stands against (deepest_trunk_joint),
// with the trunk and head's deepest in it, and the walls found toward each hand, lower arm and
// the head (find_walls), with the upper arm's depth in a hand's or lower arm's wall (the arm's
// swing turns about it, so only the push takes it out).
size_t Controller::wall_depths(std::span<WallDepth, kMaxWallDepths> out) const {
  size_t count = 0;
  if (trunk_wall_.found) {
    const float above = ground_height_ + settings_.step_height;
    float depth = 0.0f;
    for (size_t j = 1; j < globals_.size(); ++j) {
      const glm::vec3& p = globals_[j].translation;
      if (p.y > above && !in_arm(static_cast<int>(j))) {
        depth = std::max(depth, glm::dot(trunk_wall_.point - p, trunk_wall_.normal));
      }
    }
    out[count++] = {trunk_wall_.normal, depth, false};
  }
  const JointRoleIndices& roles = db_->roles();
  const int upper_arms[2] = {roles.left_upper_arm, roles.right_upper_arm};
  for (int k = 0; k < kReachingJoints; ++k) {
    const WallHit& hit = body_walls_[k];
    if (!hit.found) continue;
    const glm::vec3& p = globals_[static_cast<size_t>(hit.joint)].translation;
    // find_walls' list: the hands and the lower arms (left, right), then the head.
    const bool arm = k < 4;
    out[count++] = {hit.normal, glm::dot(hit.point - p, hit.normal), arm};
    const int upper_arm = arm ? upper_arms[k % 2] : -1;
    if (upper_arm >= 0) {
      const glm::vec3& shoulder = globals_[static_cast<size_t>(upper_arm)].translation;
      out[count++] = {hit.normal, glm::dot(hit.point - shoulder, hit.normal), false};
    }
  }
  return count;
}

// The arms' part of the push (arm_push_lag_), followed with a bounded acceleration: never more
// than the push, and never leaving the trunk, the head or an upper arm in a wall.
void Controller::follow_arm_push(std::span<const WallDepth> walls, float dt) {
  for (const int axis : {0, 2}) {
    approach(arm_push_lag_[axis], arm_push_lag_velocity_[axis], 0.0f, kArmPushAcceleration, dt);
  }
  const float lag = glm::length(arm_push_lag_);
  if (lag > glm::length(wall_push_)) arm_push_lag_ *= glm::length(wall_push_) / lag;
  for (const WallDepth& wall : walls) {
    if (wall.arm) continue;
    const float short_by =
        std::min(wall.depth, kMaxWallPush) - glm::dot(wall_push_ - arm_push_lag_, wall.normal);
    if (short_by > 0.0f) arm_push_lag_ -= wall.normal * short_by;
  }
}

// Whether `joint` is below an upper arm (the skeleton keeps each joint's subtree after it): what
// the arm's swing about the upper arm moves. Not the upper arm itself, which only the body's
// push takes out of a wall.
bool Controller::in_arm(int joint) const {
  const JointRoleIndices& roles = db_->roles();
  for (const int upper_arm : {roles.left_upper_arm, roles.right_upper_arm}) {
    if (upper_arm >= 0 && joint > upper_arm &&
        joint < upper_arm + db_->skeleton().subtree_size(upper_arm)) {
      return true;
    }
  }
  return false;
}

// What the body's push leaves of an arm in a wall (the push stops at kMaxWallPush, and eases in
// over a few updates while a swing is fast) is swung out about the upper arm (arm_off_wall.hpp):
// against the wall the simulation object stands beside, and the walls found toward the arm's
// hand and elbow, whichever side they face.
void Controller::keep_arms_off_walls() {
  const JointRoleIndices& roles = db_->roles();
  const int upper_arms[2] = {roles.left_upper_arm, roles.right_upper_arm};
  const std::span<const int> parents(db_->skeleton().parents());
  for (int side = 0; side < 2; ++side) {
    if (upper_arms[side] < 0) continue;
    // find_walls' list: the hands first, then the lower arms, left before right.
    for (const int k : {side, 2 + side}) {
      const WallHit& hit = body_walls_[k];
      if (!hit.found) continue;
      swing_arm_out_of_wall(globals_, parents, upper_arms[side], {hit.point, hit.normal},
                            kArmMargin);
    }
  }
}

// The wall the simulation object stands against, as a point on its face and its horizontal
// normal; false when there is none. Only where the wall was met: its plane goes on past its end.
bool Controller::wall_beside(glm::vec3& point, glm::vec3& normal) const {
  if (!world_ || !beside_wall(sim_position_, {obstacle_point_, obstacle_normal_},
                              settings_.character_radius)) {
    return false;
  }
  normal = glm::normalize(glm::vec3(obstacle_normal_.x, 0.0f, obstacle_normal_.z));
  point = obstacle_point_ - normal * settings_.character_radius;
  return true;
}

// The simulation object's yield toward the character (synchronize) beside the wall it slides
// along (wall_slide.hpp).
glm::vec3 Controller::without_slide_back(const glm::vec3& step, float dt) const {
  if (!world_) return step;
  const WallMet wall{obstacle_point_, obstacle_normal_};
  return mm::without_slide_back(step, sim_velocity_, obstacle_normal_,
                                beside_weight(sim_position_, wall, settings_.character_radius), dt);
}

// Walls near the feet and the arms: a small sphere swept from the root's vertical line out to
// each toe a step above the body's ground (lower things are steps the feet stand on, not
// walls), along each toe in the air's way (risers), and to each hand, elbow and the head at
// their own height when higher than a step. One batched call. The capsule keeps only the root a
// radius from a wall; these reach past it.
void Controller::find_walls(const std::array<PlacementLeg, 2>& legs,
                            const std::array<glm::vec3, 2>& shown_toes) {
  const JointRoleIndices& roles = db_->roles();
  const int reaching[kReachingJoints] = {roles.left_hand, roles.right_hand, roles.left_lower_arm,
                                         roles.right_lower_arm, roles.head};
  const glm::vec3 root = locals_[0].translation;
  const float step = ground_height_ + settings_.step_height;
  constexpr size_t kSweeps = 7 + kReachingJoints;
  std::array<ShapeSweep, kSweeps> sweeps;
  std::array<SweepHit, kSweeps> hits;
  std::array<WallHit*, kSweeps> out;
  // The least horizontal share of a face's normal that makes it a wall to each sweep.
  std::array<float, kSweeps> least_share;
  least_share.fill(0.5f);
  // The sweeps started a radius back from where they go from (the risers').
  std::array<bool, kSweeps> backed{};
  size_t count = 0;
  for (int side = 0; side < 2; ++side) {
    toe_walls_[side] = WallHit{};
    // A toe standing on ground higher than the sweep (held on a tread the body went down beside,
    // more than a step below it) is over what the sweep meets there, the riser under its own
    // tread: pushed out of it, the toe let go went 19 cm back in an update (circling off the side
    // of the second course's stairs_12_35; docs/world.md, session 32).
    if (foot_placement_.ground(side).toe > step) continue;
    const glm::vec3& toe = legs[static_cast<size_t>(side)].toe;
    out[count] = &toe_walls_[side];
    sweeps[count++] = ShapeSweep{glm::vec3(root.x, step, root.z), glm::vec3(toe.x, step, toe.z),
                                 kWallProbeRadius, 2.0f * kWallProbeRadius};
  }
  // The wall the simulation object stands against, where a toe is in its plane: swept from out
  // of the plane back to the toe, along its normal, a step above the body's ground. The plane
  // goes on past the wall's end, and a toe stepping into the second course's corridor beside the
  // end of its wall, in the plane but not in the wall, was pushed out of it, back toward the
  // body, in a few updates. Only a face the sweep meets keeps the toe out. A ledge's edge is no
  // face the toe could go into: ease_ledge_push brings it back over.
  glm::vec3 beside_point, beside_normal;
  const bool against_wall = wall_beside(beside_point, beside_normal);
  const bool beside = against_wall && !obstacle_edge_;
  for (int side = 0; side < 2; ++side) {
    beside_toe_walls_[side] = WallHit{};
    const glm::vec3 toe(legs[static_cast<size_t>(side)].toe.x, step,
                        legs[static_cast<size_t>(side)].toe.z);
    const float depth =
        beside ? glm::dot(beside_point - toe, beside_normal) + kWallProbeRadius : 0.0f;
    if (!(depth > 0.0f)) continue;
    out[count] = &beside_toe_walls_[side];
    sweeps[count++] = ShapeSweep{toe + beside_normal * (depth + kWallProbeRadius), toe,
                                 kWallProbeRadius, 2.0f * kWallProbeRadius};
  }
  // A toe in the air, from where it was to where it goes, at its height over its ground: the
  // side of a step it is not yet above (a riser) is a wall to it until it is. Without it the
  // toe went on into the riser and was lifted onto the tread in the update it got there (20 cm
  // in an update). Where it goes is where the foot lock will show it (`shown_toes`: a released
  // toe's offset decays on after the probes), and the sweep starts a radius behind where it was
  // (a sphere starting in contact finds nothing). Swept to where the offset had it, a toe creeping
  // toward stairs_20_25's landing was swept away from the riser and never held; its footprint
  // reached the landing's edge and lifted it 11 cm in an update (docs/world.md, session 28).
  for (int side = 0; side < 2; ++side) {
    riser_walls_[side] = WallHit{};
    const FootLock& f = feet_[side];
    if (f.locked || !f.has_target) continue;
    const glm::vec3& toe = legs[static_cast<size_t>(side)].toe;
    const float height =
        std::max(f.target.y, toe.y + foot_placement_.ground(side).toe - ground_height_);
    const glm::vec3& shown = shown_toes[static_cast<size_t>(side)];
    const glm::vec3 from(f.target.x, height, f.target.z), to(shown.x, height, shown.z);
    const float length = glm::length(to - from);
    if (length < 1e-4f) continue;
    out[count] = &riser_walls_[side];
    least_share[count] = kRiserNormal;  // a riser is a side, not a ramp's slope run into
    // Started a radius back, it may start inside a face the toe leaves (sweep_start.hpp).
    backed[count] = true;
    const glm::vec3 back = (to - from) * (kWallProbeRadius / length);
    sweeps[count++] = ShapeSweep{from - back, to, kWallProbeRadius, 2.0f * kWallProbeRadius};
  }
  for (int k = 0; k < kReachingJoints; ++k) {
    body_walls_[k] = WallHit{};
    if (reaching[k] < 0) continue;
    const glm::vec3& p = globals_[static_cast<size_t>(reaching[k])].translation;
    if (p.y < step) continue;
    body_walls_[k].joint = reaching[k];
    out[count] = &body_walls_[k];
    sweeps[count++] = ShapeSweep{glm::vec3(root.x, p.y - kWallProbeRadius, root.z),
                                 glm::vec3(p.x, p.y - kWallProbeRadius, p.z), kWallProbeRadius,
                                 2.0f * kWallProbeRadius};
  }
  trunk_wall_ = WallHit{};
  glm::vec3 trunk;
  if (against_wall && deepest_trunk_joint(beside_point, beside_normal, trunk_wall_.joint, trunk)) {
    out[count] = &trunk_wall_;
    sweeps[count++] = ShapeSweep{glm::vec3(root.x, trunk.y - kWallProbeRadius, root.z),
                                 glm::vec3(trunk.x, trunk.y - kWallProbeRadius, trunk.z),
                                 kWallProbeRadius, 2.0f * kWallProbeRadius};
  }
  mover_.sweep(*world_, origin_, std::span(sweeps).first(count), std::span(hits).first(count));
  for (size_t i = 0; i < count; ++i) {
    WallHit& wall = *out[i];
    const glm::vec3 n(hits[i].normal.x, 0.0f, hits[i].normal.z);
    wall.found = hits[i].hit && glm::length(n) > least_share[i] &&
                 !(backed[i] && backed_into_face(sweeps[i], hits[i], kWallProbeRadius));
    if (!wall.found) continue;
    wall.normal = glm::normalize(n);
    // The sphere's centre stopped a radius off the face.
    const glm::vec3 centre = glm::mix(sweeps[i].from, sweeps[i].to, hits[i].fraction);
    wall.point = centre - wall.normal * kWallProbeRadius;
  }
}

// The joint of the trunk or head (higher than a step, not in an arm) deepest in the plane of the
// wall the simulation object stands against (through `point`, normal `n`: wall_beside), if one is
// within a probe's radius of it: find_walls sweeps out to it from the root, and only a wall found
// there pushes the trunk (wall_depths).
// The plane goes on past the wall's end: the trunk beside the end of the second course's corridor
// wall, in the plane but not in the wall, was pushed out of it in an update (docs/world.md).
bool Controller::deepest_trunk_joint(const glm::vec3& point, const glm::vec3& n, int& joint,
                                     glm::vec3& position) const {
  const float above = ground_height_ + settings_.step_height;
  float deepest = -kWallProbeRadius;
  joint = -1;
  for (size_t j = 1; j < globals_.size(); ++j) {
    const glm::vec3& p = globals_[j].translation;
    if (p.y <= above || in_arm(static_cast<int>(j))) continue;
    const float depth = glm::dot(point - p, n);
    if (depth > deepest) {
      deepest = depth;
      joint = static_cast<int>(j);
      position = p;
    }
  }
  return joint >= 0;
}

// A toe target is kept a margin out of the walls found between the body and the toes, and out of
// the one the simulation object stands against where the toe is in it (find_walls): a step to
// the side or ahead would put the foot into it (the capsule keeps only the root a radius away).
// A toe in the air is kept out of the riser it met, which it waits at while its ground rises
// (FootPlacement, PlacementLeg's held_at_step).
void Controller::keep_toe_off_wall(int side, glm::vec3& target) const {
  const auto push_out = [&target](const glm::vec3& wall, const glm::vec3& n) {
    const float depth = glm::dot(wall - target, n) + kWallProbeRadius;
    if (depth > 0.0f) target += n * depth;
  };
  const WallHit& beside = beside_toe_walls_[side];
  if (beside.found) push_out(beside.point, beside.normal);
  const WallHit& toe_wall = toe_walls_[side];
  if (toe_wall.found) push_out(toe_wall.point, toe_wall.normal);
  const WallHit& riser = riser_walls_[side];
  if (riser.found && !feet_[side].locked) push_out(riser.point, riser.normal);
}

// How far walls keep a toe at `toe` out (FootLock::wall_push): where a wall lets go (a ledge
// that becomes a step as the body rises a centimetre, the end of a wall), the push comes back
// onto the animation on a spring (kToeWallPushHalflife) instead of at once, the toe's ground then
// probed where the eased toe is; where one pushes, the toe is out of it at once.
void Controller::ease_wall_push(int side, const glm::vec3& toe, float dt) {
  FootLock& f = feet_[side];
  // A held toe is kept out of the walls where it is, as when it was taken: nothing to ease.
  if (f.locked) f.wall_push = f.wall_push_velocity = glm::vec3(0.0f);
  const glm::vec3 before = f.wall_push;
  critical_spring_apply(f.wall_push, f.wall_push_velocity, glm::vec3(0.0f),
                        foot_springs_[side].wall_push.step(kToeWallPushHalflife, dt));
  glm::vec3 kept = toe + f.wall_push;
  keep_toe_off_wall(side, kept);
  const glm::vec3 push(kept.x - toe.x, 0.0f, kept.z - toe.z);
  const bool pushing = glm::length(push - f.wall_push) > 1e-6f;
  // A wall pushed the eased toe back out: the push is held there, growing as the wall holds the
  // toe against the animation's way, so that when the wall lets go the toe starts from the rest
  // it was at, not at once with the animation's speed (a toe held at a riser then went on at 1.8
  // m/s in an update: 110 m/s^2). The first update of a push holds it at rest: a wall found late
  // pushes at once, and its depth is no speed to go on with.
  if (pushing) {
    f.wall_push_velocity = f.wall_pushing && dt > 0.0f ? (push - before) / dt : glm::vec3(0.0f);
  }
  f.wall_pushing = pushing;
  f.wall_push = push;
}

// A toe swung out over the ledge's edge the simulation object stands at is brought back over it,
// and let go again, with at most kLedgePushAcceleration: the object stops at the edge when the
// toe is already out there, and pushed out at once (as a wall's face does) the toe moved back a
// foot's width in an update (docs/world.md, session 23). A held toe stays where it was taken.
void Controller::ease_ledge_push(int side, const glm::vec3& toe, float dt) {
  FootLock& f = feet_[side];
  if (f.locked) {
    f.ledge_lag = f.ledge_lag_velocity = f.ledge_need = f.ledge_normal = glm::vec3(0.0f);
    return;
  }
  glm::vec3 need(0.0f), edge, n(0.0f);  // n stays zero without an edge
  if (obstacle_edge_ && wall_beside(edge, n)) {
    need = n * std::max(0.0f, glm::dot(edge - (toe + f.wall_push), n) + kWallProbeRadius);
  }
  // Along the same edge the push is the need, as a wall's face's is: a toe swinging out there
  // stops at it. Where the need jumps (an edge found with the toe already out over it, another
  // edge at a corner, the edge gone) the push stays where it was and the jump is made up with
  // a bounded acceleration, each horizontal axis alone.
  if (!(glm::dot(n, f.ledge_normal) > kSameEdge)) f.ledge_lag += need - f.ledge_need;
  for (const int axis : {0, 2}) {
    approach(f.ledge_lag[axis], f.ledge_lag_velocity[axis], 0.0f, kLedgePushAcceleration, dt);
  }
  f.ledge_need = need;
  f.ledge_normal = n;
}

// Everything the walls and a ledge's edge move a toe by this update (horizontal, m).
glm::vec3 Controller::toe_push(int side) const {
  const FootLock& f = feet_[side];
  return f.wall_push + f.ledge_need - f.ledge_lag;
}

// Feet on the ground under them (foot_placement.hpp), after forward kinematics and before the
// foot lock: the probes, the pelvis drop applied to everything above the root (the root stays
// on the body's ground), and each toe's offset from where the animation puts it, which the
// foot lock adds. Needs the legs' IK: without it the feet stay the animation's.
void Controller::place_feet(float dt) {
  ground_offset_[0] = ground_offset_[1] = 0.0f;
  if (!settings_.ik_enabled || !settings_.foot_lock_enabled) return;
  std::array<PlacementLeg, 2> legs;
  std::array<glm::vec3, 2> shown_toes;
  for (int side = 0; side < 2; ++side) {
    const std::vector<int>& leg = leg_joints_[side];
    PlacementLeg& p = legs[static_cast<size_t>(side)];
    p.hip = globals_[static_cast<size_t>(leg[0])].translation;
    p.ankle = globals_[static_cast<size_t>(leg[2])].translation;
    p.toe = globals_[static_cast<size_t>(leg_end(side))].translation;
    // The ground is probed where the foot will be: a held foot where its lock holds it, a
    // released one where its decaying offset still has it (so that the ground under it moves
    // as continuously as the foot does), not where the animation has it.
    const FootLock& f = feet_[side];
    const glm::vec3 at = f.locked ? f.position : p.toe + f.offset;
    glm::vec3& shown = shown_toes[static_cast<size_t>(side)];
    shown = at;
    if (!f.locked) {
      glm::vec3 offset = f.offset, offset_velocity = f.offset_velocity;
      decay_offset(side, offset, offset_velocity, dt);
      shown = p.toe + offset;
    }
    const glm::vec3 moved(at.x - p.toe.x, 0.0f, at.z - p.toe.z);
    p.shift = moved;
    p.toe += moved;
    p.ankle += moved;
    p.length = leg_length(side);
    p.lowest = shared_->lowest_foot_end(side);
    // A foot stepping while its frame says contact is in the air, and so is a toe sweeping
    // along under its label: they look ahead like any other.
    p.planted = f.locked || (contact_label_holds(side) && !f.stepping);
    p.near_ground = p.planted || p.toe.y - ground_height_ - p.lowest < kNearGroundHeight;
    const PlaybackPoint& played = sampled_at_;
    const ControllerDatabase::FootLanding landing =
        shared_->next_landing(played.weight < 0.5f ? played.frame0 : played.frame1, side);
    p.lands = landing.found;
    p.landing = transform_point(globals_[0], landing.toe);
  }
  // A toe a wall keeps out (keep_toe_off_wall) is probed where it is kept, not where the
  // animation would put it past the wall: held on a ledge's top while the animation swings it
  // out over the drop, the ground found out there (the body's, a step lower) lowered it into the
  // ledge's edge.
  find_walls(legs, shown_toes);
  for (int side = 0; side < 2; ++side) {
    PlacementLeg& p = legs[static_cast<size_t>(side)];
    ease_wall_push(side, p.toe, dt);
    ease_ledge_push(side, p.toe, dt);
    const glm::vec3 push = toe_push(side);
    p.toe += push;
    p.ankle += push;
    // Held at a riser, the toe looks where the animation takes it, over the step.
    p.shift += push;
    p.held_at_step = riser_walls_[side].found;
  }
  FootPlacementSettings placement;
  placement.max_pelvis_drop = settings_.max_pelvis_drop;
  placement.pelvis_drop_halflife = settings_.pelvis_drop_halflife;
  placement.max_foot_tilt = settings_.max_foot_tilt;
  placement.step_height = settings_.step_height;
  placement.max_step_down = settings_.max_step_down;
  placement.pace = climb_pace_.rate();
  foot_placement_.update(*world_, origin_, mover_, placement, legs, ground_height_, sim_velocity_,
                         dt);
  debug_.world_rejected = mover_.rejected();
  const float drop = foot_placement_.pelvis_drop();
  for (size_t j = 1; j < globals_.size(); ++j) globals_[j].translation.y -= drop;
  for (int side = 0; side < 2; ++side) {
    ground_offset_[side] = foot_placement_.ground(side).toe - ground_height_ + drop;
    debug_.foot_ground[side] = foot_placement_.ground(side);
    debug_.foot_landing[side] = legs[static_cast<size_t>(side)].landing;
    debug_.foot_lands[side] =
        legs[static_cast<size_t>(side)].lands && !legs[static_cast<size_t>(side)].planted;
  }
  std::copy(foot_placement_.probe_points().begin(), foot_placement_.probe_points().end(),
            debug_.foot_probes);
  std::copy(foot_placement_.probe_grounds().begin(), foot_placement_.probe_grounds().end(),
            debug_.foot_probe_grounds);
  debug_.pelvis_drop = drop;
}

}  // namespace mm
