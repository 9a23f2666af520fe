#include "mm/programs/progress_bar.hpp"

#include <unistd.h>

#include <cstdio>
#include <utility>

namespace mm::cli {

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled), terminal_(isatty(fileno(stderr)) != 0) {}

void ProgressBar::update(size_t done, size_t total) {
  if (!enabled_ || total == 0) return;
  const int percent = static_cast<int>(100 * done / total);
  if (terminal_) {
    const int width = 40;
    const int filled = static_cast<int>(width * done / total);
    std::fprintf(stderr, "\r[%s%s] %3d %%", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), percent);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
    return;
  }
  const size_t decile = done * 10 / total;
  if (decile > last_decile_ || done == total) {
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %3d %%\n", label_.c_str(), percent);
  }
}

}  // namespace mm::cli
