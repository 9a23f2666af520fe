#pragma once
// Live input from the devices GLFW sees: the first connected gamepad, looked up again every
// frame so one can be plugged in or pulled out while running, and the keyboard and mouse
// always (both add up). The orbit camera is driven here too, since mouse drags and the right
// stick move it, and its yaw is what makes "forward" point away from the camera.
//
// Gamepad: left stick moves; right stick turns the facing while strafing and orbits the camera
// otherwise; right trigger or A runs; left trigger or left bumper strafes.
// Keyboard: WASD or arrows move, Shift runs, Ctrl strafes (facing away from the camera),
// Q / E orbit, T requests the "wave" tag while held. Mouse: left drag orbits, wheel zooms.

#include <string>

#include "mm/controller/input.hpp"
#include "orbit_camera.hpp"

struct GLFWwindow;

namespace mm::viewer {

class LiveInput {
 public:
  // Installs a scroll callback on the window (the window's user pointer becomes this object,
  // which therefore must not move while the window lives).
  explicit LiveInput(GLFWwindow* window);
  LiveInput(const LiveInput&) = delete;
  LiveInput& operator=(const LiveInput&) = delete;

  // This frame's input; moves the camera. When the panel has the mouse or the keyboard, those
  // are left to it.
  ControllerInput read(OrbitCamera& camera, float dt, bool panel_has_mouse,
                       bool panel_has_keyboard);
  // "gamepad: <name>" or "keyboard and mouse".
  const std::string& device() const { return device_; }

 private:
  static void on_scroll(GLFWwindow* window, double x, double y);
  void read_gamepad(ControllerInput& input, OrbitCamera& camera, float dt);
  void read_keyboard(ControllerInput& input, OrbitCamera& camera, float dt);
  void read_mouse(OrbitCamera& camera);

  GLFWwindow* window_;
  std::string device_ = "keyboard and mouse";
  double last_x_ = 0.0, last_y_ = 0.0;
  bool dragging_ = false;
  float scroll_ = 0.0f;
};

}  // namespace mm::viewer
