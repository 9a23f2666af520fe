// `mm search-bench`: builds every search structure over one database, runs the same noisy
// queries through each, and prints build time, memory, latency percentiles, exactness against
// `brute`, and speed-ups over `brute` and `brute-simd` measured in the same run.

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <flann/flann.hpp>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/database/search.hpp"
#include "mm/database/search_kernels.hpp"
#include "mm/database/search_synthetic.hpp"

namespace mm::cli {
namespace {

using Clock = std::chrono::steady_clock;

const char* const kUsage = R"(usage: mm search-bench (--db <file.mmdb> | --synthetic) [options]

Builds each search structure over the database (timed), runs the same queries through every
method and prints, per method: build time, memory, median and p99 latency per query, the rate
of exact matches (same cost as brute within 1e-5 relative), the mean cost ratio to the exact
cost, and the speed-up of the median over brute and over brute-simd (always run as baselines).
Then how crowded the queries' neighbourhoods are: the share of the candidates within 1.2x and
1.5x of the nearest row's distance (median, p90, p99 over the queries). Where a large share lies
that close, an exact search has little to skip and cannot be much faster than a scan.

options:
  --db FILE              the database (.mmdb, from `mm build`)
  --synthetic            use generated curve-like data instead (no file needed)
  --queries N            number of queries (default 2000)
  --noise S              Gaussian noise added to each query, normalized units (default 0.1)
  --methods LIST         comma-separated methods (default: all; known: brute, brute-simd, aabb,
                         kdtree, boxtree, approx, kdtree-eps)
  --json FILE            also write the results as JSON
  --seed N               query seed (default 1)
  --playing              each query plays its source frame (continuation, window, transition
                         cost apply); by default nothing plays (plain nearest neighbour)
  --window N             window of skipped frames when --playing (default 20)
  --transition-cost C    transition cost when --playing (default 0.5)
  --include TAGS         tag filter: comma-separated tags every candidate's clip must carry
  --exclude TAGS         tag filter: comma-separated tags no candidate's clip may carry
  --leaf-size N          kdtree leaf size in rows (default 32)
  --boxtree-leaf-size N  boxtree leaf size in rows, a multiple of 8 (default 64)
  --kdtree-group-rows N  rows per k-means group (default 4096, approx 0; dense groups get their
  --boxtree-group-rows N own tree in their own axes, the rest share one; 0 for a single tree)
  --approx-group-rows N
  --raw-axes             build the trees over the raw columns instead of the principal axes
  --repeat R             time every query R times and keep its fastest run (default 1): R rounds,
                         each one pass per method, so that a slow spell of a shared machine
                         hits every method alike
  --clock wall|cpu       wall time (default) or the thread's CPU time (ignores preemption)
  --approx-trees N       approx: randomized trees (default 1)
  --approx-checks N      approx: leaf checks per query (default 128)
  --eps E                kdtree-eps: distance within (1 + E) times the best (default 3)
  --no-flann-reference   leave out the flann-plain row (FLANN's single tree as shipped: raw
                         columns, no constraints; shown only when nothing plays and no tag
                         filter is given, to compare this machine with plain FLANN elsewhere)
  --batch                also time batched queries on 1 and 2 threads
  --quiet                no progress on the terminal
)";

struct Arguments {
  std::string db_path;
  bool synthetic = false;
  int queries = 2000;
  float noise = 0.1f;
  std::vector<std::string> methods;
  std::string json_path;
  uint64_t seed = 1;
  bool playing = false;
  int window = 20;
  float transition_cost = 0.5f;
  std::vector<std::string> include;
  std::vector<std::string> exclude;
  SearchOptions options;
  bool batch = false;
  bool flann_reference = true;
  bool quiet = false;
  int repeat = 1;
  bool cpu_clock = false;
};

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> items;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t comma = std::min(list.find(',', start), list.size());
    if (comma > start) items.push_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return items;
}

