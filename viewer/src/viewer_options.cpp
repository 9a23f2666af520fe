#include "viewer_options.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "number_parsing.hpp"

namespace mm::viewer {
namespace {

const char* const kViewerUsage = R"(usage: mm-viewer [--db FILE.mmdb | --data FOLDER] [options]

The motion-matching demo: a character driven by a gamepad or the keyboard, in a window, or
headless into screenshots. Without --db or --data it builds the database from $MM_DATA, else
from ../shared/mocap/bandai-normal, and caches it next to the program (viewer-cache/).

input (windowed): gamepad left stick moves, right stick faces while strafing and orbits the
  camera otherwise, right trigger or A runs, left trigger or LB strafes; keyboard WASD or
  arrows move, Shift runs, Ctrl strafes, Q/E orbit, T waves; mouse drag orbits, wheel zooms;
  F1 hides the panel, F12 saves a screenshot (mm-viewer-<time>.png), Esc quits.

options:
  --db FILE          a database built by `mm build`
  --data FOLDER      BVH/glTF files to build the database from first (with a progress bar)
  --body FILE.glb    a skinned glTF character whose joint names match the database's, instead
                     of the body generated from the skeleton
  --weights METHOD   the generated body's weights: distance, envelope, heat (default),
                     geodesic
  --skinning lbs|dqs linear-blend or dual-quaternion skinning (default dqs)
  --script FILE      replay a script (the `mm eval` format) instead of live input
  --record FILE      record the live input into FILE (the same format) until the window closes
  --set NAME=VALUE   any controller setting (see `mm eval --help`); repeatable
  --debug LIST       debug drawing, comma separated: trajectory, roots, features, contacts,
                     skeleton, or none (default trajectory,roots,contacts)
  --no-panel         hide the panel
  --headless         no window: render offscreen (EGL surfaceless); needs --script
  --frames N         stop after N frames (headless default: the script's length and 2 s)
  --screenshot FILE  a PNG of the last frame
  --every K          also a screenshot every K frames (FILE with -<frame> before .png)
  --plot FILE        a top-down PNG of the whole run: paths, transitions, stands, contacts
  --size WxH         image or window size in pixels (default 1280x720)
  --dt SECONDS       seconds per update (default: the wall clock in a window, 1/60 headless)
  -h, --help         this text

exit status: 0 fine, 1 bad database, script, body or no display, 2 bad usage
)";

int usage_error(const std::string& message) {
  std::fprintf(stderr, "mm-viewer: %s\n\n%s", message.c_str(), kViewerUsage);
  return 2;
}

// A whole number in [low, high].
std::optional<int> parse_count(const std::string& text, int low, int high) {
  const std::optional<long long> n = cli::parse_count(text);
  if (!n || *n < low || *n > high) return std::nullopt;
  return static_cast<int>(*n);
}

bool parse_size(const std::string& text, int& width, int& height) {
  const size_t x = text.find('x');
  if (x == std::string::npos) return false;
  const auto w = parse_count(text.substr(0, x), 64, 8192);
  const auto h = parse_count(text.substr(x + 1), 64, 8192);
  if (!w || !h) return false;
  width = *w;
  height = *h;
  return true;
}

bool parse_debug(const std::string& text, DebugToggles& toggles) {
  toggles = {false, false, false, false, false};
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
      return false;
  }
  return true;
}

// Options that take a value; returns an exit code, or -1 when the value was taken.
int parse_valued(const std::string& a, const std::string& v, ViewerOptions& out) {
  if (a == "--db")
    out.db_path = v;
  else if (a == "--data")
    out.data_path = v;
  else if (a == "--body")
    out.body_path = v;
  else if (a == "--script")
    out.script_path = v;
  else if (a == "--record")
    out.record_path = v;
  else if (a == "--screenshot")
    out.screenshot_path = v;
  else if (a == "--plot")
    out.plot_path = v;
  else if (a == "--weights") {
    const auto method = parse_weight_method(v);
    if (!method) return usage_error("--weights needs distance, envelope, heat or geodesic");
    out.weights = *method;
  } else if (a == "--skinning") {
    if (!parse_skinning_method(v, out.skinning)) return usage_error("--skinning needs lbs or dqs");
  } else if (a == "--set") {
    const size_t eq = v.find('=');
    if (eq == std::string::npos) return usage_error("--set needs NAME=VALUE");
    if (Status s = set_controller_setting(out.settings, v.substr(0, eq), v.substr(eq + 1)); !s) {
      return usage_error(s.message());
    }
  } else if (a == "--debug") {
    if (!parse_debug(v, out.toggles)) {
      return usage_error("--debug takes trajectory, roots, features, contacts, skeleton or none");
    }
  } else if (a == "--frames") {
    const auto n = parse_count(v, 1, 10'000'000);
    if (!n) return usage_error("--frames needs a whole number of frames >= 1");
    out.frames = *n;
  } else if (a == "--every") {
    const auto n = parse_count(v, 1, 10'000'000);
    if (!n) return usage_error("--every needs a whole number of frames >= 1");
    out.every = *n;
  } else if (a == "--size") {
    if (!parse_size(v, out.width, out.height)) return usage_error("--size needs WxH, 64 to 8192");
  } else if (a == "--dt") {
    const auto dt = cli::parse_number(v);
    if (!dt || *dt <= 0.0 || *dt > 1.0) return usage_error("--dt needs seconds in (0, 1]");
    out.dt = static_cast<float>(*dt);
  } else {
    return usage_error("unknown option '" + a + "'");
  }
  return -1;
}

int check(const ViewerOptions& out) {
  if (!out.db_path.empty() && !out.data_path.empty())
    return usage_error("give --db or --data, not both");
  if (out.headless && out.script_path.empty()) return usage_error("--headless needs --script");
  if (!out.script_path.empty() && !out.record_path.empty()) {
    return usage_error("--record records live input; it cannot be used with --script");
  }
  if (out.every > 0 && out.screenshot_path.empty())
    return usage_error("--every needs --screenshot");
  if (Status s = out.settings.validate(); !s) return usage_error(s.message());
  return -1;
}

}  // namespace

int parse_viewer_options(const std::vector<std::string>& args, ViewerOptions& out) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kViewerUsage, stdout);
      return 0;
    }
    if (a == "--headless") {
      out.headless = true;
    } else if (a == "--no-panel") {
      out.panel = false;
    } else if (a.rfind("--", 0) == 0) {
      if (i + 1 >= args.size()) return usage_error(a + " needs a value");
      if (const int code = parse_valued(a, args[++i], out); code >= 0) return code;
    } else {
      return usage_error("unexpected argument '" + a + "'");
    }
  }
  return check(out);
}

}  // namespace mm::viewer
