#include "input_recorder.hpp"

#include <fstream>

#include "mm/controller/script.hpp"

namespace mm::viewer {

void InputRecorder::start(float now) {
  active_ = true;
  start_ = now;
  last_state_.clear();
  lines_.clear();
}

void InputRecorder::record(float now, const ControllerInput& input, std::string_view style_name) {
  if (!active_) return;
  std::string line = format_script_line(now - start_, input, style_name);
  // The state is everything after the time field.
  const size_t space = line.find(' ');
  std::string state = space == std::string::npos ? std::string() : line.substr(space);
  if (!lines_.empty() && state == last_state_) return;
  last_state_ = std::move(state);
  lines_.push_back(std::move(line));
}

Status InputRecorder::save(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) return Error{"record: cannot write '" + path.string() + "'"};
  out << "# recorded by mm-viewer: t lx ly rx ry [run] [strafe] [tag=NAME] [style=NAME] "
         "[camera=DEGREES]\n";
  for (const std::string& line : lines_) out << line << '\n';
  out.flush();
  if (!out) return Error{"record: writing '" + path.string() + "' failed"};
  return Status::success();
}

}  // namespace mm::viewer
