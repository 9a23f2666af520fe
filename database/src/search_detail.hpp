#pragma once
// Internal to the search: the candidate rows every method starts from, the per-query rules
// (continuation, window, tags) shared by the fast methods, and each method's factory.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "mm/database/search.hpp"
#include "mm/database/search_kernels.hpp"

namespace mm::search_detail {

// The searchable frames as compact rows (ascending frame order) and what the rules need.
struct CandidateSet {
  int dims = 0;
  int frame_count = 0;
  std::vector<float> rows;         // row_count * dims, row-major copies of the features
  std::vector<int> row_frame;      // per row: its database frame
  std::vector<uint64_t> row_tags;  // per row: the tag mask of its clip
  std::vector<int> frame_row;      // per frame: its row, or -1 when not searchable
  std::vector<int> frame_clip;     // per frame: its clip

  int row_count() const { return static_cast<int>(row_frame.size()); }
  const float* row(int r) const { return rows.data() + static_cast<size_t>(r) * dims; }
  size_t memory_bytes() const;
};

// Copies the searchable rows of a validated input.
CandidateSet make_candidate_set(const SearchInput& input);

// True when a clip with `tags` passes the include / exclude filter.
inline bool tags_pass(uint64_t tags, uint64_t include_tags, uint64_t exclude_tags) {
  return (tags & include_tags) == include_tags && (tags & exclude_tags) == 0;
}

// The rules applied to one query, before any structure is searched.
struct QueryPlan {
  int continuation_row = -1;  // the continuation candidate's row, or -1
  float continuation_distance = 0.0f;
  // Other candidates must have a squared distance strictly below this to win
  // (continuation distance - transition cost, or infinity without a continuation).
  float bound = 0.0f;
  search_kernels::RowFilter filter;  // tags and window (row_tags / row_frame point into the set)
};

// Finds the continuation candidate and the starting bound for `query`.
QueryPlan plan_query(const CandidateSet& set, const float* query,
                     const SearchConstraints& constraints);

// Turns the best other row a structure found (or -1) into the result: its cost is recomputed
// with the canonical distance, and the continuation wins ties.
SearchResult finish_query(const CandidateSet& set, const QueryPlan& plan, const float* query,
                          int best_row, const SearchConstraints& constraints);

// Factories of the methods (input already validated, options checked by each).
Result<std::unique_ptr<Searcher>> make_brute(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_brute_simd(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_aabb(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_kdtree(const SearchInput& input,
                                              const SearchOptions& options);
Result<std::unique_ptr<Searcher>> make_approx(const SearchInput& input,
                                              const SearchOptions& options);

}  // namespace mm::search_detail
