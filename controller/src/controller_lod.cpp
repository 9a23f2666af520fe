// The controller's cheapest step, for characters a crowd's level of detail only moves
// (crowd_scheduler.hpp): the simulation object alone, the displayed character carried along.

#include <cmath>
#include <cstddef>

#include "mm/controller/controller.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm {

void Controller::update_move_only(float dt, const ControllerInput& input) {
  if (!(dt > 0.0f) || !std::isfinite(dt) || clip_ < 0) return;
  dt = std::min(dt, settings_.max_dt);
  follow_character();
  debug_.searched = debug_.transitioned = false;
  debug_.search_seconds = 0.0f;
  desired_motion(input);
  // Moved only, the character keeps the pace of its last full update's ground: the same speed
  // up a stair at every level of detail.
  if (world_) pace_to_ground(dt);
  const glm::vec3 before = sim_position_;
  const float yaw_before = quat_yaw(sim_rotation_);
  simulate(dt);
  // The character turns and moves with the simulation object about its position: a rigid
  // motion of the whole pose, so the body is neither bent nor stretched.
  const glm::quat turn =
      glm::angleAxis(wrap_angle(quat_yaw(sim_rotation_) - yaw_before), glm::vec3(0.0f, 1.0f, 0.0f));
  // The root alone moves; the playback's anchor (move_root: the transition's source, the
  // sampled root and its velocities) is re-anchored once, at settle_carried_pose(), to where the
  // moves ended: it depends only on the root then, and re-anchoring on every move sampled the
  // database's root and turned the velocities for nothing that a move reads.
  Transform& root = locals_[0];
  root.translation = sim_position_ + turn * (root.translation - before);
  root.rotation = glm::normalize(turn * root.rotation);
  if (!pose_carried_) {
    // The first move after a posed frame: the other joints stay behind, hanging from the root
    // as it is now. Held toes would pull the legs back to where the character was; the body's
    // facing jumps; the first full update after this searches for the input of that moment.
    pose_carried_ = true;
    carried_from_ = globals_[0];
    for (FootLock& foot : feet_) foot = FootLock{};
    body_yaw_known_ = false;
    force_search_ = true;
  }
  Transform& moved = globals_[0];
  moved.translation = sim_position_ + turn * (moved.translation - before);
  moved.rotation = glm::normalize(turn * moved.rotation);
  last_root_ = sim_position_ + turn * (last_root_ - before);
  root_contacts_.clear();  // moved with the body, not against what it met
  if (origin_ != glm::dvec3(0.0)) {
    world_globals_[0] = moved;
    world_globals_[0].translation = glm::vec3(to_world(origin_, moved.translation));
  }
  if (settings_.compute_skinning) {
    settle_carried_pose();
    skinning_stale_ = true;  // computed when read (skinning_matrices())
  }
}

Transform Controller::carried_from() const {
  Transform from = carried_from_;
  if (origin_ != glm::dvec3(0.0)) from.translation = glm::vec3(to_world(origin_, from.translation));
  return from;
}

void Controller::settle_carried_pose() {
  if (!pose_carried_) return;
  pose_carried_ = false;
  const Transform moved = locals_[0];
  move_root(moved.translation, moved.rotation);
  // The rigid motion from where the held joints hang to where the root is: a turn about +Y
  // (each move turned the root about the vertical) and a translation.
  const Transform& root = globals_[0];
  const glm::quat turn = glm::normalize(root.rotation * glm::conjugate(carried_from_.rotation));
  for (size_t j = 1; j < globals_.size(); ++j) {
    Transform& global = globals_[j];
    global.translation = root.translation + turn * (global.translation - carried_from_.translation);
    global.rotation = glm::normalize(turn * global.rotation);
  }
  publish_world_transforms();
}

namespace {

// Every cache line of [begin, begin + bytes) to be written soon.
void prefetch_lines(const void* begin, size_t bytes) {
  constexpr size_t kLine = 64;
  const char* first = static_cast<const char*>(begin);
  for (size_t offset = 0; offset < bytes; offset += kLine) {
    __builtin_prefetch(first + offset, 1);
  }
}

}  // namespace

void Controller::prefetch_move_only_members() const {
  // Addresses within this object only: nothing here waits for memory. The heap arrays'
  // pointers are among the lines asked for, so prefetch_move_only() finds them in the cache.
  prefetch_lines(&origin_, sizeof(origin_));
  prefetch_lines(&sim_position_,
                 static_cast<size_t>(reinterpret_cast<const char*>(&clip_time_) -
                                     reinterpret_cast<const char*>(&sim_position_)));
  prefetch_lines(&settings_.max_dt, sizeof(settings_.max_dt));
  prefetch_lines(&feet_, sizeof(feet_));
  prefetch_lines(&last_root_, sizeof(last_root_));
  prefetch_lines(&debug_.searched, sizeof(debug_.searched));
  prefetch_lines(&debug_.transitioned, sizeof(debug_.transitioned));
  prefetch_lines(&debug_.search_seconds, sizeof(debug_.search_seconds));
  prefetch_lines(&pose_carried_, sizeof(pose_carried_));
  prefetch_lines(&locals_, sizeof(locals_));
  prefetch_lines(&globals_, sizeof(globals_));
  prefetch_lines(&world_globals_, sizeof(world_globals_));
}

void Controller::prefetch_move_only() const {
  // The poses are heap arrays: their pointers are read here (from the lines
  // prefetch_move_only_members() asked for a step earlier).
  prefetch_lines(locals_.data(), sizeof(Transform));
  // Only the root moves (the rest of the pose is carried, not rewritten).
  prefetch_lines(globals_.data(), sizeof(Transform));
  if (origin_ != glm::dvec3(0.0)) prefetch_lines(world_globals_.data(), sizeof(Transform));
}

}  // namespace mm
