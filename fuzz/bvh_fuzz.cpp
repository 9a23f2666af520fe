// libFuzzer target for the BVH importer. Whatever the bytes, parse_bvh must return: no crash,
// no sanitizer report, no hang, no allocation beyond the input's size times a constant. On top
// of that it checks the importer's contract:
// - an accepted input is a valid clip (Clip::validate: sizes, finite values, unit rotations)
//   with as many transforms as frames times joints, and at most one warning (frame lines beyond
//   "Frames:"), which starts with the file name and a line number;
// - a refused input gets a message that starts with the file name and a line number and says
//   what was expected.
// Each accepted input is parsed again with a huge scale, where position values can overflow
// float range; that must be refused or stay valid, never produce infinities.
//
// Run: cmake --build build/fuzz --target fuzz_run_bvh (see fuzz/CMakeLists.txt).

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "mm/offline/bvh.hpp"

namespace {

constexpr const char* kPath = "fuzz.bvh";

[[noreturn]] void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "bvh_fuzz: %s: %s\n", what, detail.c_str());
  std::abort();
}

// "fuzz.bvh:<line>: ..." (a bad scale option has no line, but is never used here).
void check_file_and_line(const std::string& message) {
  const std::string prefix = std::string(kPath) + ":";
  if (message.rfind(prefix, 0) != 0) fail("message does not start with the file", message);
  size_t digits = prefix.size();
  while (digits < message.size() && message[digits] >= '0' && message[digits] <= '9') ++digits;
  if (digits == prefix.size() || message.compare(digits, 2, ": ") != 0) {
    fail("message has no line number", message);
  }
}

void check(const mm::Result<mm::Clip>& clip) {
  if (clip.ok()) {
    const mm::Status valid = clip->validate();
    if (!valid.ok()) fail("accepted an invalid clip", valid.message());
    const size_t expected = static_cast<size_t>(clip->frame_count) * clip->joint_count();
    if (clip->local.size() != expected) fail("transform count", std::to_string(clip->local.size()));
    if (clip->warnings.size() > 1) fail("more than one warning", clip->warnings[1]);
    for (const std::string& warning : clip->warnings) check_file_and_line(warning);
    return;
  }
  const std::string& message = clip.message();
  check_file_and_line(message);
  if (message.find("expected") == std::string::npos) fail("message says nothing expected", message);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mm::Result<mm::Clip> clip = mm::parse_bvh(text, kPath);
  check(clip);
  if (clip.ok()) check(mm::parse_bvh(text, kPath, mm::BvhOptions{1e30f}));
  return 0;
}
