// Big worlds: the controller's local origin (local_origin.hpp). Every position the controller
// stores is relative to origin_; this file places characters in the world, moves the origin
// with the character, and publishes the world transforms of global_transforms().

#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "mm/controller/controller.hpp"

namespace mm {

void Controller::teleport(const glm::vec3& position, float yaw) {
  teleport_world(glm::dvec3(position), yaw);
}

void Controller::teleport_world(const glm::dvec3& position, float yaw) {
  origin_ = origin_for(position);
  debug_.origin = origin_;
  const bool finite = std::isfinite(position.x) && std::isfinite(position.z);
  place(finite ? to_local(origin_, glm::dvec3(position.x, 0.0, position.z)) : glm::vec3(0.0f), yaw);
}

void Controller::adjust_root(const glm::vec3& position, const glm::quat& rotation) {
  adjust_root_world(glm::dvec3(position), rotation);
}

void Controller::adjust_root_world(const glm::dvec3& position, const glm::quat& rotation) {
  adjust_root_local(to_local(origin_, position), rotation);
}

// Rebases when the character's root has strayed from the origin. The root rather than the
// simulation object: it is where the feet are, and with SyncMode::None the two part ways.
void Controller::follow_character() {
  const glm::vec3 shift = rebase_shift(locals_[0].translation);
  if (shift != glm::vec3(0.0f)) shift_origin(shift);
}

// Moves the origin by `shift` (relative to the old origin) and every stored position by the
// opposite: what lies in the world stays where it is. Directions, velocities and offsets
// (inertialization, foot release) are differences and do not move.
void Controller::shift_origin(const glm::vec3& shift) {
  origin_ += glm::dvec3(shift);
  debug_.origin = origin_;
  sim_position_ -= shift;
  last_root_ -= shift;
  root_contacts_.shift(-shift);
  obstacle_point_ -= shift;
  transition_src_position_ -= shift;
  for (std::vector<Transform>* pose : {&sampled_, &other_, &locals_}) {
    (*pose)[0].translation -= shift;  // only the root is in the world; the rest hang from it
  }
  for (Transform& global : globals_) global.translation -= shift;
  carried_from_.translation -= shift;
  for (FootLock& foot : feet_) {
    foot.position -= shift;
    foot.target -= shift;
    foot.animated -= shift;
    foot.animated_height -= shift.y;
  }
  debug_.simulation_position -= shift;
  for (int i = 0; i < ControllerDebug::kMaxTrajectoryPoints; ++i) {
    debug_.predicted_positions[i] -= shift;
    debug_.desired_positions[i] -= shift;
  }
  for (int side = 0; side < 2; ++side) {
    debug_.lock_position[side] -= shift;
    debug_.ik_target[side] -= shift;
  }
}

// global_transforms() away from the world origin: the relative globals placed in the world,
// each translation summed in double and rounded once.
void Controller::publish_world_transforms() {
  if (origin_ == glm::dvec3(0.0)) return;  // global_transforms() shows globals_ itself
#if defined(__SSE2__)
  // to_world of every joint, x and y in one pair of doubles: the same conversions and additions
  // (a float widens exactly, the sum rounds once back to float, to nearest), a joint per pass.
  const __m128d origin_xy = _mm_set_pd(origin_.y, origin_.x);
  for (size_t j = 0; j < globals_.size(); ++j) {
    const Transform& g = globals_[j];
    Transform& w = world_globals_[j];
    w.rotation = g.rotation;
    w.scale = g.scale;
    const __m128 xy =
        _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&g.translation.x)));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(&w.translation.x),
                     _mm_castps_si128(_mm_cvtpd_ps(_mm_add_pd(_mm_cvtps_pd(xy), origin_xy))));
    w.translation.z = static_cast<float>(origin_.z + static_cast<double>(g.translation.z));
  }
#else
  for (size_t j = 0; j < globals_.size(); ++j) {
    world_globals_[j] = globals_[j];
    world_globals_[j].translation = glm::vec3(to_world(origin_, globals_[j].translation));
  }
#endif
}

}  // namespace mm