// Parses the arguments; returns an exit code >= 0 when the program should stop (help, error).
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  auto number = [&](size_t& i, const std::string& flag, double lo, double hi, double& value) {
    if (i + 1 >= args.size()) {
      std::fprintf(stderr, "mm search-bench: %s needs a value\n", flag.c_str());
      return false;
    }
    const std::string& text = args[++i];
    char* end = nullptr;
    value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0' || !std::isfinite(value) || value < lo || value > hi) {
      std::fprintf(stderr, "mm search-bench: %s expects a number in [%g, %g], got '%s'\n",
                   flag.c_str(), lo, hi, text.c_str());
      return false;
    }
    return true;
  };
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    double v = 0;
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--db" && i + 1 < args.size()) {
      out.db_path = args[++i];
    } else if (a == "--synthetic") {
      out.synthetic = true;
    } else if (a == "--queries") {
      if (!number(i, a, 1, 1e7, v)) return 2;
      out.queries = static_cast<int>(v);
    } else if (a == "--noise") {
      if (!number(i, a, 0, 100, v)) return 2;
      out.noise = static_cast<float>(v);
    } else if (a == "--methods" && i + 1 < args.size()) {
      out.methods = split_list(args[++i]);
    } else if (a == "--json" && i + 1 < args.size()) {
      out.json_path = args[++i];
    } else if (a == "--seed") {
      if (!number(i, a, 0, 1e15, v)) return 2;
      out.seed = static_cast<uint64_t>(v);
    } else if (a == "--playing") {
      out.playing = true;
    } else if (a == "--window") {
      if (!number(i, a, 0, 1e6, v)) return 2;
      out.window = static_cast<int>(v);
    } else if (a == "--transition-cost") {
      if (!number(i, a, 0, 1e9, v)) return 2;
      out.transition_cost = static_cast<float>(v);
    } else if (a == "--include" && i + 1 < args.size()) {
      out.include = split_list(args[++i]);
    } else if (a == "--exclude" && i + 1 < args.size()) {
      out.exclude = split_list(args[++i]);
    } else if (a == "--leaf-size") {
      if (!number(i, a, 1, 1e6, v)) return 2;
      out.options.kdtree_leaf_size = static_cast<int>(v);
    } else if (a == "--boxtree-leaf-size") {
      if (!number(i, a, 8, 1e6, v)) return 2;
      out.options.boxtree_leaf_size = static_cast<int>(v);
    } else if (a == "--kdtree-group-rows") {
      if (!number(i, a, 0, 1e9, v)) return 2;
      out.options.kdtree_group_rows = static_cast<int>(v);
    } else if (a == "--boxtree-group-rows") {
      if (!number(i, a, 0, 1e9, v)) return 2;
      out.options.boxtree_group_rows = static_cast<int>(v);
    } else if (a == "--approx-group-rows") {
      if (!number(i, a, 0, 1e9, v)) return 2;
      out.options.approx_group_rows = static_cast<int>(v);
    } else if (a == "--raw-axes") {
      out.options.principal_axes = false;
    } else if (a == "--repeat") {
      if (!number(i, a, 1, 1000, v)) return 2;
      out.repeat = static_cast<int>(v);
    } else if (a == "--clock" && i + 1 < args.size()) {
      const std::string& clock = args[++i];
      if (clock != "wall" && clock != "cpu") {
        std::fprintf(stderr, "mm search-bench: --clock expects wall or cpu, got '%s'\n",
                     clock.c_str());
        return 2;
      }
      out.cpu_clock = clock == "cpu";
    } else if (a == "--approx-trees") {
      if (!number(i, a, 1, 64, v)) return 2;
      out.options.approx_trees = static_cast<int>(v);
    } else if (a == "--approx-checks") {
      if (!number(i, a, 1, 1e9, v)) return 2;
      out.options.approx_checks = static_cast<int>(v);
    } else if (a == "--eps") {
      if (!number(i, a, 0, 1e6, v)) return 2;
      out.options.kdtree_eps = static_cast<float>(v);
    } else if (a == "--no-flann-reference") {
      out.flann_reference = false;
    } else if (a == "--batch") {
      out.batch = true;
    } else if (a == "--quiet") {
      out.quiet = true;
    } else {
      std::fprintf(stderr, "mm search-bench: unknown or incomplete argument '%s'\n\n%s", a.c_str(),
                   kUsage);
      return 2;
    }
  }
  if (out.db_path.empty() == !out.synthetic) {
    std::fprintf(stderr, "mm search-bench: give exactly one of --db FILE or --synthetic\n\n%s",
                 kUsage);
    return 2;
  }
  // brute and brute-simd are the baselines of the speed-up columns: always run, first.
  std::vector<std::string> methods = {"brute", "brute-simd"};
  std::vector<std::string> asked = out.methods;
  if (asked.empty()) {
    for (std::string_view name : search_method_names()) asked.emplace_back(name);
  }
  for (const std::string& name : asked) {
    const auto known = search_method_names();
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::fprintf(stderr, "mm search-bench: unknown method '%s' (known:", name.c_str());
      for (std::string_view k : known)
        std::fprintf(stderr, " %.*s", static_cast<int>(k.size()), k.data());
      std::fprintf(stderr, ")\n");
      return 2;
    }
    if (std::find(methods.begin(), methods.end(), name) == methods.end()) methods.push_back(name);
  }
  out.methods = methods;
  return -1;
}

