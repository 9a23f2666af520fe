#include "live_input.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

namespace mm::viewer {
namespace {

constexpr float kStickDeadzone = 0.15f;   // for the camera orbit (the controller has its own)
constexpr float kTriggerPressed = 0.3f;   // triggers rest at -1 and go to +1
constexpr float kOrbitYawSpeed = 2.5f;    // rad/s at full right stick or Q/E
constexpr float kOrbitPitchSpeed = 1.2f;  // rad/s
constexpr float kMouseRadiansPerPixel = 0.006f;

glm::vec2 clamp_to_disc(glm::vec2 v) {
  const float length = glm::length(v);
  return length > 1.0f ? v / length : v;
}

bool key(GLFWwindow* window, int k) {
  return glfwGetKey(window, k) == GLFW_PRESS;
}

}  // namespace

LiveInput::LiveInput(GLFWwindow* window) : window_(window) {
  glfwSetWindowUserPointer(window, this);
  glfwSetScrollCallback(window, &LiveInput::on_scroll);
}

void LiveInput::on_scroll(GLFWwindow* window, double, double y) {
  auto* self = static_cast<LiveInput*>(glfwGetWindowUserPointer(window));
  if (self) self->scroll_ += static_cast<float>(y);
}

ControllerInput LiveInput::read(OrbitCamera& camera, float dt, bool panel_has_mouse,
                                bool panel_has_keyboard) {
  ControllerInput input;
  read_gamepad(input, camera, dt);
  if (!panel_has_keyboard) read_keyboard(input, camera, dt);
  if (!panel_has_mouse) read_mouse(camera);
  scroll_ = 0.0f;
  input.left_stick = clamp_to_disc(input.left_stick);
  input.right_stick = clamp_to_disc(input.right_stick);
  input.camera_yaw = camera.yaw;
  return input;
}

void LiveInput::read_gamepad(ControllerInput& input, OrbitCamera& camera, float dt) {
  int pad = -1;
  for (int j = GLFW_JOYSTICK_1; j <= GLFW_JOYSTICK_LAST && pad < 0; ++j) {
    if (glfwJoystickIsGamepad(j)) pad = j;
  }
  GLFWgamepadstate state;
  if (pad < 0 || !glfwGetGamepadState(pad, &state)) {
    device_ = "keyboard and mouse";
    return;
  }
  const char* name = glfwGetGamepadName(pad);
  device_ = std::string("gamepad: ") + (name ? name : "unnamed");
  // GLFW's stick y grows downward; the controller's grows forward.
  input.left_stick = {state.axes[GLFW_GAMEPAD_AXIS_LEFT_X], -state.axes[GLFW_GAMEPAD_AXIS_LEFT_Y]};
  const glm::vec2 right{state.axes[GLFW_GAMEPAD_AXIS_RIGHT_X],
                        -state.axes[GLFW_GAMEPAD_AXIS_RIGHT_Y]};
  input.run = state.axes[GLFW_GAMEPAD_AXIS_RIGHT_TRIGGER] > kTriggerPressed ||
              state.buttons[GLFW_GAMEPAD_BUTTON_A] == GLFW_PRESS;
  input.strafe = state.axes[GLFW_GAMEPAD_AXIS_LEFT_TRIGGER] > kTriggerPressed ||
                 state.buttons[GLFW_GAMEPAD_BUTTON_LEFT_BUMPER] == GLFW_PRESS;
  if (input.strafe) {
    input.right_stick = right;
  } else if (glm::length(right) > kStickDeadzone) {
    camera.orbit(right.x * kOrbitYawSpeed * dt, -right.y * kOrbitPitchSpeed * dt);
  }
}

void LiveInput::read_keyboard(ControllerInput& input, OrbitCamera& camera, float dt) {
  GLFWwindow* w = window_;
  glm::vec2 move(0.0f);
  if (key(w, GLFW_KEY_W) || key(w, GLFW_KEY_UP)) move.y += 1.0f;
  if (key(w, GLFW_KEY_S) || key(w, GLFW_KEY_DOWN)) move.y -= 1.0f;
  if (key(w, GLFW_KEY_D) || key(w, GLFW_KEY_RIGHT)) move.x += 1.0f;
  if (key(w, GLFW_KEY_A) || key(w, GLFW_KEY_LEFT)) move.x -= 1.0f;
  if (glm::length(move) > 0.0f) input.left_stick += glm::normalize(move);
  if (key(w, GLFW_KEY_LEFT_SHIFT) || key(w, GLFW_KEY_RIGHT_SHIFT)) input.run = true;
  if (key(w, GLFW_KEY_LEFT_CONTROL) || key(w, GLFW_KEY_RIGHT_CONTROL)) {
    input.strafe = true;
    if (glm::length(input.right_stick) < kStickDeadzone) input.right_stick = {0.0f, 1.0f};
  }
  if (key(w, GLFW_KEY_T)) input.tag = "wave";
  float orbit = 0.0f;
  if (key(w, GLFW_KEY_Q)) orbit -= 1.0f;
  if (key(w, GLFW_KEY_E)) orbit += 1.0f;
  camera.orbit(orbit * kOrbitYawSpeed * dt, 0.0f);
}

void LiveInput::read_mouse(OrbitCamera& camera) {
  double x = 0.0, y = 0.0;
  glfwGetCursorPos(window_, &x, &y);
  const bool pressed = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  if (pressed && dragging_) {
    camera.orbit(static_cast<float>(x - last_x_) * kMouseRadiansPerPixel,
                 static_cast<float>(y - last_y_) * kMouseRadiansPerPixel);
  }
  dragging_ = pressed;
  last_x_ = x;
  last_y_ = y;
  if (scroll_ != 0.0f) camera.zoom(scroll_);
}

}  // namespace mm::viewer
