#pragma once
// Internal to the search library (not installed): the candidate rows every method starts from,
// the per-query rules (continuation, window, tags) shared by the fast methods, and each method's
// factory. The comparison baselines (bench/baselines/) build on these too.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <span>
#include <vector>

#include "mm/runtime/assert.hpp"
#include "mm/search/kernels.hpp"
#include "mm/search/search.hpp"

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

// Candidate rows packed in blocks of 8 for the scan kernels, with the OR and AND of the tags of
// each block's rows (so a scan skips blocks that cannot pass a tag filter).
struct PackedBlocks {
  int block_count = 0;
  std::vector<float> blocks;  // search_kernels::pack_blocks() layout
  std::vector<uint64_t> block_tags_or;
  std::vector<uint64_t> block_tags_and;

  // Packs `rows` (set.row_count() rows of set.dims floats, in the set's row order; the set's
  // own rows or a transform of them).
  void pack(const CandidateSet& set, const float* rows);
  // Points `filter` at the block tags when the query has a tag filter.
  void use_block_tags(const SearchConstraints& constraints,
                      search_kernels::RowFilter& filter) const;
  size_t memory_bytes() const {
    return blocks.capacity() * sizeof(float) +
           (block_tags_or.capacity() + block_tags_and.capacity()) * sizeof(uint64_t);
  }
};

// Eight floats as a GCC vector: 256-bit AVX code in the AVX2 build of the traversal, two SSE
// registers in the portable one.
typedef float Float8 __attribute__((vector_size(32)));

// Squared distance from `query` to the box [lo, hi]; all three padded to a multiple of 8 (the
// padding columns hold zeros, which add nothing).
__attribute__((always_inline)) inline float box_distance(const float* query, const float* lo,
                                                         const float* hi, int padded_dims) {
  const Float8 zero = {};
  Float8 acc = {};
  for (int d = 0; d < padded_dims; d += 8) {
    Float8 q;
    Float8 l;
    Float8 h;
    std::memcpy(&q, query + d, sizeof q);
    std::memcpy(&l, lo + d, sizeof l);
    std::memcpy(&h, hi + d, sizeof h);
    const Float8 below = l - q;
    const Float8 above = q - h;
    Float8 gap = below > above ? below : above;
    gap = gap > zero ? gap : zero;
    acc += gap * gap;
  }
  float lanes[8];
  std::memcpy(lanes, &acc, sizeof lanes);
  return ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
         ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
}

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

// An orthonormal change of basis of the feature space: the principal axes of the rows, largest
// variance first. Distances are preserved up to rounding, and trees split along the directions
// the data actually spreads in.
struct FeatureRotation {
  int dims = 0;
  int padded_dims = 0;           // dims rounded up to a multiple of 8
  std::vector<float> mean;       // dims: subtracted before rotating
  std::vector<float> axes;       // dims * padded_dims: axes[d * padded_dims + k] is component d
                                 // of axis k (zero for k >= dims)
  std::vector<double> variance;  // dims: variance along each axis, descending

  bool empty() const { return dims == 0; }
  // Sum of the variances along the axes (the rows' total variance).
  double total_variance() const { return std::accumulate(variance.begin(), variance.end(), 0.0); }
  // y = axes^T (x - mean) in float; y holds padded_dims floats (the padding comes out 0).
  void apply(const float* x, float* y) const;
  // Bound on |computed y - exact y| per unit of |x - mean|: each coordinate sums dims products
  // in float (2 * dims roundings of 2^-24 relative to the sum of |terms| <= |x - mean|), over
  // sqrt(dims) coordinates, with a factor 2 of margin.
  float error_per_norm() const {
    const auto n = static_cast<float>(dims);
    return 2.0f * std::sqrt(n) * (2.0f * n + 2.0f) * 5.97e-8f;
  }
  size_t memory_bytes() const {
    return (mean.capacity() + axes.capacity()) * sizeof(float) +
           variance.capacity() * sizeof(double);
  }
};

// Principal axes of `row_count` rows (row-major, `dims` columns), estimated from at most
// `max_sample_rows` evenly spaced rows (the rotation only needs to be orthonormal to be exact).
FeatureRotation principal_axes(const float* rows, int row_count, int dims, int max_sample_rows);

// Euclidean norm of a row.
float row_norm(const float* x, int dims);

// Rotates `count` rows in place (each `dims` floats, `stride` floats apart) into `rotation`'s
// axes and returns the largest norm of a rotated row (ExactRanker's max_row_norm).
float rotate_rows(const FeatureRotation& rotation, float* rows, int count, int dims, size_t stride);

