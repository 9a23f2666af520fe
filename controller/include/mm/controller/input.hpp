#pragma once
// What a player (gamepad, keyboard, script) asks of a character on one frame.
//
// Conventions (docs/conventions.md): Y up, the ground is y = 0. The camera's yaw is a rotation
// about +Y; the camera looks along (sin yaw, 0, cos yaw), so yaw 0 looks along world +Z. A stick
// is read in the camera's frame: +y pushes away from the camera (forward), +x to the camera's
// right. Sticks outside the unit disc are scaled back onto it; non-finite values count as 0.

#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

namespace mm {

struct ControllerInput {
  glm::vec2 left_stick{0.0f};   // move: x right, y forward, relative to the camera
  glm::vec2 right_stick{0.0f};  // facing while strafing, same axes; ignored otherwise
  float camera_yaw = 0.0f;      // radians about +Y; the camera looks along (sin, 0, cos)
  bool run = false;             // run speeds instead of walk speeds
  bool strafe = false;          // keep facing the right stick (or the current facing)
  // A facing to take, as a world yaw (radians about +Y; the character's forward axis then
  // points along (sin, 0, cos)), whatever the sticks say: standing, the character turns on the
  // spot to it; moving, it keeps facing it as when strafing. Not finite (the default): none.
  float facing_yaw = std::numeric_limits<float>::quiet_NaN();
  // Play clips carrying this tag (e.g. "wave"): a database tag equal to it, or whose first word
  // is it ("wave" matches "wave-both-hands" and "wave-left-hand"). Empty: locomotion. The view
  // is read during update() only; it need not outlive the call. Matching it against the
  // database's tag names is string work, so resolve it outside update() into tag_bits below.
  std::string_view tag;
  // The requested style, an id from ControllerDatabase::style_id() (resolved once, outside
  // update()); -1 (or an id the database does not have): any style. Frames of other styles pay
  // ControllerSettings::style_cost in the search (docs/controller.md, Styles).
  int style = -1;
  // `tag` resolved against the database, ControllerDatabase::tag_bits(tag), outside update()
  // (InputScript::resolve_styles() does it for a script's lines, the viewer and the Python
  // binding when they set a tag): update() then reads only these bits (0: locomotion) and
  // never looks at `tag`. Empty: update() resolves `tag` itself, comparing it with every tag
  // name of the database on every call.
  std::optional<uint64_t> tag_bits;
};

}  // namespace mm
