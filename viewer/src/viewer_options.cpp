#include "viewer_options.hpp"

#include <optional>
#include <sstream>

#include "mm/controller/script.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/number_parsing.hpp"
#include "mm/programs/shared_options.hpp"

namespace mm::viewer {
namespace {

const char* const kDescription =
    "The motion-matching demo: a character driven by a gamepad or the keyboard, in a window, or "
    "headless into screenshots. Without --db or --data it builds the database from $MM_DATA, else "
    "from ../shared/mocap/bandai-normal, and caches it next to the program (viewer-cache/).\n\n"
    "input (windowed): gamepad left stick moves, right stick faces while strafing and orbits the "
    "camera otherwise, right trigger or A runs, left trigger or LB strafes; keyboard WASD or "
    "arrows move, Shift runs, Ctrl strafes, Q/E orbit, T waves; mouse drag orbits, wheel zooms; "
    "F1 hides the panel, F12 saves a screenshot (mm-viewer-<time>.png), Esc quits.";

constexpr int kMinSize = 64, kMaxSize = 8192;

// "WxH", each side a whole number of pixels in [kMinSize, kMaxSize].
std::optional<std::pair<int, int>> parse_size(const std::string& text) {
  const size_t x = text.find('x');
  if (x == std::string::npos) return std::nullopt;
  const auto w = cli::parse_count(text.substr(0, x));
  const auto h = cli::parse_count(text.substr(x + 1));
  if (!w || !h || *w < kMinSize || *w > kMaxSize || *h < kMinSize || *h > kMaxSize) {
    return std::nullopt;
  }
  return std::pair{static_cast<int>(*w), static_cast<int>(*h)};
}

// A comma-separated list of debug drawings, or nothing when an item is not one of them.
std::optional<DebugToggles> parse_debug(const std::string& text) {
  DebugToggles toggles = {false, false, false, false, false};
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    if (item == "trajectory")
      toggles.trajectory = true;
    else if (item == "roots")
      toggles.roots = true;
    else if (item == "features")
      toggles.features = true;
    else if (item == "contacts")
      toggles.contacts = true;
    else if (item == "skeleton")
      toggles.skeleton = true;
    else if (item != "none")
      return std::nullopt;
  }
  return toggles;
}

// The files the viewer reads and writes.
void add_file_options(CLI::App& app, ViewerOptions& out) {
  app.add_option("--db", out.db_path, "a database built by `mm build`")->type_name("FILE");
  app.add_option("--data", out.data_path,
                 "BVH/glTF files to build the database from first (with a progress bar)")
      ->type_name("FOLDER");
  app.add_option("--body", out.body_path,
                 "a skinned glTF character whose joint names match the database's, instead of "
                 "the body generated from the skeleton")
      ->type_name("FILE.glb");
  app.add_option("--script", out.script_path,
                 "replay a script (the `mm eval` format) instead of live input")
      ->type_name("FILE");
  app.add_option("--record", out.record_path,
                 "record the live input into FILE (the same format) until the window closes")
      ->type_name("FILE");
  app.add_option("--world", out.world_path,
                 "a level (.gltf or .glb, Y up, metres; every mesh is static collision "
                 "geometry) the character runs in, through Bullet, drawn instead of the grid "
                 "(data/levels/course.glb: the test course, docs/world-levels.md)")
      ->type_name("LEVEL");
  app.add_option("--start", out.start,
                 "where the character stands first, world X and Z in metres (default 0,0)")
      ->type_name("X,Z")
      ->check(cli::number_pair_in("X,Z", -1e7, 1e7));
}

// How the character looks and moves.
void add_character_options(CLI::App& app, ViewerOptions& out) {
  cli::add_weights_option(app, out.weights, "the generated body's weights (default heat)");
  app.add_option_function<std::string>(
         "--skinning",
         [&out](const std::string& name) { parse_skinning_method(name, out.skinning); },
         "linear-blend or dual-quaternion skinning (default dqs)")
      ->check(CLI::IsMember({"lbs", "dqs"}))
      ->type_name("");
  cli::add_set_option(app, out.settings);
  app.add_option_function<std::string>(
         "--debug", [&out](const std::string& text) { out.toggles = *parse_debug(text); },
         "debug drawing, comma separated: trajectory, roots, features, contacts, skeleton, or "
         "none (default trajectory,roots,contacts)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (parse_debug(text)) return {};
            return "'" + text +
                   "' is not a list of trajectory, roots, features, contacts, skeleton or none";
          },
          ""))
      ->type_name("LIST");
  app.add_flag_callback(
      "--no-panel", [&out] { out.panel = false; }, "hide the panel");
}

