#pragma once
// Option values of the command-line programs (`mm`, `mm-viewer`): the whole text or nothing.

#include <optional>
#include <string>
#include <utility>

namespace mm::cli {

// The whole text parsed as a finite number, or nothing (no trailing characters allowed).
std::optional<double> parse_number(const std::string& text);

// The whole text parsed as a non-negative integer, or nothing ("1.5" and "-2" are refused).
std::optional<long long> parse_count(const std::string& text);

// "A,B": two finite numbers separated by one comma (a point on the ground, say), or nothing.
std::optional<std::pair<double, double>> parse_number_pair(const std::string& text);

// "NAME=VALUE" split at its first '=', both sides non-empty, or nothing.
std::optional<std::pair<std::string, std::string>> split_assignment(const std::string& text);

}  // namespace mm::cli
