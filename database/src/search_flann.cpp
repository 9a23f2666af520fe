// The FLANN-based methods: `kdtree` (flann::KDTreeSingleIndex, exact) and `approx`
// (flann::KDTreeIndex, randomized trees with a leaf-check budget).
//
// Both index the searchable rows only (the mask is fixed when the database is built),
// optionally in principal-axes coordinates, and apply the per-query rules inside a custom
// FLANN result set: a row that fails the tag filter or lies in the window is never recorded,
// and the bound starts at the continuation's distance minus the transition cost. Rows found in
// the rotated space are decided by their unrotated distance (ExactRanker). The single tree
// prunes a branch only when its lower bound reaches the threshold, so it stays exact under
// every constraint.
//
// FLANN allocates inside findNeighbors(): KDTreeSingleIndex a vector of dims floats per query,
// KDTreeIndex a branch heap (a reserve of one entry per row) and a visited bitset of one bit per
// row. Those are FLANN's internals; nothing else on these paths allocates.

#include <flann/flann.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "search_detail.hpp"

namespace mm::search_detail {

namespace {

using FlannDistance = flann::L2<float>;

// Keeps the single best row that passes the filter, below a threshold that only shrinks.
class ConstrainedBestResultSet final : public flann::ResultSet<float> {
 public:
  ConstrainedBestResultSet(const search_kernels::RowFilter& filter, float threshold)
      : filter_(filter) {
    best_.distance = threshold;
  }

  // FLANN's randomized trees keep searching past the check budget while this is false: a
  // result exists once a bound (the continuation) or a passing row is known.
  bool full() const override {
    return best_.row >= 0 || best_.distance < std::numeric_limits<float>::infinity();
  }
  void addPoint(float distance, size_t index) override {
    const int row = static_cast<int>(index);
    if (!(distance < best_.distance) || !filter_.passes(row)) return;
    if (filter_.offer != nullptr) {
      filter_.offer(filter_.offer_context, row, distance, best_);
    } else {
      best_.distance = distance;
      best_.row = row;
    }
  }
  float worstDist() const override { return best_.distance; }

  int best_row() const { return best_.row; }

 private:
  const search_kernels::RowFilter& filter_;
  search_kernels::ScanBest best_;
};

// What differs between the exact and the randomized FLANN index.
struct ExactTraits {
  using Index = flann::KDTreeSingleIndex<FlannDistance>;
  static constexpr std::string_view kName = "kdtree";
  static constexpr bool kExact = true;
  // KDTreeSingleIndex with reorder copies the rows into tree order.
  static constexpr bool kCopiesRows = true;
};
struct ApproxTraits {
  using Index = flann::KDTreeIndex<FlannDistance>;
  static constexpr std::string_view kName = "approx";
  static constexpr bool kExact = false;
  static constexpr bool kCopiesRows = false;
};

template <class Traits>
class FlannSearcher final : public Searcher {
 public:
  // `params` builds the index; `search_params` is used for every query.
  static Result<std::unique_ptr<Searcher>> make(const SearchInput& input, bool rotate,
                                                const flann::IndexParams& params,
                                                const flann::SearchParams& search_params) {
    auto searcher = std::unique_ptr<FlannSearcher>(new FlannSearcher(input, search_params));
    CandidateSet& set = searcher->set_;
    const int rows = set.row_count();
    if (rows == 0) return std::unique_ptr<Searcher>(std::move(searcher));
    if (rotate) {
      searcher->rotation_ = principal_axes(set.rows.data(), rows, set.dims, 4096);
      searcher->points_.resize(set.rows.size());
      float rotated[kMaxSearchDims];
      for (int r = 0; r < rows; ++r) {
        searcher->rotation_.apply(set.row(r), rotated);
        std::copy_n(rotated, set.dims, searcher->points_.data() + static_cast<size_t>(r) * set.dims);
        searcher->max_row_norm_ = std::max(searcher->max_row_norm_, row_norm(rotated, set.dims));
      }
    }
    try {
      float* data = rotate ? searcher->points_.data() : set.rows.data();
      flann::Matrix<float> matrix(data, static_cast<size_t>(rows), static_cast<size_t>(set.dims));
      searcher->index_ = std::make_unique<typename Traits::Index>(matrix, params);
      searcher->index_->buildIndex();
    } catch (const std::exception& e) {
      return Error{std::string(Traits::kName) + ": FLANN failed to build the index: " + e.what()};
    }
    return std::unique_ptr<Searcher>(std::move(searcher));
  }

