// `mm search-bench`: builds every search structure over one database, runs the same noisy
// queries through each, and prints build time, memory, latency percentiles, exactness against
// `brute`, and speed-ups over the brute-force scans measured in the same run. The library's
// methods and the comparison baselines (bench/baselines/) share one interface, so every row is
// measured the same way.
//
// The phases, in order: parse the options, load the data, make the queries, build every
// structure (timed), run the query rounds, compare with the brute-force rows, print the table
// and the neighbourhood statistics, time batched runs (--batch), write the JSON (--json).

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/database/search_input.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/search/kernels.hpp"
#include "mm/search/search.hpp"
#include "mm/search_baselines/baselines.hpp"
#include "mm/search_baselines/synthetic.hpp"

namespace mm::cli {
namespace {

using Clock = std::chrono::steady_clock;

const char* const kDescription =
    R"(Builds each search structure over the database (timed), runs the same queries through every
method and prints, per method: build time, memory, median and p99 latency per query, the rate
of exact matches (same cost as brute within 1e-5 relative), the mean cost ratio to the exact
cost, and the speed-up of the median over brute, over brute-simd and over the fastest
brute-force scan of the run (brute, brute-simd and brute-staged always run as baselines).
Then how crowded the queries' neighbourhoods are: the share of the candidates within 1.2x and
1.5x of the nearest row's distance (median, p90, p99 over the queries). Where a large share lies
that close, an exact search has little to skip and cannot be much faster than a scan.)";

// The brute-force rows every run starts with: the speed-up columns are relative to them.
const std::vector<std::string> kBruteForceRows = {"brute", "brute-simd", "brute-staged"};

struct Arguments {
  std::string db_path;
  bool synthetic = false;
  int synthetic_clips = 600;
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
  BaselineSearchOptions options;
  bool batch = false;
  bool flann_reference = true;
  bool quiet = false;
  int repeat = 1;
  bool cpu_clock = false;
};

// --- options -----------------------------------------------------------------------------------

void add_data_options(CLI::App& app, Arguments& out) {
  app.add_option("--db", out.db_path, "the database (.mmdb, from `mm build`)")->type_name("FILE");
  app.add_flag("--synthetic", out.synthetic, "use generated curve-like data instead (no file)");
  app.add_option("--synthetic-clips", out.synthetic_clips,
                 "clips of generated data with --synthetic (60 to 300 frames each)")
      ->check(integer_in(1, 100'000))
      ->capture_default_str();
  app.add_option("--queries", out.queries, "number of queries")
      ->check(integer_in(1, 10'000'000))
      ->capture_default_str();
  app.add_option("--noise", out.noise, "Gaussian noise added to each query, normalized units")
      ->check(number_in(0, 100))
      ->capture_default_str();
  std::vector<std::string> known(bench_method_names().begin(), bench_method_names().end());
  app.add_option("--methods", out.methods, "comma-separated methods (default: all)")
      ->delimiter(',')
      ->check(CLI::IsMember(known))
      ->type_name("LIST");
  app.add_option("--json", out.json_path, "also write the results as JSON")->type_name("FILE");
  app.add_option("--seed", out.seed, "query seed")
      ->check(integer_in(0, 1'000'000'000'000'000))
      ->capture_default_str();
}

void add_rule_options(CLI::App& app, Arguments& out) {
  app.add_flag("--playing", out.playing,
               "each query plays its source frame (continuation, window, transition cost "
               "apply); by default nothing plays (plain nearest neighbour)");
  app.add_option("--window", out.window, "window of skipped frames when --playing")
      ->check(integer_in(0, 1'000'000))
      ->capture_default_str();
  app.add_option("--transition-cost", out.transition_cost, "transition cost when --playing")
      ->check(number_in(0, 1e9))
      ->capture_default_str();
  app.add_option("--include", out.include, "tags every candidate's clip must carry")
      ->delimiter(',')
      ->type_name("TAGS");
  app.add_option("--exclude", out.exclude, "tags no candidate's clip may carry")
      ->delimiter(',')
      ->type_name("TAGS");
}

void add_structure_options(CLI::App& app, Arguments& out) {
  SearchOptions& o = out.options;
  app.add_option("--leaf-size", o.kdtree_leaf_size, "kdtree leaf size in rows")
      ->check(integer_in(1, 1'000'000))
      ->capture_default_str();
  app.add_option("--boxtree-leaf-size", o.boxtree_leaf_size,
                 "boxtree leaf size in rows, a multiple of 8")
      ->check(integer_in(8, 1'000'000))
      ->capture_default_str();
  app.add_option("--kdtree-group-rows", o.kdtree_group_rows,
                 "rows per k-means group (dense groups get their own tree in their own axes, "
                 "the rest share one; 0 for a single tree)")
      ->check(integer_in(0, 1'000'000'000))
      ->capture_default_str();
  app.add_option("--boxtree-group-rows", o.boxtree_group_rows, "the same for boxtree")
      ->check(integer_in(0, 1'000'000'000))
      ->capture_default_str();
  app.add_option("--approx-group-rows", out.options.approx_group_rows, "the same for approx")
      ->check(integer_in(0, 1'000'000'000))
      ->capture_default_str();
  app.add_flag_callback(
      "--raw-axes", [&o] { o.principal_axes = false; },
      "build the trees over the raw columns instead of the principal axes");
  app.add_option("--approx-trees", out.options.approx_trees, "approx: randomized trees")
      ->check(integer_in(1, 64))
      ->capture_default_str();
  app.add_option("--approx-checks", out.options.approx_checks, "approx: leaf checks per query")
      ->check(integer_in(1, 1'000'000'000))
      ->capture_default_str();
  app.add_option("--eps", o.kdtree_eps, "kdtree-eps: distance within (1 + E) times the best")
      ->check(number_in(0, 1e6))
      ->capture_default_str();
}

void add_run_options(CLI::App& app, Arguments& out) {
  app.add_option("--repeat", out.repeat,
                 "time every query R times and keep its fastest run: R rounds, each one pass "
                 "per method, so that a slow spell of a shared machine hits every method alike")
      ->check(integer_in(1, 1000))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--clock", [&out](const std::string& clock) { out.cpu_clock = clock == "cpu"; },
         "wall time (default) or the thread's CPU time (ignores preemption)")
      ->check(CLI::IsMember({"wall", "cpu"}))
      ->type_name("wall|cpu");
  app.add_flag_callback(
      "--no-flann-reference", [&out] { out.flann_reference = false; },
      "leave out the flann-plain row (FLANN's single tree as shipped: raw columns, no "
      "constraints; shown only when nothing plays and no tag filter is given)");
  app.add_flag("--batch", out.batch, "also time batched queries on 1 and 2 threads");
  app.add_flag("--quiet", out.quiet, "no progress on the terminal");
}

// Parses the arguments; returns an exit code >= 0 when the program should stop (help, error).
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  CLI::App app{"", "mm search-bench"};
  set_up_app(app);
  app.footer(kDescription);  // after the options, so the help starts with the usage line
  add_data_options(app, out);
  add_rule_options(app, out);
  add_structure_options(app, out);
  add_run_options(app, out);
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  if (out.db_path.empty() == !out.synthetic) {
    return usage_error(app, "give exactly one of --db FILE or --synthetic");
  }
  // The brute-force rows are the baselines of the speed-up columns: always run, first.
  std::vector<std::string> methods = kBruteForceRows;
  std::vector<std::string> asked = out.methods;
  if (asked.empty()) asked.assign(bench_method_names().begin(), bench_method_names().end());
  for (const std::string& name : asked) {
    if (std::find(methods.begin(), methods.end(), name) == methods.end()) methods.push_back(name);
  }
  out.methods = methods;
  return -1;
}

// --- measuring ---------------------------------------------------------------------------------

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
  double speedup_best_brute = 0;
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

// One method under test: its report, its structure, and each query's fastest time so far.
struct TimedMethod {
  MethodReport report;
  std::unique_ptr<Searcher> searcher;
  std::vector<double> times;
};

// The data under test: a database file or synthetic rows, seen as a SearchInput.
struct BenchData {
  std::optional<Database> database;
  std::unique_ptr<DatabaseSearchInput> database_input;
  SyntheticSearchData synthetic;
  SearchInput input;
  std::string source;
  int candidates = 0;
  uint64_t include_tags = 0;
  uint64_t exclude_tags = 0;
};

// The queries and the constraints each one runs under.
struct BenchQueries {
  NoisyQueries queries;
  std::vector<SearchConstraints> constraints;
};

// Everything the phases after the measurements read.
struct BenchRun {
  const Arguments& arguments;
  const BenchData& data;
  const BenchQueries& queries;
};

// Tag names to masks (the database's tag table); synthetic data has no names. Returns an exit
// code >= 0 on an unknown tag.
int resolve_tags(const Arguments& arguments, BenchData& data) {
  for (const auto* names : {&arguments.include, &arguments.exclude}) {
    for (const std::string& name : *names) {
      const std::string one[] = {name};
      const uint64_t bit = data.database->tag_mask(one);
      if (bit == 0) {
        std::fprintf(stderr, "mm search-bench: the database has no tag '%s'\n", name.c_str());
        return 2;
      }
      (names == &arguments.include ? data.include_tags : data.exclude_tags) |= bit;
    }
  }
  return -1;
}

// Phase 1: the data. Returns an exit code >= 0 when the program should stop.
int load_data(const Arguments& arguments, BenchData& data) {
  if (arguments.synthetic) {
    SyntheticSearchSpec spec;
    spec.clip_count = arguments.synthetic_clips;
    data.synthetic = make_synthetic_search_data(spec);
    data.input = data.synthetic.input();
    data.source = "synthetic (" + std::to_string(spec.clip_count) + " clips)";
  } else {
    auto loaded = load_database(arguments.db_path);
    if (!loaded) {
      std::fprintf(stderr, "mm search-bench: %s\n", loaded.message().c_str());
      return 1;
    }
    data.database.emplace(std::move(loaded).value());
    data.database_input = std::make_unique<DatabaseSearchInput>(*data.database);
    data.input = data.database_input->input;
    data.source = arguments.db_path;
  }
  if (Status valid = data.input.validate(); !valid) {
    std::fprintf(stderr, "mm search-bench: %s\n", valid.message().c_str());
    return 1;
  }
  data.candidates =
      static_cast<int>(std::count(data.input.searchable.begin(), data.input.searchable.end(), 1));
  return resolve_tags(arguments, data);
}

// Phase 2: the queries. Returns an exit code >= 0 when there is nothing to query.
int make_queries(const Arguments& arguments, const BenchData& data, BenchQueries& out) {
  out.queries = make_noisy_queries(data.input, arguments.queries, arguments.noise, arguments.seed);
  if (out.queries.count() == 0) {
    std::fprintf(stderr, "mm search-bench: the database has no searchable frame\n");
    return 1;
  }
  out.constraints.assign(static_cast<size_t>(out.queries.count()), {});
  for (int i = 0; i < out.queries.count(); ++i) {
    SearchConstraints& c = out.constraints[static_cast<size_t>(i)];
    if (arguments.playing) {
      c.current_frame = out.queries.source_frames[static_cast<size_t>(i)];
      c.window_frames = arguments.window;
      c.transition_cost = arguments.transition_cost;
    }
    c.include_tags = data.include_tags;
    c.exclude_tags = data.exclude_tags;
  }
  return -1;
}

void print_header(const BenchRun& run) {
  const Arguments& a = run.arguments;
  std::printf(
      "search-bench: %s\n  %d frames, %d candidates, %d dims; %d queries, noise %g, %s; "
      "scan kernel %s; %s clock, fastest of %d run%s per query (rounds over all methods)\n",
      run.data.source.c_str(), run.data.input.frame_count(), run.data.candidates,
      run.data.input.dims, run.queries.queries.count(), static_cast<double>(a.noise),
      a.playing ? "playing the source frame" : "nothing playing", search_kernels::scan_blocks_isa(),
      a.cpu_clock ? "thread CPU" : "wall", a.repeat, a.repeat == 1 ? "" : "s");
}

// Builds one structure, timed. `make` returns the searcher or an error.
template <class Make>
int build_method(const std::string& name, Make make, Progress& progress,
                 std::vector<TimedMethod>& methods) {
  TimedMethod method;
  method.report.name = name;
  progress.show(name + ": building", 0, 1);
  const auto build_start = Clock::now();
  auto made = make();
  method.report.build_ms =
      std::chrono::duration<double, std::milli>(Clock::now() - build_start).count();
  progress.clear();
  if (!made) {
    std::fprintf(stderr, "mm search-bench: %s\n", made.message().c_str());
    return 1;
  }
  method.searcher = std::move(made.value());
  method.report.memory_bytes = method.searcher->memory_bytes();
  methods.push_back(std::move(method));
  return -1;
}

// Phase 3: every structure, built first (timed). The flann-plain reference row calibrates this
// machine against other measurements of plain FLANN; it cannot apply the rules, so it only runs
// when nothing plays and no tag filter is given.
int build_methods(const BenchRun& run, Progress& progress, std::vector<TimedMethod>& methods) {
  const Arguments& arguments = run.arguments;
  const SearchInput& input = run.data.input;
  for (const std::string& name : arguments.methods) {
    auto make = [&] { return make_bench_searcher(name, input, arguments.options); };
    if (const int code = build_method(name, make, progress, methods); code >= 0) return code;
  }
  const bool unconstrained =
      !arguments.playing && run.data.include_tags == 0 && run.data.exclude_tags == 0;
  if (unconstrained && arguments.flann_reference) {
    auto make = [&] { return make_flann_plain_searcher(input); };
    if (const int code = build_method("flann-plain", make, progress, methods); code >= 0)
      return code;
  }
  return -1;
}

// Runs every query once through `method`, keeping each query's fastest time. A warm-up comes
// first: the passes of the other methods have evicted this one's structure from the caches.
void time_pass(TimedMethod& method, const BenchQueries& queries, bool cpu_clock, Progress& progress,
               const std::string& stage) {
  const int count = queries.queries.count();
  auto search = [&](int i) {
    return method.searcher->search(queries.queries.query(i),
                                   queries.constraints[static_cast<size_t>(i)]);
  };
  const int warmup = std::min(count, 64);
  for (int i = 0; i < warmup; ++i) {
    volatile float sink = search(i).cost;
    (void)sink;
  }
  method.times.resize(static_cast<size_t>(count), std::numeric_limits<double>::infinity());
  method.report.results.resize(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double start = now_us(cpu_clock);
    method.report.results[static_cast<size_t>(i)] = search(i);
    const double elapsed = now_us(cpu_clock) - start;
    method.times[static_cast<size_t>(i)] = std::min(method.times[static_cast<size_t>(i)], elapsed);
    if ((i & 63) == 0) progress.show(stage, i, count);
  }
  progress.clear();
}

// Phase 4: the queries in `repeat` rounds, each round one pass per method: a slow spell of a
// shared machine then hits every method alike, and each query keeps its fastest run.
void run_rounds(const BenchRun& run, Progress& progress, std::vector<TimedMethod>& methods) {
  const int repeat = run.arguments.repeat;
  for (int round = 0; round < repeat; ++round) {
    for (TimedMethod& method : methods) {
      std::string stage = method.report.name + ": queries";
      if (repeat > 1)
        stage += ", round " + std::to_string(round + 1) + "/" + std::to_string(repeat);
      time_pass(method, run.queries, run.arguments.cpu_clock, progress, stage);
    }
  }
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

// Exact-match rate and mean cost ratio of `r` against the reference answers.
void compare_with_reference(MethodReport& r, const MethodReport& reference) {
  int exact = 0;
  double ratio_sum = 0;
  int ratio_count = 0;
  for (size_t i = 0; i < r.results.size(); ++i) {
    const float expected = reference.results[i].cost;
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
}

// The brute-force row with the lowest median: the fair baseline of every speed-up.
const MethodReport& best_brute_force(const std::vector<MethodReport>& reports) {
  const MethodReport* best = &reports[0];
  for (const MethodReport& r : reports) {
    if (is_brute_force(r.name) && r.median_us < best->median_us) best = &r;
  }
  return *best;
}

// Phase 5: latency summaries, quality against brute and speed-ups over the brute-force rows
// (the first rows, in the order of kBruteForceRows).
std::vector<MethodReport> compare_methods(std::vector<TimedMethod>& methods) {
  std::vector<MethodReport> reports;
  for (TimedMethod& method : methods) {
    summarize_times(method);
    reports.push_back(std::move(method.report));
  }
  const MethodReport& brute = reports[0];
  const MethodReport& brute_simd = reports[1];
  const double best_brute_us = best_brute_force(reports).median_us;
  for (MethodReport& r : reports) {
    compare_with_reference(r, brute);
    r.speedup_brute = brute.median_us / r.median_us;
    r.speedup_brute_simd = brute_simd.median_us / r.median_us;
    r.speedup_best_brute = best_brute_us / r.median_us;
  }
  return reports;
}

void print_table(const std::vector<MethodReport>& reports) {
  std::printf("\n%-12s %10s %11s %10s %10s %8s %10s %9s %12s %12s\n", "method", "build ms",
              "memory", "median us", "p99 us", "exact", "cost ratio", "x brute", "x brute-simd",
              "x best brute");
  for (const MethodReport& r : reports) {
    std::printf("%-12s %10.1f %11s %10.2f %10.2f %8.4f %10.5f %9.1f %12.2f %12.2f\n",
                r.name.c_str(), r.build_ms, format_bytes(r.memory_bytes).c_str(), r.median_us,
                r.p99_us, r.exact_match_rate, r.cost_ratio, r.speedup_brute, r.speedup_brute_simd,
                r.speedup_best_brute);
  }
  std::printf("(x best brute: over %s, the fastest brute-force scan of this run)\n",
              best_brute_force(reports).name.c_str());
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

// The candidate rows of the neighbourhood statistics.
std::vector<const float*> filtered_rows(const BenchData& data) {
  const SearchInput& input = data.input;
  std::vector<const float*> rows;
  for (int f = 0; f < input.frame_count(); ++f) {
    const uint64_t tags =
        input.clips[static_cast<size_t>(input.frame_clip[static_cast<size_t>(f)])].tags;
    if (input.searchable[static_cast<size_t>(f)] &&
        (tags & data.include_tags) == data.include_tags && (tags & data.exclude_tags) == 0) {
      rows.push_back(input.features.data() + static_cast<size_t>(f) * input.dims);
    }
  }
  return rows;
}

// Phase 6: the neighbourhood statistics.
Neighbourhood measure_neighbourhood(const BenchRun& run, Progress& progress) {
  const std::vector<const float*> rows = filtered_rows(run.data);
  const NoisyQueries& queries = run.queries.queries;
  const int dims = run.data.input.dims;
  Neighbourhood out;
  if (rows.empty()) return out;
  const search_kernels::RowDistanceFn distance = search_kernels::row_distance();
  std::vector<float> distances(rows.size());
  for (int i = 0; i < queries.count(); ++i) {
    if ((i & 63) == 0) progress.show("neighbourhoods", i, queries.count());
    const float* query = queries.query(i).data();
    float nearest = std::numeric_limits<float>::infinity();
    for (size_t r = 0; r < rows.size(); ++r) {
      distances[r] = distance(query, rows[r], dims);
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

void print_neighbourhood(const Neighbourhood& n) {
  if (n.shares[0].empty()) return;
  std::printf(
      "\nneighbourhood: share of the candidates within 1.2x / 1.5x of the nearest row's "
      "distance:\n  median %.2f %% / %.2f %%, p90 %.2f %% / %.2f %%, p99 %.2f %% / %.2f %%\n",
      100 * percentile(n.shares[0], 0.5), 100 * percentile(n.shares[1], 0.5),
      100 * percentile(n.shares[0], 0.9), 100 * percentile(n.shares[1], 0.9),
      100 * percentile(n.shares[0], 0.99), 100 * percentile(n.shares[1], 0.99));
}

// Phase 7 (--batch): many characters per call, the same queries in one batch on one and on two
// threads. Adds each method's figures to `json`.
int run_batches(const BenchRun& run, nlohmann::json& json) {
  const BenchQueries& q = run.queries;
  std::printf("\nbatched (%d queries per call), microseconds per query:\n", q.queries.count());
  std::printf("%-12s %10s %10s %8s\n", "method", "1 thread", "2 threads", "speed-up");
  std::vector<SearchResult> results(static_cast<size_t>(q.queries.count()));
  for (const std::string& name : run.arguments.methods) {
    auto made = make_bench_searcher(name, run.data.input, run.arguments.options);
    if (!made) return 1;
    double per_query[2] = {0, 0};
    for (int threads = 1; threads <= 2; ++threads) {
      SearchBatchRunner runner(threads);
      runner.run(*made.value(), q.queries.features, q.constraints, results);  // warm-up
      const auto start = Clock::now();
      runner.run(*made.value(), q.queries.features, q.constraints, results);
      per_query[threads - 1] =
          std::chrono::duration<double, std::micro>(Clock::now() - start).count() /
          q.queries.count();
    }
    std::printf("%-12s %10.2f %10.2f %8.2f\n", name.c_str(), per_query[0], per_query[1],
                per_query[0] / per_query[1]);
    json[name]["batch_us_per_query_1_thread"] = per_query[0];
    json[name]["batch_us_per_query_2_threads"] = per_query[1];
  }
  return -1;
}

// The JSON's "run" object: what was measured, and the neighbourhood statistics.
nlohmann::json run_json(const BenchRun& run, const Neighbourhood& neighbourhood,
                        const std::vector<MethodReport>& reports) {
  const Arguments& a = run.arguments;
  nlohmann::json out = {{"database", run.data.source},
                        {"frames", run.data.input.frame_count()},
                        {"candidates", run.data.candidates},
                        {"dims", run.data.input.dims},
                        {"queries", run.queries.queries.count()},
                        {"noise", a.noise},
                        {"seed", a.seed},
                        {"playing", a.playing},
                        {"repeat", a.repeat},
                        {"clock", a.cpu_clock ? "thread_cpu" : "wall"},
                        {"scan_kernel", search_kernels::scan_blocks_isa()},
                        {"best_brute", best_brute_force(reports).name}};
  for (int k = 0; k < 2; ++k) {
    if (neighbourhood.shares[k].empty()) continue;
    char key[64];
    std::snprintf(key, sizeof key, "share_within_%.1fx_nearest", Neighbourhood::kFactors[k]);
    out[key] = {{"median", percentile(neighbourhood.shares[k], 0.5)},
                {"p90", percentile(neighbourhood.shares[k], 0.9)},
                {"p99", percentile(neighbourhood.shares[k], 0.99)}};
  }
  return out;
}

// Phase 8 (--json): the run and every method's row.
int write_json(const BenchRun& run, const Neighbourhood& neighbourhood,
               const std::vector<MethodReport>& reports, nlohmann::json& json) {
  json["run"] = run_json(run, neighbourhood, reports);
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
    m["speedup_vs_best_brute"] = r.speedup_best_brute;
  }
  const std::string& path = run.arguments.json_path;
  std::ofstream file(path);
  file << json.dump(2) << "\n";
  if (!file) {
    std::fprintf(stderr, "mm search-bench: could not write %s\n", path.c_str());
    return 1;
  }
  return -1;
}

int run_search_bench(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;
  BenchData data;
  if (const int code = load_data(arguments, data); code >= 0) return code;
  BenchQueries queries;
  if (const int code = make_queries(arguments, data, queries); code >= 0) return code;
  const BenchRun run{arguments, data, queries};
  print_header(run);

  Progress progress(!arguments.quiet);
  std::vector<TimedMethod> methods;
  if (const int code = build_methods(run, progress, methods); code >= 0) return code;
  run_rounds(run, progress, methods);
  const std::vector<MethodReport> reports = compare_methods(methods);
  print_table(reports);
  const Neighbourhood neighbourhood = measure_neighbourhood(run, progress);
  print_neighbourhood(neighbourhood);

  nlohmann::json json;
  if (arguments.batch) {
    if (const int code = run_batches(run, json); code >= 0) return code;
  }
  if (!arguments.json_path.empty()) {
    if (const int code = write_json(run, neighbourhood, reports, json); code >= 0) return code;
  }
  return 0;
}

const bool registered =
    register_command({"search-bench", "benchmark the search structures on a database (headless)",
                      &run_search_bench});

}  // namespace
}  // namespace mm::cli
