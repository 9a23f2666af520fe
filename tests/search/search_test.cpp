// Search: the rules on hand-made databases, the kernels against scalar loops, and every method
// against the `brute` reference on synthetic curve-like data under every combination of
// constraints. (search_real_test.cpp does the same on real motion capture.)

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mm/search/kernels.hpp"
#include "mm/search/search.hpp"
#include "mm/search_baselines/baselines.hpp"
#include "mm/search_baselines/synthetic.hpp"
#include "search_rules.hpp"

// Every allocation of this test program is counted, so that a test can check that a searcher's
// hot path allocates nothing.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// Every replaceable form goes through malloc and free, so the sanitizers see matching pairs.
// Not inlined: GCC would otherwise pair an inlined free() with the new-expression and warn.
namespace {
void* counted_malloc(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size != 0 ? size : 1);
}
void* counted_aligned(std::size_t size, std::align_val_t align) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto alignment = static_cast<std::size_t>(align);
  return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}
}  // namespace

[[gnu::noinline]] void* operator new(std::size_t size) {
  if (void* p = counted_malloc(size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t size) {
  if (void* p = counted_malloc(size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
[[gnu::noinline]] void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
[[gnu::noinline]] void* operator new(std::size_t size, std::align_val_t align) {
  if (void* p = counted_aligned(size, align)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void* operator new[](std::size_t size, std::align_val_t align) {
  if (void* p = counted_aligned(size, align)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace mm {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Same cost within 1e-5 relative (the definition of an exact match).
bool same_cost(float a, float b) {
  if (a == b) return true;
  return std::fabs(a - b) <= 1e-5f * std::max(std::fabs(a), std::fabs(b));
}

// A library method or a baseline (bench/baselines/).
std::unique_ptr<Searcher> make(std::string_view method, const SearchInput& input,
                               const BaselineSearchOptions& options = {}) {
  auto searcher = make_bench_searcher(method, input, options);
  EXPECT_TRUE(searcher.ok()) << method << ": " << (searcher.ok() ? "" : searcher.message());
  return searcher.ok() ? std::move(searcher.value()) : nullptr;
}

// A tiny database written out by hand in the synthetic data type: 1-d features, so every
// distance is easy to verify.
//   clip 0 "walk" (tag bit 0): frames 0..5, values 0,1,2,3,4,5; frame 5 not searchable
//   clip 1 "run"  (tag bit 1): frames 6..11, values 10,11,12,13,14,15; frame 11 not searchable
//   clip 2 "idle" (tags 0 and 2): frames 12..14, values 2.5, 2.5, 2.5 (exact duplicates)
struct TinyDatabase : SyntheticSearchData {
  TinyDatabase() {
    dims = 1;
    features = {0, 1, 2, 3, 4, 5, 10, 11, 12, 13, 14, 15, 2.5f, 2.5f, 2.5f};
    searchable = {1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 0, 1, 1, 1};
    frame_clip = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 2, 2, 2};
    clips = {{0, 6, 0b001}, {6, 12, 0b010}, {12, 15, 0b101}};
  }
};

class TinyRules : public ::testing::TestWithParam<std::string_view> {
 protected:
  void SetUp() override {
    BaselineSearchOptions options;
    options.kdtree_leaf_size = 2;
    options.approx_checks = 1000;  // more checks than rows: exhaustive on this size
    searcher_ = make(GetParam(), db_.input(), options);
    ASSERT_NE(searcher_, nullptr);
  }
  SearchResult find(float query, const SearchConstraints& constraints) const {
    return searcher_->search(std::span<const float>(&query, 1), constraints);
  }
  // The constraints while `current_frame` plays.
  static SearchConstraints playing(int current_frame, int window_frames, float transition_cost) {
    SearchConstraints c;
    c.current_frame = current_frame;
    c.window_frames = window_frames;
    c.transition_cost = transition_cost;
    return c;
  }
  TinyDatabase db_;
  std::unique_ptr<Searcher> searcher_;
};

TEST_P(TinyRules, NothingPlayingPicksTheNearestSearchableFramePlusTransitionCost) {
  SearchConstraints c;
  c.transition_cost = 0.5f;
  SearchResult r = find(4.75f, c);  // frame 5 (value 5) is not searchable: frame 4 wins
  EXPECT_EQ(r.frame, 4);
  EXPECT_NEAR(r.cost, 0.5625f + 0.5f, 1e-6f);
  EXPECT_FALSE(r.continuation);
  r = find(16.0f, c);  // frame 11 (15) is excluded, frame 10 (14) costs 4 + 0.5
  EXPECT_EQ(r.frame, 10);
  EXPECT_NEAR(r.cost, 4.5f, 1e-6f);
}

TEST_P(TinyRules, WindowSkipsNeighboursButNotTheContinuation) {
  SearchConstraints c = playing(2, 1, 0.0f);  // frames 1..3 skipped, except the continuation 3
  // Query 2.0: frame 2 (d 0) and 1 (d 1) are in the window; continuation 3 costs 1; idle
  // frames 12..14 cost 0.25 and win.
  SearchResult r = find(2.0f, c);
  EXPECT_GE(r.frame, 12);
  EXPECT_LE(r.frame, 14);
  EXPECT_NEAR(r.cost, 0.25f, 1e-6f);
  // A transition cost of 1 makes the continuation (cost 1, no extra) beat idle (0.25 + 1) and
  // frame 0 (4 + 1).
  c.transition_cost = 1.0f;
  r = find(2.0f, c);
  EXPECT_EQ(r.frame, 3);
  EXPECT_TRUE(r.continuation);
  EXPECT_NEAR(r.cost, 1.0f, 1e-6f);
}

TEST_P(TinyRules, ContinuationWinsAnExactTie) {
  const SearchConstraints c = playing(0, 0, 0.0f);
  // Query 1.5: the continuation (frame 1) and frame 2 are both at 0.25; the continuation wins.
  const SearchResult r = find(1.5f, c);
  EXPECT_EQ(r.frame, 1);
  EXPECT_TRUE(r.continuation);
  EXPECT_NEAR(r.cost, 0.25f, 1e-6f);
}

TEST_P(TinyRules, ContinuationMustBeSearchableAndInTheSameClip) {
  SearchConstraints c = playing(4, 0, 100.0f);  // next frame 5 is not searchable: no continuation
  SearchResult r = find(5.0f, c);
  EXPECT_FALSE(r.continuation);
  EXPECT_EQ(r.frame, 3);  // frame 4 is the window; frame 3 costs 4 + 100
  EXPECT_NEAR(r.cost, 104.0f, 1e-4f);
  c.current_frame = 5;  // next frame 6 is in another clip: no continuation either
  r = find(10.0f, c);
  EXPECT_FALSE(r.continuation);
  EXPECT_EQ(r.frame, 6);
  EXPECT_NEAR(r.cost, 100.0f, 1e-4f);
}

TEST_P(TinyRules, TagFiltersApplyToEveryCandidateIncludingTheContinuation) {
  SearchConstraints c;
  c.transition_cost = 0.0f;
  c.include_tags = 0b001;  // walk and idle
  SearchResult r = find(11.0f, c);
  EXPECT_EQ(r.frame, 4);  // the run frames are filtered out
  EXPECT_NEAR(r.cost, 49.0f, 1e-4f);
  c.include_tags = 0b101;  // idle only (must carry both tags)
  r = find(0.0f, c);
  EXPECT_GE(r.frame, 12);
  EXPECT_NEAR(r.cost, 6.25f, 1e-5f);
  c.include_tags = 0;
  c.exclude_tags = 0b100;  // no idle
  r = find(2.5f, c);
  EXPECT_TRUE(r.frame == 2 || r.frame == 3);
  EXPECT_NEAR(r.cost, 0.25f, 1e-6f);
  // The continuation of a run frame is filtered out by include walk: frame 7 is not chosen.
  c.exclude_tags = 0;
  c.include_tags = 0b001;
  c.current_frame = 6;
  c.transition_cost = 1000.0f;
  r = find(11.0f, c);
  EXPECT_FALSE(r.continuation);
  EXPECT_EQ(r.frame, 4);
  EXPECT_NEAR(r.cost, 1049.0f, 1e-2f);
}

TEST_P(TinyRules, NoCandidateGivesFrameMinusOne) {
  SearchConstraints c;
  c.include_tags = 0b110;  // no clip carries both run and idle
  const SearchResult r = find(1.0f, c);
  EXPECT_EQ(r.frame, -1);
  EXPECT_EQ(r.cost, kInf);
}

// Test names from method names ("brute-simd" -> "brute_simd").
std::string method_test_name(const ::testing::TestParamInfo<std::string_view>& param_info) {
  std::string name(param_info.param);
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(AllMethods, TinyRules, ::testing::ValuesIn(bench_method_names()),
                         method_test_name);

TEST(SearchInputValidation, RejectsEveryInconsistency) {
  TinyDatabase db;
  EXPECT_TRUE(db.input().validate().ok());
  {
    SearchInput in = db.input();
    in.dims = 0;
    EXPECT_FALSE(in.validate().ok());
    in.dims = kMaxSearchDims + 1;
    EXPECT_FALSE(in.validate().ok());
  }
  {
    SearchInput in = db.input();
    in.features = in.features.first(14);
    const Status s = in.validate();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("14"), std::string::npos) << s.message();
  }
  {
    SearchInput in = db.input();
    in.frame_clip = in.frame_clip.first(3);
    EXPECT_FALSE(in.validate().ok());
  }
  {
    TinyDatabase bad;
    bad.frame_clip[4] = 7;  // no such clip
    EXPECT_FALSE(bad.input().validate().ok());
    EXPECT_FALSE(make_searcher("brute-simd", bad.input()).ok());
    EXPECT_FALSE(make_bench_searcher("brute", bad.input()).ok());
  }
  {
    TinyDatabase bad;
    bad.frame_clip[4] = 1;  // clip 1 is frames 6..11
    const Status s = bad.input().validate();
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("clip 1"), std::string::npos) << s.message();
  }
  {
    TinyDatabase bad;
    bad.features[3] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(bad.input().validate().ok());
  }
}

TEST(SearchFactory, RejectsUnknownMethodsAndBadOptions) {
  TinyDatabase db;
  auto unknown = make_searcher("octree", db.input());
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("brute-simd"), std::string::npos) << unknown.message();
  SearchOptions options;
  options.kdtree_leaf_size = 0;
  EXPECT_FALSE(make_searcher("kdtree", db.input(), options).ok());
  BaselineSearchOptions baseline_options;
  baseline_options.approx_checks = 0;
  EXPECT_FALSE(make_bench_searcher("approx", db.input(), baseline_options).ok());
  auto unknown_baseline = make_bench_searcher("octree", db.input());
  ASSERT_FALSE(unknown_baseline.ok());
  EXPECT_NE(unknown_baseline.message().find("brute-staged"), std::string::npos)
      << unknown_baseline.message();
  for (float eps : {-0.5f, std::numeric_limits<float>::quiet_NaN(), kInf}) {
    options = {};
    options.kdtree_eps = eps;
    auto refused = make_searcher("kdtree-eps", db.input(), options);
    ASSERT_FALSE(refused.ok()) << eps;
    EXPECT_NE(refused.message().find("eps"), std::string::npos) << refused.message();
  }
  for (std::string_view name : bench_method_names()) {
    auto s = make_bench_searcher(name, db.input());
    ASSERT_TRUE(s.ok()) << name;
    EXPECT_EQ(s.value()->method(), name);
    EXPECT_EQ(s.value()->dims(), 1);
    EXPECT_GT(s.value()->memory_bytes(), 0u);
    EXPECT_EQ(s.value()->exact(), name != "approx" && name != "kdtree-eps");
  }
}

// The library offers what a user would choose; the comparison baselines are not among them.
TEST(SearchFactory, LibraryMethodsExcludeTheBaselines) {
  TinyDatabase db;
  const auto library = search_method_names();
  EXPECT_EQ(std::vector<std::string_view>(library.begin(), library.end()),
            (std::vector<std::string_view>{"brute-simd", "kdtree", "boxtree", "kdtree-eps"}));
  for (std::string_view name : baseline_method_names()) {
    EXPECT_FALSE(make_searcher(name, db.input()).ok()) << name;
    EXPECT_TRUE(make_bench_searcher(name, db.input()).ok()) << name;
  }
  auto plain = make_flann_plain_searcher(db.input());
  ASSERT_TRUE(plain.ok()) << plain.message();
  const float q = 2.1f;  // nearest: frame 2 (value 2)
  EXPECT_EQ(plain.value()->search(std::span<const float>(&q, 1), {}).frame, 2);
}

TEST(SearchFactory, EmptyCandidateSetFindsNothing) {
  TinyDatabase db;
  std::fill(db.searchable.begin(), db.searchable.end(), uint8_t{0});
  for (std::string_view name : bench_method_names()) {
    auto s = make(name, db.input());
    ASSERT_NE(s, nullptr);
    const float q = 1.0f;
    EXPECT_EQ(s->search(std::span<const float>(&q, 1), {}).frame, -1) << name;
  }
}

// --- kernels --------------------------------------------------------------------------------

TEST(SearchKernels, DistancesMatchHandComputation) {
  const float a[3] = {1, 2, 3};
  const float b[3] = {2, 0, 3};
  EXPECT_FLOAT_EQ(search_kernels::squared_distance(a, b, 3), 5.0f);
  // Stops at the first partial sum >= bound: 1 after one column, 5 after two.
  EXPECT_FLOAT_EQ(search_kernels::squared_distance_bounded(a, b, 3, 0.5f), 1.0f);
  EXPECT_FLOAT_EQ(search_kernels::squared_distance_bounded(a, b, 3, 100.0f), 5.0f);
  const float lo[3] = {0, 3, -1};
  const float hi[3] = {2, 4, 1};
  // Inside on x, 1 below on y, 2 above on z: 0 + 1 + 4.
  EXPECT_FLOAT_EQ(search_kernels::box_squared_distance_bounded(a, lo, hi, 3, kInf), 5.0f);
}

TEST(SearchKernels, PackBlocksIsColumnMajorPerBlockWithFarPadding) {
  const int rows = 10;
  const int dims = 3;
  std::vector<float> data(rows * dims);
  for (int i = 0; i < rows * dims; ++i) data[i] = static_cast<float>(i);
  std::vector<float> packed(search_kernels::blocked_float_count(rows, dims));
  ASSERT_EQ(packed.size(), 2u * dims * 8);
  search_kernels::pack_blocks(data.data(), rows, dims, packed.data());
  // Row 9 (block 1, lane 1), column 2 holds 9 * 3 + 2.
  EXPECT_EQ(packed[(1 * dims + 2) * 8 + 1], 29.0f);
  EXPECT_EQ(packed[(0 * dims + 1) * 8 + 5], 16.0f);
  EXPECT_GT(packed[(1 * dims + 0) * 8 + 7], 1e20f);  // padding row 15
}

// Scans against a scalar loop on random rows with random tags and windows.
void check_scan(search_kernels::ScanBlocksFn scan) {
  std::mt19937 rng(7);
  std::normal_distribution<float> gauss;
  for (int dims : {1, 2, 7, 16, 24, 27, 33}) {
    const int rows = 203;  // not a multiple of 8 or 32: exercises the tails
    std::vector<float> data(static_cast<size_t>(rows) * dims);
    for (float& v : data) v = gauss(rng);
    std::vector<uint64_t> tags(rows);
    std::vector<int> frames(rows);
    for (int r = 0; r < rows; ++r) {
      tags[r] = rng() & 7u;
      frames[r] = 2 * r;
    }
    std::vector<float> packed(search_kernels::blocked_float_count(rows, dims));
    search_kernels::pack_blocks(data.data(), rows, dims, packed.data());
    const int blocks = (rows + 7) / 8;
    std::vector<uint64_t> block_or(blocks, 0), block_and(blocks, ~uint64_t{0});
    for (int r = 0; r < rows; ++r) {
      block_or[r / 8] |= tags[r];
      block_and[r / 8] &= tags[r];
    }
    for (int trial = 0; trial < 40; ++trial) {
      std::vector<float> q(dims);
      for (float& v : q) v = gauss(rng);
      search_kernels::RowFilter filter;
      filter.row_tags = tags.data();
      filter.row_frame = frames.data();
      filter.row_count = rows;
      filter.include_tags = trial % 3 == 0 ? 1 : 0;
      filter.exclude_tags = trial % 4 == 0 ? 2 : 0;
      filter.window_first = trial * 9;
      filter.window_last = trial * 9 + trial % 5 * 20;
      if (trial % 2) {
        filter.block_tags_or = block_or.data();
        filter.block_tags_and = block_and.data();
      }
      const float bound = trial % 7 == 0 ? 0.5f * dims : kInf;
      int expected_row = -1;
      float expected = bound;
      for (int r = 0; r < rows; ++r) {
        if (!filter.passes(r)) continue;
        const float d =
            search_kernels::squared_distance(q.data(), &data[static_cast<size_t>(r) * dims], dims);
        if (d < expected) {
          expected = d;
          expected_row = r;
        }
      }
      search_kernels::ScanBest best;
      best.distance = bound;
      scan(packed.data(), 0, blocks, dims, q.data(), filter, best);
      ASSERT_EQ(best.row >= 0, expected_row >= 0) << "dims " << dims << " trial " << trial;
      if (expected_row >= 0) {
        EXPECT_TRUE(same_cost(best.distance, expected)) << best.distance << " vs " << expected;
        const float d = search_kernels::squared_distance(
            q.data(), &data[static_cast<size_t>(best.row) * dims], dims);
        EXPECT_TRUE(same_cost(d, expected));
        EXPECT_TRUE(filter.passes(best.row));
      }
    }
  }
}

TEST(SearchKernels, PortableScanMatchesScalarLoop) {
  check_scan(&search_kernels::scan_blocks_portable);
}

TEST(SearchKernels, Avx2ScanMatchesScalarLoop) {
  // This machine and the CI machine support AVX2; the check keeps the test honest elsewhere.
  if (!search_kernels::avx2_supported()) {
    EXPECT_EQ(search_kernels::scan_blocks(), &search_kernels::scan_blocks_portable);
    return;
  }
  EXPECT_STREQ(search_kernels::scan_blocks_isa(), "avx2");
  check_scan(&search_kernels::scan_blocks_avx2);
}

TEST(SearchKernels, StagedAvx2ScanMatchesScalarLoop) {
  if (!search_kernels::avx2_supported()) {
    EXPECT_EQ(search_kernels::scan_blocks_staged(), &search_kernels::scan_blocks_portable);
    return;
  }
  EXPECT_EQ(search_kernels::scan_blocks_staged(), &search_kernels::scan_blocks_staged_avx2);
  check_scan(&search_kernels::scan_blocks_staged_avx2);
}

// Row distances against the column-order sum, for every column count up to 40 (whole blocks of
// 8 and every tail length), with each row placed at the very end of its own allocation so that
// reading past `dims` floats would touch memory the sanitizer build reports. Then the bounded
// version: a result <= bound must be the full distance, bit for bit, and a row above the bound
// must report a value above it.
void check_row_distance(search_kernels::RowDistanceFn distance,
                        search_kernels::BoundedRowDistanceFn bounded) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> value(-3.0f, 3.0f);
  int stopped_early = 0;
  for (int dims = 1; dims <= 40; ++dims) {
    for (int trial = 0; trial < 20; ++trial) {
      const auto a = std::make_unique<float[]>(static_cast<size_t>(dims));
      const auto b = std::make_unique<float[]>(static_cast<size_t>(dims));
      double exact = 0.0;
      for (int d = 0; d < dims; ++d) {
        a[static_cast<size_t>(d)] = value(rng);
        b[static_cast<size_t>(d)] = value(rng);
        const double diff =
            static_cast<double>(a[static_cast<size_t>(d)]) - b[static_cast<size_t>(d)];
        exact += diff * diff;
      }
      const float full = distance(a.get(), b.get(), dims);
      EXPECT_NEAR(full, exact, 1e-5 * exact + 1e-30) << "dims " << dims;
      EXPECT_NEAR(full, search_kernels::squared_distance(a.get(), b.get(), dims),
                  1e-5 * exact + 1e-30);
      for (const float fraction : {0.0f, 0.1f, 0.5f, 0.999f, 1.0f, 2.0f}) {
        const float bound = full * fraction;
        const float got = bounded(a.get(), b.get(), dims, bound);
        if (full <= bound) {
          EXPECT_EQ(got, full) << "dims " << dims << ", bound " << bound;
        } else {
          EXPECT_GT(got, bound) << "dims " << dims << ", bound " << bound;
          stopped_early += got < full ? 1 : 0;
        }
      }
      EXPECT_EQ(bounded(a.get(), b.get(), dims, kInf), full) << "dims " << dims;
    }
  }
  // Rows of 16 columns or more stop after their first 8 when the bound is 0.
  EXPECT_GT(stopped_early, 0);
  const float a[3] = {1, 2, 3};
  const float b[3] = {2, 0, 3};
  EXPECT_FLOAT_EQ(distance(a, b, 3), 5.0f);
}

TEST(SearchKernels, PortableRowDistanceMatchesColumnSum) {
  check_row_distance(&search_kernels::row_distance_portable,
                     &search_kernels::row_distance_bounded_portable);
}

TEST(SearchKernels, Avx2RowDistanceMatchesColumnSum) {
  if (!search_kernels::avx2_supported()) {
    EXPECT_EQ(search_kernels::row_distance(), &search_kernels::row_distance_portable);
    EXPECT_EQ(search_kernels::row_distance_bounded(),
              &search_kernels::row_distance_bounded_portable);
    return;
  }
  EXPECT_EQ(search_kernels::row_distance(), &search_kernels::row_distance_avx2);
  EXPECT_EQ(search_kernels::row_distance_bounded(), &search_kernels::row_distance_bounded_avx2);
  check_row_distance(&search_kernels::row_distance_avx2,
                     &search_kernels::row_distance_bounded_avx2);
}

// --- every method against brute on synthetic data --------------------------------------------

SyntheticSearchData small_synthetic() {
  SyntheticSearchSpec spec;
  spec.clip_count = 50;
  spec.min_clip_frames = 60;
  spec.max_clip_frames = 180;
  spec.seed = 3;
  return make_synthetic_search_data(spec);
}

// Query i: a searchable frame's features plus Gaussian noise, playing that frame or another.
struct Query {
  std::vector<float> features;
  SearchConstraints constraints;
};

std::vector<Query> constrained_queries(const SyntheticSearchData& data, int per_combination,
                                       uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss;
  std::vector<int> frames;
  for (int f = 0; f < data.frame_count(); ++f) {
    if (data.searchable[f]) frames.push_back(f);
  }
  std::vector<Query> queries;
  const float noises[] = {0.0f, 0.1f, 0.5f};
  const float costs[] = {0.0f, 0.3f, 5.0f};
  for (int playing = 0; playing < 2; ++playing) {
    for (int window : {0, 10}) {
      for (float cost : costs) {
        for (uint64_t include : {uint64_t{0}, uint64_t{2}}) {
          for (uint64_t exclude : {uint64_t{0}, uint64_t{1}, uint64_t{4}}) {
            for (int i = 0; i < per_combination; ++i) {
              const int source = frames[rng() % frames.size()];
              Query q;
              const float noise = noises[i % 3];
              for (int d = 0; d < data.dims; ++d) {
                q.features.push_back(data.features[static_cast<size_t>(source) * data.dims + d] +
                                     noise * gauss(rng));
              }
              q.constraints.current_frame =
                  playing ? (i % 2 ? source : frames[rng() % frames.size()]) : -1;
              q.constraints.window_frames = window;
              q.constraints.transition_cost = cost;
              q.constraints.include_tags = include;
              q.constraints.exclude_tags = exclude;
              queries.push_back(std::move(q));
            }
          }
        }
      }
    }
  }
  return queries;
}

// The queries as one batch: their features back to back, and one constraint each.
std::pair<std::vector<float>, std::vector<SearchConstraints>> as_batch(
    const std::vector<Query>& queries) {
  std::pair<std::vector<float>, std::vector<SearchConstraints>> batch;
  for (const Query& q : queries) {
    batch.first.insert(batch.first.end(), q.features.begin(), q.features.end());
    batch.second.push_back(q.constraints);
  }
  return batch;
}

// Checks that `r` obeys the rules for query `q`, with its cost recomputed independently.
void expect_valid(const SyntheticSearchData& data, const Query& q, const SearchResult& r) {
  test::expect_obeys_search_rules(data.input(), q.features, q.constraints, r);
}

class SyntheticExactness : public ::testing::TestWithParam<std::string_view> {};

TEST_P(SyntheticExactness, SameCostAsBruteUnderEveryConstraintCombination) {
  const SyntheticSearchData data = small_synthetic();
  auto brute = make("brute", data.input());
  auto method = make(GetParam(), data.input());
  ASSERT_NE(brute, nullptr);
  ASSERT_NE(method, nullptr);
  const std::vector<Query> queries = constrained_queries(data, 12, 11);  // 72 combinations
  ASSERT_GE(queries.size(), 800u);
  int mismatches = 0;
  for (const Query& q : queries) {
    const SearchResult expected = brute->search(q.features, q.constraints);
    const SearchResult got = method->search(q.features, q.constraints);
    expect_valid(data, q, expected);
    expect_valid(data, q, got);
    ASSERT_EQ(got.frame >= 0, expected.frame >= 0);
    if (!same_cost(got.cost, expected.cost)) ++mismatches;
  }
  EXPECT_EQ(mismatches, 0) << "of " << queries.size();
}

INSTANTIATE_TEST_SUITE_P(ExactMethods, SyntheticExactness,
                         ::testing::Values("brute-simd", "brute-staged", "aabb", "kdtree",
                                           "boxtree"),
                         method_test_name);

TEST(SyntheticApprox, NeverBelowExactAlwaysValidMostlyExact) {
  const SyntheticSearchData data = small_synthetic();
  auto brute = make("brute", data.input());
  auto approx = make("approx", data.input());
  ASSERT_NE(approx, nullptr);
  const std::vector<Query> queries = constrained_queries(data, 6, 12);
  int exact = 0;
  for (const Query& q : queries) {
    const SearchResult expected = brute->search(q.features, q.constraints);
    const SearchResult got = approx->search(q.features, q.constraints);
    expect_valid(data, q, got);
    // The approximate answer can only be as good as the exact one, never better.
    EXPECT_GE(got.cost, expected.cost * (1.0f - 1e-5f));
    // It finds a candidate whenever one exists (it keeps searching until it has one).
    EXPECT_EQ(got.frame >= 0, expected.frame >= 0);
    exact += same_cost(got.cost, expected.cost);
  }
  // A loose floor: the randomized trees with a 64-check budget find most nearest neighbours
  // on this data (the benchmark measures the real rate).
  EXPECT_GT(exact, static_cast<int>(queries.size()) / 2);
}

// kdtree-eps: never better than exact, never worse than (1 + eps) times exact, and exact with
// eps 0.
TEST(SyntheticApprox, KdtreeEpsStaysWithinItsBound) {
  const SyntheticSearchData data = small_synthetic();
  auto brute = make("brute", data.input());
  const std::vector<Query> queries = constrained_queries(data, 6, 12);
  for (float eps : {0.0f, 0.5f, 2.0f, 8.0f}) {
    BaselineSearchOptions options;
    options.kdtree_eps = eps;
    auto approx = make("kdtree-eps", data.input(), options);
    ASSERT_NE(approx, nullptr);
    int exact = 0;
    for (const Query& q : queries) {
      const SearchResult expected = brute->search(q.features, q.constraints);
      const SearchResult got = approx->search(q.features, q.constraints);
      expect_valid(data, q, got);
      EXPECT_EQ(got.frame >= 0, expected.frame >= 0);
      EXPECT_GE(got.cost, expected.cost * (1.0f - 1e-5f)) << "eps " << eps;
      EXPECT_LE(got.cost, expected.cost * (1.0f + eps) * (1.0f + 1e-5f) + 1e-6f) << "eps " << eps;
      exact += same_cost(got.cost, expected.cost);
    }
    if (eps == 0.0f) {
      EXPECT_EQ(exact, static_cast<int>(queries.size()));
    } else {
      EXPECT_GT(exact, static_cast<int>(queries.size()) / 2) << "eps " << eps;
    }
  }
}

// The trees' groups built on four threads answer exactly as when built on one.
TEST(SearchThreads, KdtreeBuiltOnFourThreadsAnswersAsOnOne) {
  const SyntheticSearchData data = small_synthetic();
  BaselineSearchOptions one_thread, four_threads;
  one_thread.build_threads = 1;
  four_threads.build_threads = 4;
  for (const char* method : {"kdtree", "kdtree-eps"}) {
    auto serial = make(method, data.input(), one_thread);
    auto parallel = make(method, data.input(), four_threads);
    ASSERT_NE(serial, nullptr);
    ASSERT_NE(parallel, nullptr);
    for (const Query& q : constrained_queries(data, 2, 7)) {
      const SearchResult a = serial->search(q.features, q.constraints);
      const SearchResult b = parallel->search(q.features, q.constraints);
      ASSERT_EQ(a.frame, b.frame) << method;
      ASSERT_EQ(a.cost, b.cost) << method;
    }
  }
}

TEST(SearchBatchThreads, BatchedResultsEqualSingleSearches) {
  const SyntheticSearchData data = small_synthetic();
  auto kdtree = make("kdtree", data.input());
  ASSERT_NE(kdtree, nullptr);
  const std::vector<Query> queries = constrained_queries(data, 3, 5);
  const auto [flat, constraints] = as_batch(queries);
  std::vector<SearchResult> results(queries.size());
  SearchBatchRunner runner(2);
  EXPECT_EQ(runner.thread_count(), 2);
  for (int repeat = 0; repeat < 3; ++repeat) {
    std::fill(results.begin(), results.end(), SearchResult{});
    runner.run(*kdtree, flat, constraints, results);
    for (size_t i = 0; i < queries.size(); ++i) {
      const SearchResult single = kdtree->search(queries[i].features, queries[i].constraints);
      ASSERT_EQ(results[i].frame, single.frame) << i;
      ASSERT_EQ(results[i].cost, single.cost) << i;
    }
  }
  // One constraint shared by every query.
  const SearchConstraints shared = constraints[0];
  runner.run(*kdtree, flat, std::span<const SearchConstraints>(&shared, 1), results);
  for (size_t i = 0; i < queries.size(); ++i) {
    EXPECT_EQ(results[i].cost, kdtree->search(queries[i].features, shared).cost);
  }
}

// The hot paths of the methods not built on FLANN allocate nothing (FLANN allocates inside its
// findNeighbors(), as flann_forest.hpp documents), and neither does a batched run.
TEST(SearchAllocations, HotPathsDoNotAllocate) {
  const SyntheticSearchData data = small_synthetic();
  const std::vector<Query> queries = constrained_queries(data, 1, 9);
  for (const char* name : {"brute", "brute-simd", "brute-staged", "aabb", "boxtree"}) {
    auto searcher = make(name, data.input());
    ASSERT_NE(searcher, nullptr);
    const long before = g_allocations.load();
    float sum = 0.0f;
    for (const Query& q : queries) sum += searcher->search(q.features, q.constraints).cost;
    EXPECT_EQ(g_allocations.load() - before, 0) << name;
    EXPECT_TRUE(std::isfinite(sum) || std::isinf(sum));
  }
  auto boxtree = make("boxtree", data.input());
  const auto [flat, constraints] = as_batch(queries);
  std::vector<SearchResult> results(queries.size());
  SearchBatchRunner runner(2);
  runner.run(*boxtree, flat, constraints, results);  // the worker has started and waited once
  const long before = g_allocations.load();
  runner.run(*boxtree, flat, constraints, results);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

TEST(SyntheticData, HasClipsTailsAndAStandingCluster) {
  const SyntheticSearchData data = small_synthetic();
  ASSERT_TRUE(data.input().validate().ok());
  EXPECT_EQ(data.clips.size(), 50u);
  int standing = 0;
  for (const SearchClip& clip : data.clips) {
    EXPECT_GE(clip.end - clip.start, 60);
    EXPECT_LE(clip.end - clip.start, 180);
    // The last 30 frames of each clip are not searchable, the others are.
    EXPECT_TRUE(data.searchable[clip.end - 30 - 1]);
    EXPECT_FALSE(data.searchable[clip.end - 30]);
    standing += (clip.tags & 1) != 0;
  }
  EXPECT_GT(standing, 10);
  EXPECT_LT(standing, 40);
}

}  // namespace
}  // namespace mm
