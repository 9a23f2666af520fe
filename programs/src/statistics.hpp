#pragma once
// Running statistics of a run in fixed memory, shared by the evaluation's accumulators
// (evaluation.cpp, ground_metrics.cpp). Internal to programs/.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mm/runtime/float_to_integer.hpp"

namespace mm::detail {

// The 0-based index of the p-th percentile (0..100) among `count` sorted values (count > 0), by
// nearest rank.
inline size_t nearest_rank(double p, size_t count) {
  const double exact_rank = std::ceil(p / 100.0 * static_cast<double>(count));
  return std::min(count - 1, clamped_integer<size_t>(exact_rank) - (p > 0.0 ? 1 : 0));
}

// The percentiles of a run in fixed memory, whatever its length: a histogram of the values by
// their binary exponent and the first kMantissaBits bits of their mantissa, so a bin spans a
// 2^-kMantissaBits fraction of its lower edge. A percentile is taken by nearest rank, as over
// the sorted values, and reported as the middle of the bin that rank falls in, clamped to the
// smallest and largest value seen: within 2^-(kMantissaBits + 1) (0.05 %) of the exact
// nearest-rank value (exact when all the values are equal).
// Values below 2^kLowestExponent (zero included) share one bin (absolute resolution
// 2^kLowestExponent in the values' unit); values from 2^kHighestExponent up and infinity
// share the last, reported as the largest value seen; NaN is not counted. The bins (about
// 0.5 MB) are allocated by the first value.
class PercentileHistogram {
 public:
  void add(double value) {
    if (std::isnan(value)) return;
    if (bins_.empty()) bins_.assign(kBinCount, 0);
    ++bins_[bin_of(value)];
    ++count_;
    if (count_ == 1) min_ = max_ = value;
    min_ = std::min(min_, value);
    max_ = std::max(max_, value);
  }

  size_t count() const { return count_; }
  double max() const { return count_ > 0 ? max_ : 0.0; }

  // Allocates the bins now rather than at the first value (before a timed loop).
  void reserve() {
    if (bins_.empty()) bins_.assign(kBinCount, 0);
  }

  // Counts `other`'s values as if they had been added here (e.g. one histogram per thread).
  void merge(const PercentileHistogram& other) {
    if (other.count_ == 0) return;
    if (bins_.empty()) bins_.assign(kBinCount, 0);
    for (size_t bin = 0; bin < kBinCount; ++bin) bins_[bin] += other.bins_[bin];
    min_ = count_ == 0 ? other.min_ : std::min(min_, other.min_);
    max_ = count_ == 0 ? other.max_ : std::max(max_, other.max_);
    count_ += other.count_;
  }

  // The p-th percentile (0..100) by nearest rank (see the class); 0 for no values.
  double percentile(double p) const {
    if (count_ == 0) return 0.0;
    const size_t rank = nearest_rank(p, count_);
    size_t below = 0;
    for (size_t bin = 0; bin < kBinCount; ++bin) {
      below += bins_[bin];
      if (below > rank) return std::clamp(middle_of(bin), min_, max_);
    }
    return max_;
  }

 private:
  static constexpr int kMantissaBits = 10;
  static constexpr int kLowestExponent = -20;
  static constexpr int kHighestExponent = 40;
  static constexpr size_t kSubBins = size_t{1} << kMantissaBits;
  // The bin below 2^kLowestExponent, kSubBins per octave, the bin from 2^kHighestExponent up.
  static constexpr size_t kBinCount = 2 + (kHighestExponent - kLowestExponent) * kSubBins;

  static size_t bin_of(double value) {
    if (!(value < std::ldexp(1.0, kHighestExponent))) return kBinCount - 1;
    if (value < std::ldexp(1.0, kLowestExponent)) return 0;
    int exponent = 0;
    const double mantissa = std::frexp(value, &exponent);  // value = mantissa * 2^exponent
    // value in [2^(exponent - 1), 2^exponent); 2 * mantissa in [1, 2).
    const size_t octave = clamped_integer<size_t>(exponent - 1 - kLowestExponent);
    const size_t sub =
        std::min(kSubBins - 1,
                 clamped_integer<size_t>((2.0 * mantissa - 1.0) * static_cast<double>(kSubBins)));
    return 1 + octave * kSubBins + sub;
  }

  double middle_of(size_t bin) const {
    if (bin == 0) return std::ldexp(0.5, kLowestExponent);
    if (bin == kBinCount - 1) return max_;
    const size_t octave = (bin - 1) / kSubBins, sub = (bin - 1) % kSubBins;
    return std::ldexp(1.0 + (static_cast<double>(sub) + 0.5) / static_cast<double>(kSubBins),
                      static_cast<int>(octave) + kLowestExponent);
  }

  std::vector<uint64_t> bins_;
  size_t count_ = 0;
  double min_ = 0.0, max_ = 0.0;
};

// A mean kept as a sum and a count: 0 for no values.
struct RunningMean {
  double sum = 0.0;
  int count = 0;
  void add(double value) {
    sum += value;
    ++count;
  }
  double value() const { return count > 0 ? sum / count : 0.0; }
};

// A percentile over values in [lowest, highest] by fixed-width bins (values outside are counted
// in the end bins): for signed values such as heights, which PercentileHistogram (non-negative
// magnitudes) cannot hold. Reported as the bin's middle, clamped to the smallest and largest
// value seen.
class LinearHistogram {
 public:
  LinearHistogram(double lowest, double highest, size_t bins)
      : lowest_(lowest), width_((highest - lowest) / static_cast<double>(bins)), bins_(bins, 0) {}

  void add(double value) {
    if (std::isnan(value)) return;
    const double x = std::floor((value - lowest_) / width_);
    const size_t bin = x <= 0.0 ? 0 : std::min(bins_.size() - 1, clamped_integer<size_t>(x));
    ++bins_[bin];
    min_ = count_ == 0 ? value : std::min(min_, value);
    max_ = count_ == 0 ? value : std::max(max_, value);
    ++count_;
  }

  size_t count() const { return count_; }
  double min() const { return count_ > 0 ? min_ : 0.0; }

  double percentile(double p) const {
    if (count_ == 0) return 0.0;
    const size_t rank = nearest_rank(p, count_);
    size_t below = 0;
    for (size_t bin = 0; bin < bins_.size(); ++bin) {
      below += bins_[bin];
      if (below > rank) {
        return std::clamp(lowest_ + (static_cast<double>(bin) + 0.5) * width_, min_, max_);
      }
    }
    return max_;
  }

 private:
  double lowest_, width_;
  std::vector<uint64_t> bins_;
  size_t count_ = 0;
  double min_ = 0.0, max_ = 0.0;
};

}  // namespace mm::detail