// How the run goes and what it leaves behind.
void add_run_options(CLI::App& app, ViewerOptions& out) {
  app.add_flag("--headless", out.headless,
               "no window: render offscreen (EGL surfaceless); needs --script or --crowd");
  app.add_option("--frames", out.frames,
                 "stop after N frames (headless default: the script's length and 2 s)")
      ->check(cli::integer_in(1, kMaxRunFrames))
      ->type_name("N");
  app.add_option("--screenshot", out.screenshot_path, "a PNG of the last frame")->type_name("FILE");
  app.add_option("--every", out.every,
                 "also a screenshot every K frames (FILE with -<frame> before .png)")
      ->check(cli::integer_in(1, 10'000'000))
      ->type_name("K");
  app.add_option("--plot", out.plot_path,
                 "a top-down PNG of the whole run: paths, transitions, stands, contacts")
      ->type_name("FILE");
  app.add_option_function<std::string>(
         "--size",
         [&out](const std::string& text) { std::tie(out.width, out.height) = *parse_size(text); },
         "image or window size in pixels (default 1280x720)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (parse_size(text)) return {};
            return "'" + text + "' is not WxH with each side from " + std::to_string(kMinSize) +
                   " to " + std::to_string(kMaxSize);
          },
          ""))
      ->type_name("WxH");
  cli::add_dt_option(app, out.dt, "default: the wall clock in a window, 1/60 headless");
  // The picture only: a script's camera yaw still turns its stick input.
  app.add_option(
         "--view-turn", out.view_turn_deg,
         "with --script, turn the camera about the character by DEG from the script's camera "
         "(the picture only: the script's input is unchanged; default 0)")
      ->check(cli::number_in(-180.0, 180.0))
      ->type_name("DEG");
  app.add_option("--view-pitch", out.view_pitch_deg,
                 "the camera's downward pitch in degrees (default 17)")
      ->check(cli::number_in(-5.0, 80.0))
      ->type_name("DEG");
  app.add_option("--view-distance", out.view_distance,
                 "the camera's distance from the character in metres (default 3.6)")
      ->check(cli::number_in(1.0, 30.0))
      ->type_name("M");
}

// The crowd (crowd_run.hpp).
void add_crowd_options(CLI::App& app, ViewerOptions& out) {
  app.add_option("--crowd", out.crowd,
                 "a crowd of N characters on varied scripted input around the camera, under a "
                 "frame budget (level of detail), drawn with instancing; headless it needs no "
                 "--script and writes mm-viewer-crowd.png unless --screenshot says otherwise")
      ->check(cli::integer_in(1, 1'000'000))
      ->type_name("N");
  app.add_option("--budget-ms", out.budget_ms,
                 "the crowd's frame budget in ms, also a slider in the panel (default 4; 0: every "
                 "character at full rate)")
      ->check(CLI::Range(0.0f, 1000.0f))
      ->type_name("MS");
  app.add_flag("--tier-colours", out.tier_colours,
               "colour the crowd by level-of-detail tier from the start (key T, a panel checkbox)");
}

// The options that only make sense together; -1 when they are fine, else 2 (printed).
int check_combinations(const CLI::App& app, const ViewerOptions& out) {
  if (!out.db_path.empty() && !out.data_path.empty()) {
    return cli::usage_error(app, "give --db or --data, not both");
  }
  if (out.crowd > 0 && (!out.script_path.empty() || !out.record_path.empty() ||
                        !out.world_path.empty() || !out.body_path.empty())) {
    return cli::usage_error(app,
                            "--crowd runs its own input on flat ground: it cannot be used "
                            "with --script, --record, --world or --body");
  }
  if (out.crowd == 0 && (app.count("--budget-ms") > 0 || out.tier_colours)) {
    return cli::usage_error(app, "--budget-ms and --tier-colours need --crowd");
  }
  if (out.headless && out.script_path.empty() && out.crowd == 0) {
    return cli::usage_error(app, "--headless needs --script or --crowd");
  }
  if (!out.script_path.empty() && !out.record_path.empty()) {
    return cli::usage_error(app, "--record records live input; it cannot be used with --script");
  }
  if (out.every > 0 && out.screenshot_path.empty() && out.crowd == 0) {
    return cli::usage_error(app, "--every needs --screenshot");
  }
  return cli::check_settings(app, out.settings);
}

}  // namespace

int parse_viewer_options(const std::vector<std::string>& args, ViewerOptions& out) {
  CLI::App app(kDescription, "mm-viewer");
  cli::set_up_app(app);
  app.footer("exit status: 0 fine, 1 bad database, script, body or no display, 2 bad usage");
  add_file_options(app, out);
  add_character_options(app, out);
  add_run_options(app, out);
  add_crowd_options(app, out);
  if (const int code = cli::parse_command_line(app, args); code >= 0) return code;
  return check_combinations(app, out);
}

}  // namespace mm::viewer
