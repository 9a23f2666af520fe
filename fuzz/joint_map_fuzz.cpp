// libFuzzer target for the joint map file (parse_joint_map, mm/database/joint_roles.hpp).
// Whatever the text, parse_joint_map must return, and:
// - a refusal reads "fuzz.map:<line>: <what is wrong>";
// - an accepted map assigns only roles of kJointRoles, each once, to non-empty joint names
//   without surrounding spaces, with a line number in the text and the file as source.
// Seeds: maps like the ones docs/your-own-data.md and tests/offline/joint_roles_test.cpp show
// (written into the corpus by fuzz/CMakeLists.txt).
//
// Run: scripts/fuzz.sh, or cmake --build build/fuzz --target fuzz_run_joint_map.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_checks.hpp"
#include "mm/offline/joint_map.hpp"

namespace {

using mm::fuzz::fail;

constexpr const char* kName = "fuzz.map";

bool spaced(const std::string& s) {
  return s.empty() || s.front() == ' ' || s.front() == '\t' || s.back() == ' ' || s.back() == '\t';
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto map = mm::parse_joint_map(text, kName);
  if (!map.ok()) {
    mm::fuzz::check_line_message(map.message(), kName);
    return 0;
  }
  const size_t lines = static_cast<size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
  std::set<std::string> roles;
  for (const mm::JointRoleAssignment& a : *map) {
    if (!mm::find_joint_role(a.role)) fail("unknown role accepted", a.role);
    if (!roles.insert(a.role).second) fail("role accepted twice", a.role);
    if (spaced(a.joint)) fail("joint name empty or not trimmed", "'" + a.joint + "'");
    if (a.line < 1 || static_cast<size_t>(a.line) > lines) {
      fail("line out of the text", std::to_string(a.line));
    }
    if (a.source != kName) fail("source is not the file", a.source);
  }
  return 0;
}
