// `brute-simd`: every candidate row, blocks of 8 rows with vector code. The brute-force
// reference of the library.

#include <algorithm>

#include "detail.hpp"

namespace mm::search_detail {

void PackedBlocks::pack(const CandidateSet& set, const float* rows) {
  using search_kernels::kBlockRows;
  const int count = set.row_count();
  block_count = (count + kBlockRows - 1) / kBlockRows;
  blocks.resize(search_kernels::blocked_float_count(count, set.dims));
  search_kernels::pack_blocks(rows, count, set.dims, blocks.data());
  block_tags_or.assign(static_cast<size_t>(block_count), 0);
  block_tags_and.assign(static_cast<size_t>(block_count), ~uint64_t{0});
  for (int r = 0; r < count; ++r) {
    block_tags_or[static_cast<size_t>(r / kBlockRows)] |= set.row_tags[static_cast<size_t>(r)];
    block_tags_and[static_cast<size_t>(r / kBlockRows)] &= set.row_tags[static_cast<size_t>(r)];
  }
}

void PackedBlocks::use_block_tags(const SearchConstraints& constraints,
                                  search_kernels::RowFilter& filter) const {
  if (constraints.include_tags != 0 || constraints.exclude_tags != 0) {
    filter.block_tags_or = block_tags_or.data();
    filter.block_tags_and = block_tags_and.data();
  }
}

namespace {

class BlockedScanSearcher final : public Searcher {
 public:
  explicit BlockedScanSearcher(const SearchInput& input)
      : set_(make_candidate_set(input)), scan_(search_kernels::scan_blocks()) {
    blocks_.pack(set_, set_.rows.data());
  }

  std::string_view method() const override { return "brute-simd"; }
  int dims() const override { return set_.dims; }
  bool exact() const override { return true; }
  size_t memory_bytes() const override { return set_.memory_bytes() + blocks_.memory_bytes(); }

  SearchResult search(std::span<const float> query,
                      const SearchConstraints& constraints) const override {
    MM_ASSERT(static_cast<int>(query.size()) == set_.dims);
    QueryPlan plan = plan_query(set_, query.data(), constraints);
    // Distances are never negative: with a bound <= 0 nothing can beat the continuation.
    if (!(plan.bound > 0.0f)) return finish_query(set_, plan, query.data(), -1, constraints);
    blocks_.use_block_tags(constraints, plan.filter);
    search_kernels::ScanBest best;
    best.distance = plan.bound;
    scan_(blocks_.blocks.data(), 0, blocks_.block_count, set_.dims, query.data(), plan.filter,
          best);
    return finish_query(set_, plan, query.data(), best.row, constraints);
  }

 private:
  CandidateSet set_;
  search_kernels::ScanBlocksFn scan_;
  PackedBlocks blocks_;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_brute_simd(const SearchInput& input) {
  return std::unique_ptr<Searcher>(std::make_unique<BlockedScanSearcher>(input));
}

}  // namespace mm::search_detail