  std::string_view method() const override { return Traits::kName; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return Traits::kExact; }
  size_t memory_bytes() const override {
    size_t bytes = set_.memory_bytes() + points_.capacity() * sizeof(float) +
                   rotation_.memory_bytes();
    if (index_) {
      const size_t rows = static_cast<size_t>(set_.row_count());
      // usedMemory() counts FLANN's node pool and index array; add its per-row pointer table
      // and, for the reordering single tree, its copy of the rows.
      bytes += static_cast<size_t>(index_->usedMemory()) + rows * sizeof(float*);
      if (Traits::kCopiesRows) bytes += rows * static_cast<size_t>(set_.dims) * sizeof(float);
    }
    return bytes;
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == set_.dims);
    QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f) || !index_) {
      return finish_query(set_, plan, query.data(), -1, constraints);
    }
    float threshold = plan.bound;
    const float* point = query.data();
    float rotated[kMaxSearchDims];
    ExactRanker ranker;
    if (!rotation_.empty()) {
      rotation_.apply(query.data(), rotated);
      point = rotated;
      ranker.start(set_, rotation_, query.data(), plan.bound, row_norm(rotated, set_.dims),
                   max_row_norm_);
      plan.filter.offer = &ExactRanker::offer;
      plan.filter.offer_context = &ranker;
      threshold = ranker.threshold();
    }
    ConstrainedBestResultSet result(plan.filter, threshold);
    index_->findNeighbors(result, point, search_params_);
    return finish_query(set_, plan, query.data(), result.best_row(), constraints);
  }

 private:
  FlannSearcher(const SearchInput& input, const flann::SearchParams& search_params)
      : set_(make_candidate_set(input)), search_params_(search_params) {}

  CandidateSet set_;
  flann::SearchParams search_params_;
  FeatureRotation rotation_;  // empty axes when the index is over the raw rows
  std::vector<float> points_;  // rotated rows (FLANN keeps pointers into them)
  float max_row_norm_ = 0.0f;
  std::unique_ptr<typename Traits::Index> index_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_kdtree(const SearchInput& input,
                                              const SearchOptions& options) {
  if (options.kdtree_leaf_size < 1) {
    return Error{"kdtree: leaf size must be >= 1, got " + std::to_string(options.kdtree_leaf_size)};
  }
  // KDTreeSingleIndex ignores the check count, and eps 0 keeps it exact.
  return FlannSearcher<ExactTraits>::make(
      input, options.principal_axes,
      flann::KDTreeSingleIndexParams(options.kdtree_leaf_size, /*reorder=*/true),
      flann::SearchParams());
}

Result<std::unique_ptr<Searcher>> make_approx(const SearchInput& input,
                                              const SearchOptions& options) {
  if (options.approx_trees < 1) {
    return Error{"approx: tree count must be >= 1, got " + std::to_string(options.approx_trees)};
  }
  if (options.approx_checks < 1) {
    return Error{"approx: the check budget must be >= 1 (unlimited checks are not allowed), got " +
                 std::to_string(options.approx_checks)};
  }
  return FlannSearcher<ApproxTraits>::make(input, options.principal_axes,
                                           flann::KDTreeIndexParams(options.approx_trees),
                                           flann::SearchParams(options.approx_checks));
}

}  // namespace mm::search_detail
