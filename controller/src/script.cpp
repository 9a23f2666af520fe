#include "mm/controller/script.hpp"

#include "mm/controller/controller.hpp"

#include "mm/database/files.hpp"
#include "mm/runtime/float_to_integer.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <system_error>
#include <utility>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/assert.hpp"

namespace mm {

namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

// Longer tokens are cut in messages, so that a binary file given by mistake does not print
// itself into the error.
constexpr size_t kMaxQuotedToken = 40;

bool is_separator(char c) {
  return c == ' ' || c == '\t';
}

// The same character set as database tags (mm/offline/tags.hpp), so that a script can request
// any tag a database can carry.
bool is_tag_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.' || c == ':' || c == '+';
}

std::string quoted(std::string_view token) {
  // Appended piece by piece: g++ 12 gives a false -Wrestrict for "'" + std::string(...).
  std::string text = "'";
  text += token.substr(0, kMaxQuotedToken);
  text += token.size() > kMaxQuotedToken ? "...'" : "'";
  return text;
}

// A whole token as a finite float, or false. std::from_chars, unlike strtof, does not follow
// the C locale, so "0.5" means one half whatever the program's locale is. A leading '+' is
// accepted because people write it, although from_chars itself does not.
bool parse_finite(std::string_view token, float& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return false;
  value += 0.0f;  // -0 becomes +0, so that "-0" and "0" are the same state
  return true;
}

// The shortest text that reads back as `value` ("2.5", not "2.500000").
template <std::floating_point Float>
std::string shortest(Float value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  MM_ASSERT(ec == std::errc());
  (void)ec;
  return std::string(buffer, end);
}

// The shortest fixed-point text that reads back as `value` ("0.0001", not "1e-04"), for values
// known to be of moderate size (the limits, a valid time step).
std::string fixed(float value) {
  char buffer[64];  // enough for any float of moderate size
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  MM_ASSERT(ec == std::errc());
  (void)ec;
  return std::string(buffer, end);
}

// What each stick number of a line is, for messages.
constexpr std::string_view kStickNames[4] = {"the left stick's x", "the left stick's y",
                                             "the right stick's x", "the right stick's y"};

// Appends `value` with `decimals` digits after the point, without "-0.000" for a value that
// rounds to zero. std::to_chars, unlike printf, does not follow the C locale either.
void append_fixed(std::string& out, double value, int decimals) {
  char buffer[64];  // enough for any finite float in fixed notation
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, decimals);
  MM_ASSERT(ec == std::errc());
  (void)ec;
  std::string_view text(buffer, static_cast<size_t>(end - buffer));
  if (text.starts_with('-') && text.find_first_not_of("0.", 1) == std::string_view::npos) {
    text.remove_prefix(1);
  }
  out += text;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Run limits

Result<int> scripted_run_frames(float seconds, float dt) {
  if (!(dt >= kMinRunDt && dt <= kMaxRunDt)) {
    return Error{"the time step must be in [" + fixed(kMinRunDt) + ", " + fixed(kMaxRunDt) +
                 "] seconds, found " + shortest(dt)};
  }
  if (!(seconds >= 0.0f) || !std::isfinite(seconds)) {
    return Error{"the run length must be a finite number of seconds >= 0, found " +
                 shortest(seconds)};
  }
  const float needed = std::ceil(seconds / dt);
  const std::optional<int> frames = checked_integer<int>(needed);
  if (!frames || *frames > kMaxRunFrames) {
    const std::optional<int64_t> whole = checked_integer<int64_t>(needed);
    return Error{"a run of " + shortest(seconds) + " s at a time step of " + fixed(dt) +
                 " s needs " + (whole ? std::to_string(*whole) : shortest(needed)) +
                 " frames, more than the limit of " + std::to_string(kMaxRunFrames)};
  }
  return *frames;
}

// ---------------------------------------------------------------------------------------------
// InputScript

InputScript::InputScript(const InputScript& other) : events_(other.events_) {
  repoint_tags();
}

InputScript& InputScript::operator=(const InputScript& other) {
  if (this != &other) {
    events_ = other.events_;
    repoint_tags();
  }
  return *this;
}

InputScript::InputScript(std::vector<ScriptEvent> events) : events_(std::move(events)) {
  MM_ASSERT(
      std::is_sorted(events_.begin(), events_.end(),
                     [](const ScriptEvent& a, const ScriptEvent& b) { return a.time < b.time; }));
  repoint_tags();
}

// A copied ScriptEvent still views the tag of the event it was copied from; `tag` is the owner,
// so every view is rebuilt from it. (Moves keep the vector's buffer, hence the strings.)
Status InputScript::resolve_styles(const ControllerDatabase& database,
                                   std::string_view name_for_messages, int default_style) {
  for (ScriptEvent& event : events_) {
    event.input.tag_bits = database.tag_bits(event.tag);
    if (event.style.empty()) {
      event.input.style = default_style;
      continue;
    }
    Result<int> id = database.style_id(event.style);
    if (!id) {
      return Error{std::string(name_for_messages) + ":" + std::to_string(event.line) + ": " +
                   id.message()};
    }
    event.input.style = *id;
  }
  return Status::success();
}

