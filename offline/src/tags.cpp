#include "mm/offline/tags.hpp"

#include <algorithm>
#include <cctype>

#include "mm/database/files.hpp"

namespace mm {

namespace {

bool is_tag_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
         c == ':' || c == '+';
}

void sort_unique(std::vector<std::string>& tags) {
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
}

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  while (true) {
    const size_t at = text.find(separator, start);
    parts.push_back(
        text.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start));
    if (at == std::string_view::npos) break;
    start = at + 1;
  }
  return parts;
}

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c));
  });
}

}  // namespace

bool glob_match(std::string_view pattern, std::string_view text) {
  // Iterative matcher with one backtrack point (the last '*'): linear in practice, never
  // exponential.
  size_t p = 0, t = 0, star = std::string_view::npos, resume = 0;
  while (t < text.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == text[t])) {
      ++p;
      ++t;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = t;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      t = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

Result<std::vector<TagRule>> parse_tag_manifest(std::string_view text,
                                                std::string_view path_for_messages) {
  std::vector<TagRule> rules;
  int line_number = 0;
  for (std::string_view line : split(text, '\n')) {
    ++line_number;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos)
      line = line.substr(0, hash);
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      const size_t start = i;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i > start) words.emplace_back(line.substr(start, i - start));
    }
    if (words.empty()) continue;
    const std::string where =
        std::string(path_for_messages) + ":" + std::to_string(line_number) + ": ";
    if (words.size() < 2) {
      return Error{where + "expected '<glob> <tag>|style=NAME ...', found only '" + words[0] + "'"};
    }
    TagRule rule;
    rule.pattern = words[0];
    rule.line = line_number;
    for (size_t w = 1; w < words.size(); ++w) {
      if (words[w].starts_with("style=")) {
        const std::string style = words[w].substr(6);
        if (!rule.style.empty()) return Error{where + "two styles on one line"};
        if (style.empty() || !std::all_of(style.begin(), style.end(), is_tag_char)) {
          return Error{where +
                       "expected style=NAME with a name of letters, digits and _-.:+, found '" +
                       words[w] + "'"};
        }
        rule.style = style;
        continue;
      }
      const std::string& tag = words[w];
      const auto bad = std::find_if(tag.begin(), tag.end(), [](char c) { return !is_tag_char(c); });
      if (bad != tag.end()) {
        return Error{where + "tag '" + tag + "' has the character '" + std::string(1, *bad) +
                     "'; tags are letters, digits and _-.:+"};
      }
      rule.tags.push_back(tag);
    }
    rules.push_back(std::move(rule));
  }
  return rules;
}

Result<std::vector<TagRule>> load_tag_manifest(const std::filesystem::path& path) {
  auto contents = read_whole_file(path, "tag manifest");
  if (!contents) return contents.error();
  return parse_tag_manifest(contents->text(), path.string());
}

std::vector<std::string> tags_from_name(std::string_view clip_name) {
  const std::vector<std::string_view> parts = split(clip_name, '_');
  // A take ("003_genuine") or one of its segments ("003_genuine_at68s").
  if (parts.size() >= 2 && parts.size() <= 3 && !parts[0].empty() && all_digits(parts[0]) &&
      (parts[1] == "genuine" || parts[1] == "acted")) {
    return {"idle", "reactidle", std::string(parts[1])};  // sorted
  }
  if (parts.size() != 4 || parts[0].substr(0, 8) != "dataset-" || !all_digits(parts[0].substr(8)) ||
      parts[1].empty() || parts[2].empty() || !all_digits(parts[3])) {
    return {};
  }
  std::vector<std::string> tags = {std::string(parts[1]), std::string(parts[2])};
  const std::string_view first_word = parts[1].substr(0, parts[1].find('-'));
  if (first_word == "walk" || first_word == "run" || first_word == "dash") {
    tags.emplace_back("locomotion");
    tags.emplace_back(first_word);
  } else {
    tags.emplace_back("action");
  }
  sort_unique(tags);
  return tags;
}

std::string clip_style(std::string_view clip_name, const std::vector<TagRule>& rules) {
  std::string style;
  for (const TagRule& rule : rules) {
    if (!rule.style.empty() && glob_match(rule.pattern, clip_name)) style = rule.style;
  }
  if (!style.empty()) return style;
  const std::vector<std::string_view> parts = split(clip_name, '_');
  if (parts.size() == 4 && parts[0].starts_with("dataset-") && all_digits(parts[0].substr(8)) &&
      !parts[1].empty() && !parts[2].empty() && all_digits(parts[3])) {
    return std::string(parts[2]);
  }
  return {};
}

std::string swap_left_right(std::string_view tag) {
  // Only whole words swap: "left" not preceded by a letter, and no word continues in lower
  // case after it ("leftover", "straight" stay); "Left"/"Right" may also start a camel-case
  // word ("turnLeft").
  auto is_lower = [](char c) { return std::islower(static_cast<unsigned char>(c)) != 0; };
  auto is_alpha = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; };
  const std::pair<std::string_view, std::string_view> swaps[] = {
      {"left", "right"}, {"right", "left"}, {"Left", "Right"}, {"Right", "Left"}};
  std::string out;
  out.reserve(tag.size() + 1);
  size_t i = 0;
  while (i < tag.size()) {
    bool swapped = false;
    for (const auto& [from, to] : swaps) {
      if (!tag.substr(i).starts_with(from)) continue;
      const bool capital = from[0] == 'L' || from[0] == 'R';
      const bool starts_word = i == 0 || (capital ? true : !is_alpha(tag[i - 1]));
      const size_t after = i + from.size();
      const bool ends_word = after == tag.size() || !is_lower(tag[after]);
      if (starts_word && ends_word) {
        out += to;
        i = after;
        swapped = true;
        break;
      }
    }
    if (!swapped) out += tag[i++];
  }
  return out;
}

std::vector<std::string> clip_tags(std::string_view clip_name, bool mirrored,
                                   const std::vector<TagRule>& rules) {
  std::vector<std::string> tags = tags_from_name(clip_name);
  for (const TagRule& rule : rules) {
    if (!glob_match(rule.pattern, clip_name)) continue;
    tags.insert(tags.end(), rule.tags.begin(), rule.tags.end());
    if (!rule.style.empty()) tags.push_back(rule.style);
  }
  if (mirrored) {
    for (std::string& tag : tags) tag = swap_left_right(tag);
    tags.emplace_back("mirrored");
  }
  sort_unique(tags);
  return tags;
}

}  // namespace mm
