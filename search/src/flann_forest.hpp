#pragma once
// Internal to the search library (not installed): FLANN indices over k-means groups of the
// candidate rows, searched under the rules. `kdtree` and `kdtree-eps` (flann.cpp) and the
// randomized-trees baseline `approx` (bench/baselines/) are instances of FlannSearcher.
//
// All three index the searchable rows only (the mask is fixed when the database is built),
// split into k-means groups (RowGroups) with one FLANN index per group, each over the group's
// principal-axes coordinates. A query visits the groups nearest first by the distance to their
// bounding box and stops at the first group whose box is farther than the best cost found. Inside a
// group the per-query rules are applied by a custom FLANN result set: a row that fails the tag
// filter or lies in the window is never recorded, and the threshold starts at the best so far (at
// first the continuation's distance minus the transition cost). Rows found in a rotated space are
// decided by their unrotated distance (ExactRanker). The single trees prune a branch only when
// its lower bound reaches the threshold, so `kdtree` is exact under every constraint.
//
// Why groups: FLANN bounds a branch by the cutting planes on its path plus the distance to the
// root box. With one tree over everything, the root box spans the whole database, and for a
// noisy query near the dense cluster of standing gestures the bound misses the query's offset in
// every dimension the path did not cut, so the search visits most of the cluster. A group's root
// box is tight around the group (in its own axes), so that offset is counted from the start.
//
// FLANN allocates inside findNeighbors(): KDTreeSingleIndex a vector of dims floats per call,
// KDTreeIndex a branch heap (a reserve of one entry per row of the group) and a visited bitset of
// one bit per row. Those are FLANN's internals; nothing else on these paths allocates.

#include <flann/flann.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "detail.hpp"
#include "mm/internal/workers.hpp"

namespace mm::search_detail {

// FLANN's L2, with the row distance from our kernel (8 columns at a time, AVX2 when the CPU has
// it) instead of FLANN's column-at-a-time loop, which is markedly slower per query. The single
// tree passes its threshold, and the kernel stops after 8 or 16 columns once the partial sum
// exceeds it: in principal axes most rows a leaf visits stop after 8 (figures in docs/search.md).
struct FlannDistance {
  typedef bool is_kdtree_distance;
  typedef float ElementType;
  typedef float ResultType;

  template <typename Iterator1, typename Iterator2>
  float operator()(Iterator1 a, Iterator2 b, size_t size, float worst_dist = -1) const {
    // FLANN passes -1 when there is no bound.
    if (bounded && worst_dist >= 0.0f)
      return bounded_kernel(&*a, &*b, static_cast<int>(size), worst_dist);
    return kernel(&*a, &*b, static_cast<int>(size));
  }
  // One column's share of the distance (FLANN's incremental bound of a branch).
  template <typename U, typename V>
  float accum_dist(const U& a, const V& b, int) const {
    return (a - b) * (a - b);
  }

  search_kernels::RowDistanceFn kernel = search_kernels::row_distance();
  search_kernels::BoundedRowDistanceFn bounded_kernel = search_kernels::row_distance_bounded();
  // Whether rows may stop early. Not in a dense group in its own axes: there the query's noise
  // outweighs the rows' spread in every axis, about half the rows stop, unpredictably, and the
  // mispredicted branches cost more than the stops save (docs/search.md).
  bool bounded = true;
};

// Keeps the single best row that passes the filter, below a threshold that only shrinks.
class ConstrainedBestResultSet final : public flann::ResultSet<float> {
 public:
  ConstrainedBestResultSet(const search_kernels::RowFilter& filter, float threshold)
      : filter_(filter), restricts_(filter.restricts()) {
    best_.distance = threshold;
  }

  // FLANN's randomized trees keep searching past the check budget while this is false: a
  // result exists once a bound (the continuation, an earlier group) or a passing row is known.
  bool full() const override {
    return best_.row >= 0 || best_.distance < std::numeric_limits<float>::infinity();
  }
  void addPoint(float distance, size_t index) override {
    const int row = static_cast<int>(index);
    if (!(distance < best_.distance) || (restricts_ && !filter_.passes(row))) return;
    if (filter_.offer != nullptr) {
      filter_.offer(filter_.offer_context, row, distance, best_);
    } else {
      best_.distance = distance;
      best_.row = row;
    }
  }
  float worstDist() const override { return best_.distance; }

  const search_kernels::ScanBest& best() const { return best_; }

 private:
  const search_kernels::RowFilter& filter_;
  const bool restricts_;  // false: every row passes, so its tags and frame need not be read
  search_kernels::ScanBest best_;
};

// The traits of a FlannSearcher: `Index` (the FLANN index type), `kName` (the method's name),
// `kExact` (whether the search is exact) and `kCopiesRows` (whether the index keeps its own copy
// of the rows, so ours can be released once built).
// One group: its rows (rotated or not), their candidate rows, frames and tags, and the index.
template <class Index>
struct FlannGroup {
  FeatureRotation rotation;    // empty when the index is over the raw columns
  std::vector<float> points;   // the group's rows in the index's space (FLANN points into
                               // it), released once built when the index keeps its own copy
  std::vector<int> set_rows;   // index row -> candidate row
  std::vector<int> frames;     // index row -> frame
  std::vector<uint64_t> tags;  // index row -> clip tags
  float max_row_norm = 0.0f;
  std::unique_ptr<Index> index;
};

// Groups of rows with one index each, their boxes, and the search over them.
template <class Index>
struct FlannForest {
  RowGroups groups;
  std::vector<FlannGroup<Index>> trees;  // one per group
  size_t rows = 0;                       // rows over all groups

