// Google Benchmark for the search kernels and structures: the blocked scan (scalar loop,
// portable vectors, AVX2), every method's query on the same rows, and batched queries on one and
// two threads. After the run, each result is printed again as a ratio to its baseline measured
// in the same run (scan: the scalar loop; search: brute, brute-simd and brute-staged; batch: one
// thread).
//
// Rows: synthetic curve-like data (600 clips, ~90k searchable rows) by default, or a database
// file named by MM_BENCH_DB (e.g. build/<you>/all.mmdb from `mm build`).
//   search_bench --benchmark_min_time=0.2

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mm/database/database_file.hpp"
#include "mm/database/search_input.hpp"
#include "mm/search/kernels.hpp"
#include "mm/search/search.hpp"
#include "mm/search_baselines/baselines.hpp"
#include "mm/search_baselines/synthetic.hpp"

namespace {

using namespace mm;

// The rows every benchmark uses, loaded or generated once.
struct BenchData {
  std::optional<Database> database;                     // when MM_BENCH_DB names a file
  std::unique_ptr<DatabaseSearchInput> database_input;  // its search views
  SyntheticSearchData synthetic;
  SearchInput input;
  NoisyQueries queries;        // 1024 queries, noise 0.1
  std::vector<float> rows;     // the searchable rows, row-major
  std::vector<float> blocks;   // the same, packed in blocks of 8
  std::vector<uint64_t> tags;  // zeros: no filter
  std::vector<int> frames;     // row indices: no window
  std::string source;
};

const BenchData& data() {
  static const BenchData d = [] {
    BenchData out;
    const char* path = std::getenv("MM_BENCH_DB");
    if (path != nullptr && *path != '\0') {
      auto loaded = load_database(path);
      if (loaded) {
        out.database.emplace(std::move(loaded).value());
        out.database_input = std::make_unique<DatabaseSearchInput>(*out.database);
        out.input = out.database_input->input;
        out.source = path;
      } else {
        std::fprintf(stderr, "search_bench: %s; using synthetic data\n", loaded.message().c_str());
      }
    }
    if (out.source.empty()) {
      SyntheticSearchSpec spec;
      spec.clip_count = 600;
      out.synthetic = make_synthetic_search_data(spec);
      out.input = out.synthetic.input();
      out.source = "synthetic";
    }
    out.queries = make_noisy_queries(out.input, 1024, 0.1f, 7);
    const int dims = out.input.dims;
    for (int f = 0; f < out.input.frame_count(); ++f) {
      if (!out.input.searchable[static_cast<size_t>(f)]) continue;
      const float* row = out.input.features.data() + static_cast<size_t>(f) * dims;
      out.rows.insert(out.rows.end(), row, row + dims);
    }
    const int count = static_cast<int>(out.rows.size() / static_cast<size_t>(dims));
    out.blocks.resize(search_kernels::blocked_float_count(count, dims));
    search_kernels::pack_blocks(out.rows.data(), count, dims, out.blocks.data());
    out.tags.assign(static_cast<size_t>(count), 0);
    out.frames.resize(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) out.frames[static_cast<size_t>(i)] = i;
    std::fprintf(stderr, "search_bench: %s, %d searchable rows of %d dims\n", out.source.c_str(),
                 count, dims);
    return out;
  }();
  return d;
}

int row_count() {
  return static_cast<int>(data().rows.size() / static_cast<size_t>(data().input.dims));
}

// Every row's distance to one query, row-major, as a tree's leaf visits them: the full distance,
// or bounded by the best so far (FLANN's single tree passes its threshold).
template <class Distance>
void row_distances_with(benchmark::State& state, const Distance& distance) {
  const BenchData& d = data();
  const int dims = d.input.dims;
  const int rows = row_count();
  int q = 0;
  for (auto _ : state) {
    const float* query = d.queries.query(q++ % d.queries.count()).data();
    float best = std::numeric_limits<float>::infinity();
    for (int r = 0; r < rows; ++r) {
      best = std::min(best,
                      distance(query, d.rows.data() + static_cast<size_t>(r) * dims, dims, best));
    }
    benchmark::DoNotOptimize(best);
  }
  state.SetItemsProcessed(state.iterations() * rows);
}

// A full distance in the bounded signature (the bound is not used).
template <search_kernels::RowDistanceFn Full>
float ignoring_bound(const float* a, const float* b, int dims, float) {
  return Full(a, b, dims);
}

// --- the blocked scan kernel against a plain loop ----------------------------------------------

// The scalar loop: the column-order distance with an early exit per row, over every row.
void BM_Scan_Scalar(benchmark::State& state) {
  row_distances_with(state, &search_kernels::squared_distance_bounded);
}

void scan_with(benchmark::State& state, search_kernels::ScanBlocksFn scan) {
  const BenchData& d = data();
  const int rows = row_count();
  search_kernels::RowFilter filter;
  filter.row_tags = d.tags.data();
  filter.row_frame = d.frames.data();
  filter.row_count = rows;
  const int blocks = (rows + search_kernels::kBlockRows - 1) / search_kernels::kBlockRows;
  int q = 0;
  for (auto _ : state) {
    search_kernels::ScanBest best;
    scan(d.blocks.data(), 0, blocks, d.input.dims, d.queries.query(q++ % d.queries.count()).data(),
         filter, best);
    benchmark::DoNotOptimize(best);
  }
  state.SetItemsProcessed(state.iterations() * rows);
}

void BM_Scan_Portable(benchmark::State& state) {
  scan_with(state, &search_kernels::scan_blocks_portable);
}

// False (and the run marked as skipped) on a CPU without AVX2 + FMA.
bool avx2_or_skip(benchmark::State& state) {
  if (search_kernels::avx2_supported()) return true;
  state.SkipWithError("this CPU has no AVX2 + FMA");
  return false;
}

void BM_Scan_Avx2(benchmark::State& state) {
  if (avx2_or_skip(state)) scan_with(state, &search_kernels::scan_blocks_avx2);
}
// The staged scan on the same (unrotated) rows: the box tree uses it in principal axes, where
// far rows stop after 8 or 16 columns more often than here.
void BM_Scan_Avx2_Staged(benchmark::State& state) {
  if (avx2_or_skip(state)) scan_with(state, &search_kernels::scan_blocks_staged_avx2);
}

BENCHMARK(BM_Scan_Scalar)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Scan_Portable)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Scan_Avx2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Scan_Avx2_Staged)->Unit(benchmark::kMicrosecond);

