#pragma once
// Records live input as a script (controller/include/mm/controller/script.hpp), one line per
// change of state, so a session can be replayed with `mm-viewer --script` or measured with
// `mm eval --script`. Times start at 0 when recording starts.

#include <filesystem>
#include <string>
#include <vector>

#include "mm/controller/input.hpp"
#include "mm/runtime/result.hpp"

namespace mm::viewer {

class InputRecorder {
 public:
  void start(float now);
  void stop() { active_ = false; }
  bool active() const { return active_; }
  // Adds a line when the input differs from the last recorded one (at the printed precision).
  // `style_name`: the name of input.style (empty: none), written as style=NAME.
  void record(float now, const ControllerInput& input, std::string_view style_name = {});
  int line_count() const { return static_cast<int>(lines_.size()); }
  // Writes the script; fails with a message naming the file.
  Status save(const std::filesystem::path& path) const;

 private:
  bool active_ = false;
  float start_ = 0.0f;
  std::string last_state_;
  std::vector<std::string> lines_;
};

}  // namespace mm::viewer