// Latency and quality of one method over all queries.
struct MethodReport {
  std::string name;
  double build_ms = 0;
  size_t memory_bytes = 0;
  double median_us = 0;
  double p99_us = 0;
  double mean_us = 0;
  double exact_match_rate = 0;
  double cost_ratio = 0;
  double speedup_brute = 0;
  double speedup_brute_simd = 0;
  std::vector<SearchResult> results;
};

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

// Microseconds on the wall clock or on this thread's CPU clock.
double now_us(bool cpu_clock) {
  if (cpu_clock) {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
  }
  return std::chrono::duration<double, std::micro>(Clock::now().time_since_epoch()).count();
}

bool same_cost(float a, float b) {
  if (a == b) return true;
  return std::fabs(a - b) <= 1e-5f * std::max(std::fabs(a), std::fabs(b));
}

// Progress on a terminal: one line, rewritten at most every 100 ms.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled && isatty(fileno(stderr))) {}
  void show(const std::string& what, int done, int total) {
    if (!enabled_) return;
    const auto now = Clock::now();
    if (done != 0 && done != total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    std::fprintf(stderr, "\r\033[K  %s %d/%d", what.c_str(), done, total);
    std::fflush(stderr);
  }
  void clear() {
    if (enabled_) std::fprintf(stderr, "\r\033[K");
  }

 private:
  bool enabled_;
  Clock::time_point last_{};
};

// One method under test: its report, how to run query i, and each query's fastest time so far.
struct TimedMethod {
  MethodReport report;
  std::function<SearchResult(int)> search;
  std::vector<double> times;
};

// Runs every query once through `method`, keeping each query's fastest time. A warm-up comes
// first: the passes of the other methods have evicted this one's structure from the caches.
void time_pass(TimedMethod& method, int count, bool cpu_clock, Progress& progress,
               const std::string& stage) {
  const int warmup = std::min(count, 64);
  for (int i = 0; i < warmup; ++i) {
    volatile float sink = method.search(i).cost;
    (void)sink;
  }
  method.times.resize(static_cast<size_t>(count), std::numeric_limits<double>::infinity());
  method.report.results.resize(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double start = now_us(cpu_clock);
    method.report.results[static_cast<size_t>(i)] = method.search(i);
    const double elapsed = now_us(cpu_clock) - start;
    method.times[static_cast<size_t>(i)] = std::min(method.times[static_cast<size_t>(i)], elapsed);
    if ((i & 63) == 0) progress.show(stage, i, count);
  }
  progress.clear();
}

