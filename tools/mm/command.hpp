#pragma once
// Subcommands of the `mm` tool register themselves here; main() dispatches by name.
// Each command parses its own arguments, prints --help, and returns a process exit code.

#include <string>
#include <vector>

namespace mm::cli {

using CommandFn = int (*)(const std::vector<std::string>& args);

struct Command {
  const char* name;     // e.g. "build"
  const char* summary;  // one line for `mm --help`
  CommandFn run;        // receives the arguments after the command name
};

// Adds a command to the table; call from a static initializer in the command's file:
//   static const bool registered = mm::cli::register_command({"build", "...", &run_build});
bool register_command(const Command& command);
const std::vector<Command>& commands();

}  // namespace mm::cli
