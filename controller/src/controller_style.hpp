#pragma once
// Styles in the search: frames of the requested style (and of clips without a style) compete at
// their plain cost, frames of any other style pay an added cost. The searchers know only tag
// filters, so this is two or three exact filtered searches whose answers are compared with the
// added cost, which keeps the result exactly the best frame under that cost.

#include <cstdint>
#include <span>

#include "mm/search/search.hpp"

namespace mm {

// The best frame for `query` under `constraints` (its tag filters apply to every part), where
// a frame whose clip carries a style tag in `all_style_tags` other than `style_tags` pays
// `style_cost` on top. style_tags == 0 (no request): one plain search. Does not allocate.
SearchResult search_in_style(const Searcher& searcher, std::span<const float> query,
                             const SearchConstraints& constraints, uint64_t style_tags,
                             uint64_t all_style_tags, float style_cost);

}  // namespace mm
