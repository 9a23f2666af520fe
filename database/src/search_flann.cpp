// The FLANN-based methods: `kdtree` (flann::KDTreeSingleIndex, exact) and `approx`
// (flann::KDTreeIndex, randomized trees with a leaf-check budget).
//
// Both index the searchable rows only (the mask is fixed when the database is built) and apply
// the per-query rules inside a custom FLANN result set: a row that fails the tag filter or lies
// in the window is never recorded, and the bound starts at the continuation's distance minus
// the transition cost. The single tree prunes a branch only when its lower bound is >= the best
// recorded distance, so the search stays exact under every constraint.
//
// FLANN allocates inside findNeighbors(): KDTreeSingleIndex a vector of dims floats per query,
// KDTreeIndex a branch heap (reserve of one entry per row) and a visited bitset of one bit per
// row. Those are FLANN's internals; nothing else on these paths allocates.

#include <flann/flann.hpp>

#include <algorithm>
#include <limits>

#include "search_detail.hpp"

namespace mm::search_detail {

namespace {

using FlannDistance = flann::L2<float>;

// Keeps the single best row that passes the filter, with a distance strictly below the bound.
class ConstrainedBestResultSet final : public flann::ResultSet<float> {
 public:
  ConstrainedBestResultSet(const search_kernels::RowFilter& filter, float bound)
      : filter_(filter), best_distance_(bound) {}

  // FLANN's randomized trees keep searching past the check budget while this is false: a
  // result exists once a bound (the continuation) or a passing row is known.
  bool full() const override {
    return best_row_ >= 0 || best_distance_ < std::numeric_limits<float>::infinity();
  }
  void addPoint(float distance, size_t index) override {
    const int row = static_cast<int>(index);
    if (distance < best_distance_ && filter_.passes(row)) {
      best_distance_ = distance;
      best_row_ = row;
    }
  }
  float worstDist() const override { return best_distance_; }

  int best_row() const { return best_row_; }

 private:
  const search_kernels::RowFilter& filter_;
  float best_distance_;
  int best_row_ = -1;
};

// FLANN reports usedMemory() for its node pool and index array; add the reordered copy of the
// rows (KDTreeSingleIndex with reorder) and the per-row pointer table every FLANN index keeps.
size_t flann_dataset_overhead(size_t rows) { return rows * sizeof(float*); }

class FlannKdTreeSearcher final : public Searcher {
 public:
  static Result<std::unique_ptr<Searcher>> make(const SearchInput& input, int leaf_size) {
    auto searcher = std::unique_ptr<FlannKdTreeSearcher>(new FlannKdTreeSearcher(input));
    if (searcher->set_.row_count() > 0) {
      try {
        flann::Matrix<float> rows(searcher->set_.rows.data(),
                                  static_cast<size_t>(searcher->set_.row_count()),
                                  static_cast<size_t>(searcher->set_.dims));
        searcher->index_ = std::make_unique<flann::KDTreeSingleIndex<FlannDistance>>(
            rows, flann::KDTreeSingleIndexParams(leaf_size, true));
        searcher->index_->buildIndex();
      } catch (const std::exception& e) {
        return Error{std::string("kdtree: FLANN failed to build the index: ") + e.what()};
      }
    }
    return std::unique_ptr<Searcher>(std::move(searcher));
  }

  std::string_view method() const override { return "kdtree"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override {
    size_t bytes = set_.memory_bytes();
    if (index_) {
      const size_t rows = static_cast<size_t>(set_.row_count());
      bytes += static_cast<size_t>(index_->usedMemory()) + flann_dataset_overhead(rows) +
               rows * static_cast<size_t>(set_.dims) * sizeof(float);
    }
    return bytes;
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == set_.dims);
    const QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f) || !index_) return finish_query(set_, plan, query.data(), -1, constraints);
    ConstrainedBestResultSet result(plan.filter, plan.bound);
    // KDTreeSingleIndex ignores the check count and eps is 0: the search is exact.
    index_->findNeighbors(result, query.data(), flann::SearchParams());
    return finish_query(set_, plan, query.data(), result.best_row(), constraints);
  }

 private:
  explicit FlannKdTreeSearcher(const SearchInput& input) : set_(make_candidate_set(input)) {}

  CandidateSet set_;
  std::unique_ptr<flann::KDTreeSingleIndex<FlannDistance>> index_;
};

class FlannApproxSearcher final : public Searcher {
 public:
  static Result<std::unique_ptr<Searcher>> make(const SearchInput& input, int trees, int checks) {
    auto searcher = std::unique_ptr<FlannApproxSearcher>(new FlannApproxSearcher(input, checks));
    if (searcher->set_.row_count() > 0) {
      try {
        flann::Matrix<float> rows(searcher->set_.rows.data(),
                                  static_cast<size_t>(searcher->set_.row_count()),
                                  static_cast<size_t>(searcher->set_.dims));
        searcher->index_ = std::make_unique<flann::KDTreeIndex<FlannDistance>>(
            rows, flann::KDTreeIndexParams(trees));
        searcher->index_->buildIndex();
      } catch (const std::exception& e) {
        return Error{std::string("approx: FLANN failed to build the index: ") + e.what()};
      }
    }
    return std::unique_ptr<Searcher>(std::move(searcher));
  }

  std::string_view method() const override { return "approx"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return false; }
  size_t memory_bytes() const override {
    size_t bytes = set_.memory_bytes();
    if (index_) {
      bytes += static_cast<size_t>(index_->usedMemory()) +
               flann_dataset_overhead(static_cast<size_t>(set_.row_count()));
    }
    return bytes;
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == set_.dims);
    const QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f) || !index_) return finish_query(set_, plan, query.data(), -1, constraints);
    ConstrainedBestResultSet result(plan.filter, plan.bound);
    index_->findNeighbors(result, query.data(), flann::SearchParams(checks_));
    return finish_query(set_, plan, query.data(), result.best_row(), constraints);
  }

 private:
  FlannApproxSearcher(const SearchInput& input, int checks)
      : set_(make_candidate_set(input)), checks_(checks) {}

  CandidateSet set_;
  int checks_;
  std::unique_ptr<flann::KDTreeIndex<FlannDistance>> index_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_kdtree(const SearchInput& input,
                                              const SearchOptions& options) {
  if (options.kdtree_leaf_size < 1) {
    return Error{"kdtree: leaf size must be >= 1, got " + std::to_string(options.kdtree_leaf_size)};
  }
  return FlannKdTreeSearcher::make(input, options.kdtree_leaf_size);
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
  return FlannApproxSearcher::make(input, options.approx_trees, options.approx_checks);
}

}  // namespace mm::search_detail
