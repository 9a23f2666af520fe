#pragma once
// The search rules (mm/search/search.hpp) checked on one answer, independently of any searcher:
// shared by the synthetic and the real-data search tests (header-only: nothing else uses it).

#include <gtest/gtest.h>

#include <algorithm>
#include <span>

#include "mm/search/search.hpp"

namespace mm::test {

// Checks that `result` obeys the rules for `query` under `c`: a searchable frame whose clip
// passes the tag filter, outside the window unless it is the continuation, flagged as the
// continuation exactly when it is one, and with its cost recomputed in double.
inline void expect_obeys_search_rules(const SearchInput& input, std::span<const float> query,
                                      const SearchConstraints& c, const SearchResult& result) {
  const int frame = result.frame;
  if (frame < 0) return;
  ASSERT_LT(frame, input.frame_count());
  EXPECT_TRUE(input.searchable[frame]);
  const uint64_t tags = input.clips[input.frame_clip[frame]].tags;
  EXPECT_EQ(tags & c.include_tags, c.include_tags);
  EXPECT_EQ(tags & c.exclude_tags, 0u);
  const bool is_next = c.current_frame >= 0 && frame == c.current_frame + 1 &&
                       input.frame_clip[frame] == input.frame_clip[c.current_frame];
  EXPECT_EQ(result.continuation, is_next);
  if (!is_next && c.current_frame >= 0) {
    EXPECT_TRUE(frame < c.current_frame - c.window_frames ||
                frame > c.current_frame + c.window_frames);
  }
  double d = 0;
  for (int k = 0; k < input.dims; ++k) {
    const double diff =
        double(query[k]) - input.features[static_cast<size_t>(frame) * input.dims + k];
    d += diff * diff;
  }
  const double expected = d + (is_next ? 0.0 : c.transition_cost);
  EXPECT_NEAR(result.cost, expected, 1e-5 * std::max(1.0, expected));
}

}  // namespace mm::test
