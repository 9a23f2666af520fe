#pragma once
// Styles in the search: frames of the requested style (and of clips without a style) compete at
// their plain cost, frames of other styles pay an added cost that grows along the style's
// fallback order (ControllerDatabase::style_fallback): its nearest rich style, then normal,
// then any other style. The searchers know only tag filters, so this is up to five exact
// filtered searches in order of their added cost, stopping as soon as no later tier can win,
// which keeps the result exactly the best frame under those costs.

#include <cstdint>
#include <span>

#include "mm/search/search.hpp"

namespace mm {

// The tag bits of one request's tiers and what each tier pays on top of its plain cost.
struct StyleTiers {
  uint64_t own = 0;               // the requested style's tag; 0: no request, one plain search
  uint64_t fallback[2] = {0, 0};  // its fallback styles' tags in order (0: none)
  uint64_t all = 0;               // every style's tag
  // The distinct tag masks of the clips without a style: their search is skipped when none
  // passes the constraints (a filter that excludes every style prunes no tree node, so that
  // search would visit every row to find nothing).
  std::span<const uint64_t> styleless_tags;
  float fallback_cost[2] = {0.0f, 0.0f};
  float other_cost = 0.0f;  // any style neither own nor a fallback
};

// The tiers of a request for `style` (-1: none) under the settings' style costs: the first
// fallback pays style_cost, the second style_cost + style_fallback_step, other styles
// style_cost + 2 * style_fallback_step.
class ControllerDatabase;
StyleTiers style_tiers(const ControllerDatabase& database, int style, float style_cost,
                       float style_fallback_step);

// The best frame for `query` under `constraints` (its tag filters apply to every part), with
// the tiers' added costs. Does not allocate.
SearchResult search_in_style(const Searcher& searcher, std::span<const float> query,
                             const SearchConstraints& constraints, const StyleTiers& tiers);

}  // namespace mm
