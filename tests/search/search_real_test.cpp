// Search on real motion capture: every exact method against `brute` on databases built from
// the Bandai clips (a mixed subset of ~50 clips, and the whole normal-style set), thousands of
// noisy queries under every combination of constraints; `approx` within its bounds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mm/database/search_input.hpp"
#include "mm/offline/builder.hpp"
#include "mm/search/search.hpp"
#include "mm/search_baselines/baselines.hpp"
#include "mm/search_baselines/synthetic.hpp"
#include "normal_database.hpp"
#include "search_rules.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

// Same cost within 1e-5 relative (the definition of an exact match).
bool same_cost(float a, float b) {
  if (a == b) return true;
  return std::fabs(a - b) <= 1e-5f * std::max(std::fabs(a), std::fabs(b));
}

// Every 9th file of the normal-style set (52 clips: walks, turns, runs and standing gestures),
// plus the duplicated takes walk-turn-left 027 and 031 (identical frame for frame).
// A failed build or load was reported by its EXPECT; value() then stops the program.
const Database& subset_database() {
  static const Result<Database> db = [] {
    const fs::path folder = test::data_dir();
    auto files = collect_input_files(std::span<const fs::path>(&folder, 1));
    EXPECT_TRUE(files) << files.message();
    std::vector<fs::path> chosen;
    if (files) {
      for (size_t i = 0; i < files->size(); i += 9) chosen.push_back((*files)[i]);
    }
    for (const char* duplicate :
         {"dataset-2_walk-turn-left_normal_027", "dataset-2_walk-turn-left_normal_031"}) {
      const fs::path path = test::clip_path(duplicate);
      if (std::find(chosen.begin(), chosen.end(), path) == chosen.end()) chosen.push_back(path);
    }
    auto built = build_database(chosen, BuildOptions{});
    EXPECT_TRUE(built) << built.message();
    return built;
  }();
  return db.value();
}

const Database& normal_database() {
  static const Result<Database> db = [] {
    auto loaded = test::normal_database();
    EXPECT_TRUE(loaded) << loaded.message();
    return loaded;
  }();
  return db.value();
}

// The search views of a database (one per database, kept for the whole test program).
const SearchInput& views(const Database& db) {
  static std::map<const Database*, std::unique_ptr<DatabaseSearchInput>> made;
  std::unique_ptr<DatabaseSearchInput>& entry = made[&db];
  if (!entry) entry = std::make_unique<DatabaseSearchInput>(db);
  return entry->input;
}

uint64_t tag(const Database& db, const std::string& name) {
  const std::string names[] = {name};
  return db.tag_mask(names);
}

struct Query {
  std::vector<float> features;
  SearchConstraints constraints;
};

// `count` queries drawn from searchable frames plus noise (0.02 to 0.5), cycling through every
// combination of: nothing playing / playing the source frame / playing another frame; windows
// 0 and 15; transition costs 0, 0.3 and 2; include none / walk / action / walk-turn-left (few
// rows: the tag-class indices of kdtree and approx serve it); exclude none / run / locomotion.
std::vector<Query> real_queries(const Database& db, int count, uint64_t seed) {
  const SearchInput input = views(db);
  const float noises[] = {0.02f, 0.1f, 0.25f, 0.5f};
  std::vector<Query> queries;
  std::mt19937 rng(static_cast<uint32_t>(seed));
  const uint64_t includes[] = {0, tag(db, "walk"), tag(db, "action"), tag(db, "walk-turn-left")};
  const uint64_t excludes[] = {0, tag(db, "run"), tag(db, "locomotion")};
  const float costs[] = {0.0f, 0.3f, 2.0f};
  for (int i = 0; i < count; ++i) {
    const NoisyQueries one = make_noisy_queries(input, 1, noises[i % 4], seed * 100003 + i);
    Query q;
    q.features.assign(one.features.begin(), one.features.end());
    int k = i / 4;
    const int playing = k % 3;
    k /= 3;
    q.constraints.window_frames = (k % 2) * 15;
    k /= 2;
    q.constraints.transition_cost = costs[k % 3];
    k /= 3;
    q.constraints.include_tags = includes[k % 4];
    k /= 4;
    q.constraints.exclude_tags = excludes[k % 3];
    if (playing == 1) q.constraints.current_frame = one.source_frames[0];
    if (playing == 2)
      q.constraints.current_frame =
          static_cast<int>(rng() % static_cast<uint32_t>(db.frame_count()));
    queries.push_back(std::move(q));
  }
  return queries;
}

