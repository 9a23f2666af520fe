#pragma once
// The command-line conventions of `mm` and `mm-viewer`, on top of CLI11: every command builds a
// CLI::App, declares typed options, and hands its arguments to parse_command_line.
//
// Exit codes: 0 after --help, 2 after a usage error (unknown option, missing required option,
// a value of the wrong type or out of range), 1 for failures at run time.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace mm::cli {

// A CLI::App named after the command as typed ("mm build", "mm-viewer"), whose help starts
// with "usage: <name> ...".
void set_up_app(CLI::App& app);

// Parses `args` (the words after the command name, in order). Returns -1 when the command
// should go on, otherwise the exit code after printing: the help on stdout (0), or the error
// prefixed with the program's name and a pointer to --help on stderr (2).
int parse_command_line(CLI::App& app, const std::vector<std::string>& args);

// A validator for integer options: the text must be a whole integer within [lo, hi]; "1.5",
// "1e3" and "12abc" are refused as not integers, before any range message.
CLI::Validator integer_in(long long lo, long long hi);

// A validator for real-valued options: a finite number within [lo, hi] (NaN and inf refused).
CLI::Validator number_in(double lo, double hi);

}  // namespace mm::cli
