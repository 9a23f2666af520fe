#pragma once
// What the debug drawing shows of a controller, each part switched on and off on its own:
// - trajectory: the desired trajectory (where the stick says, green) and the predicted one
//   (where the simulation object's springs go, blue), with their facings;
// - roots: the simulation object (orange ring and facing) and the character's root (white);
// - features: the last search's query (yellow) and the chosen frame's features (magenta),
//   denormalized and placed in the character's root frame: foot positions as crosses, their
//   and the hips' velocities as lines (a tenth of a second long), trajectory points and
//   facings on the ground;
// - contacts: each toe's circle, green in contact, grey in the air; a locked toe's held point
//   (red cross) and the IK target;
// - skeleton: every bone as a line, drawn over the body.

#include "debug_lines.hpp"
#include "mm/controller/controller.hpp"

namespace mm::viewer {

struct DebugToggles {
  bool trajectory = true;
  bool roots = true;
  bool features = false;
  bool contacts = true;
  bool skeleton = false;
};

// Lines drawn into the scene (depth-tested).
void draw_controller_debug(const Controller& controller, const DebugToggles& toggles,
                           DebugLines& lines);
// The skeleton, meant to be drawn over the body.
void draw_skeleton(const Controller& controller, DebugLines& lines);

}  // namespace mm::viewer
