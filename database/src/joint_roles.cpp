#include "mm/database/joint_roles.hpp"

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mm {

std::vector<std::string> side_names(bool left, std::span<const std::string_view> patterns) {
  const std::pair<std::string_view, std::string_view> words[] = {
      {"{Side}", left ? "Left" : "Right"},
      {"{side}", left ? "left" : "right"},
      {"{S}", left ? "L" : "R"},
      {"{s}", left ? "l" : "r"}};
  std::vector<std::string> out;
  out.reserve(patterns.size());
  for (std::string_view pattern : patterns) {
    std::string name(pattern);
    for (const auto& [from, to] : words) {
      for (size_t at = name.find(from); at != std::string::npos; at = name.find(from, at)) {
        name.replace(at, from.size(), to);
      }
    }
    out.push_back(std::move(name));
  }
  return out;
}

}  // namespace mm
