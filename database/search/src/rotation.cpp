// Principal axes of the feature rows (a Jacobi eigen decomposition of their covariance), and
// the exact re-ranking that keeps searches in the rotated space exact.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "detail.hpp"

namespace mm::search_detail {

namespace {

// Eight floats as a GCC vector (AVX in the AVX2 build, two SSE registers otherwise).
typedef float Float8 __attribute__((vector_size(32)));

// Column by column, every column adds a multiple of its row of the axes matrix to the sums, 8
// axes at a time, so there is no horizontal reduction. `Blocks` > 0 fixes the number of 8-axis
// blocks at compile time, so the sums stay in registers; 0 handles any size from memory.
template <int Blocks>
__attribute__((always_inline)) inline void rotate_blocks(const FeatureRotation& r, const float* x,
                                                         float* y) {
  constexpr int kStackBlocks = kMaxSearchDims / 8;
  Float8 sums[Blocks > 0 ? Blocks : kStackBlocks];
  const int blocks = Blocks > 0 ? Blocks : r.padded_dims / 8;
  for (int b = 0; b < blocks; ++b) sums[b] = Float8{};
  for (int d = 0; d < r.dims; ++d) {
    const float centred = x[d] - r.mean[static_cast<size_t>(d)];
    const float* components = r.axes.data() + static_cast<size_t>(d) * r.padded_dims;
    for (int b = 0; b < blocks; ++b) {
      Float8 axis_part;
      std::memcpy(&axis_part, components + 8 * b, sizeof axis_part);
      sums[b] += axis_part * centred;
    }
  }
  std::memcpy(y, sums, static_cast<size_t>(r.padded_dims) * sizeof(float));
}

__attribute__((always_inline)) inline void rotate(const FeatureRotation& r, const float* x,
                                                  float* y) {
  switch (r.padded_dims / 8) {
    case 1:
      return rotate_blocks<1>(r, x, y);
    case 2:
      return rotate_blocks<2>(r, x, y);
    case 3:
      return rotate_blocks<3>(r, x, y);
    case 4:
      return rotate_blocks<4>(r, x, y);
    default:
      return rotate_blocks<0>(r, x, y);
  }
}

__attribute__((target("avx2,fma"))) void rotate_avx2(const FeatureRotation& r, const float* x,
                                                     float* y) {
  rotate(r, x, y);
}

void rotate_portable(const FeatureRotation& r, const float* x, float* y) {
  rotate(r, x, y);
}

}  // namespace

void FeatureRotation::apply(const float* x, float* y) const {
  static const auto kernel = search_kernels::avx2_supported() ? &rotate_avx2 : &rotate_portable;
  kernel(*this, x, y);
}

float row_norm(const float* x, int dims) {
  float sum = 0.0f;
  for (int d = 0; d < dims; ++d) sum += x[d] * x[d];
  return std::sqrt(sum);
}

float rotate_rows(const FeatureRotation& rotation, float* rows, int count, int dims,
                  size_t stride) {
  float max_norm = 0.0f;
  float rotated[kMaxSearchDims];
  for (int i = 0; i < count; ++i) {
    float* row = rows + static_cast<size_t>(i) * stride;
    rotation.apply(row, rotated);
    std::copy_n(rotated, dims, row);
    max_norm = std::max(max_norm, row_norm(rotated, dims));
  }
  return max_norm;
}

namespace {

// Eigen decomposition of the symmetric matrix `a` (n x n, destroyed) by cyclic Jacobi
// rotations: on return the diagonal of `a` holds the eigenvalues and the columns of `v` the
// eigenvectors. Plenty for n <= kMaxSearchDims at build time.
void jacobi_eigen(size_t n, std::vector<double>& a, std::vector<double>& v) {
  v.assign(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) v[i * n + i] = 1.0;
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0.0;
    double diagonal = 0.0;
    for (size_t i = 0; i < n; ++i) {
      diagonal += a[i * n + i] * a[i * n + i];
      for (size_t j = i + 1; j < n; ++j) off += a[i * n + j] * a[i * n + j];
    }
    if (off <= 1e-24 * diagonal || off == 0.0) return;
    for (size_t p = 0; p < n; ++p) {
      for (size_t q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (apq == 0.0) continue;
        const double theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
        const double t =
            (theta >= 0.0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0);
        const double s = t * c;
        for (size_t k = 0; k < n; ++k) {
          const double akp = a[k * n + p];
          const double akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (size_t k = 0; k < n; ++k) {
          const double apk = a[p * n + k];
          const double aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
        for (size_t k = 0; k < n; ++k) {
          const double vkp = v[k * n + p];
          const double vkq = v[k * n + q];
          v[k * n + p] = c * vkp - s * vkq;
          v[k * n + q] = s * vkp + c * vkq;
        }
      }
    }
  }
}

}  // namespace

FeatureRotation principal_axes(const float* rows, int row_count, int dims, int max_sample_rows) {
  FeatureRotation rotation;
  rotation.dims = dims;
  rotation.padded_dims = (dims + 7) / 8 * 8;
  const auto n = static_cast<size_t>(dims);
  const auto padded = static_cast<size_t>(rotation.padded_dims);
  std::vector<double> mean(n, 0.0);
  std::vector<double> covariance(n * n, 0.0);
  const int step = std::max(1, row_count / std::max(1, max_sample_rows));
  size_t samples = 0;
  for (int r = 0; r < row_count; r += step, ++samples) {
    for (size_t d = 0; d < n; ++d) mean[d] += rows[static_cast<size_t>(r) * n + d];
  }
  if (samples > 0) {
    for (double& m : mean) m /= static_cast<double>(samples);
  }
  std::vector<double> centred(n);
  for (int r = 0; r < row_count; r += step) {
    for (size_t d = 0; d < n; ++d) centred[d] = rows[static_cast<size_t>(r) * n + d] - mean[d];
    for (size_t a = 0; a < n; ++a) {
      for (size_t b = a; b < n; ++b) covariance[a * n + b] += centred[a] * centred[b];
    }
  }
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a; b < n; ++b) {
      covariance[a * n + b] /= static_cast<double>(std::max<size_t>(samples, 1));
      covariance[b * n + a] = covariance[a * n + b];
    }
  }
  std::vector<double> vectors;
  jacobi_eigen(n, covariance, vectors);
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return covariance[a * n + a] > covariance[b * n + b];
  });
  rotation.mean.assign(mean.begin(), mean.end());
  rotation.axes.assign(n * padded, 0.0f);
  rotation.variance.assign(n, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const size_t source = order[k];
    rotation.variance[k] = std::max(0.0, covariance[source * n + source]);
    for (size_t d = 0; d < n; ++d) {
      rotation.axes[d * padded + k] = static_cast<float>(vectors[d * n + source]);
    }
  }
  return rotation;
}

void ExactRanker::resolve() {
  const float limit = threshold();
  for (int i = 0; i < pending; ++i) {
    if (!(pending_distance[i] <= limit)) continue;
    const int row = pending_row[i];
    const int set_row = scanned_to_set != nullptr ? scanned_to_set[row] : row;
    const float distance = search_kernels::squared_distance(query, set->row(set_row), set->dims);
    if (distance < best_distance) {
      best_distance = distance;
      best_row = row;
    }
  }
  pending = 0;
  // Every offered row is decided: the best of them (or the bound) is the tightest upper bound.
  upper = best_distance;
}

void ExactRanker::offer(void* context, int row, float scanned_distance,
                        search_kernels::ScanBest& best) {
  ExactRanker& ranker = *static_cast<ExactRanker*>(context);
  if (ranker.pending == kPendingRows) ranker.resolve();
  ranker.pending_row[ranker.pending] = row;
  ranker.pending_distance[ranker.pending] = scanned_distance;
  ++ranker.pending;
  // The row's canonical distance is at most its scanned one plus the slack.
  ranker.upper = std::min(ranker.upper, scanned_distance + ranker.slack(scanned_distance));
  best.row = row;
  best.distance = ranker.threshold();
}

}  // namespace mm::search_detail