// --- the row distance (FLANN's inner loop) against the column-order sum -----------------------

void BM_RowDistance_Scalar(benchmark::State& state) {
  row_distances_with(state, &ignoring_bound<&search_kernels::squared_distance>);
}
void BM_RowDistance_Portable(benchmark::State& state) {
  row_distances_with(state, &ignoring_bound<&search_kernels::row_distance_portable>);
}
void BM_RowDistance_Avx2(benchmark::State& state) {
  if (avx2_or_skip(state))
    row_distances_with(state, &ignoring_bound<&search_kernels::row_distance_avx2>);
}
void BM_RowDistance_Avx2_Bounded(benchmark::State& state) {
  if (avx2_or_skip(state)) row_distances_with(state, &search_kernels::row_distance_bounded_avx2);
}

BENCHMARK(BM_RowDistance_Scalar)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RowDistance_Portable)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RowDistance_Avx2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RowDistance_Avx2_Bounded)->Unit(benchmark::kMicrosecond);

// --- one query through every method -----------------------------------------------------------

const Searcher& searcher(const std::string& method) {
  static std::map<std::string, std::unique_ptr<Searcher>> built;
  auto& slot = built[method];
  if (!slot) {
    auto made = make_bench_searcher(method, data().input);
    if (!made) {
      std::fprintf(stderr, "search_bench: %s\n", made.message().c_str());
      std::exit(1);
    }
    slot = std::move(made).value();
  }
  return *slot;
}

void BM_Search(benchmark::State& state, const std::string& method) {
  const Searcher& s = searcher(method);
  const BenchData& d = data();
  int q = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        s.search(d.queries.query(q++ % d.queries.count()), SearchConstraints{}));
  }
  state.SetItemsProcessed(state.iterations());
}

