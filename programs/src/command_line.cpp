#include "mm/programs/command_line.hpp"

#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "mm/programs/number_parsing.hpp"

namespace mm::cli {

namespace {

constexpr size_t kHelpWidth = 100;
constexpr size_t kOptionColumn = 34;

// `text` with its spaces turned into line breaks so that no line passes `width` (a word longer
// than that keeps its line); existing line breaks stay.
std::string wrap(const std::string& text, size_t width) {
  std::string out;
  size_t line_start = 0;
  std::stringstream words(text);
  for (std::string line; std::getline(words, line, '\n');) {
    if (!out.empty()) out += '\n';
    line_start = out.size();
    std::stringstream line_words(line);
    for (std::string word; line_words >> word;) {
      if (out.size() > line_start) {
        if (out.size() - line_start + 1 + word.size() > width) {
          out += '\n';
          line_start = out.size();
        } else {
          out += ' ';
        }
      }
      out += word;
    }
  }
  return out;
}

// CLI11's formatter with the usage line first, then the command's description, both wrapped;
// option descriptions wrapped to the help's width; and an option's value shown as its type
// name and its validators' descriptions joined by spaces ("SECONDS in [0, 60]") where CLI11
// joins them with ':'.
class Formatter : public CLI::Formatter {
 public:
  std::string make_description(const CLI::App*) const override { return {}; }

  std::string make_usage(const CLI::App* app, std::string name) const override {
    std::string text = CLI::Formatter::make_usage(app, std::move(name));
    if (!app->get_description().empty())
      text += "\n" + wrap(app->get_description(), kHelpWidth) + "\n";
    return text;
  }

  std::string make_option_desc(const CLI::Option* option) const override {
    return wrap(CLI::Formatter::make_option_desc(option), kHelpWidth - kOptionColumn);
  }

  std::string make_option_opts(const CLI::Option* option) const override {
    std::string text = CLI::Formatter::make_option_opts(option);
    const std::string type = option->get_type_name();
    if (type.empty() || !option->get_option_text().empty()) return text;
    const size_t at = text.find(type);
    if (at == std::string::npos) return text;
    std::string spaced;
    std::stringstream pieces(type);
    for (std::string piece; std::getline(pieces, piece, ':');) {
      if (!piece.empty()) spaced.append(spaced.empty() ? "" : " ").append(piece);
    }
    return text.replace(at, type.size(), spaced);
  }
};

template <typename T>
std::string bounds_text(const char* open, T lo, T hi) {
  std::ostringstream text;
  text << open << lo << ", " << hi << "]";
  return text.str();
}

// A validator for a finite number; `below_range` says whether a value is under the range.
CLI::Validator finite_number(const std::string& range, double hi,
                             std::function<bool(double)> below_range) {
  return CLI::Validator(
      [hi, range, below_range](std::string& text) -> std::string {
        const auto value = parse_number(text);
        if (!value) return "'" + text + "' is not a finite number";
        if (below_range(*value) || *value > hi) return text + " is outside " + range;
        return {};
      },
      "in " + range);
}

}  // namespace

void set_up_app(CLI::App& app) {
  auto formatter = std::make_shared<Formatter>();
  formatter->label("Usage", "usage");
  formatter->column_width(kOptionColumn);
  app.formatter(formatter);
  // An option given twice keeps its last value, as scripts that append overrides expect;
  // repeatable options keep every value.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

int usage_error(const CLI::App& app, const std::string& message) {
  std::fprintf(stderr, "%s: %s\nrun '%s --help' for the options\n", app.get_name().c_str(),
               message.c_str(), app.get_name().c_str());
  return 2;
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
    return usage_error(app, error.what());
  }
  return -1;
}

CLI::Validator integer_in(long long lo, long long hi) {
  const std::string range = bounds_text("[", lo, hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const bool negative = !text.empty() && text[0] == '-';
        const auto magnitude = parse_count(negative ? text.substr(1) : text);
        if (!magnitude) return "'" + text + "' is not an integer";
        const long long value = negative ? -*magnitude : *magnitude;
        if (value < lo || value > hi) return text + " is outside " + range;
        return {};
      },
      "in " + range);
}

CLI::Validator number_in(double lo, double hi) {
  return finite_number(bounds_text("[", lo, hi), hi, [lo](double x) { return x < lo; });
}

CLI::Validator number_over(double lo, double hi) {
  return finite_number(bounds_text("(", lo, hi), hi, [lo](double x) { return x <= lo; });
}

CLI::Validator number_pair_in(const std::string& form, double lo, double hi) {
  const std::string range = bounds_text("[", lo, hi);
  return CLI::Validator(
      [form, lo, hi, range](std::string& text) -> std::string {
        const auto pair = parse_number_pair(text);
        if (!pair) return "'" + text + "' is not " + form + " (two finite numbers and a comma)";
        for (const double value : {pair->first, pair->second}) {
          if (value < lo || value > hi) return text + " has a number outside " + range;
        }
        return {};
      },
      "each in " + range);
}

CLI::Validator assignment(const std::string& form) {
  return CLI::Validator(
      [form](std::string& text) -> std::string {
        if (!split_assignment(text)) return "'" + text + "' is not " + form;
        return {};
      },
      "");
}

}  // namespace mm::cli
