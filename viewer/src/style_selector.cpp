#include "style_selector.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>

namespace mm::viewer {

namespace {

// The first gamepad's D-pad left and right, or false when there is none.
void dpad(bool& left, bool& right) {
  left = right = false;
  for (int j = GLFW_JOYSTICK_1; j <= GLFW_JOYSTICK_LAST; ++j) {
    GLFWgamepadstate state;
    if (!glfwJoystickIsGamepad(j) || !glfwGetGamepadState(j, &state)) continue;
    left = state.buttons[GLFW_GAMEPAD_BUTTON_DPAD_LEFT] == GLFW_PRESS;
    right = state.buttons[GLFW_GAMEPAD_BUTTON_DPAD_RIGHT] == GLFW_PRESS;
    return;
  }
}

}  // namespace

std::string_view StyleSelector::name(const ControllerDatabase& database, int style) {
  if (style < 0 || style >= database.style_count()) return "any";
  return database.database().style_names()[static_cast<size_t>(style)];
}

// Cycles through -1 (any) and 0 .. count - 1.
void StyleSelector::step(const ControllerDatabase& database, int by) {
  const int slots = database.style_count() + 1;
  style_ = (style_ + 1 + by + slots) % slots - 1;
}

void StyleSelector::poll(GLFWwindow* window, const ControllerDatabase& database,
                         bool keyboard_free) {
  if (database.style_count() == 0) return;
  bool down[12] = {};
  dpad(down[0], down[1]);
  for (int k = 0; k < 10 && keyboard_free; ++k) {
    down[2 + k] = glfwGetKey(window, GLFW_KEY_0 + k) == GLFW_PRESS;
  }
  for (int i = 0; i < 12; ++i) {
    const bool pressed = down[i] && !was_down_[i];
    was_down_[i] = down[i];
    if (!pressed) continue;
    if (i == 0) step(database, -1);
    if (i == 1) step(database, 1);
    if (i >= 2) {
      const int key = i - 2;
      const int style = key == 0 ? 9 : key - 1;  // 1 is the first style, 0 the tenth
      if (style < database.style_count()) style_ = style;
    }
  }
}

void StyleSelector::draw(const ControllerDatabase& database) {
  if (database.style_count() == 0) {
    ImGui::TextDisabled("style: the database has none");
    return;
  }
  const std::string current(name(database, style_));
  if (ImGui::BeginCombo("style (D-pad, 1-9, 0)", current.c_str())) {
    for (int s = -1; s < database.style_count(); ++s) {
      const std::string label(name(database, s));
      if (ImGui::Selectable(label.c_str(), s == style_)) style_ = s;
    }
    ImGui::EndCombo();
  }
}

}  // namespace mm::viewer
