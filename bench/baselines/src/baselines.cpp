#include "mm/search_baselines/baselines.hpp"

#include <algorithm>
#include <string>

#include "factories.hpp"

namespace mm {

std::span<const std::string_view> baseline_method_names() {
  static constexpr std::string_view names[] = {"brute", "brute-staged", "aabb", "approx"};
  return names;
}

std::span<const std::string_view> bench_method_names() {
  static constexpr std::string_view names[] = {
      "brute", "brute-simd", "brute-staged", "aabb", "kdtree", "boxtree", "approx", "kdtree-eps"};
  return names;
}

bool is_brute_force(std::string_view method) {
  return method == "brute" || method == "brute-simd" || method == "brute-staged";
}

Result<std::unique_ptr<Searcher>> make_bench_searcher(std::string_view method,
                                                      const SearchInput& input,
                                                      const BaselineSearchOptions& options) {
  const auto baselines = baseline_method_names();
  if (std::find(baselines.begin(), baselines.end(), method) == baselines.end()) {
    auto made = make_searcher(method, input, options);
    if (made) return made;
    const auto library = search_method_names();
    if (std::find(library.begin(), library.end(), method) != library.end()) return made;
    std::string known;
    for (std::string_view name : bench_method_names())
      known.append(known.empty() ? "" : ", ").append(name);
    return Error{"unknown search method '" + std::string(method) + "' (known: " + known + ")"};
  }
  if (Status valid = input.validate(); !valid) return Error{valid.message()};
  if (method == "brute") return search_baselines::make_brute(input);
  if (method == "brute-staged") return search_baselines::make_brute_staged(input);
  if (method == "aabb") return search_baselines::make_aabb(input);
  return search_baselines::make_approx(input, options);
}

}  // namespace mm