// The report's latency fields from the fastest time of every query.
void summarize_times(TimedMethod& method) {
  MethodReport& report = method.report;
  report.median_us = percentile(method.times, 0.5);
  report.p99_us = percentile(method.times, 0.99);
  double sum = 0;
  for (double t : method.times) sum += t;
  report.mean_us = sum / static_cast<double>(method.times.size());
}

// How crowded each query's neighbourhood is: the share of the candidates (searchable rows that
// pass the tag filter) whose squared distance is within `factor` times the nearest one's. An
// exact method must rule out every row below the best cost, and the more rows lie just above it
// the less a bound can skip: when a large share lies within 1.5x, no exact structure can be
// much faster than a scan. The play rules are left out: this describes the data, not a method.
struct Neighbourhood {
  static constexpr double kFactors[2] = {1.2, 1.5};
  std::vector<double> shares[2];  // per factor: one share per query
};

Neighbourhood measure_neighbourhood(const SearchInput& input, const NoisyQueries& queries,
                                    uint64_t include_tags, uint64_t exclude_tags,
                                    Progress& progress) {
  std::vector<const float*> rows;
  for (int f = 0; f < input.frame_count(); ++f) {
    const uint64_t tags =
        input.clips[static_cast<size_t>(input.frame_clip[static_cast<size_t>(f)])].tags;
    if (input.searchable[static_cast<size_t>(f)] && (tags & include_tags) == include_tags &&
        (tags & exclude_tags) == 0) {
      rows.push_back(input.features.data() + static_cast<size_t>(f) * input.dims);
    }
  }
  Neighbourhood out;
  if (rows.empty()) return out;
  const search_kernels::RowDistanceFn distance = search_kernels::row_distance();
  std::vector<float> distances(rows.size());
  for (int i = 0; i < queries.count(); ++i) {
    if ((i & 63) == 0) progress.show("neighbourhoods", i, queries.count());
    const float* query = queries.query(i).data();
    float nearest = std::numeric_limits<float>::infinity();
    for (size_t r = 0; r < rows.size(); ++r) {
      distances[r] = distance(query, rows[r], input.dims);
      nearest = std::min(nearest, distances[r]);
    }
    for (int k = 0; k < 2; ++k) {
      const auto limit = static_cast<float>(nearest * Neighbourhood::kFactors[k]);
      const auto within =
          std::count_if(distances.begin(), distances.end(), [&](float d) { return d <= limit; });
      out.shares[k].push_back(static_cast<double>(within) / static_cast<double>(rows.size()));
    }
  }
  progress.clear();
  return out;
}

