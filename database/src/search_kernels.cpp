#include "mm/database/search_kernels.hpp"

#include <immintrin.h>

#include <cstring>

namespace mm::search_kernels {

namespace {

// Value of the padding rows of the last block: its square overflows to infinity, so a padding
// row never compares below any bound.
constexpr float kPaddingValue = 1e30f;

// Eight floats as a GCC vector (two SSE registers on plain x86-64).
typedef float Float8 __attribute__((vector_size(32)));

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

__attribute__((target("avx2,fma"))) void scan_blocks_avx2(const float* blocks, int first_block,
                                                          int last_block, int dims,
                                                          const float* query,
                                                          const RowFilter& filter,
                                                          ScanBest& best) {
  const size_t stride = static_cast<size_t>(dims) * kBlockRows;
  __m256 bound = _mm256_set1_ps(best.distance);
  alignas(32) float distances[4][kBlockRows];
  int b = first_block;
  // Four blocks at a time: four independent FMA chains keep both FMA pipes busy.
  for (; b + 4 <= last_block; b += 4) {
    if (!filter.block_may_pass(b) && !filter.block_may_pass(b + 1) &&
        !filter.block_may_pass(b + 2) && !filter.block_may_pass(b + 3)) {
      continue;
    }
    const float* block0 = blocks + b * stride;
    const float* block1 = block0 + stride;
    const float* block2 = block1 + stride;
    const float* block3 = block2 + stride;
    __m256 acc0 = _mm256_setzero_ps();
    __m256 acc1 = _mm256_setzero_ps();
    __m256 acc2 = _mm256_setzero_ps();
    __m256 acc3 = _mm256_setzero_ps();
    for (int d = 0; d < dims; ++d) {
      const __m256 q = _mm256_broadcast_ss(query + d);
      const __m256 diff0 = _mm256_sub_ps(q, _mm256_loadu_ps(block0 + d * kBlockRows));
      const __m256 diff1 = _mm256_sub_ps(q, _mm256_loadu_ps(block1 + d * kBlockRows));
      const __m256 diff2 = _mm256_sub_ps(q, _mm256_loadu_ps(block2 + d * kBlockRows));
      const __m256 diff3 = _mm256_sub_ps(q, _mm256_loadu_ps(block3 + d * kBlockRows));
      acc0 = _mm256_fmadd_ps(diff0, diff0, acc0);
      acc1 = _mm256_fmadd_ps(diff1, diff1, acc1);
      acc2 = _mm256_fmadd_ps(diff2, diff2, acc2);
      acc3 = _mm256_fmadd_ps(diff3, diff3, acc3);
    }
    const __m256 below = _mm256_or_ps(
        _mm256_or_ps(_mm256_cmp_ps(acc0, bound, _CMP_LT_OQ), _mm256_cmp_ps(acc1, bound, _CMP_LT_OQ)),
        _mm256_or_ps(_mm256_cmp_ps(acc2, bound, _CMP_LT_OQ), _mm256_cmp_ps(acc3, bound, _CMP_LT_OQ)));
    if (_mm256_movemask_ps(below) == 0) continue;
    _mm256_store_ps(distances[0], acc0);
    _mm256_store_ps(distances[1], acc1);
    _mm256_store_ps(distances[2], acc2);
    _mm256_store_ps(distances[3], acc3);
    for (int k = 0; k < 4; ++k) {
      if (filter.block_may_pass(b + k)) {
        consider_lanes(distances[k], (b + k) * kBlockRows, filter, best);
      }
    }
    bound = _mm256_set1_ps(best.distance);
  }
  for (; b < last_block; ++b) {
    if (!filter.block_may_pass(b)) continue;
    const float* block = blocks + b * stride;
    __m256 acc0 = _mm256_setzero_ps();
    __m256 acc1 = _mm256_setzero_ps();
    int d = 0;
    for (; d + 1 < dims; d += 2) {
      const __m256 diff0 =
          _mm256_sub_ps(_mm256_broadcast_ss(query + d), _mm256_loadu_ps(block + d * kBlockRows));
      const __m256 diff1 = _mm256_sub_ps(_mm256_broadcast_ss(query + d + 1),
                                         _mm256_loadu_ps(block + (d + 1) * kBlockRows));
      acc0 = _mm256_fmadd_ps(diff0, diff0, acc0);
      acc1 = _mm256_fmadd_ps(diff1, diff1, acc1);
    }
    if (d < dims) {
      const __m256 diff0 =
          _mm256_sub_ps(_mm256_broadcast_ss(query + d), _mm256_loadu_ps(block + d * kBlockRows));
      acc0 = _mm256_fmadd_ps(diff0, diff0, acc0);
    }
    const __m256 acc = _mm256_add_ps(acc0, acc1);
    if (_mm256_movemask_ps(_mm256_cmp_ps(acc, bound, _CMP_LT_OQ)) == 0) continue;
    _mm256_store_ps(distances[0], acc);
    consider_lanes(distances[0], b * kBlockRows, filter, best);
    bound = _mm256_set1_ps(best.distance);
  }
}

bool avx2_supported() {
  static const bool supported = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return supported;
}

ScanBlocksFn scan_blocks() { return avx2_supported() ? &scan_blocks_avx2 : &scan_blocks_portable; }

const char* scan_blocks_isa() { return avx2_supported() ? "avx2" : "portable"; }

}  // namespace mm::search_kernels
