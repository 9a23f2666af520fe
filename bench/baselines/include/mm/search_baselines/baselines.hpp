#pragma once
// Search methods that only serve comparison, next to the benchmarks: they share the Searcher
// interface and the rules of mm/search/search.hpp, so every row of `mm search-bench` and every
// test runs the same way, but a user picks from the library's methods (search_method_names()).

#include <memory>
#include <span>
#include <string_view>

#include "mm/runtime/result.hpp"
#include "mm/search/search.hpp"

namespace mm {

// The library's options plus those of the baselines.
struct BaselineSearchOptions : SearchOptions {
  // Randomized trees of `approx`.
  int approx_trees = 1;
  // Leaf checks per query of `approx` (its budget; never unlimited).
  int approx_checks = 128;
  // Rows per k-means group of `approx`; 0 (the default) builds a single tree, since the check
  // budget would be spent per group.
  int approx_group_rows = 0;
};

// The baselines:
// - brute: every frame checked against the rules as written (early exit per row): the plain
//   reference the tests check every method against.
// - brute-staged: every candidate row in the principal axes of all rows, scanned by the staged
//   AVX2 kernel (the boxtree's leaf scan, search_kernels::scan_blocks_staged()): the strongest
//   brute force, exact.
// - aabb: bounding boxes over blocks of 16 and 64 consecutive rows with early exits per
//   dimension (the structure of Daniel Holden's Motion-Matching demo).
// - approx: FLANN's randomized KD-tree (KDTreeIndex) with a leaf-check budget; not exact.
std::span<const std::string_view> baseline_method_names();

// Every method a benchmark compares, library and baselines, brute-force ones first.
std::span<const std::string_view> bench_method_names();

// True for the methods that scan every candidate (brute, brute-simd, brute-staged).
bool is_brute_force(std::string_view method);

// Builds a library method (make_searcher()) or a baseline by name; fails on an unknown name,
// invalid input or invalid options.
Result<std::unique_ptr<Searcher>> make_bench_searcher(std::string_view method,
                                                      const SearchInput& input,
                                                      const BaselineSearchOptions& options = {});

// FLANN's exact single tree as shipped (raw columns, FLANN's L2, its default leaf size) over the
// searchable rows, named "flann-plain". It ignores the rules (window, continuation, tags): its
// answer is the nearest searchable row plus the transition cost. It calibrates a machine against
// other measurements of plain FLANN; it is not a method.
Result<std::unique_ptr<Searcher>> make_flann_plain_searcher(const SearchInput& input);

}  // namespace mm
