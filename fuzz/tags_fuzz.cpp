// libFuzzer target for the tag manifest (database/include/mm/offline/tags.hpp). Whatever the
// text, parse_tag_manifest must return, and:
// - a refusal reads "fuzz.tags:<line>: <what was expected>";
// - an accepted manifest's rules each have a glob, at least one tag or a style (a line may
//   give only a style), tags and style of letters, digits and "_-.:+", and a line number in
//   the text; matching them against clip names (clip_tags,
//   glob_match, mirrored or not) gives sorted tags without duplicates.
// Seeds: manifests like the ones tests/offline/tags_test.cpp reads (written into the corpus
// by fuzz/CMakeLists.txt).
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_tags.

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_checks.hpp"
#include "mm/offline/tags.hpp"

namespace {

using mm::fuzz::fail;

constexpr const char* kName = "fuzz.tags";

bool tag_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) ||
         std::string_view("_-.:+").find(c) != std::string_view::npos;
}

void check_tags(const std::vector<std::string>& tags) {
  if (!std::is_sorted(tags.begin(), tags.end()) ||
      std::adjacent_find(tags.begin(), tags.end()) != tags.end()) {
    fail("clip tags not sorted and unique", tags.empty() ? "" : tags.front());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const mm::Result<std::vector<mm::TagRule>> rules = mm::parse_tag_manifest(text, kName);
  if (!rules.ok()) {
    mm::fuzz::check_line_message(rules.message(), kName);
    return 0;
  }
  const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  for (const mm::TagRule& rule : *rules) {
    if (rule.pattern.empty() || (rule.tags.empty() && rule.style.empty())) {
      fail("rule without glob, tags or style", rule.pattern);
    }
    if (!std::all_of(rule.style.begin(), rule.style.end(), tag_char)) fail("bad style", rule.style);
    if (rule.line < 1 || static_cast<size_t>(rule.line) > lines) {
      fail("rule line out of the text", std::to_string(rule.line));
    }
    for (const std::string& tag : rule.tags) {
      if (tag.empty() || !std::all_of(tag.begin(), tag.end(), tag_char)) fail("bad tag", tag);
    }
  }
  for (std::string_view clip :
       {"dataset-2_walk-turn-left_normal_001", "003_genuine_at68s", "idle", "", "*?"}) {
    check_tags(mm::clip_tags(clip, false, *rules));
    check_tags(mm::clip_tags(clip, true, *rules));
  }
  // Each glob against the manifest's own text (bounded): the matcher must stay fast on
  // patterns made of many stars.
  const std::string_view subject = text.substr(0, 256);
  for (const mm::TagRule& rule : *rules) (void)mm::glob_match(rule.pattern, subject);
  return 0;
}
