#pragma once
// The Dear ImGui panel of the windowed viewer: frame and search timings, what is playing (clip,
// frame, tags), the last search's cost channel by channel, and live controls for the main
// settings, the feature weights, the body's skinning and weights, the debug drawing, pausing
// and recording the input.

#include <string>

#include "input_recorder.hpp"
#include "scene.hpp"
#include "style_selector.hpp"

namespace mm::viewer {

// What the panel edits outside the scene.
struct PanelState {
  SkinningMethod skinning = SkinningMethod::DualQuaternion;
  bool show_body = true;
  bool paused = false;
  float time_scale = 1.0f;
  InputRecorder* recorder = nullptr;  // null: no recording (replaying a script)
  StyleSelector* styles = nullptr;    // null: the style comes from a script
  std::string record_path;
  std::string input_source;  // "gamepad: ...", "keyboard and mouse", "script: FILE"
  std::string message;       // the outcome of the last action, shown until replaced
};

void draw_panel(Scene& scene, PanelState& state);

}  // namespace mm::viewer
