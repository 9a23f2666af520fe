#pragma once
// Checks the fuzz targets share: failing loudly (libFuzzer then saves the input), and the form
// of the messages of the line-based text formats.

#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace mm::fuzz {

[[noreturn]] inline void fail(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz check failed: %s: %s\n", what, detail.c_str());
  std::abort();
}

// A refusal of a line-based text file must read "<name>:<line>: <what was expected or
// wrong>", with a line number of at least 1.
inline void check_line_message(const std::string& message, std::string_view name) {
  const std::string prefix = std::string(name) + ":";
  if (message.rfind(prefix, 0) != 0) fail("message does not start with the file", message);
  size_t digits = prefix.size();
  while (digits < message.size() && message[digits] >= '0' && message[digits] <= '9') ++digits;
  if (digits == prefix.size() || message[prefix.size()] == '0' ||
      message.compare(digits, 2, ": ") != 0 || message.size() == digits + 2) {
    fail("message has no line number or no reason", message);
  }
}

}  // namespace mm::fuzz
