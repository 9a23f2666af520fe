#include "mm/search/kernels.hpp"

#include <immintrin.h>

#include <cstring>
#include <initializer_list>

namespace mm::search_kernels {

namespace {

// Value of the padding rows of the last block: its square overflows to infinity, so a padding
// row never compares below any bound.
constexpr float kPaddingValue = 1e30f;

// Eight floats as a GCC vector (two SSE registers on plain x86-64).
typedef float Float8 __attribute__((vector_size(32)));

// The lanes summed pairwise, the order every row distance uses.
float sum_lanes(const Float8& acc) {
  float lanes[8];
  std::memcpy(lanes, &acc, sizeof lanes);
  return ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) +
         ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
}

// The rare path of a scan: some lane of a block beat the bound; check the lanes in row order
// and keep the best passing one.
__attribute__((noinline)) void consider_lanes(const float* distances, int first_row,
                                              const RowFilter& filter, ScanBest& best) {
  for (int lane = 0; lane < kBlockRows; ++lane) {
    const float distance = distances[lane];
    if (distance < best.distance && filter.passes(first_row + lane)) {
      if (filter.offer != nullptr) {
        filter.offer(filter.offer_context, first_row + lane, distance, best);
      } else {
        best.distance = distance;
        best.row = first_row + lane;
      }
    }
  }
}

}  // namespace

float squared_distance(const float* a, const float* b, int dims) {
  float sum = 0.0f;
  for (int d = 0; d < dims; ++d) {
    const float diff = a[d] - b[d];
    sum += diff * diff;
  }
  return sum;
}

float squared_distance_bounded(const float* a, const float* b, int dims, float bound) {
  float sum = 0.0f;
  for (int d = 0; d < dims; ++d) {
    const float diff = a[d] - b[d];
    sum += diff * diff;
    if (sum >= bound) return sum;
  }
  return sum;
}

float box_squared_distance_bounded(const float* point, const float* lo, const float* hi, int dims,
                                   float bound) {
  float sum = 0.0f;
  for (int d = 0; d < dims; ++d) {
    const float v = point[d];
    const float gap = v < lo[d] ? lo[d] - v : (v > hi[d] ? v - hi[d] : 0.0f);
    sum += gap * gap;
    if (sum >= bound) return sum;
  }
  return sum;
}

