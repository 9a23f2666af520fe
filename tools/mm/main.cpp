// `mm`: the motion-matching command line. `mm <command> --help` describes each command.

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "command.hpp"

namespace mm::cli {

static std::vector<Command>& table() {
  static std::vector<Command> t;
  return t;
}

bool register_command(const Command& command) {
  table().push_back(command);
  return true;
}

const std::vector<Command>& commands() {
  return table();
}

}  // namespace mm::cli

static void print_usage(FILE* out) {
  std::fprintf(
      out, "usage: mm <command> [arguments]   (mm <command> --help for details)\n\ncommands:\n");
  auto list = mm::cli::commands();
  std::sort(list.begin(), list.end(),
            [](const auto& a, const auto& b) { return std::strcmp(a.name, b.name) < 0; });
  for (const auto& c : list) std::fprintf(out, "  %-14s %s\n", c.name, c.summary);
}

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    print_usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  for (const auto& c : mm::cli::commands()) {
    if (!std::strcmp(c.name, argv[1]))
      return c.run(std::vector<std::string>(argv + 2, argv + argc));
  }
  std::fprintf(stderr, "mm: unknown command '%s'\n\n", argv[1]);
  print_usage(stderr);
  return 2;
}
