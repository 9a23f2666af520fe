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
// with "usage: <name> ...". An option's value shows as its type and its validators' ranges or
// choices, e.g. "--idle SECONDS in [0, 60]" or "--ik {on,off}". Call it before declaring the
// options: an option given twice then keeps its last value (repeatable ones keep every value).
void set_up_app(CLI::App& app);

// Parses `args` (the words after the command name, in order). Returns -1 when the command
// should go on, otherwise the exit code after printing: the help on stdout (0), or the error
// as usage_error prints it (2).
int parse_command_line(CLI::App& app, const std::vector<std::string>& args);

// A usage error the parser cannot see (two options that go together, a file extension): prints
// the message prefixed with the program's name and a pointer to --help on stderr; returns 2.
int usage_error(const CLI::App& app, const std::string& message);

// A validator for integer options: the text must be a whole integer within [lo, hi]; "1.5",
// "1e3" and "12abc" are refused as not integers, before any range message.
CLI::Validator integer_in(long long lo, long long hi);

// A validator for real-valued options: a finite number within [lo, hi] (NaN and inf refused).
CLI::Validator number_in(double lo, double hi);

// The same for a range open below: a finite number with lo < x <= hi (a positive length,
// a rate, a time step).
CLI::Validator number_over(double lo, double hi);

// A validator for "A,B" options: two finite numbers separated by a comma, each within
// [lo, hi]; `form` names the parts in the message and the help, e.g. "X,Z".
CLI::Validator number_pair_in(const std::string& form, double lo, double hi);

// A validator for "NAME=VALUE" options (both sides non-empty); `form` names the parts in the
// message and the help, e.g. "ROLE=JOINT".
CLI::Validator assignment(const std::string& form);

}  // namespace mm::cli
