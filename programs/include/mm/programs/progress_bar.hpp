#pragma once
// A build's progress on the terminal, for the programs that build databases (`mm build`,
// `mm-viewer --data`): a redrawn bar on a terminal, or a plain line every 10 % when stderr is a
// file or a pipe (CI logs). Called from the builder's progress callback, never two at a time.

#include <cstddef>
#include <string>

namespace mm::cli {

class ProgressBar {
 public:
  // `label` starts the plain lines ("mm build: 40 %"); a disabled bar prints nothing.
  ProgressBar(std::string label, bool enabled);
  void update(size_t done, size_t total);

 private:
  std::string label_;
  bool enabled_;
  bool terminal_;
  size_t last_decile_ = 0;
};

}  // namespace mm::cli
