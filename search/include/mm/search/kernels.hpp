#pragma once
// The inner loops of the search structures, on explicit views (pointers and sizes), so that
// they can be tested and benchmarked on their own. Nothing here allocates.

#include <cstddef>
#include <cstdint>
#include <limits>

namespace mm::search_kernels {

// Squared Euclidean distance between two rows of `dims` floats, summed in column order: the
// canonical value every searcher reports as the cost.
float squared_distance(const float* a, const float* b, int dims);

// Like squared_distance(), but stops once the partial sum reaches `bound` and then returns a
// value >= bound (a partial sum only grows, so the row cannot beat `bound`).
float squared_distance_bounded(const float* a, const float* b, int dims, float bound);

// Squared distance from `point` to the axis-aligned box [lo, hi], stopping once it reaches
// `bound` (then returning a value >= bound). A lower bound of the distance to any row inside.
float box_squared_distance_bounded(const float* point, const float* lo, const float* hi, int dims,
                                   float bound);

// Squared distance of two rows summed 8 columns at a time, for structures that visit one row at
// a time (the FLANN trees). The order of summation differs from squared_distance(), so the
// result may differ from the canonical value by rounding. Reads exactly `dims` floats of each.
using RowDistanceFn = float (*)(const float* a, const float* b, int dims);
float row_distance_portable(const float* a, const float* b, int dims);
// AVX2 + FMA version: call only when avx2_supported().
float row_distance_avx2(const float* a, const float* b, int dims);
// The fastest row distance this CPU supports, chosen once at run time.
RowDistanceFn row_distance();

// The row distance with a bound: while at least 8 columns remain (after 8, then 16 columns), a
// partial sum above `bound` is returned at once. A result <= bound is the full distance, bit for
// bit the value of the unbounded version, and a result > bound means the full one is > bound too
// (the partial sums only grow). Reads at most `dims` floats of each row. Worth it where most
// rows stop early (rows in principal axes, far from the query).
using BoundedRowDistanceFn = float (*)(const float* a, const float* b, int dims, float bound);
float row_distance_bounded_portable(const float* a, const float* b, int dims, float bound);
// AVX2 + FMA version: call only when avx2_supported().
float row_distance_bounded_avx2(const float* a, const float* b, int dims, float bound);
// The fastest bounded row distance this CPU supports.
BoundedRowDistanceFn row_distance_bounded();

// Rows per block of the blocked layout.
inline constexpr int kBlockRows = 8;

// Floats needed to hold `row_count` rows of `dims` floats in blocks of kBlockRows.
size_t blocked_float_count(int row_count, int dims);

// Copies row-major `rows` into the blocked layout `out` (blocked_float_count() floats): block b
// holds rows [8b, 8b + 8) stored column-major, out[(b * dims + d) * 8 + lane]. Missing rows of
// the last block are filled with a value far outside any normalized feature, so their distance
// overflows to infinity and never wins.
void pack_blocks(const float* rows, int row_count, int dims, float* out);

// Best row of a scan: the lowest distance strictly below the starting bound (row -1 if none).
struct ScanBest {
  int row = -1;
  float distance = std::numeric_limits<float>::infinity();
};

// Which rows a scan may return. Rows are indices into the blocked rows; a row passes when it
// is < row_count, its tags contain every include tag and none of the exclude tags, and its
// frame lies outside [window_first, window_last].
struct RowFilter {
  const uint64_t* row_tags = nullptr;  // per row: the tag mask of its clip
  const int* row_frame = nullptr;      // per row: its database frame
  int row_count = 0;                   // rows at or past this index are padding
  uint64_t include_tags = 0;           // every one of these tags is required
  uint64_t exclude_tags = 0;           // none of these tags is allowed
  int window_first = 0;                // first skipped frame
  int window_last = -1;                // last skipped frame (empty window when < window_first)
  // Per block: OR and AND of the tags of its rows, to skip a block whose rows all fail the
  // tag filter without computing distances (both null when no block may be skipped).
  const uint64_t* block_tags_or = nullptr;
  const uint64_t* block_tags_and = nullptr;
  // Optional: for rows scanned in a transformed space (e.g. rotated), decides by the exact
  // distance. Called for each passing row whose scanned distance is below best.distance; it
  // updates `best` itself (best.distance is then the pruning threshold in the scanned space).
  void (*offer)(void* context, int row, float scanned_distance, ScanBest& best) = nullptr;
  void* offer_context = nullptr;

  // False when every row below row_count passes (no tag filter, no window).
  bool restricts() const {
    return include_tags != 0 || exclude_tags != 0 || window_first <= window_last;
  }
  // True when `row` may be returned.
  bool passes(int row) const {
    if (row >= row_count) return false;
    const uint64_t tags = row_tags[row];
    if ((tags & include_tags) != include_tags || (tags & exclude_tags) != 0) return false;
    const int frame = row_frame[row];
    return frame < window_first || frame > window_last;
  }
  // True when some row of block `block` may pass the tag filter.
  bool block_may_pass(int block) const {
    if (block_tags_or == nullptr) return true;
    return (block_tags_or[block] & include_tags) == include_tags &&
           (block_tags_and[block] & exclude_tags) == 0;
  }
};

// Scans blocks [first_block, last_block) of `blocks` (the packed layout) for the passing row
// with the lowest squared distance to `query` that is strictly below `bound`. `best` carries
// the bound in and the answer out: call with best.distance = bound, best.row = -1.
using ScanBlocksFn = void (*)(const float* blocks, int first_block, int last_block, int dims,
                              const float* query, const RowFilter& filter, ScanBest& best);

// Portable version (GCC vector extensions, SSE2 on x86-64).
void scan_blocks_portable(const float* blocks, int first_block, int last_block, int dims,
                          const float* query, const RowFilter& filter, ScanBest& best);
// AVX2 + FMA version: call only when avx2_supported().
void scan_blocks_avx2(const float* blocks, int first_block, int last_block, int dims,
                      const float* query, const RowFilter& filter, ScanBest& best);
// Like scan_blocks_avx2(), but a group of blocks is left once the distances of all its rows over
// the first 8 (then 16) columns reach the bound: for rows in principal axes, where the leading
// columns carry most of the spread. The same best row and distance as scan_blocks_avx2().
void scan_blocks_staged_avx2(const float* blocks, int first_block, int last_block, int dims,
                             const float* query, const RowFilter& filter, ScanBest& best);
// True when this CPU runs AVX2 and FMA (checked once with __builtin_cpu_supports).
bool avx2_supported();
// The fastest scan this CPU supports, chosen once at run time.
ScanBlocksFn scan_blocks();
// The staged scan this CPU supports (the portable scan has no stages).
ScanBlocksFn scan_blocks_staged();
// "avx2" or "portable": which scan_blocks() runs here.
const char* scan_blocks_isa();

}  // namespace mm::search_kernels