// Decides rows found in a rotated space by their canonical (unrotated) distance, so a rotated
// structure returns exactly what brute force returns. Rotation and float rounding move a
// distance by at most `slack(d)`. Offered rows wait in a small buffer and get their canonical
// distance only when it is full or the search ends (resolve()), and then only those still under
// the threshold: most rows offered early are beaten later, and each canonical distance costs
// reads far from the structure's own rows (a sizeable share of a kdtree query otherwise).
// Meanwhile the scan threshold follows `upper`, an upper bound on the best canonical distance:
// the canonical best row lies at most slack above it in the scanned space, so it is never pruned.
struct ExactRanker {
  const CandidateSet* set = nullptr;
  const float* query = nullptr;         // unrotated
  const int* scanned_to_set = nullptr;  // scanned row -> candidate row (null: the same)
  float best_distance = 0.0f;           // canonical distance of best_row (the bound while none)
  int best_row = -1;                    // scanned row of the best decided row, -1 while none
  float upper = 0.0f;                   // >= the best canonical distance of every offered row
  float rotation_error = 0.0f;          // bound on |rotated difference - exact difference|
  float relative_error = 0.0f;          // relative rounding of one distance computation
  static constexpr int kPendingRows = 16;
  int pending_row[kPendingRows];         // offered rows not decided yet
  float pending_distance[kPendingRows];  // their scanned distances
  int pending = 0;

  // Prepares the ranker for one query: `rotated_query_norm` is |rotated query| and
  // `max_row_norm` the largest |rotated row| (both about |x - mean|), `bound` the plan's bound
  // (a row must be strictly below it).
  void start(const CandidateSet& candidates, const FeatureRotation& rotation,
             const float* unrotated_query, float bound, float rotated_query_norm,
             float max_row_norm) {
    set = &candidates;
    query = unrotated_query;
    best_distance = bound;
    best_row = -1;
    upper = bound;
    pending = 0;
    // The query's and the row's rotation errors add up; 1.01 covers the norms themselves
    // being computed from rounded values.
    rotation_error = 1.01f * rotation.error_per_norm() * (rotated_query_norm + max_row_norm);
    // A distance sums dims squares in float (FMA or not), computed in both spaces.
    relative_error = 2.0f * (static_cast<float>(candidates.dims) + 2.0f) * 5.97e-8f;
  }
  // Upper bound on |rotated distance - canonical distance| near distance d (0 for an infinite d,
  // which needs no margin).
  float slack(float d) const {
    if (!(d < std::numeric_limits<float>::infinity())) return 0.0f;
    const float e = rotation_error;
    return 2.0f * relative_error * d + 2.0f * std::sqrt(d) * e + e * e;
  }
  // The scan threshold: no row scanned at or above it can be the canonical best.
  float threshold() const { return upper + slack(upper); }
  // Decides the pending rows that may still win; best_row (-1 if no row beat the bound) and
  // best_distance are then final for the rows offered so far. Call once the scan is done.
  void resolve();
  // RowFilter::offer hook: context is an ExactRanker. Sets best.row to the offered row (a row
  // was found) and best.distance to the new threshold.
  static void offer(void* context, int row, float scanned_distance, search_kernels::ScanBest& best);
};

// The most groups k-means forms, and the most groups a RowGroups may hold (tag classes).
inline constexpr int kMaxKmeansGroups = 64;
inline constexpr int kMaxGroups = 256;

// A group's lower bound for one query: the squared distance to its box.
struct GroupDistance {
  float distance;
  int group;
};

// Groups of candidate rows (k-means, about group_rows each; a dense cluster is split again), with
// their bounding boxes in the original space and the OR and AND of their rows' tags. Tree
// methods build one structure per group and visit groups nearest first.
struct RowGroups {
  int query_dims = 0;        // columns of a query
  int padded_dims = 0;       // columns rounded up to a multiple of 8
  std::vector<float> boxes;  // per group: padded lows, then padded highs
  std::vector<uint64_t> tags_or;
  std::vector<uint64_t> tags_and;

  int count() const { return static_cast<int>(tags_or.size()); }
  size_t memory_bytes() const;
  // Writes the groups that may pass the tag filter to `out` (room for kMaxGroups), nearest box
  // first, and returns how many.
  int order(const float* query, const SearchConstraints& constraints, GroupDistance* out) const;
  // True when a group at box distance `distance` cannot hold a row better than `best`: the box
  // distance is a float sum in the original space, and a relative margin covers its rounding.
  static bool beyond(float distance, float best) { return distance > best * 1.00001f; }
};

// A group of rows whose total variance (the sum over columns) is below this is dense, such as
// the standing gestures: 1 % of the variance of an even sample of all candidates.
double dense_variance_below(const CandidateSet& set);

// Groups the candidate rows; `rows_out` receives each group's candidate rows. group_rows <= 0
// makes one group of all rows.
RowGroups make_row_groups(const CandidateSet& set, int group_rows,
                          std::vector<std::vector<int>>& rows_out);

// Boxes and tag summaries of given groups of candidate rows (at most kMaxGroups).
RowGroups row_groups_of(const CandidateSet& set, const std::vector<std::vector<int>>& rows);

// The candidate rows by the exact tag mask of their clip ("tag classes"), in order of first
// appearance; empty when there are more than kMaxGroups classes.
std::vector<std::vector<int>> tag_classes(const CandidateSet& set);

// Factories of the methods (input already validated, options checked by each).
Result<std::unique_ptr<Searcher>> make_brute_simd(const SearchInput& input);
Result<std::unique_ptr<Searcher>> make_kdtree(const SearchInput& input,
                                              const SearchOptions& options);
Result<std::unique_ptr<Searcher>> make_kdtree_eps(const SearchInput& input,
                                                  const SearchOptions& options);
Result<std::unique_ptr<Searcher>> make_boxtree(const SearchInput& input,
                                               const SearchOptions& options);

}  // namespace mm::search_detail
