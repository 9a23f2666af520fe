// Row groups shared by the tree methods: k-means groups of the candidate rows, each with its
// bounding box in the original space, so that a query visits groups nearest first and skips a
// group once the distance to its box reaches the best cost found.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <random>

#include "detail.hpp"

namespace mm::search_detail {

namespace {

using search_kernels::kBlockRows;

// The nearest of a set of centres to a candidate row, with the blocked scan over the centres.
class NearestCentre {
 public:
  explicit NearestCentre(const CandidateSet& set) : set_(set) {}

  // `centres` holds whole rows of set.dims floats.
  void set_centres(const std::vector<float>& centres) {
    const int dims = set_.dims;
    count_ = static_cast<int>(centres.size() / static_cast<size_t>(dims));
    packed_.assign(search_kernels::blocked_float_count(count_, dims), 0.0f);
    search_kernels::pack_blocks(centres.data(), count_, dims, packed_.data());
    no_tags_.assign(static_cast<size_t>(count_), 0);
    ids_.resize(static_cast<size_t>(count_));
    std::iota(ids_.begin(), ids_.end(), 0);
    filter_.row_tags = no_tags_.data();
    filter_.row_frame = ids_.data();
    filter_.row_count = count_;
  }

  int operator()(int row) const {
    search_kernels::ScanBest best;
    scan_(packed_.data(), 0, (count_ + kBlockRows - 1) / kBlockRows, set_.dims, set_.row(row),
          filter_, best);
    return std::max(best.row, 0);
  }