  bool empty() const { return trees.empty(); }

  // Sets up one group per entry of `rows_of_groups` (candidate rows of `set`); the indices are
  // built by build_group(), which may run for several groups at once.
  void prepare(const CandidateSet& set, std::vector<std::vector<int>> rows_of_groups) {
    groups = row_groups_of(set, rows_of_groups);
    trees.resize(rows_of_groups.size());
    for (size_t g = 0; g < rows_of_groups.size(); ++g) {
      rows += rows_of_groups[g].size();
      trees[g].set_rows = std::move(rows_of_groups[g]);
    }
  }

  // Copies group g's rows (into its principal axes when `rotate`) and builds its index.
  Status build_group(size_t g, const CandidateSet& set, bool rotate, double dense_below,
                     const flann::IndexParams& params, std::string_view method,
                     bool index_copies_rows) {
    const int dims = set.dims;
    FlannGroup<Index>& group = trees[g];
    const int count = static_cast<int>(group.set_rows.size());
    if (count == 0) return Status::success();
    try {
      group.points.resize(static_cast<size_t>(count) * dims);
      group.frames.reserve(group.set_rows.size());
      group.tags.reserve(group.set_rows.size());
      for (int i = 0; i < count; ++i) {
        const int r = group.set_rows[static_cast<size_t>(i)];
        std::copy_n(set.row(r), dims, group.points.data() + static_cast<size_t>(i) * dims);
        group.frames.push_back(set.row_frame[static_cast<size_t>(r)]);
        group.tags.push_back(set.row_tags[static_cast<size_t>(r)]);
      }
      if (rotate) {
        group.rotation = principal_axes(group.points.data(), count, dims, 4096);
        group.max_row_norm = rotate_rows(group.rotation, group.points.data(), count, dims,
                                         static_cast<size_t>(dims));
      }
      // Rows stop early only in principal axes (the leading columns carry the spread), and not
      // in a dense group.
      FlannDistance distance;
      distance.bounded = rotate && group.rotation.total_variance() >= dense_below;
      flann::Matrix<float> matrix(group.points.data(), static_cast<size_t>(count),
                                  static_cast<size_t>(dims));
      group.index = std::make_unique<Index>(matrix, params, distance);
      group.index->buildIndex();
      // A reordering single tree searches its own copy of the rows; ours is not read again.
      if (index_copies_rows) std::vector<float>().swap(group.points);
    } catch (const std::exception& e) {
      return Error{std::string(method) + ": FLANN failed to build an index: " + e.what()};
    }
    return Status::success();
  }

  size_t memory_bytes(int dims, bool copies_rows) const {
    size_t bytes = groups.memory_bytes();
    for (const FlannGroup<Index>& group : trees) {
      const size_t count = group.set_rows.size();
      bytes += group.rotation.memory_bytes() + group.points.capacity() * sizeof(float) +
               group.set_rows.capacity() * sizeof(int) + group.frames.capacity() * sizeof(int) +
               group.tags.capacity() * sizeof(uint64_t);
      if (group.index) {
        // usedMemory() counts FLANN's node pool and index array; add its per-row pointer table
        // and, for the reordering single tree, its copy of the rows.
        bytes += static_cast<size_t>(group.index->usedMemory()) + count * sizeof(float*);
        if (copies_rows) bytes += count * static_cast<size_t>(dims) * sizeof(float);
      }
    }
    return bytes;
  }

  // Visits the groups nearest first while their box can still hold a better row; `best_distance`
  // and `best_row` (a candidate row) carry the best so far in and out.
  void search(const CandidateSet& set, const float* query, const QueryPlan& plan,
              const SearchConstraints& constraints, const flann::SearchParams& search_params,
              float& best_distance, int& best_row) const {
    GroupDistance order[kMaxGroups];
    const int count = groups.order(query, constraints, order);
    for (int i = 0; i < count && !RowGroups::beyond(order[i].distance, best_distance); ++i) {
      const FlannGroup<Index>& group = trees[static_cast<size_t>(order[i].group)];
      if (!group.index) continue;
      search_kernels::RowFilter filter = plan.filter;
      filter.row_tags = group.tags.data();
      filter.row_frame = group.frames.data();
      filter.row_count = static_cast<int>(group.frames.size());
      const float* point = query;
      float rotated[kMaxSearchDims];
      ExactRanker ranker;
      float threshold = best_distance;
      if (!group.rotation.empty()) {
        group.rotation.apply(query, rotated);
        point = rotated;
        ranker.start(set, group.rotation, query, best_distance, row_norm(rotated, set.dims),
                     group.max_row_norm);
        ranker.scanned_to_set = group.set_rows.data();
        filter.offer = &ExactRanker::offer;
        filter.offer_context = &ranker;
        threshold = ranker.threshold();
      }
      ConstrainedBestResultSet result(filter, threshold);
      group.index->findNeighbors(result, point, search_params);
      int found = result.best().row;
      float found_distance = result.best().distance;
      if (!group.rotation.empty()) {
        ranker.resolve();
        found = ranker.best_row;
        found_distance = ranker.best_distance;
      }
      if (found >= 0) {
        best_distance = found_distance;
        best_row = group.set_rows[static_cast<size_t>(found)];
      }
    }
  }
};

template <class Traits>
class FlannSearcher final : public Searcher {
 public:
  using Forest = FlannForest<typename Traits::Index>;

