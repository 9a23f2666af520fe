// The controller in the game's world (world.hpp, docs/world.md): the simulation object, its
// predicted trajectory and the animated root are moved through it by one CharacterMover, and
// the body stands on the ground under the root. None of this runs without a world: the flat
// plane is exactly the controller without it.

#include <algorithm>
#include <array>
#include <cmath>

#include "mm/controller/controller.hpp"
#include "mm/runtime/spring.hpp"

namespace mm {

void Controller::set_world(const WorldQueries* world) {
  world_ = world;
  ground_height_ = ground_velocity_ = 0.0f;
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
  mover_.collide(*world_, origin_, character_shape(), std::span(starts).first(n), positions,
                 std::span(moved).first(n));
  for (size_t i = 0; i < n; ++i) positions[i] = moved[i].position;
  debug_.world_rejected = mover_.rejected();
}

// The root's step since the last update, the animation's own displacement, through the world,
// before the synchronization pulls it toward the simulation object: root motion cannot walk
// through a wall either, and the simulation object's yield toward the root (synchronize) moves
// it toward a place the world allows.
void Controller::collide_root_motion() {
  const Transform root = locals_[0];
  const glm::vec3 goal(root.translation.x, 0.0f, root.translation.z);
  const MoveResult m = mover_.move(*world_, origin_, character_shape(), last_root_, goal);
  if (m.position.x != goal.x || m.position.z != goal.z) {
    move_root(glm::vec3(m.position.x, root.translation.y, m.position.z), root.rotation);
  }
  last_root_.y = m.position.y;
  debug_.world_rejected = mover_.rejected();
}

// The body lifted onto the ground under the root, on a spring: up and down stairs the hips rise
// and fall without popping. The root's own height stays the data's (its plane, y = 0): the
// transition's root mapping never sees the ground; the lift is added to the displayed pose only.
// The ground is the one found under the root before the synchronization's small pull.
void Controller::lift_to_ground(float dt) {
  last_root_ = glm::vec3(locals_[0].translation.x, last_root_.y, locals_[0].translation.z);
  critical_spring_update(ground_height_, ground_velocity_, last_root_.y,
                         settings_.ground_height_halflife, dt);
  locals_[0].translation.y += ground_height_;
  debug_.ground_height = ground_height_;
}

// A placement on the world's ground: the simulation object on the ground under it (searched
// from step_height above its height), the body at that height at once, nothing moving.
void Controller::settle_on_ground() {
  GroundHit hit;
  if (mover_.ground(*world_, origin_, character_shape(), sim_position_, hit)) {
    sim_position_.y = hit.point.y;
  }
  ground_height_ = sim_position_.y;
  ground_velocity_ = 0.0f;
  last_root_ = sim_position_;
  debug_.ground_height = ground_height_;
}

}  // namespace mm
