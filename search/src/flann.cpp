// The exact FLANN methods: `kdtree` (flann::KDTreeSingleIndex, exact) and `kdtree-eps` (the
// same tree searched with FLANN's eps: within (1 + eps) of the best). How they search is in
// flann_forest.hpp.

#include "flann_forest.hpp"

namespace mm::search_detail {

namespace {

// What differs between the exact and the eps search.
struct ExactTraits {
  using Index = flann::KDTreeSingleIndex<FlannDistance>;
  static constexpr std::string_view kName = "kdtree";
  static constexpr bool kExact = true;
  // KDTreeSingleIndex with reorder copies the rows into tree order.
  static constexpr bool kCopiesRows = true;
};
struct EpsTraits {
  using Index = flann::KDTreeSingleIndex<FlannDistance>;
  static constexpr std::string_view kName = "kdtree-eps";
  static constexpr bool kExact = false;
  static constexpr bool kCopiesRows = true;
};

// The options `kdtree` and `kdtree-eps` share.
Status check_single_tree_options(std::string_view method, const SearchOptions& options) {
  if (options.kdtree_leaf_size < 1) {
    return Error{std::string(method) + ": leaf size must be >= 1, got " +
                 std::to_string(options.kdtree_leaf_size)};
  }
  if (options.kdtree_group_rows < 0) {
    return Error{std::string(method) + ": rows per group must be >= 0 (0: one group), got " +
                 std::to_string(options.kdtree_group_rows)};
  }
  return Status::success();
}

}  // namespace

Result<std::unique_ptr<Searcher>> make_kdtree(const SearchInput& input,
                                              const SearchOptions& options) {
  if (Status valid = check_single_tree_options("kdtree", options); !valid)
    return Error{valid.message()};
  // KDTreeSingleIndex ignores the check count, and eps 0 keeps it exact.
  return FlannSearcher<ExactTraits>::make(
      input, options, options.kdtree_group_rows,
      flann::KDTreeSingleIndexParams(options.kdtree_leaf_size, /*reorder=*/true),
      flann::SearchParams());
}

Result<std::unique_ptr<Searcher>> make_kdtree_eps(const SearchInput& input,
                                                  const SearchOptions& options) {
  if (Status valid = check_single_tree_options("kdtree-eps", options); !valid) {
    return Error{valid.message()};
  }
  if (!(options.kdtree_eps >= 0.0f) || !std::isfinite(options.kdtree_eps)) {
    return Error{"kdtree-eps: eps must be finite and >= 0, got " +
                 std::to_string(options.kdtree_eps)};
  }
  // FLANN skips a branch when its lower bound times (1 + eps) reaches the best distance so far.
  flann::SearchParams search_params;
  search_params.eps = options.kdtree_eps;
  return FlannSearcher<EpsTraits>::make(
      input, options, options.kdtree_group_rows,
      flann::KDTreeSingleIndexParams(options.kdtree_leaf_size, /*reorder=*/true), search_params);
}

}  // namespace mm::search_detail