// Many characters per call: all 1024 queries in one batch.
void BM_Batch(benchmark::State& state, const std::string& method) {
  const Searcher& s = searcher(method);
  const BenchData& d = data();
  SearchBatchRunner runner(static_cast<int>(state.range(0)));
  std::vector<SearchResult> results(static_cast<size_t>(d.queries.count()));
  const SearchConstraints shared;
  for (auto _ : state) {
    runner.run(s, d.queries.features, std::span<const SearchConstraints>(&shared, 1), results);
    benchmark::DoNotOptimize(results.data());
  }
  state.SetItemsProcessed(state.iterations() * d.queries.count());
}

const bool registered = [] {
  for (std::string_view name : bench_method_names()) {
    const std::string method(name);
    benchmark::RegisterBenchmark(("BM_Search/" + method).c_str(), [method](benchmark::State& st) {
      BM_Search(st, method);
    })->Unit(benchmark::kMicrosecond);
  }
  for (const char* method : {"kdtree", "boxtree"}) {
    const std::string m(method);
    benchmark::RegisterBenchmark(("BM_Batch/" + m).c_str(),
                                 [m](benchmark::State& st) { BM_Batch(st, m); })
        ->Arg(1)
        ->Arg(2)
        ->UseRealTime()
        ->Unit(benchmark::kMicrosecond);
  }
  return true;
}();

// Prints the usual table, and keeps each run's time per iteration for the ratios.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.error_occurred || run.iterations == 0) continue;
      time_per_iteration_[run.benchmark_name()] = run.GetAdjustedRealTime();
    }
  }
  // Speed-up of `name` over `baseline` (how many times faster per iteration; every pair compared
  // here does the same work per iteration and uses the same time unit), 0 when either is missing.
  double speedup(const std::string& name, const std::string& baseline) const {
    const auto a = time_per_iteration_.find(name);
    const auto b = time_per_iteration_.find(baseline);
    if (a == time_per_iteration_.end() || b == time_per_iteration_.end() || a->second <= 0)
      return 0;
    return b->second / a->second;
  }

 private:
  std::map<std::string, double> time_per_iteration_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nspeed-ups measured in this run (%s scan kernel):\n",
              search_kernels::scan_blocks_isa());
  for (const char* scan : {"BM_Scan_Portable", "BM_Scan_Avx2", "BM_Scan_Avx2_Staged"}) {
    if (const double x = reporter.speedup(scan, "BM_Scan_Scalar"); x > 0) {
      std::printf("  %-28s %7.2fx the scalar loop\n", scan, x);
    }
  }
  for (const char* kernel : {"BM_RowDistance_Portable", "BM_RowDistance_Avx2"}) {
    if (const double x = reporter.speedup(kernel, "BM_RowDistance_Scalar"); x > 0) {
      std::printf("  %-28s %7.2fx the column-order loop\n", kernel, x);
    }
  }
  if (const double x = reporter.speedup("BM_RowDistance_Avx2_Bounded", "BM_RowDistance_Avx2");
      x > 0) {
    std::printf("  %-28s %7.2fx the full AVX2 distance\n", "BM_RowDistance_Avx2_Bounded", x);
  }
  for (std::string_view name : bench_method_names()) {
    const std::string run = "BM_Search/" + std::string(name);
    const double over_brute = reporter.speedup(run, "BM_Search/brute");
    const double over_simd = reporter.speedup(run, "BM_Search/brute-simd");
    const double over_staged = reporter.speedup(run, "BM_Search/brute-staged");
    if (over_brute > 0) {
      std::printf("  %-28s %7.1fx brute, %6.2fx brute-simd, %6.2fx brute-staged\n", run.c_str(),
                  over_brute, over_simd, over_staged);
    }
  }
  for (const char* method : {"kdtree", "boxtree"}) {
    const std::string base = std::string("BM_Batch/") + method;
    if (const double x = reporter.speedup(base + "/2/real_time", base + "/1/real_time"); x > 0) {
      std::printf("  %-28s %7.2fx one thread, on two threads\n", base.c_str(), x);
    }
  }
  benchmark::Shutdown();
  return 0;
}
