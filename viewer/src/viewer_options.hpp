#pragma once
// The command line of mm-viewer (`mm-viewer --help`; declared in viewer_options.cpp).

#include <cmath>
#include <string>
#include <vector>

#include "debug_drawing.hpp"
#include "mm/controller/controller.hpp"
#include "mm/offline/bone_weights.hpp"
#include "skinned_body.hpp"

namespace mm::viewer {

struct ViewerOptions {
  std::string db_path;    // --db
  std::string data_path;  // --data (neither: $MM_DATA, else the shared Bandai folder)
  std::string body_path;  // --body: a skinned glTF character instead of the generated body
  WeightMethod weights = WeightMethod::HeatDiffusion;
  SkinningMethod skinning = SkinningMethod::DualQuaternion;
  std::string script_path;  // replay instead of live input
  std::string record_path;  // record the live input into this script file
  std::string world_path;   // --world: a level the character runs in (docs/world.md)
  std::string start;        // --start X,Z: where the character stands first (world metres)
  ControllerSettings settings;
  bool headless = false;
  int frames = 0;  // 0: windowed runs until closed; headless runs the script and 2 s more
  std::string screenshot_path;
  int every = 0;  // also a screenshot every K frames
  std::string plot_path;
  int width = 1280, height = 720;
  float dt = 0.0f;  // seconds per update; 0: the wall clock (windowed), 1/60 (headless)
  // Where the camera looks from: turned about the character from the input's camera yaw, its
  // pitch and distance (OrbitCamera's, in degrees and metres); NaN keeps the camera's own.
  float view_turn_deg = 0.0f;
  float view_pitch_deg = NAN;
  float view_distance = NAN;
  bool panel = true;
  DebugToggles toggles;
  int crowd = 0;           // --crowd N: a crowd of N characters instead of one (crowd_run.hpp)
  float budget_ms = 4.0f;  // --budget-ms: the crowd's frame budget (0: none)
  bool tier_colours = false;
};

// Parses the arguments (without the program name). Returns the exit code to stop with (0 after
// --help, 2 on a usage error, with the message printed) or -1 to go on.
int parse_viewer_options(const std::vector<std::string>& args, ViewerOptions& out);

}  // namespace mm::viewer
