#pragma once
// Internal to the baselines: each baseline's factory (input already validated).

#include <memory>

#include "mm/runtime/result.hpp"
#include "mm/search_baselines/baselines.hpp"

namespace mm::search_baselines {

Result<std::unique_ptr<Searcher>> make_brute(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_brute_staged(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_aabb(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_approx(const SearchInput& input,
                                              const BaselineSearchOptions& options);

}  // namespace mm::search_baselines
