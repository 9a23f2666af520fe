// `brute-staged`: every candidate row, in the principal axes of all rows, scanned by the staged
// AVX2 kernel that scans the boxtree's leaves. In principal axes the leading columns carry most
// of the spread, so most groups of blocks are left after 8 or 16 columns: the strongest scan, and
// the fair baseline of a structure's speed-up. Rows are decided by their canonical distance
// (ExactRanker), so the answer is exactly the reference's.

#include <cassert>

#include "detail.hpp"
#include "factories.hpp"

namespace mm::search_baselines {

namespace {

using namespace search_detail;

class StagedScanSearcher final : public Searcher {
 public:
  explicit StagedScanSearcher(const SearchInput& input)
      : set_(make_candidate_set(input)), scan_(search_kernels::scan_blocks_staged()) {
    const int rows = set_.row_count();
    const int dims = set_.dims;
    std::vector<float> rotated_rows = set_.rows;
    if (rows > 0) {
      rotation_ = principal_axes(rotated_rows.data(), rows, dims, 4096);
      max_row_norm_ =
          rotate_rows(rotation_, rotated_rows.data(), rows, dims, static_cast<size_t>(dims));
    }
    blocks_.pack(set_, rotated_rows.data());
  }

  std::string_view method() const override { return "brute-staged"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override {
    return set_.memory_bytes() + rotation_.memory_bytes() + blocks_.memory_bytes();
  }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    assert(static_cast<int>(query.size()) == set_.dims);
    QueryPlan plan = plan_query(set_, query.data(), constraints);
    if (!(plan.bound > 0.0f) || rotation_.empty()) {
      return finish_query(set_, plan, query.data(), -1, constraints);
    }
    blocks_.use_block_tags(constraints, plan.filter);
    float rotated[kMaxSearchDims];
    rotation_.apply(query.data(), rotated);
    ExactRanker ranker;
    ranker.start(set_, rotation_, query.data(), plan.bound, row_norm(rotated, set_.dims),
                 max_row_norm_);
    plan.filter.offer = &ExactRanker::offer;
    plan.filter.offer_context = &ranker;
    search_kernels::ScanBest best;
    best.distance = ranker.threshold();
    scan_(blocks_.blocks.data(), 0, blocks_.block_count, set_.dims, rotated, plan.filter, best);
    ranker.resolve();
    return finish_query(set_, plan, query.data(), ranker.best_row, constraints);
  }

 private:
  CandidateSet set_;
  search_kernels::ScanBlocksFn scan_;
  FeatureRotation rotation_;  // the principal axes of all candidate rows
  float max_row_norm_ = 0.0f;
  PackedBlocks blocks_;  // the rotated rows
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_brute_staged(const SearchInput& input) {
  return std::unique_ptr<Searcher>(std::make_unique<StagedScanSearcher>(input));
}

}  // namespace mm::search_baselines