// The rules, checked independently of any searcher (cost recomputed in double).
void expect_valid(const Database& db, const Query& q, const SearchResult& r) {
  test::expect_obeys_search_rules(views(db), q.features, q.constraints, r);
}

// A method and the options that change its structure (each variant is its own code path).
struct MethodCase {
  const char* method;
  bool principal_axes = true;
  int group_rows = -1;  // -1: the method's default
  bool tag_class_indices = true;

  BaselineSearchOptions options() const {
    BaselineSearchOptions o;
    o.principal_axes = principal_axes;
    o.tag_class_indices = tag_class_indices;
    if (group_rows >= 0)
      o.kdtree_group_rows = o.boxtree_group_rows = o.approx_group_rows = group_rows;
    return o;
  }
};

std::string case_name(const ::testing::TestParamInfo<MethodCase>& info) {
  const MethodCase& c = info.param;
  std::string name = std::string(c.method) + (c.principal_axes ? "" : "_raw") +
                     (c.group_rows >= 0 ? "_groups" + std::to_string(c.group_rows) : "") +
                     (c.tag_class_indices ? "" : "_no_tag_classes");
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

const MethodCase kExactCases[] = {
    {"brute-simd"},
    {"brute-staged"},
    {"aabb"},
    {"kdtree"},                    // one FLANN tree in principal axes, tag-class indices
    {"kdtree", false, -1, false},  // one FLANN tree over the raw columns, filter only
    {"kdtree", true, 1024},        // a FLANN tree per k-means group
    {"boxtree"},                   // k-means groups, each in its own axes
    {"boxtree", false},            // groups over the raw columns
    {"boxtree", true, 0},          // a single tree
};

class RealExactness : public ::testing::TestWithParam<MethodCase> {};

TEST_P(RealExactness, SameCostAsBruteOnTwoThousandConstrainedQueries) {
  const Database& db = subset_database();
  ASSERT_GT(db.clips().size(), 40u);
  ASSERT_GT(db.frame_count(), 5000);
  auto brute = make_bench_searcher("brute", views(db));
  auto method = make_bench_searcher(GetParam().method, views(db), GetParam().options());
  ASSERT_TRUE(brute) << brute.message();
  ASSERT_TRUE(method) << method.message();
  const std::vector<Query> queries = real_queries(db, 2000, 17);
  int mismatches = 0;
  int with_result = 0;
  for (const Query& q : queries) {
    const SearchResult expected = brute.value()->search(q.features, q.constraints);
    const SearchResult got = method.value()->search(q.features, q.constraints);
    expect_valid(db, q, expected);
    expect_valid(db, q, got);
    ASSERT_EQ(got.frame >= 0, expected.frame >= 0);
    with_result += expected.frame >= 0;
    if (!same_cost(got.cost, expected.cost)) {
      ++mismatches;
      ADD_FAILURE() << GetParam().method << ": cost " << got.cost << " (frame " << got.frame
                    << ") vs brute " << expected.cost << " (frame " << expected.frame << ")";
      if (mismatches > 5) break;
    }
  }
  EXPECT_EQ(mismatches, 0);
  // The filters leave candidates for most queries: the test compares real answers.
  EXPECT_GT(with_result, 1500);
}

TEST_P(RealExactness, ExactDuplicateFramesTieAtZeroDistance) {
  const Database& db = subset_database();
  auto method = make_bench_searcher(GetParam().method, views(db), GetParam().options());
  ASSERT_TRUE(method) << method.message();
  // Takes 027 and 031 of walk-turn-left are the same capture shifted by 23 frames: away from
  // the clip ends their feature rows are bitwise equal. Query such a row of 027 exactly, with
  // the frame excluded by the window: the twin in 031 is at distance 0, so the cost is exactly
  // the transition cost, whatever rotation the structure searches in.
  int clip027 = -1;
  int clip031 = -1;
  for (size_t c = 0; c < db.clips().size(); ++c) {
    if (db.clips()[c].name == "dataset-2_walk-turn-left_normal_027") clip027 = static_cast<int>(c);
    if (db.clips()[c].name == "dataset-2_walk-turn-left_normal_031") clip031 = static_cast<int>(c);
  }
  ASSERT_GE(clip027, 0);
  ASSERT_GE(clip031, 0);
  const ClipRange& a = db.clips()[clip027];
  const ClipRange& b = db.clips()[clip031];
  int checked = 0;
  for (int f = a.start; f < a.end; ++f) {
    if (!db.searchable()[f]) continue;
    const std::span<const float> row = db.feature_row(f);
    bool has_twin = false;
    for (int g = b.start; g < b.end && !has_twin; ++g) {
      const std::span<const float> other = db.feature_row(g);
      has_twin = db.searchable()[g] && std::equal(row.begin(), row.end(), other.begin());
    }
    if (!has_twin) continue;
    const std::vector<float> query(row.begin(), row.end());
    SearchConstraints c;
    c.current_frame = f;
    c.window_frames = 2;  // the frame itself and its neighbours; the twin is 100+ frames away
    c.transition_cost = 0.25f;
    const SearchResult r = method.value()->search(query, c);
    EXPECT_EQ(r.cost, 0.25f) << "frame " << f;
    EXPECT_GT(std::abs(r.frame - f), 2);
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

INSTANTIATE_TEST_SUITE_P(ExactMethods, RealExactness, ::testing::ValuesIn(kExactCases), case_name);

// Runs `method` and brute on 1000 constrained queries of the subset database; checks that every
// answer is valid, never better than exact, never worse than `worst_factor` times exact (when
// finite), and
// found whenever a candidate exists; returns how many match brute's cost.
int approximate_exact_count(const char* method, const BaselineSearchOptions& options, uint64_t seed,
                            float worst_factor) {
  const Database& db = subset_database();
  auto brute = make_bench_searcher("brute", views(db));
  auto approx = make_bench_searcher(method, views(db), options);
  EXPECT_TRUE(approx) << approx.message();
  if (!approx) return 0;
  const std::vector<Query> queries = real_queries(db, 1000, seed);
  int exact = 0;
  for (const Query& q : queries) {
    const SearchResult expected = brute.value()->search(q.features, q.constraints);
    const SearchResult got = approx.value()->search(q.features, q.constraints);
    expect_valid(db, q, got);
    EXPECT_EQ(got.frame >= 0, expected.frame >= 0);
    EXPECT_GE(got.cost, expected.cost * (1.0f - 1e-5f));
    if (std::isfinite(worst_factor)) {
      EXPECT_LE(got.cost, expected.cost * worst_factor * (1.0f + 1e-5f));
    }
    exact += same_cost(got.cost, expected.cost);
  }
  return exact;
}

TEST(RealApprox, WithinItsBoundsOnConstrainedQueries) {
  // Randomized, with no bound above: a loose floor only (the benchmark measures the rate).
  EXPECT_GT(approximate_exact_count("approx", {}, 23, std::numeric_limits<float>::infinity()), 500);
}

// kdtree-eps with its default eps on the same kind of queries (noise up to 0.5, a quarter of
// them at 0.5): within its (1 + eps) bound, and mostly exact (the benchmark measures the real
// rate and speed per noise level).
TEST(RealApprox, KdtreeEpsWithinItsBoundOnConstrainedQueries) {
  const BaselineSearchOptions options;
  EXPECT_GT(approximate_exact_count("kdtree-eps", options, 29, 1.0f + options.kdtree_eps), 700);
}

// The whole normal-style set (more than half standing gestures): the fast exact structures
// against brute on unconstrained and playing queries.
TEST(RealNormalSet, TreesMatchBruteOnTheFullDatabase) {
  const Database& db = normal_database();
  ASSERT_GT(db.frame_count(), 50000);
  const SearchInput input = views(db);
  auto brute = make_bench_searcher("brute", input);
  ASSERT_TRUE(brute) << brute.message();
  for (const char* name : {"kdtree", "boxtree"}) {
    auto method = make_bench_searcher(name, input);
    ASSERT_TRUE(method) << method.message();
    int mismatches = 0;
    for (float noise : {0.1f, 0.5f}) {
      const NoisyQueries queries = make_noisy_queries(input, 150, noise, 5);
      for (int i = 0; i < queries.count(); ++i) {
        SearchConstraints c;
        if (i % 2) {
          c.current_frame = queries.source_frames[static_cast<size_t>(i)];
          c.window_frames = 20;
          c.transition_cost = 0.5f;
        }
        const SearchResult expected = brute.value()->search(queries.query(i), c);
        const SearchResult got = method.value()->search(queries.query(i), c);
        mismatches += !same_cost(got.cost, expected.cost);
      }
    }
    EXPECT_EQ(mismatches, 0) << name;
  }
}

}  // namespace
}  // namespace mm
