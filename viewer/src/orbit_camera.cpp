#include "orbit_camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "mm/runtime/spring.hpp"

namespace mm::viewer {
namespace {

constexpr float kTargetHeight = 0.9f;  // metres above the root: the character's middle

}  // namespace

void OrbitCamera::follow(const glm::vec3& root, float dt, float halflife) {
  const glm::vec3 goal = root + glm::vec3(0.0f, kTargetHeight, 0.0f);
  critical_spring_update(target, target_velocity, goal, halflife, dt);
}

void OrbitCamera::snap(const glm::vec3& root) {
  target = root + glm::vec3(0.0f, kTargetHeight, 0.0f);
  target_velocity = glm::vec3(0.0f);
}

void OrbitCamera::orbit(float delta_yaw, float delta_pitch) {
  if (!std::isfinite(delta_yaw) || !std::isfinite(delta_pitch)) return;
  yaw = std::remainder(yaw + delta_yaw, 2.0f * glm::pi<float>());
  pitch = std::clamp(pitch + delta_pitch, kMinPitch, kMaxPitch);
}

void OrbitCamera::zoom(float notches) {
  if (!std::isfinite(notches)) return;
  distance = std::clamp(distance * std::pow(0.9f, notches), kMinDistance, kMaxDistance);
}

glm::vec3 OrbitCamera::eye() const {
  const glm::vec3 forward(std::sin(yaw), 0.0f, std::cos(yaw));
  return target - forward * (distance * std::cos(pitch)) +
         glm::vec3(0.0f, distance * std::sin(pitch), 0.0f);
}

CameraMatrices OrbitCamera::matrices(int width, int height) const {
  CameraMatrices m;
  m.eye = eye();
  m.view = glm::lookAt(m.eye, target, glm::vec3(0.0f, 1.0f, 0.0f));
  const float aspect =
      static_cast<float>(std::max(width, 1)) / static_cast<float>(std::max(height, 1));
  m.projection = glm::perspective(fov_y, aspect, 0.05f, 200.0f);
  return m;
}

}  // namespace mm::viewer
