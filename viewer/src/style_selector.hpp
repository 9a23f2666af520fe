#pragma once
// The demo's style request (docs/controller.md, Styles): a combo in the panel, the gamepad's
// D-pad left / right cycling through "any" and every style of the database, and the number
// keys 1-9 picking the first nine styles, 0 the tenth. The chosen id goes into every live
// input's ControllerInput::style; the name is resolved here, never in update().

#include <string>
#include <string_view>

#include "mm/controller/controller.hpp"
#include "mm/controller/input.hpp"

struct GLFWwindow;

namespace mm::viewer {

class StyleSelector {
 public:
  // Reads the D-pad and the number keys (edges only: one step per press). `keyboard_free`:
  // the panel does not have the keyboard.
  void poll(GLFWwindow* window, const ControllerDatabase& database, bool keyboard_free);
  // The combo, inside the current ImGui window.
  void draw(const ControllerDatabase& database);
  void apply(ControllerInput& input) const { input.style = style_; }
  int style() const { return style_; }
  // The style's name, "any" for none.
  static std::string_view name(const ControllerDatabase& database, int style);

 private:
  void step(const ControllerDatabase& database, int by);
  int style_ = -1;
  bool was_down_[12] = {};  // D-pad left, right, then keys 0-9
};

}  // namespace mm::viewer