void InputScript::repoint_tags() {
  for (ScriptEvent& event : events_) event.input.tag = event.tag;
}

float InputScript::duration() const {
  return events_.empty() ? 0.0f : events_.back().time;
}

int InputScript::index_at(float t) const {
  // Written so that a NaN time, like a time before the first line, gives the neutral input.
  if (events_.empty() || !(t >= events_.front().time)) return -1;
  const auto after =
      std::upper_bound(events_.begin(), events_.end(), t,
                       [](float time, const ScriptEvent& e) { return time < e.time; });
  // upper_bound passes every line at time t, so of equal times the later line wins.
  return static_cast<int>(after - events_.begin()) - 1;
}

ControllerInput InputScript::at(float t) const {
  const int index = index_at(t);
  return index < 0 ? ControllerInput{} : events_[static_cast<size_t>(index)].input;
}

// ---------------------------------------------------------------------------------------------
// Parsing

namespace {

// One line's tokens: comments ('#' to the end) and a Windows line end dropped, split at
// separators.
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens) {
  if (const size_t hash = line.find('#'); hash != std::string_view::npos) {
    line = line.substr(0, hash);
  }
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  tokens.clear();
  for (size_t i = 0; i < line.size();) {
    while (i < line.size() && is_separator(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_separator(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

// One line's tokens and how to name them in messages ("file:line: ").
struct ScriptLine {
  const std::vector<std::string_view>& tokens;
  std::string where;

  std::string found(size_t index) const {
    return index < tokens.size() ? quoted(tokens[index]) : std::string("the end of the line");
  }
};

// The time (never before the previous line's) and the four stick values.
Status parse_time_and_sticks(const ScriptLine& line, const std::vector<ScriptEvent>& events,
                             ScriptEvent& event) {
  if (!parse_finite(line.tokens[0], event.time) || event.time < 0.0f ||
      event.time > kMaxScriptSeconds) {
    return Error{line.where + "expected the time in seconds (a number in [0, " +
                 shortest(kMaxScriptSeconds) + "], the longest script), found " + line.found(0)};
  }
  if (!events.empty() && event.time < events.back().time) {
    return Error{line.where + "expected a time >= " + shortest(events.back().time) +
                 " (the time of line " + std::to_string(events.back().line) + "), found " +
                 line.found(0)};
  }
  float sticks[4] = {};
  for (size_t k = 0; k < 4; ++k) {
    const size_t index = k + 1;
    if (index >= line.tokens.size() || !parse_finite(line.tokens[index], sticks[k]) ||
        sticks[k] < -1.0f || sticks[k] > 1.0f) {
      return Error{line.where + "expected " + std::string(kStickNames[k]) +
                   " (a number in [-1, 1]), found " + line.found(index)};
    }
  }
  event.input.left_stick = {sticks[0], sticks[1]};
  event.input.right_stick = {sticks[2], sticks[3]};
  return Status::success();
}

// The optional flags after the sticks, each at most once: run, strafe, tag=NAME, style=NAME,
// camera=DEGREES.
Status parse_flags(const ScriptLine& line, ScriptEvent& event) {
  bool seen_run = false, seen_strafe = false, seen_tag = false, seen_camera = false,
       seen_style = false;
  // True the second time a flag is seen on this line.
  auto repeated = [](bool& seen) { return std::exchange(seen, true); };
  for (size_t index = 5; index < line.tokens.size(); ++index) {
    const std::string_view token = line.tokens[index];
    auto twice = [&](std::string_view flag) {
      return Error{line.where + "expected " + std::string(flag) +
                   " at most once on a line, found " + quoted(token) + " again"};
    };
    if (token == "run") {
      if (repeated(seen_run)) return twice("run");
      event.input.run = true;
    } else if (token == "strafe") {
      if (repeated(seen_strafe)) return twice("strafe");
      event.input.strafe = true;
    } else if (token.starts_with("tag=")) {
      if (repeated(seen_tag)) return twice("tag=NAME");
      const std::string_view name = token.substr(4);
      if (name.empty() || !std::all_of(name.begin(), name.end(), is_tag_char)) {
        return Error{line.where +
                     "expected tag=NAME with a name of letters, digits and _-.:+, found " +
                     quoted(token)};
      }
      event.tag = name;
    } else if (token.starts_with("style=")) {
      if (repeated(seen_style)) return twice("style=NAME");
      const std::string_view name = token.substr(6);
      if (name.empty() || !std::all_of(name.begin(), name.end(), is_tag_char)) {
        return Error{line.where +
                     "expected style=NAME with a name of letters, digits and _-.:+, found " +
                     quoted(token)};
      }
      event.style = name;
    } else if (token.starts_with("camera=")) {
      if (repeated(seen_camera)) return twice("camera=DEGREES");
      float degrees = 0.0f;
      if (!parse_finite(token.substr(7), degrees)) {
        return Error{line.where +
                     "expected camera=DEGREES with a finite number of degrees, found " +
                     quoted(token)};
      }
      event.input.camera_yaw = static_cast<float>(degrees * kRadiansPerDegree);
    } else {
      return Error{line.where +
                   "expected run, strafe, tag=NAME, style=NAME or camera=DEGREES, found " +
                   quoted(token)};
    }
  }
  return Status::success();
}

}  // namespace

Result<InputScript> parse_input_script(std::string_view text, std::string_view name_for_messages) {
  // Some Windows editors start a UTF-8 file with an invisible byte order mark; it is no token.
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  std::vector<ScriptEvent> events;
  std::vector<std::string_view> tokens;
  int line_number = 0;
  size_t line_start = 0;
  while (line_start <= text.size()) {
    size_t line_end = text.find('\n', line_start);
    if (line_end == std::string_view::npos) line_end = text.size();
    split_tokens(text.substr(line_start, line_end - line_start), tokens);
    line_start = line_end + 1;
    ++line_number;
    if (tokens.empty()) continue;

    const ScriptLine line{
        tokens, std::string(name_for_messages) + ":" + std::to_string(line_number) + ": "};
    ScriptEvent event;
    event.line = line_number;
    if (Status s = parse_time_and_sticks(line, events, event); !s) return Error{s.message()};
    if (Status s = parse_flags(line, event); !s) return Error{s.message()};
    events.push_back(std::move(event));
  }
  return InputScript(std::move(events));
}

Result<InputScript> load_input_script(const std::filesystem::path& path) {
  auto contents = read_whole_file(path, "input script");
  if (!contents) return contents.error();
  return parse_input_script(contents->text(), path.string());
}

// ---------------------------------------------------------------------------------------------
// Formatting

std::string format_script_line(float time, const ControllerInput& input,
                               std::string_view style_name) {
  // The line must parse whatever a live source hands over: a non-finite value prints as 0
  // (input.hpp: it counts as 0), a negative time as 0, and a stick with a component beyond
  // [-1, 1] is scaled back along its direction, which the controller's own scaling onto the
  // unit disc then treats exactly as the original.
  auto finite_or_zero = [](float v) { return std::isfinite(v) ? v : 0.0f; };
  auto printable_stick = [&](glm::vec2 stick) {
    stick = {finite_or_zero(stick.x), finite_or_zero(stick.y)};
    const float largest = std::max(std::abs(stick.x), std::abs(stick.y));
    if (largest > 1.0f) stick = glm::clamp(stick / largest, -1.0f, 1.0f);
    return stick;
  };
  const glm::vec2 left = printable_stick(input.left_stick);
  const glm::vec2 right = printable_stick(input.right_stick);

  std::string line;
  append_fixed(line, std::max(finite_or_zero(time), 0.0f), 3);
  for (const float value : {left.x, left.y, right.x, right.y}) {
    line += ' ';
    append_fixed(line, value, 3);
  }
  if (input.run) line += " run";
  if (input.strafe) line += " strafe";
  if (!input.tag.empty()) {
    // A tag outside the tag characters would not parse back; tags come from the program.
    MM_ASSERT(std::all_of(input.tag.begin(), input.tag.end(), is_tag_char));
    line += " tag=";
    line += input.tag;
  }
  if (!style_name.empty()) {
    // Style names come from the database, whose builder takes them from tag characters.
    MM_ASSERT(std::all_of(style_name.begin(), style_name.end(), is_tag_char));
    line += " style=";
    line += style_name;
  }
  const double degrees = finite_or_zero(input.camera_yaw) / kRadiansPerDegree;
  if (std::abs(degrees) >= 0.05) {  // absent means 0, which is what "camera=0.0" would say
    line += " camera=";
    append_fixed(line, degrees, 1);
  }
  return line;
}

namespace {

// A float in [0, 1) from the generator's raw bits (std::uniform_real_distribution differs
// between standard libraries; this does not).
float unit(std::mt19937& rng) {
  return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f);
}

}  // namespace

InputScript varied_input_script(uint32_t seed, float seconds) {
  std::mt19937 rng(seed * 2654435761u + 12345u);
  std::vector<ScriptEvent> events;
  float t = 0.0f;
  int line = 1;
  while (t < seconds) {
    ScriptEvent e;
    e.time = t;
    e.line = line++;
    const float kind = unit(rng);
    const float angle = unit(rng) * glm::two_pi<float>();
    if (kind < 0.15f) {
      e.input.left_stick = glm::vec2(0.0f);  // stand
    } else {
      e.input.left_stick = glm::vec2(std::sin(angle), std::cos(angle));
    }
    e.input.run = unit(rng) < 0.3f;
    e.input.strafe = unit(rng) < 0.1f;
    if (e.input.strafe) {
      const float facing = unit(rng) * glm::two_pi<float>();
      e.input.right_stick = glm::vec2(std::sin(facing), std::cos(facing));
    }
    e.input.camera_yaw = unit(rng) < 0.2f ? (unit(rng) - 0.5f) * glm::pi<float>() : 0.0f;
    events.push_back(e);
    t += 0.5f + 2.5f * unit(rng);
  }
  return InputScript(std::move(events));
}

}  // namespace mm