namespace {

// The row distance, 8 columns at a time; with `Bounded`, a partial sum above `bound` after 8 or
// 16 columns is returned at once. The plain version has no such checks: where rows rarely stop
// (a dense group, whose rows are all about as far as the query's noise), the checks and their
// mispredicted branches cost more than the stops save.
template <bool Bounded>
float row_distance_portable_impl(const float* a, const float* b, int dims, float bound) {
  Float8 acc = {};
  int d = 0;
  for (; d + 8 <= dims; d += 8) {
    Float8 x;
    Float8 y;
    std::memcpy(&x, a + d, sizeof x);
    std::memcpy(&y, b + d, sizeof y);
    const Float8 diff = x - y;
    acc += diff * diff;
    if (Bounded && d + 16 <= dims) {
      const float partial = sum_lanes(acc);
      if (partial > bound) return partial;
    }
  }
  float sum = sum_lanes(acc);
  for (; d < dims; ++d) {
    const float diff = a[d] - b[d];
    sum += diff * diff;
  }
  return sum;
}

__attribute__((target("avx2,fma"), always_inline)) inline float horizontal_sum(__m256 v) {
  __m128 sum = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  sum = _mm_add_ps(sum, _mm_movehl_ps(sum, sum));
  sum = _mm_add_ss(sum, _mm_movehdup_ps(sum));
  return _mm_cvtss_f32(sum);
}

template <bool Bounded>
__attribute__((target("avx2,fma"), always_inline)) inline float row_distance_avx2_impl(
    const float* a, const float* b, int dims, float bound) {
  __m256 acc = _mm256_setzero_ps();
  int d = 0;
  for (; d + 8 <= dims; d += 8) {
    const __m256 diff = _mm256_sub_ps(_mm256_loadu_ps(a + d), _mm256_loadu_ps(b + d));
    acc = _mm256_fmadd_ps(diff, diff, acc);
    if (Bounded && d + 16 <= dims) {
      const float partial = horizontal_sum(acc);
      if (partial > bound) return partial;
    }
  }
  if (d < dims) {
    // The masked loads read only the remaining columns (never past the end of a row).
    const __m256i mask =
        _mm256_cmpgt_epi32(_mm256_set1_epi32(dims - d), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    const __m256 diff =
        _mm256_sub_ps(_mm256_maskload_ps(a + d, mask), _mm256_maskload_ps(b + d, mask));
    acc = _mm256_fmadd_ps(diff, diff, acc);
  }
  return horizontal_sum(acc);
}

}  // namespace

float row_distance_portable(const float* a, const float* b, int dims) {
  return row_distance_portable_impl<false>(a, b, dims, 0.0f);
}

float row_distance_bounded_portable(const float* a, const float* b, int dims, float bound) {
  return row_distance_portable_impl<true>(a, b, dims, bound);
}

__attribute__((target("avx2,fma"))) float row_distance_avx2(const float* a, const float* b,
                                                            int dims) {
  return row_distance_avx2_impl<false>(a, b, dims, 0.0f);
}

__attribute__((target("avx2,fma"))) float row_distance_bounded_avx2(const float* a, const float* b,
                                                                    int dims, float bound) {
  return row_distance_avx2_impl<true>(a, b, dims, bound);
}

size_t blocked_float_count(int row_count, int dims) {
  const size_t blocks = (static_cast<size_t>(row_count) + kBlockRows - 1) / kBlockRows;
  return blocks * static_cast<size_t>(dims) * kBlockRows;
}

void pack_blocks(const float* rows, int row_count, int dims, float* out) {
  const int block_count = (row_count + kBlockRows - 1) / kBlockRows;
  for (int b = 0; b < block_count; ++b) {
    float* block = out + static_cast<size_t>(b) * dims * kBlockRows;
    for (int lane = 0; lane < kBlockRows; ++lane) {
      const int row = b * kBlockRows + lane;
      for (int d = 0; d < dims; ++d) {
        block[d * kBlockRows + lane] =
            row < row_count ? rows[static_cast<size_t>(row) * dims + d] : kPaddingValue;
      }
    }
  }
}

void scan_blocks_portable(const float* blocks, int first_block, int last_block, int dims,
                          const float* query, const RowFilter& filter, ScanBest& best) {
  const size_t stride = static_cast<size_t>(dims) * kBlockRows;
  for (int b = first_block; b < last_block; ++b) {
    if (!filter.block_may_pass(b)) continue;
    const float* block = blocks + b * stride;
    // Two accumulators halve the dependency chain of the additions.
    Float8 acc0 = {};
    Float8 acc1 = {};
    int d = 0;
    for (; d + 1 < dims; d += 2) {
      Float8 x0;
      Float8 x1;
      std::memcpy(&x0, block + d * kBlockRows, sizeof x0);
      std::memcpy(&x1, block + (d + 1) * kBlockRows, sizeof x1);
      const Float8 diff0 = query[d] - x0;
      const Float8 diff1 = query[d + 1] - x1;
      acc0 += diff0 * diff0;
      acc1 += diff1 * diff1;
    }
    if (d < dims) {
      Float8 x0;
      std::memcpy(&x0, block + d * kBlockRows, sizeof x0);
      const Float8 diff0 = query[d] - x0;
      acc0 += diff0 * diff0;
    }
    const Float8 acc = acc0 + acc1;
    float distances[kBlockRows];
    std::memcpy(distances, &acc, sizeof distances);
    bool any = false;
    for (int lane = 0; lane < kBlockRows; ++lane) any |= distances[lane] < best.distance;
    if (any) consider_lanes(distances, b * kBlockRows, filter, best);
  }
}

namespace {

// Adds columns [from, to) of the rows of `Count` consecutive blocks to their squared distances,
// each block summed in two chains (even and odd columns) so that 2 * Count independent FMA
// chains hide the FMA latency. `from` is even, so splitting a row into column ranges adds the
// same terms to the same chains in the same order as one pass.
template <int Count>
__attribute__((target("avx2,fma"), always_inline)) inline void add_columns_avx2(
    const float* first_block, size_t stride, int from, int to, const float* query, __m256* even,
    __m256* odd) {
  int d = from;
  for (; d + 1 < to; d += 2) {
    const __m256 q0 = _mm256_broadcast_ss(query + d);
    const __m256 q1 = _mm256_broadcast_ss(query + d + 1);
    for (int k = 0; k < Count; ++k) {
      const float* column = first_block + k * stride + d * kBlockRows;
      const __m256 diff0 = _mm256_sub_ps(q0, _mm256_loadu_ps(column));
      const __m256 diff1 = _mm256_sub_ps(q1, _mm256_loadu_ps(column + kBlockRows));
      even[k] = _mm256_fmadd_ps(diff0, diff0, even[k]);
      odd[k] = _mm256_fmadd_ps(diff1, diff1, odd[k]);
    }
  }
  if (d < to) {
    const __m256 q0 = _mm256_broadcast_ss(query + d);
    for (int k = 0; k < Count; ++k) {
      const __m256 diff0 =
          _mm256_sub_ps(q0, _mm256_loadu_ps(first_block + k * stride + d * kBlockRows));
      even[k] = _mm256_fmadd_ps(diff0, diff0, even[k]);
    }
  }
}

// True when some row of the `Count` blocks has a (partial) distance below the bound.
template <int Count>
__attribute__((target("avx2,fma"), always_inline)) inline bool any_below_avx2(
    const __m256* distances, __m256 bound) {
  __m256 below = _mm256_cmp_ps(distances[0], bound, _CMP_LT_OQ);
  for (int k = 1; k < Count; ++k) {
    below = _mm256_or_ps(below, _mm256_cmp_ps(distances[k], bound, _CMP_LT_OQ));
  }
  return _mm256_movemask_ps(below) != 0;
}

// Checks `Count` blocks of distances against the bound; the rare path keeps the best row. When
// `Staged`, the partial distances after 8 and after 16 columns are checked first, and the blocks
// are left as soon as every row is already at or above the bound (partial sums only grow): in
// principal axes the leading columns carry most of the spread, so far rows stop early.
template <int Count, bool Staged>
__attribute__((target("avx2,fma"), always_inline)) inline void scan_group_avx2(
    const float* blocks, int b, size_t stride, int dims, const float* query,
    const RowFilter& filter, ScanBest& best, __m256& bound) {
  const float* first_block = blocks + b * stride;
  __m256 even[Count];
  __m256 odd[Count];
  __m256 distances[Count];
  for (int k = 0; k < Count; ++k) {
    even[k] = _mm256_setzero_ps();
    odd[k] = _mm256_setzero_ps();
  }
  int from = 0;
  if constexpr (Staged) {
    for (const int stage_end : {8, 16}) {
      if (stage_end + 8 > dims) break;
      add_columns_avx2<Count>(first_block, stride, from, stage_end, query, even, odd);
      from = stage_end;
      for (int k = 0; k < Count; ++k) distances[k] = _mm256_add_ps(even[k], odd[k]);
      if (!any_below_avx2<Count>(distances, bound)) return;
    }
  }
  add_columns_avx2<Count>(first_block, stride, from, dims, query, even, odd);
  for (int k = 0; k < Count; ++k) distances[k] = _mm256_add_ps(even[k], odd[k]);
  if (!any_below_avx2<Count>(distances, bound)) return;
  alignas(32) float lanes[kBlockRows];
  for (int k = 0; k < Count; ++k) {
    if (!filter.block_may_pass(b + k)) continue;
    _mm256_store_ps(lanes, distances[k]);
    consider_lanes(lanes, (b + k) * kBlockRows, filter, best);
  }
  bound = _mm256_set1_ps(best.distance);
}

template <bool Staged>
__attribute__((target("avx2,fma"), always_inline)) inline void scan_blocks_avx2_impl(
    const float* blocks, int first_block, int last_block, int dims, const float* query,
    const RowFilter& filter, ScanBest& best) {
  const size_t stride = static_cast<size_t>(dims) * kBlockRows;
  __m256 bound = _mm256_set1_ps(best.distance);
  int b = first_block;
  // Four blocks at a time, then two, then one: eight, four or two FMA chains in flight.
  for (; b + 4 <= last_block; b += 4) {
    if (!filter.block_may_pass(b) && !filter.block_may_pass(b + 1) &&
        !filter.block_may_pass(b + 2) && !filter.block_may_pass(b + 3)) {
      continue;
    }
    scan_group_avx2<4, Staged>(blocks, b, stride, dims, query, filter, best, bound);
  }
  if (b + 2 <= last_block) {
    if (filter.block_may_pass(b) || filter.block_may_pass(b + 1)) {
      scan_group_avx2<2, Staged>(blocks, b, stride, dims, query, filter, best, bound);
    }
    b += 2;
  }
  if (b < last_block && filter.block_may_pass(b)) {
    scan_group_avx2<1, Staged>(blocks, b, stride, dims, query, filter, best, bound);
  }
}

}  // namespace

__attribute__((target("avx2,fma"))) void scan_blocks_avx2(const float* blocks, int first_block,
                                                          int last_block, int dims,
                                                          const float* query,
                                                          const RowFilter& filter, ScanBest& best) {
  scan_blocks_avx2_impl<false>(blocks, first_block, last_block, dims, query, filter, best);
}

__attribute__((target("avx2,fma"))) void scan_blocks_staged_avx2(const float* blocks,
                                                                 int first_block, int last_block,
                                                                 int dims, const float* query,
                                                                 const RowFilter& filter,
                                                                 ScanBest& best) {
  scan_blocks_avx2_impl<true>(blocks, first_block, last_block, dims, query, filter, best);
}

bool avx2_supported() {
  static const bool supported = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return supported;
}

ScanBlocksFn scan_blocks() {
  return avx2_supported() ? &scan_blocks_avx2 : &scan_blocks_portable;
}

ScanBlocksFn scan_blocks_staged() {
  return avx2_supported() ? &scan_blocks_staged_avx2 : &scan_blocks_portable;
}

RowDistanceFn row_distance() {
  return avx2_supported() ? &row_distance_avx2 : &row_distance_portable;
}

BoundedRowDistanceFn row_distance_bounded() {
  return avx2_supported() ? &row_distance_bounded_avx2 : &row_distance_bounded_portable;
}

const char* scan_blocks_isa() {
  return avx2_supported() ? "avx2" : "portable";
}

}  // namespace mm::search_kernels
