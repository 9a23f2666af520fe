// "flann-plain": FLANN's exact single tree as shipped, for calibration against other
// measurements of plain FLANN.

#include <flann/flann.hpp>

#include <limits>
#include <vector>

#include "mm/search_baselines/baselines.hpp"

namespace mm {

namespace {

class FlannPlainSearcher final : public Searcher {
 public:
  explicit FlannPlainSearcher(const SearchInput& input) : dims_(input.dims) {
    for (int f = 0; f < input.frame_count(); ++f) {
      if (!input.searchable[static_cast<size_t>(f)]) continue;
      const float* row = input.features.data() + static_cast<size_t>(f) * dims_;
      rows_.insert(rows_.end(), row, row + dims_);
      row_frame_.push_back(f);
    }
    if (row_frame_.empty()) return;
    index_ = std::make_unique<Index>(
        flann::Matrix<float>(rows_.data(), row_frame_.size(), static_cast<size_t>(dims_)),
        flann::KDTreeSingleIndexParams());
    index_->buildIndex();
  }

  std::string_view method() const override { return "flann-plain"; }
  int dims() const override { return dims_; }
  bool exact() const override { return false; }  // it ignores the rules
  size_t memory_bytes() const override {
    // Our rows, the index's reordered copy of them, and its node pool.
    return rows_.size() * sizeof(float) * 2 + row_frame_.capacity() * sizeof(int) +
           (index_ ? static_cast<size_t>(index_->usedMemory()) : 0);
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    SearchResult result;
    if (!index_) return result;
    int nearest = -1;
    float distance = std::numeric_limits<float>::infinity();
    flann::Matrix<int> indices(&nearest, 1, 1);
    flann::Matrix<float> distances(&distance, 1, 1);
    index_->knnSearch(flann::Matrix<float>(const_cast<float*>(query.data()), 1, query.size()),
                      indices, distances, 1, flann::SearchParams(flann::FLANN_CHECKS_UNLIMITED));
    if (nearest >= 0) {
      result.frame = row_frame_[static_cast<size_t>(nearest)];
      result.cost = distance + constraints.transition_cost;
    }
    return result;
  }

 private:
  using Index = flann::KDTreeSingleIndex<flann::L2<float>>;
  int dims_;
  std::vector<float> rows_;     // the searchable rows, FLANN points into them
  std::vector<int> row_frame_;  // index row -> frame
  std::unique_ptr<Index> index_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_flann_plain_searcher(const SearchInput& input) {
  if (Status valid = input.validate(); !valid) return Error{valid.message()};
  try {
    return std::unique_ptr<Searcher>(std::make_unique<FlannPlainSearcher>(input));
  } catch (const std::exception& e) {
    return Error{std::string("flann-plain: FLANN failed to build an index: ") + e.what()};
  }
}

}  // namespace mm