  // `params` builds every index; `search_params` is used for every query. With more than one
  // tag class, a second forest holds one index per class, for queries whose tag filter leaves
  // few rows: filtering inside the main index would reject most of what it visits.
  static Result<std::unique_ptr<Searcher>> make(const SearchInput& input,
                                                const SearchOptions& options, int group_rows,
                                                const flann::IndexParams& params,
                                                const flann::SearchParams& search_params) {
    auto searcher = std::unique_ptr<FlannSearcher>(new FlannSearcher(input, search_params));
    const CandidateSet& set = searcher->set_;
    if (set.row_count() == 0) return std::unique_ptr<Searcher>(std::move(searcher));
    std::vector<std::vector<int>> rows;
    make_row_groups(set, group_rows, rows);
    searcher->main_.prepare(set, std::move(rows));
    std::vector<std::vector<int>> classes = tag_classes(set);
    if (options.tag_class_indices && classes.size() > 1) {
      searcher->classes_.prepare(set, std::move(classes));
    }
    // Every group of both forests is one job; the largest go first so that the threads finish
    // together.
    struct Job {
      Forest* forest;
      size_t group;
      size_t rows;
    };
    std::vector<Job> jobs;
    for (Forest* forest : {&searcher->main_, &searcher->classes_}) {
      for (size_t g = 0; g < forest->trees.size(); ++g) {
        jobs.push_back({forest, g, forest->trees[g].set_rows.size()});
      }
    }
    std::stable_sort(jobs.begin(), jobs.end(),
                     [](const Job& a, const Job& b) { return a.rows > b.rows; });
    const double dense_below = dense_variance_below(set);
    std::vector<Status> built(jobs.size(), Status::success());
    detail::run_workers(
        jobs.size(), detail::worker_threads(options.build_threads), [&](int, size_t j) {
          built[j] =
              jobs[j].forest->build_group(jobs[j].group, set, options.principal_axes, dense_below,
                                          params, Traits::kName, Traits::kCopiesRows);
        });
    for (const Status& status : built) {
      if (!status) return Error{status.message()};
    }
    return std::unique_ptr<Searcher>(std::move(searcher));
  }

  std::string_view method() const override { return Traits::kName; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return Traits::kExact; }
  size_t memory_bytes() const override {
    return set_.memory_bytes() + main_.memory_bytes(set_.dims, Traits::kCopiesRows) +
           classes_.memory_bytes(set_.dims, Traits::kCopiesRows);
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    MM_ASSERT(static_cast<int>(query.size()) == set_.dims);
    const QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f)) return finish_query(set_, plan, query.data(), -1, constraints);
    float best_distance = plan.bound;
    int best_row = -1;
    const Forest& forest = uses_classes(constraints) ? classes_ : main_;
    forest.search(set_, query.data(), plan, constraints, search_params_, best_distance, best_row);
    return finish_query(set_, plan, query.data(), best_row, constraints);
  }

 private:
  FlannSearcher(const SearchInput& input, const flann::SearchParams& search_params)
      : set_(make_candidate_set(input)), search_params_(search_params) {}

  // True when the tag filter leaves less than a quarter of the rows: then the per-class indices
  // of the passing classes are searched instead of the main ones.
  bool uses_classes(const SearchConstraints& constraints) const {
    if (classes_.empty() || (constraints.include_tags == 0 && constraints.exclude_tags == 0)) {
      return false;
    }
    size_t passing = 0;
    for (int c = 0; c < classes_.groups.count(); ++c) {
      const uint64_t tags = classes_.groups.tags_or[static_cast<size_t>(c)];  // one mask per class
      if (tags_pass(tags, constraints.include_tags, constraints.exclude_tags)) {
        passing += classes_.trees[static_cast<size_t>(c)].set_rows.size();
      }
    }
    return 4 * passing < classes_.rows;
  }

  CandidateSet set_;
  flann::SearchParams search_params_;
  Forest main_;     // all rows: one index, or one per k-means group
  Forest classes_;  // one index per tag class (empty with a single class)
};

}  // namespace mm::search_detail
