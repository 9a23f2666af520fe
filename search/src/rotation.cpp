// Principal axes of the feature rows (the eigen decomposition of their covariance, by Eigen), and
// the exact re-ranking that keeps searches in the rotated space exact.

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Eigen/Eigenvalues>

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

FeatureRotation principal_axes(const float* rows, int row_count, int dims, int max_sample_rows) {
  FeatureRotation rotation;
  rotation.dims = dims;
  rotation.padded_dims = (dims + 7) / 8 * 8;
  const auto n = static_cast<size_t>(dims);
  const auto padded = static_cast<size_t>(rotation.padded_dims);
  std::vector<double> mean(n, 0.0);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(dims, dims);
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
    const Eigen::Map<const Eigen::VectorXd> c(centred.data(), dims);
    covariance.selfadjointView<Eigen::Lower>().rankUpdate(c);
  }
  covariance /= static_cast<double>(std::max<size_t>(samples, 1));
  // Eigen's solver reads the lower triangle, which rankUpdate filled.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
  const Eigen::VectorXd& values = solver.eigenvalues();  // ascending
  const Eigen::MatrixXd& vectors = solver.eigenvectors();
  rotation.mean.assign(mean.begin(), mean.end());
  rotation.axes.assign(n * padded, 0.0f);
  rotation.variance.assign(n, 0.0);
  for (size_t k = 0; k < n; ++k) {  // the largest variance first
    const Eigen::Index source = dims - 1 - static_cast<Eigen::Index>(k);
    rotation.variance[k] = std::max(0.0, values(source));
    for (size_t d = 0; d < n; ++d) {
      rotation.axes[d * padded + k] =
          static_cast<float>(vectors(static_cast<Eigen::Index>(d), source));
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
