// `aabb`: two levels of bounding boxes over consecutive rows with early exits per dimension, the
// structure of Daniel Holden's Motion-Matching demo.

#include <algorithm>
#include <cassert>
#include <limits>

#include "detail.hpp"
#include "factories.hpp"

namespace mm::search_baselines {

namespace {

using search_detail::CandidateSet;
using search_detail::finish_query;
using search_detail::make_candidate_set;
using search_detail::plan_query;
using search_detail::QueryPlan;

// Bounding boxes (lo, hi per dimension) over consecutive groups of `size` rows.
struct BoxLevel {
  int size = 0;
  std::vector<float> lo;
  std::vector<float> hi;

  void build(const CandidateSet& set, int group_size) {
    size = group_size;
    const int rows = set.row_count();
    const int boxes = (rows + size - 1) / size;
    const auto dims = static_cast<size_t>(set.dims);
    lo.assign(static_cast<size_t>(boxes) * dims, std::numeric_limits<float>::infinity());
    hi.assign(static_cast<size_t>(boxes) * dims, -std::numeric_limits<float>::infinity());
    for (int r = 0; r < rows; ++r) {
      const float* row = set.row(r);
      float* box_lo = lo.data() + static_cast<size_t>(r / size) * dims;
      float* box_hi = hi.data() + static_cast<size_t>(r / size) * dims;
      for (size_t d = 0; d < dims; ++d) {
        box_lo[d] = std::min(box_lo[d], row[d]);
        box_hi[d] = std::max(box_hi[d], row[d]);
      }
    }
  }
  size_t memory_bytes() const { return (lo.capacity() + hi.capacity()) * sizeof(float); }
};

class AabbSearcher final : public Searcher {
 public:
  static constexpr int kSmallBox = 16;
  static constexpr int kLargeBox = 64;

  explicit AabbSearcher(const SearchInput& input) : set_(make_candidate_set(input)) {
    small_.build(set_, kSmallBox);
    large_.build(set_, kLargeBox);
  }

  std::string_view method() const override { return "aabb"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override {
    return set_.memory_bytes() + small_.memory_bytes() + large_.memory_bytes();
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == set_.dims);
    const float* q = query.data();
    const QueryPlan plan = plan_query(set_, q, constraints);
    if (!(plan.bound > 0.0f)) return finish_query(set_, plan, q, -1, constraints);
    const int dims = set_.dims;
    const int rows = set_.row_count();
    float best = plan.bound;
    int best_row = -1;
    for (int large_first = 0; large_first < rows; large_first += kLargeBox) {
      const size_t large_box = static_cast<size_t>(large_first / kLargeBox) * dims;
      if (search_kernels::box_squared_distance_bounded(
              q, large_.lo.data() + large_box, large_.hi.data() + large_box, dims, best) >= best) {
        continue;
      }
      const int large_last = std::min(rows, large_first + kLargeBox);
      for (int small_first = large_first; small_first < large_last; small_first += kSmallBox) {
        const size_t small_box = static_cast<size_t>(small_first / kSmallBox) * dims;
        if (search_kernels::box_squared_distance_bounded(q, small_.lo.data() + small_box,
                                                         small_.hi.data() + small_box, dims,
                                                         best) >= best) {
          continue;
        }
        const int small_last = std::min(large_last, small_first + kSmallBox);
        for (int r = small_first; r < small_last; ++r) {
          if (!plan.filter.passes(r)) continue;
          const float distance =
              search_kernels::squared_distance_bounded(q, set_.row(r), dims, best);
          if (distance < best) {
            best = distance;
            best_row = r;
          }
        }
      }
    }
    return finish_query(set_, plan, q, best_row, constraints);
  }

 private:
  CandidateSet set_;
  BoxLevel small_;
  BoxLevel large_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_aabb(const SearchInput& input) {
  return std::unique_ptr<Searcher>(std::make_unique<AabbSearcher>(input));
}

}  // namespace mm::search_baselines
