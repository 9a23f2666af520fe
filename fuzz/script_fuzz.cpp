// libFuzzer target for the input-script parser (controller/include/mm/controller/script.hpp).
// Whatever the text, parse_input_script must return, and:
// - a refusal reads "fuzz.txt:<line>: <what was expected>";
// - an accepted script has times >= 0, finite and non-decreasing, sticks in [-1, 1], finite
//   camera yaws, tag views on the events' own text; at() past the end gives the last line's
//   state; and every event printed by format_script_line parses back to the same state to the
//   printed precision (3 decimals, camera 1 decimal of a degree).
// Seeds: scripts/input/*.txt (copied into the corpus by fuzz/CMakeLists.txt).
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_script.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_checks.hpp"
#include "mm/controller/script.hpp"

namespace {

using mm::fuzz::fail;

constexpr const char* kName = "fuzz.txt";

bool near(float a, float b, float tolerance) {
  return std::abs(a - b) <= tolerance + 1e-6f * std::max(std::abs(a), std::abs(b));
}

void check_event(const mm::ScriptEvent& event, float previous_time) {
  const mm::ControllerInput& in = event.input;
  if (!std::isfinite(event.time) || event.time < previous_time) {
    fail("time not finite or decreasing", std::to_string(event.time));
  }
  for (float v : {in.left_stick.x, in.left_stick.y, in.right_stick.x, in.right_stick.y}) {
    if (!(v >= -1.0f && v <= 1.0f)) fail("stick out of [-1, 1]", std::to_string(v));
  }
  if (!std::isfinite(in.camera_yaw)) fail("camera yaw not finite", "");
  if (in.tag != event.tag || (!event.tag.empty() && in.tag.data() != event.tag.data())) {
    fail("tag view does not show the event's tag", event.tag);
  }
}

void check_round_trip(const mm::ScriptEvent& event) {
  const std::string line = mm::format_script_line(event.time, event.input);
  const mm::Result<mm::InputScript> again = mm::parse_input_script(line, kName);
  if (!again.ok()) fail("a formatted line does not parse", line + " -> " + again.message());
  if (again->events().size() != 1) fail("a formatted line is not one event", line);
  const mm::ControllerInput& a = event.input;
  const mm::ControllerInput& b = again->events()[0].input;
  const float yaw_step = 0.05f * 3.14159265f / 180.0f;
  if (!near(again->events()[0].time, event.time, 0.0005f) ||
      !near(a.left_stick.x, b.left_stick.x, 0.0005f) ||
      !near(a.left_stick.y, b.left_stick.y, 0.0005f) ||
      !near(a.right_stick.x, b.right_stick.x, 0.0005f) ||
      !near(a.right_stick.y, b.right_stick.y, 0.0005f) || a.run != b.run || a.strafe != b.strafe ||
      a.tag != b.tag || !near(a.camera_yaw, b.camera_yaw, yaw_step)) {
    fail("a formatted line parses to another state", line);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const mm::Result<mm::InputScript> script = mm::parse_input_script(text, kName);
  if (!script.ok()) {
    mm::fuzz::check_line_message(script.message(), kName);
    return 0;
  }
  float previous = 0.0f;
  for (const mm::ScriptEvent& event : script->events()) {
    check_event(event, previous);
    check_round_trip(event);
    previous = event.time;
  }
  if (!script->events().empty()) {
    const mm::ScriptEvent& last = script->events().back();
    const mm::ControllerInput after = script->at(script->duration() + 1.0f);
    if (after.left_stick != last.input.left_stick || after.tag != last.tag) {
      fail("the last line does not hold after the end", std::to_string(last.line));
    }
  }
  return 0;
}
