#pragma once
// Scripted input: a text file of timed stick and button states, so that a run is reproducible
// without a gamepad (mm eval, mm crowd-bench, mm-viewer --script, tests).
//
// Format: one line per change of state,
//   t lx ly rx ry [run] [strafe] [tag=NAME] [style=NAME] [camera=DEGREES]
// - t: seconds, non-decreasing from line to line (equal times: the later line wins), at most
//   kMaxScriptSeconds;
// - lx ly: the left stick, rx ry: the right stick, each in [-1, 1] (see input.hpp for axes);
// - run, strafe: the buttons held (absent: released);
// - tag=NAME: request clips carrying the tag NAME (absent: locomotion);
// - style=NAME: request the style NAME (absent: any); names are resolved against a database by
//   InputScript::resolve_styles() before the run;
// - camera=DEGREES: the camera's yaw about +Y in degrees (absent: 0, looking along world +Z).
// Each line is a whole state: it holds until the next line, and the last holds forever. Before
// the first line's time the input is neutral (sticks released, camera 0). '#' starts a
// comment; blank lines are ignored. A malformed line is refused with its file name, line
// number and what was expected.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mm/controller/input.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

class ControllerDatabase;

// Bounded runs. A scripted run (mm eval, mm-viewer --headless) is refused up front, with a
// message, when it would be longer than these limits, instead of running for days or converting
// an absurd frame count to an integer:
// - a script's times are at most kMaxScriptSeconds (8 hours; refused at parse, naming the file
//   and line). Times are floats: at 8 hours they still resolve 2 ms, a quarter of a 1/144 s
//   frame;
// - a run's time step is in [kMinRunDt, kMaxRunDt] seconds (10 kHz to 1 Hz);
// - a run takes at most kMaxRunFrames updates (2^22: 8 hours at 1/144 s, 19 hours at 1/60 s).
// The evaluation streams its frames (evaluation.hpp), so memory does not grow with the frame
// count; the limit keeps run times and frame indices (int) sane.
inline constexpr float kMaxScriptSeconds = 8.0f * 3600.0f;
inline constexpr float kMinRunDt = 1e-4f;
inline constexpr float kMaxRunDt = 1.0f;
// The time step of a run (mm eval, a crowd, the headless viewer) when none is given: 60 Hz.
inline constexpr float kDefaultRunDt = 1.0f / 60.0f;
inline constexpr int kMaxRunFrames = 1 << 22;

// The number of updates a run of `seconds` at `dt` takes (ceil(seconds / dt) in float), or
// an error naming the values and the limit when dt is outside [kMinRunDt, kMaxRunDt], seconds
// is negative or not finite, or the count exceeds kMaxRunFrames.
Result<int> scripted_run_frames(float seconds, float dt);

// One line of a script.
struct ScriptEvent {
  float time = 0.0f;      // seconds
  ControllerInput input;  // camera_yaw in radians; input.tag views `tag` below
  std::string tag;        // owns the tag text (empty: none)
  int line = 0;           // line number in the source, for messages
  // The style=NAME text (empty: none); input.style is its id once resolved. Last, with an
  // initializer, so that positional initializers of the fields above stay complete.
  std::string style = {};
};

class InputScript {
 public:
  InputScript() = default;
  // Copies keep their tag views pointing into their own events.
  InputScript(const InputScript& other);
  InputScript& operator=(const InputScript& other);
  InputScript(InputScript&&) noexcept = default;
  InputScript& operator=(InputScript&&) noexcept = default;

  // Takes events in time order (non-decreasing; asserted) and re-points their tag views.
  explicit InputScript(std::vector<ScriptEvent> events);

  const std::vector<ScriptEvent>& events() const { return events_; }
  // The time of the last line (0 for an empty script).
  float duration() const;
  // The input in effect at time t (see the top of this file). Does not allocate.
  ControllerInput at(float t) const;
  // Index of the line in effect at t, or -1 before the first line.
  int index_at(float t) const;
  // Sets every line's input.style from its style name (a line without one gets
  // `default_style`, -1: any), and its input.tag_bits from its tag (an unknown tag: 0, plain
  // locomotion, as update() would resolve it), so that update() does no string work. An unknown
  // name fails with "<name_for_messages>:<line>: " and ControllerDatabase::style_id()'s message.
  Status resolve_styles(const ControllerDatabase& database, std::string_view name_for_messages,
                        int default_style = -1);

 private:
  void repoint_tags();
  std::vector<ScriptEvent> events_;
};

// Parses script text. `name_for_messages` (a file name) starts every error message, which
// also gives the 1-based line number and what was expected there.
Result<InputScript> parse_input_script(std::string_view text, std::string_view name_for_messages);

// Reads and parses a script file.
Result<InputScript> load_input_script(const std::filesystem::path& path);

// One line of the format for this state (used to record live input); parsing it gives the
// same state back to the printed precision. `style_name` (the name of input.style, which the
// line cannot look up: the input holds only an id) is written as style=NAME when not empty.
std::string format_script_line(float time, const ControllerInput& input,
                               std::string_view style_name = {});

// A reproducible input script of `seconds` for character `seed`: every 0.5 to 3 s the stick
// takes a new direction (sometimes released, sometimes running, sometimes strafing with the
// camera turned). The same seed always gives the same script, on every platform.
InputScript varied_input_script(uint32_t seed, float seconds);

}  // namespace mm
