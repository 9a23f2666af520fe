#pragma once
// Runs the `mm` program under test (MM_TOOL_PATH, set by tests/CMakeLists.txt for the tools
// suites) in a shell and captures what it prints.

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace mm::test {

struct CommandRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

inline CommandRun run_mm(const std::string& arguments) {
  // Built with append: GCC 12 gives a false -Wrestrict on chains of operator+ with literals.
  std::string command = "'";
  command.append(MM_TOOL_PATH).append("' ").append(arguments).append(" 2>&1");
  CommandRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return run;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// A path in single quotes, for a command line (the test paths hold no quotes).
inline std::string quoted(const std::filesystem::path& p) {
  std::string q = "'";
  return q.append(p.string()).append("'");
}

}  // namespace mm::test
