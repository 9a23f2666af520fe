// `approx`: FLANN's randomized KD-trees (flann::KDTreeIndex) with a leaf-check budget, searched
// under the rules like the library's FLANN trees (flann_forest.hpp).

#include "factories.hpp"
#include "flann_forest.hpp"

namespace mm::search_baselines {

namespace {

struct ApproxTraits {
  using Index = flann::KDTreeIndex<search_detail::FlannDistance>;
  static constexpr std::string_view kName = "approx";
  static constexpr bool kExact = false;
  static constexpr bool kCopiesRows = false;
};

}  // namespace

Result<std::unique_ptr<Searcher>> make_approx(const SearchInput& input,
                                              const BaselineSearchOptions& options) {
  if (options.approx_trees < 1) {
    return Error{"approx: tree count must be >= 1, got " + std::to_string(options.approx_trees)};
  }
  if (options.approx_checks < 1) {
    return Error{"approx: the check budget must be >= 1 (unlimited checks are not allowed), got " +
                 std::to_string(options.approx_checks)};
  }
  if (options.approx_group_rows < 0) {
    return Error{"approx: rows per group must be >= 0 (0: one group), got " +
                 std::to_string(options.approx_group_rows)};
  }
  return search_detail::FlannSearcher<ApproxTraits>::make(
      input, options, options.approx_group_rows, flann::KDTreeIndexParams(options.approx_trees),
      flann::SearchParams(options.approx_checks));
}

}  // namespace mm::search_baselines
