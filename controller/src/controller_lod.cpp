// The controller's cheapest step, for characters a crowd's level of detail only moves
// (crowd_scheduler.hpp): the simulation object alone, the displayed character carried along.

#include <cmath>

#include "mm/controller/controller.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/skinning.hpp"

namespace mm {

void Controller::update_move_only(float dt, const ControllerInput& input) {
  if (!(dt > 0.0f) || !std::isfinite(dt) || clip_ < 0) return;
  dt = std::min(dt, settings_.max_dt);
  follow_character();
  debug_.searched = debug_.transitioned = false;
  debug_.search_seconds = 0.0f;
  desired_motion(input);
  const glm::vec3 before = sim_position_;
  const float yaw_before = quat_yaw(sim_rotation_);
  simulate(dt);
  // The character turns and moves with the simulation object about its position: a rigid
  // motion of the whole pose, so the body is neither bent nor stretched.
  const glm::quat turn =
      glm::angleAxis(wrap_angle(quat_yaw(sim_rotation_) - yaw_before), glm::vec3(0.0f, 1.0f, 0.0f));
  const glm::vec3 root = sim_position_ + turn * (locals_[0].translation - before);
  move_root(root, glm::normalize(turn * locals_[0].rotation));
  for (Transform& global : globals_) {
    global.translation = sim_position_ + turn * (global.translation - before);
    global.rotation = glm::normalize(turn * global.rotation);
  }
  last_root_ = sim_position_ + turn * (last_root_ - before);
  // Held toes would pull the legs back to where the character was; the body's facing jumped.
  for (FootLock& foot : feet_) foot = FootLock{};
  body_yaw_known_ = false;
  // The first full update after this searches for the input of that moment.
  force_search_ = true;
  publish_world_transforms();
  if (settings_.compute_skinning) {
    mm::skinning_matrices(global_transforms(), inverse_bind_, skinning_);
  }
}

}  // namespace mm
