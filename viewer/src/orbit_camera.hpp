#pragma once
// The camera: it orbits a target that follows the character, at a yaw, a pitch and a distance.
// Its yaw is the one the controller reads (input.hpp): the camera looks along
// (sin yaw, 0, cos yaw), so pushing the stick forward walks away from the camera.

#include <glm/glm.hpp>

#include "renderer.hpp"

namespace mm::viewer {

struct OrbitCamera {
  float yaw = 0.0f;       // radians about +Y
  float pitch = 0.30f;    // radians looking down, in [kMinPitch, kMaxPitch]
  float distance = 3.6f;  // metres from the target, in [kMinDistance, kMaxDistance]
  float fov_y = 0.75f;    // radians
  glm::vec3 target{0.0f, 0.9f, 0.0f};
  glm::vec3 target_velocity{0.0f};  // of the spring that follows the character

  static constexpr float kMinPitch = -0.1f, kMaxPitch = 1.4f;
  static constexpr float kMinDistance = 1.0f, kMaxDistance = 30.0f;

  // Moves the target toward the character's root (at mid height) on a critical spring, so the
  // camera trails a little and the character's own motion stays visible.
  void follow(const glm::vec3& root, float dt, float halflife = 0.15f);
  // Jumps to the character (the first frame, a teleport).
  void snap(const glm::vec3& root);
  // Mouse drag or right stick: radians; mouse wheel: a zoom factor per notch.
  void orbit(float delta_yaw, float delta_pitch);
  void zoom(float notches);

  glm::vec3 eye() const;
  CameraMatrices matrices(int width, int height) const;
};

}  // namespace mm::viewer