int run_search_bench(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;

  // The data: a database file or synthetic rows.
  Database database;
  SyntheticSearchData synthetic;
  SearchInput input;
  std::string source;
  if (arguments.synthetic) {
    SyntheticSearchSpec spec;
    spec.clip_count = 600;
    synthetic = make_synthetic_search_data(spec);
    input = synthetic.input();
    source = "synthetic (600 clips)";
  } else {
    auto loaded = load_database(arguments.db_path);
    if (!loaded) {
      std::fprintf(stderr, "mm search-bench: %s\n", loaded.message().c_str());
      return 1;
    }
    database = std::move(loaded.value());
    input = search_input(database);
    source = arguments.db_path;
  }
  if (Status valid = input.validate(); !valid) {
    std::fprintf(stderr, "mm search-bench: %s\n", valid.message().c_str());
    return 1;
  }
  // Tag names to masks (the database's tag table); synthetic data has no names.
  uint64_t include_tags = 0;
  uint64_t exclude_tags = 0;
  for (const auto* names : {&arguments.include, &arguments.exclude}) {
    for (const std::string& name : *names) {
      const std::string one[] = {name};
      const uint64_t bit = database.tag_mask(one);
      if (bit == 0) {
        std::fprintf(stderr, "mm search-bench: the database has no tag '%s'\n", name.c_str());
        return 2;
      }
      (names == &arguments.include ? include_tags : exclude_tags) |= bit;
    }
  }
  const int candidates =
      static_cast<int>(std::count(input.searchable.begin(), input.searchable.end(), 1));
  const NoisyQueries queries =
      make_noisy_queries(input, arguments.queries, arguments.noise, arguments.seed);
  if (queries.count() == 0) {
    std::fprintf(stderr, "mm search-bench: the database has no searchable frame\n");
    return 1;
  }
  std::vector<SearchConstraints> constraints(static_cast<size_t>(queries.count()));
  for (int i = 0; i < queries.count(); ++i) {
    SearchConstraints& c = constraints[static_cast<size_t>(i)];
    if (arguments.playing) {
      c.current_frame = queries.source_frames[static_cast<size_t>(i)];
      c.window_frames = arguments.window;
      c.transition_cost = arguments.transition_cost;
    }
    c.include_tags = include_tags;
    c.exclude_tags = exclude_tags;
  }

  std::printf(
      "search-bench: %s\n  %d frames, %d candidates, %d dims; %d queries, noise %g, %s; "
      "scan kernel %s; %s clock, fastest of %d run%s per query (rounds over all methods)\n",
      source.c_str(), input.frame_count(), candidates, input.dims, queries.count(),
      static_cast<double>(arguments.noise),
      arguments.playing ? "playing the source frame" : "nothing playing",
      search_kernels::scan_blocks_isa(), arguments.cpu_clock ? "thread CPU" : "wall",
      arguments.repeat, arguments.repeat == 1 ? "" : "s");

  // Every structure is built first (timed), then the queries run in `repeat` rounds, each
  // round one pass per method: a slow spell of a shared machine then hits every method alike,
  // and each query keeps its fastest run.
  Progress progress(!arguments.quiet);
  std::vector<std::unique_ptr<Searcher>> searchers;
  std::vector<TimedMethod> methods;
  for (const std::string& name : arguments.methods) {
    TimedMethod method;
    method.report.name = name;
    progress.show(name + ": building", 0, 1);
    const auto build_start = Clock::now();
    auto made = make_searcher(name, input, arguments.options);
    method.report.build_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - build_start).count();
    progress.clear();
    if (!made) {
      std::fprintf(stderr, "mm search-bench: %s\n", made.message().c_str());
      return 1;
    }
    const Searcher* searcher = made.value().get();
    searchers.push_back(std::move(made.value()));
    method.report.memory_bytes = searcher->memory_bytes();
    method.search = [searcher, &queries, &constraints](int i) {
      return searcher->search(queries.query(i), constraints[static_cast<size_t>(i)]);
    };
    methods.push_back(std::move(method));
  }
  // The reference row: FLANN's exact single tree as shipped (raw columns, FLANN's L2, its
  // default leaf size, no constraints), on the same queries. It calibrates this machine against
  // other measurements of plain FLANN; it is not a method (it cannot apply the rules).
  const bool unconstrained = !arguments.playing && include_tags == 0 && exclude_tags == 0;
  std::vector<float> plain_rows;
  std::vector<int> plain_row_frame;
  std::unique_ptr<flann::KDTreeSingleIndex<flann::L2<float>>> plain_index;
  if (unconstrained && arguments.flann_reference) {
    TimedMethod method;
    method.report.name = "flann-plain";
    progress.show(method.report.name + ": building", 0, 1);
    for (int f = 0; f < input.frame_count(); ++f) {
      if (!input.searchable[static_cast<size_t>(f)]) continue;
      const float* row = input.features.data() + static_cast<size_t>(f) * input.dims;
      plain_rows.insert(plain_rows.end(), row, row + input.dims);
      plain_row_frame.push_back(f);
    }
    const auto build_start = Clock::now();
    plain_index = std::make_unique<flann::KDTreeSingleIndex<flann::L2<float>>>(
        flann::Matrix<float>(plain_rows.data(), plain_row_frame.size(),
                             static_cast<size_t>(input.dims)),
        flann::KDTreeSingleIndexParams());
    plain_index->buildIndex();
    method.report.build_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - build_start).count();
    progress.clear();
    method.report.memory_bytes =
        plain_rows.size() * sizeof(float) * 2 + static_cast<size_t>(plain_index->usedMemory());
    const auto* index = plain_index.get();
    method.search = [index, &plain_row_frame, &queries, &constraints](int i) {
      int nearest = -1;
      float distance = std::numeric_limits<float>::infinity();
      flann::Matrix<int> indices(&nearest, 1, 1);
      flann::Matrix<float> distances(&distance, 1, 1);
      const std::span<const float> query = queries.query(i);
      index->knnSearch(flann::Matrix<float>(const_cast<float*>(query.data()), 1, query.size()),
                       indices, distances, 1, flann::SearchParams(flann::FLANN_CHECKS_UNLIMITED));
      SearchResult result;
      if (nearest >= 0) {
        result.frame = plain_row_frame[static_cast<size_t>(nearest)];
        result.cost = distance + constraints[static_cast<size_t>(i)].transition_cost;
      }
      return result;
    };
    methods.push_back(std::move(method));
  }
  for (int round = 0; round < arguments.repeat; ++round) {
    for (TimedMethod& method : methods) {
      std::string stage = method.report.name + ": queries";
      if (arguments.repeat > 1)
        stage += ", round " + std::to_string(round + 1) + "/" + std::to_string(arguments.repeat);
      time_pass(method, queries.count(), arguments.cpu_clock, progress, stage);
    }
  }
  std::vector<MethodReport> reports;
  for (TimedMethod& method : methods) {
    summarize_times(method);
    reports.push_back(std::move(method.report));
  }

  // Quality against brute (reports[0]) and speed-ups over the baselines (reports[0], [1]).
  const MethodReport& brute = reports[0];
  const MethodReport& brute_simd = reports[1];
  for (MethodReport& r : reports) {
    int exact = 0;
    double ratio_sum = 0;
    int ratio_count = 0;
    for (size_t i = 0; i < r.results.size(); ++i) {
      const float expected = brute.results[i].cost;
      const float got = r.results[i].cost;
      exact += same_cost(got, expected);
      if (std::isfinite(expected) && std::isfinite(got) && expected > 0) {
        ratio_sum += static_cast<double>(got) / expected;
        ++ratio_count;
      } else if (same_cost(got, expected)) {
        ratio_sum += 1.0;
        ++ratio_count;
      }
    }
    r.exact_match_rate = static_cast<double>(exact) / static_cast<double>(r.results.size());
    r.cost_ratio = ratio_count ? ratio_sum / ratio_count : 1.0;
    r.speedup_brute = brute.median_us / r.median_us;
    r.speedup_brute_simd = brute_simd.median_us / r.median_us;
  }

  std::printf("\n%-11s %10s %11s %10s %10s %8s %10s %9s %11s\n", "method", "build ms", "memory",
              "median us", "p99 us", "exact", "cost ratio", "x brute", "x brute-simd");
  for (const MethodReport& r : reports) {
    std::printf("%-11s %10.1f %11s %10.2f %10.2f %8.4f %10.5f %9.1f %11.2f\n", r.name.c_str(),
                r.build_ms, format_bytes(r.memory_bytes).c_str(), r.median_us, r.p99_us,
                r.exact_match_rate, r.cost_ratio, r.speedup_brute, r.speedup_brute_simd);
  }

  const Neighbourhood neighbourhood =
      measure_neighbourhood(input, queries, include_tags, exclude_tags, progress);
  if (!neighbourhood.shares[0].empty()) {
    std::printf(
        "\nneighbourhood: share of the candidates within 1.2x / 1.5x of the nearest row's "
        "distance:\n  median %.2f %% / %.2f %%, p90 %.2f %% / %.2f %%, p99 %.2f %% / %.2f %%\n",
        100 * percentile(neighbourhood.shares[0], 0.5),
        100 * percentile(neighbourhood.shares[1], 0.5),
        100 * percentile(neighbourhood.shares[0], 0.9),
        100 * percentile(neighbourhood.shares[1], 0.9),
        100 * percentile(neighbourhood.shares[0], 0.99),
        100 * percentile(neighbourhood.shares[1], 0.99));
  }

  nlohmann::json json;
  if (arguments.batch) {
    // Many characters per call: the same queries in one batch, on one and on two threads.
    std::printf("\nbatched (%d queries per call), microseconds per query:\n", queries.count());
    std::printf("%-11s %10s %10s %8s\n", "method", "1 thread", "2 threads", "speed-up");
    std::vector<SearchResult> results(static_cast<size_t>(queries.count()));
    for (const std::string& name : arguments.methods) {
      auto made = make_searcher(name, input, arguments.options);
      if (!made) return 1;
      double per_query[2] = {0, 0};
      for (int threads = 1; threads <= 2; ++threads) {
        SearchBatchRunner runner(threads);
        runner.run(*made.value(), queries.features, constraints, results);  // warm-up
        const auto start = Clock::now();
        runner.run(*made.value(), queries.features, constraints, results);
        per_query[threads - 1] =
            std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
            queries.count();
      }
      std::printf("%-11s %10.2f %10.2f %8.2f\n", name.c_str(), per_query[0], per_query[1],
                  per_query[0] / per_query[1]);
      json[name]["batch_us_per_query_1_thread"] = per_query[0];
      json[name]["batch_us_per_query_2_threads"] = per_query[1];
    }
  }

  if (!arguments.json_path.empty()) {
    json["run"] = {{"database", source},
                   {"frames", input.frame_count()},
                   {"candidates", candidates},
                   {"dims", input.dims},
                   {"queries", queries.count()},
                   {"noise", arguments.noise},
                   {"seed", arguments.seed},
                   {"playing", arguments.playing},
                   {"repeat", arguments.repeat},
                   {"clock", arguments.cpu_clock ? "thread_cpu" : "wall"},
                   {"scan_kernel", search_kernels::scan_blocks_isa()}};
    for (int k = 0; k < 2; ++k) {
      if (neighbourhood.shares[k].empty()) continue;
      char key[64];
      std::snprintf(key, sizeof key, "share_within_%.1fx_nearest", Neighbourhood::kFactors[k]);
      json["run"][key] = {{"median", percentile(neighbourhood.shares[k], 0.5)},
                          {"p90", percentile(neighbourhood.shares[k], 0.9)},
                          {"p99", percentile(neighbourhood.shares[k], 0.99)}};
    }
    for (const MethodReport& r : reports) {
      nlohmann::json& m = json[r.name];
      m["build_ms"] = r.build_ms;
      m["memory_bytes"] = r.memory_bytes;
      m["median_us"] = r.median_us;
      m["p99_us"] = r.p99_us;
      m["mean_us"] = r.mean_us;
      m["exact_match_rate"] = r.exact_match_rate;
      m["cost_ratio"] = r.cost_ratio;
      m["speedup_vs_brute"] = r.speedup_brute;
      m["speedup_vs_brute_simd"] = r.speedup_brute_simd;
    }
    std::ofstream file(arguments.json_path);
    file << json.dump(2) << "\n";
    if (!file) {
      std::fprintf(stderr, "mm search-bench: could not write %s\n", arguments.json_path.c_str());
      return 1;
    }
  }
  return 0;
}

const bool registered =
    register_command({"search-bench", "benchmark the search structures on a database (headless)",
                      &run_search_bench});

}  // namespace
}  // namespace mm::cli