 private:
  const CandidateSet& set_;
  const search_kernels::ScanBlocksFn scan_ = search_kernels::scan_blocks();
  int count_ = 0;
  std::vector<float> packed_;
  std::vector<uint64_t> no_tags_;
  std::vector<int> ids_;
  search_kernels::RowFilter filter_;
};

// Splits `rows` (candidate rows of `set`) into at most `group_count` groups by k-means
// (k-means++ seeding from a fixed seed, Lloyd iterations on an evenly spaced sample, then every
// row to its nearest centre); returns the non-empty groups.
std::vector<std::vector<int>> kmeans_split(const CandidateSet& set, const std::vector<int>& rows,
                                           int group_count) {
  const int count = static_cast<int>(rows.size());
  const int dims = set.dims;
  const auto row_size = static_cast<size_t>(dims);
  std::vector<std::vector<int>> groups;
  if (group_count <= 1 || count <= group_count) {
    groups.push_back(rows);
    return groups;
  }
  const int step = std::max(1, count / 16384);
  std::vector<int> sample;
  for (int i = 0; i < count; i += step) sample.push_back(rows[static_cast<size_t>(i)]);
  // k-means++ seeding: each next centre is a sample row drawn with probability proportional to
  // its squared distance to the nearest centre so far.
  std::mt19937_64 rng(0x5eed);
  std::vector<float> centres;
  std::vector<float> nearest(sample.size(), std::numeric_limits<float>::infinity());
  const int first = sample[rng() % sample.size()];
  centres.insert(centres.end(), set.row(first), set.row(first) + dims);
  for (int k = 1; k < group_count; ++k) {
    const float* last = centres.data() + static_cast<size_t>(k - 1) * row_size;
    double total = 0.0;
    for (size_t i = 0; i < sample.size(); ++i) {
      nearest[i] =
          std::min(nearest[i], search_kernels::squared_distance(set.row(sample[i]), last, dims));
      total += nearest[i];
    }
    if (!(total > 0.0)) break;  // every sample row is a centre already
    double pick = std::uniform_real_distribution<double>(0.0, total)(rng);
    size_t chosen = sample.size() - 1;
    for (size_t i = 0; i < sample.size(); ++i) {
      pick -= nearest[i];
      if (pick <= 0.0) {
        chosen = i;
        break;
      }
    }
    centres.insert(centres.end(), set.row(sample[chosen]), set.row(sample[chosen]) + dims);
  }
  const int k_count = static_cast<int>(centres.size() / row_size);
  NearestCentre nearest_centre(set);
  std::vector<double> sums;
  std::vector<int> counts;
  for (int iteration = 0; iteration < 8; ++iteration) {
    nearest_centre.set_centres(centres);
    sums.assign(centres.size(), 0.0);
    counts.assign(static_cast<size_t>(k_count), 0);
    for (int r : sample) {
      const int c = nearest_centre(r);
      ++counts[static_cast<size_t>(c)];
      for (size_t d = 0; d < row_size; ++d)
        sums[static_cast<size_t>(c) * row_size + d] += set.row(r)[d];
    }
    for (int c = 0; c < k_count; ++c) {
      if (counts[static_cast<size_t>(c)] == 0) continue;  // keeps its old place
      for (size_t d = 0; d < row_size; ++d) {
        centres[static_cast<size_t>(c) * row_size + d] = static_cast<float>(
            sums[static_cast<size_t>(c) * row_size + d] / counts[static_cast<size_t>(c)]);
      }
    }
  }
  nearest_centre.set_centres(centres);
  std::vector<std::vector<int>> by_centre(static_cast<size_t>(k_count));
  for (int r : rows) by_centre[static_cast<size_t>(nearest_centre(r))].push_back(r);
  for (auto& group : by_centre) {
    if (!group.empty()) groups.push_back(std::move(group));
  }
  return groups;
}

// Sum of the per-column variances of `rows` (candidate rows of `set`).
double total_variance(const CandidateSet& set, const std::vector<int>& rows) {
  const auto dims = static_cast<size_t>(set.dims);
  if (rows.empty()) return 0.0;
  std::vector<double> sum(dims, 0.0);
  std::vector<double> sum_squares(dims, 0.0);
  for (int r : rows) {
    const float* row = set.row(r);
    for (size_t d = 0; d < dims; ++d) {
      sum[d] += row[d];
      sum_squares[d] += static_cast<double>(row[d]) * row[d];
    }
  }
  double variance = 0.0;
  const auto n = static_cast<double>(rows.size());
  for (size_t d = 0; d < dims; ++d)
    variance += std::max(0.0, sum_squares[d] / n - (sum[d] / n) * (sum[d] / n));
  return variance;
}

// A group is dense when its spread is below this fraction of the whole database's.
constexpr double kDenseVarianceFraction = 0.01;

// The most rows the grouping looks at (evenly spaced over the candidates).
constexpr int kGroupingSampleRows = 16384;

// Every step-th candidate row, step = row count / kGroupingSampleRows (at least 1).
std::vector<int> grouping_sample(const CandidateSet& set) {
  const int step = std::max(1, set.row_count() / kGroupingSampleRows);
  std::vector<int> sample;
  for (int r = 0; r < set.row_count(); r += step) sample.push_back(r);
  return sample;
}

// Groups of about `group_rows` candidate rows. The grouping is decided on an evenly spaced
// sample of at most kGroupingSampleRows rows: k-means over the sample, then again inside every
// group still more than twice the (scaled) size (a dense cluster, such as the standing gestures,
// takes one centre of the first pass but is split by the next), up to kMaxKmeansGroups in all.
// Only the dense groups (total variance under 1 % of the sample's) stay apart, each to get its
// own tree in its own axes: every row goes to its nearest final centre, and the rows of the
// centres that are not dense are merged into one group; at the scale of the database one tree
// in principal axes prunes as well as several, and a query then descends one tree instead of
// several. Without a dense group (all styles) this is one group of all rows, found from the
// sample alone.
std::vector<std::vector<int>> kmeans_groups(const CandidateSet& set, int group_rows) {
  const int count = set.row_count();
  std::vector<int> all(static_cast<size_t>(count));
  std::iota(all.begin(), all.end(), 0);
  if (group_rows <= 0 || count == 0) return {all};
  const int step = std::max(1, count / kGroupingSampleRows);
  const std::vector<int> sample = grouping_sample(set);
  const int sample_group_rows = std::max(1, group_rows / step);
  const auto groups_for = [&](size_t rows) {
    return static_cast<int>(std::clamp<size_t>((rows + sample_group_rows / 2) / sample_group_rows,
                                               1, kMaxKmeansGroups));
  };
  std::vector<std::vector<int>> done;
  std::vector<std::vector<int>> pending = kmeans_split(set, sample, groups_for(sample.size()));
  for (int pass = 0; pass < 4 && !pending.empty(); ++pass) {
    std::vector<std::vector<int>> next;
    for (auto& group : pending) {
      const size_t room =
          kMaxKmeansGroups - std::min<size_t>(kMaxKmeansGroups, done.size() + next.size() + 1);
      if (group.size() <= 2 * static_cast<size_t>(sample_group_rows) || room == 0) {
        done.push_back(std::move(group));
        continue;
      }
      const int parts = std::min<int>(groups_for(group.size()), static_cast<int>(room) + 1);
      std::vector<std::vector<int>> parts_found = kmeans_split(set, group, parts);
      if (parts_found.size() <= 1) {
        done.push_back(std::move(group));
        continue;
      }
      for (auto& part : parts_found) next.push_back(std::move(part));
    }
    pending = std::move(next);
  }
  for (auto& group : pending) done.push_back(std::move(group));
  const double dense_below = dense_variance_below(set);
  std::vector<uint8_t> dense(done.size(), 0);
  bool any_dense = false;
  for (size_t g = 0; g < done.size(); ++g) {
    dense[g] = total_variance(set, done[g]) < dense_below;
    any_dense = any_dense || dense[g];
  }
  if (!any_dense) return {all};
  // Every row to its nearest final centre (the mean of its sample group).
  const auto dims = static_cast<size_t>(set.dims);
  std::vector<float> centres(done.size() * dims, 0.0f);
  for (size_t g = 0; g < done.size(); ++g) {
    std::vector<double> sum(dims, 0.0);
    for (int r : done[g]) {
      for (size_t d = 0; d < dims; ++d) sum[d] += set.row(r)[d];
    }
    for (size_t d = 0; d < dims; ++d) {
      centres[g * dims + d] = static_cast<float>(sum[d] / static_cast<double>(done[g].size()));
    }
  }
  NearestCentre nearest_centre(set);
  nearest_centre.set_centres(centres);
  std::vector<std::vector<int>> by_centre(done.size());
  std::vector<int> merged;
  for (int r = 0; r < count; ++r) {
    const auto c = static_cast<size_t>(nearest_centre(r));
    (dense[c] ? by_centre[c] : merged).push_back(r);
  }
  std::vector<std::vector<int>> kept;
  if (!merged.empty()) kept.push_back(std::move(merged));  // in database order
  for (auto& group : by_centre) {
    if (!group.empty()) kept.push_back(std::move(group));
  }
  return kept;
}

}  // namespace

double dense_variance_below(const CandidateSet& set) {
  return kDenseVarianceFraction * total_variance(set, grouping_sample(set));
}

size_t RowGroups::memory_bytes() const {
  return boxes.capacity() * sizeof(float) +
         (tags_or.capacity() + tags_and.capacity()) * sizeof(uint64_t);
}

RowGroups make_row_groups(const CandidateSet& set, int group_rows,
                          std::vector<std::vector<int>>& rows_out) {
  rows_out = kmeans_groups(set, group_rows);
  return row_groups_of(set, rows_out);
}

RowGroups row_groups_of(const CandidateSet& set, const std::vector<std::vector<int>>& rows) {
  RowGroups groups;
  const int dims = set.dims;
  groups.query_dims = dims;
  groups.padded_dims = (dims + 7) / 8 * 8;
  const size_t count = rows.size();
  const size_t box_stride = 2 * static_cast<size_t>(groups.padded_dims);
  groups.boxes.assign(count * box_stride, 0.0f);
  groups.tags_or.assign(count, 0);
  groups.tags_and.assign(count, ~uint64_t{0});
  for (size_t g = 0; g < count; ++g) {
    float* lo = groups.boxes.data() + g * box_stride;
    float* hi = lo + groups.padded_dims;
    std::fill(lo, lo + dims, std::numeric_limits<float>::infinity());
    std::fill(hi, hi + dims, -std::numeric_limits<float>::infinity());
    for (int r : rows[g]) {
      const float* row = set.row(r);
      for (int d = 0; d < dims; ++d) {
        lo[d] = std::min(lo[d], row[d]);
        hi[d] = std::max(hi[d], row[d]);
      }
      groups.tags_or[g] |= set.row_tags[static_cast<size_t>(r)];
      groups.tags_and[g] &= set.row_tags[static_cast<size_t>(r)];
    }
  }
  return groups;
}

std::vector<std::vector<int>> tag_classes(const CandidateSet& set) {
  std::vector<uint64_t> masks;
  std::vector<std::vector<int>> classes;
  size_t last = 0;  // rows come clip by clip: the previous row's class is the usual answer
  for (int r = 0; r < set.row_count(); ++r) {
    const uint64_t tags = set.row_tags[static_cast<size_t>(r)];
    if (masks.empty() || masks[last] != tags) {
      last = static_cast<size_t>(std::find(masks.begin(), masks.end(), tags) - masks.begin());
      if (last == masks.size()) {
        if (masks.size() == static_cast<size_t>(kMaxGroups)) return {};
        masks.push_back(tags);
        classes.emplace_back();
      }
    }
    classes[last].push_back(r);
  }
  return classes;
}

int RowGroups::order(const float* query, const SearchConstraints& constraints,
                     GroupDistance* out) const {
  alignas(32) float padded[kMaxSearchDims + 8] = {};
  const int dims = padded_dims;  // the query's padding columns stay 0, like the boxes'
  const bool tag_filter = constraints.include_tags != 0 || constraints.exclude_tags != 0;
  const size_t box_stride = 2 * static_cast<size_t>(padded_dims);
  int count = 0;
  bool copied = false;
  for (size_t g = 0; g < tags_or.size(); ++g) {
    if (tag_filter && ((tags_or[g] & constraints.include_tags) != constraints.include_tags ||
                       (tags_and[g] & constraints.exclude_tags) != 0)) {
      continue;
    }
    if (!copied) {
      std::memcpy(padded, query, static_cast<size_t>(query_dims) * sizeof(float));
      copied = true;
    }
    const float* lo = boxes.data() + g * box_stride;
    const float* hi = lo + padded_dims;
    const GroupDistance entry{box_distance(padded, lo, hi, dims), static_cast<int>(g)};
    // Insertion sort: a few dozen groups at most.
    int i = count++;
    while (i > 0 && out[i - 1].distance > entry.distance) {
      out[i] = out[i - 1];
      --i;
    }
    out[i] = entry;
  }
  return count;
}

}  // namespace mm::search_detail
