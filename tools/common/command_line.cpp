#include "command_line.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "number_parsing.hpp"

namespace mm::cli {

void set_up_app(CLI::App& app) {
  app.get_formatter()->label("Usage", "usage");
  app.get_formatter()->column_width(34);
}

int parse_command_line(CLI::App& app, const std::vector<std::string>& args) {
  // CLI11 consumes a vector from its back.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::ParseError& error) {
    std::fprintf(stderr, "%s: %s\nrun '%s --help' for the options\n", app.get_name().c_str(),
                 error.what(), app.get_name().c_str());
    return 2;
  }
  return -1;
}

namespace {

template <typename T>
std::string bounds_text(T lo, T hi) {
  std::ostringstream text;
  text << "[" << lo << ", " << hi << "]";
  return text.str();
}

}  // namespace

CLI::Validator integer_in(long long lo, long long hi) {
  const std::string range = bounds_text(lo, hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const bool negative = !text.empty() && text[0] == '-';
        const auto magnitude = parse_count(negative ? text.substr(1) : text);
        if (!magnitude) return "'" + text + "' is not an integer";
        const long long value = negative ? -*magnitude : *magnitude;
        if (value < lo || value > hi) return text + " is outside " + range;
        return {};
      },
      "INT in " + range);
}

CLI::Validator number_in(double lo, double hi) {
  const std::string range = bounds_text(lo, hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const auto value = parse_number(text);
        if (!value) return "'" + text + "' is not a finite number";
        if (*value < lo || *value > hi) return text + " is outside " + range;
        return {};
      },
      "NUMBER in " + range);
}

}  // namespace mm::cli
