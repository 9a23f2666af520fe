// `mm crowd-bench`: many controllers over one database at 60 Hz; cost per character and the
// largest crowd one frame holds, on 1 and 2 threads.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/crowd.hpp"
#include "mm/programs/shared_options.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/level.hpp"

namespace mm::cli {
namespace {

// The share of the budget the plan holds back by default (CrowdSchedulerSettings::headroom):
// on a quiet machine the 2-thread frames' p99 is about 1.4 times their mean, and the cost model
// undercounts the 2-thread work by a tenth or more (docs/crowd.md, "crowd5" and after), so a
// plan that fills the budget makes its mean frame, not its p99, fit.
constexpr double kDefaultBudgetHeadroom = 0.3;
struct Arguments {
  std::string db_path;
  std::string json_path;
  std::string world_path;
  std::string frames_csv_path;
  bool budget_only = false;
  CrowdOptions options;
  int extra_threads = 0;
  double budget_ms = 0.0;  // 0: none
  double budget_headroom = kDefaultBudgetHeadroom;
  std::vector<float> tier_costs_us;  // empty: calibrated
};

// The full-rate runs beside a budgeted one are this long at most (s of game time): their figures
// are per character, and a full-rate crowd of the budget's size is many times slower than real
// time.
constexpr float kFullRateSecondsBesideBudget = 10.0f;
// The per-tier quality runs' crowd.
constexpr int kQualityCharacters = 16;
constexpr float kQualitySeconds = 20.0f;

// The length of crowd.hpp's comparison windows, whole seconds, for the help and the table.
std::string window_seconds() {
  return std::to_string(clamped_integer<int>(std::round(kCrowdWindowSeconds)));
}

// Parses the arguments into `out`; returns an exit code to stop with, or -1 to go on.
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  const std::string window = window_seconds();
  CLI::App app(
      "Updates N character controllers over one shared database at 60 Hz for S seconds of game "
      "time, each with its own varied scripted input (walks, turns, runs, stops, strafes, camera "
      "turns), and prints the update cost per character per frame (mean, p99, the share spent in "
      "search) and the largest crowd a 1/60 s frame holds at that cost, on 1 and on 2 threads "
      "(and on --threads T when it is another count), with the mean cost over the first and the "
      "last " +
          window +
          " s of game time and their ratio, which a cost creeping up over a long "
          "run raises. Every run ends with the same character positions whatever the thread count; "
          "the tool checks that.",
      "mm crowd-bench");
  set_up_app(app);
  app.footer(
      "exit status: 0 fine, 1 bad database or a run that differs between thread counts, 2 bad "
      "usage");
  app.add_option("--db", out.db_path, "the database")->required()->type_name("FILE");
  app.add_option("--characters", out.options.characters, "characters")
      ->required()
      ->check(integer_in(1, 100000))
      ->type_name("N");
  app.add_option("--seconds", out.options.seconds, "seconds of game time")
      ->required()
      ->check(number_over(0.0, 3600.0))
      ->type_name("S");
  app.add_option("--threads", out.extra_threads, "also run on T threads (default: only 1 and 2)")
      ->check(integer_in(1, 1024))
      ->type_name("T");
  add_set_option(app, out.options.settings);
  app.add_option("--world", out.world_path,
                 "also run the crowd in this level (.gltf or .glb; Bullet, docs/world.md), "
                 "beside the same crowd on flat ground, both starting inside the level's "
                 "bounds: the cost with the world against without, and the world's queries' "
                 "share of it")
      ->type_name("LEVEL");
  app.add_option("--budget-ms", out.budget_ms,
                 "also run the crowd under a frame budget of MS milliseconds for all characters "
                 "together (level of detail, docs/performance.md): tiers by the distance to a "
                 "camera point circling through the crowd, planned for the largest thread count "
                 "of the run; the full-rate runs beside it then last at most 10 s")
      ->check(number_over(0.0, 1000.0))
      ->type_name("MS");
  app.add_option("--budget-headroom", out.budget_headroom,
                 "the share of the budget the plan leaves unspent, for frames dearer than the "
                 "cost model (taken from the tiers below full rate; default " +
                     std::to_string(kDefaultBudgetHeadroom).substr(0, 4) + ")")
      ->check(number_in(0.0, 0.95))
      ->type_name("SHARE");
  app.add_option("--tier-costs-us", out.tier_costs_us,
                 "the budget's cost model: work per character per frame (us) at full, half, "
                 "quarter and move_only; default: measured before the runs")
      ->expected(4)
      ->delimiter(',')
      ->type_name("F,H,Q,M");
  app.add_option("--json", out.json_path, "also write the results as JSON")->type_name("FILE");
  app.add_option("--frames-csv", out.frames_csv_path,
                 "with --budget-ms: also write every steady frame of the budgeted runs as CSV "
                 "(thread count, frame, frame/plan/work ms, updates per tier, move steps, "
                 "searches, transitions, planned us), to find what makes a frame dear")
      ->type_name("FILE");
  app.add_flag("--budget-only", out.budget_only,
               "with --budget-ms: leave out the full-rate runs (their max_characters_60hz "
               "figures), for quicker measurements of the budgeted crowd");
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  return check_settings(app, out.options.settings);
}

// Characters per tier as JSON: tier name to count (the names sort with full first).
nlohmann::json tier_counts_json(const std::array<int, kCrowdTierCount>& counts) {
  nlohmann::json json = nlohmann::json::object();
  for (int t = 0; t < kCrowdTierCount; ++t) {
    json[std::string(crowd_tier_name(static_cast<CrowdTier>(t)))] = counts[static_cast<size_t>(t)];
  }
  return json;
}

// The JSON of one run, and its figures printed as a table row.
nlohmann::json report_run(const CrowdResult& run) {
  const double ratio = run.update_us_last_window / run.update_us_first_window;
  std::printf("%8d %14.2f %14.2f %12.1f%% %12.1f%% %14.3f %13.3f %16d %12.2f %12.2f %10.2f\n",
              run.threads, run.update_us_mean, run.update_us_p99, 100.0 * run.search_share,
              100.0 * run.world_share, run.frame_ms_mean, run.frame_ms_p99, run.max_characters_60hz,
              run.update_us_first_window, run.update_us_last_window, ratio);
  std::fflush(stdout);
  return {{"threads", run.threads},
          {"update_us_mean", run.update_us_mean},
          {"update_us_p99", run.update_us_p99},
          {"update_us_first_window", run.update_us_first_window},
          {"update_us_last_window", run.update_us_last_window},
          {"update_us_window_ratio", ratio},
          {"search_share", run.search_share},
          {"world_share", run.world_share},
          {"frame_ms_mean", run.frame_ms_mean},
          {"frame_ms_p99", run.frame_ms_p99},
          {"tier_counts", tier_counts_json(run.tier_counts)},
          {"full_min", run.full_min},
          {"planned_cost_us_mean", run.planned_cost_us_mean},
          {"plan_ms_mean", run.plan_ms_mean},
          {"steps_ms_mean", run.steps_ms_mean},
          {"sync_ms_mean", run.sync_ms_mean},
          {"work_ms_mean", run.work_ms_mean},
          {"work_ms_p99", run.work_ms_p99},
          {"max_characters_60hz", run.max_characters_60hz}};
}

// Appends the steady frames of a budgeted run to the CSV at `path` (the header first when
// `header`); false when it cannot be written.
bool write_frame_records(const std::string& path, const CrowdResult& run, bool header) {
  std::ofstream file(path, header ? std::ios::trunc : std::ios::app);
  if (header) {
    file << "threads,frame,frame_ms,plan_ms,work_ms,full_updates,half_updates,quarter_updates,"
            "moves,searches,transitions,planned_us\n";
  }
  for (size_t f = 0; f < run.frame_records.size(); ++f) {
    const CrowdFrameRecord& r = run.frame_records[f];
    file << run.threads << ',' << f << ',' << r.frame_ms << ',' << r.plan_ms << ',' << r.work_ms
         << ',' << r.steps[0] << ',' << r.steps[1] << ',' << r.steps[2] << ',' << r.steps[3] << ','
         << r.searches << ',' << r.transitions << ',' << r.planned_us << '\n';
  }
  return static_cast<bool>(file);
}

// Whether a run ends in the reference's poses, exactly.
bool same_poses(const std::vector<Transform>& reference, const CrowdResult& run) {
  if (reference.size() != run.final_poses.size()) return false;
  for (size_t k = 0; k < reference.size(); ++k) {
    const Transform& a = reference[k];
    const Transform& b = run.final_poses[k];
    if (a.translation != b.translation || a.rotation != b.rotation || a.scale != b.scale) {
      return false;
    }
  }
  return true;
}

// Runs the crowd on every thread count into `json`; returns whether every run ended with the
// same positions, or nothing (with the message printed) when a run failed.
std::optional<bool> run_thread_counts(const std::shared_ptr<const ControllerDatabase>& shared,
                                      Arguments& arguments, nlohmann::json& json) {
  CrowdOptions& options = arguments.options;
  std::set<int> thread_counts = {1, 2};
  if (arguments.extra_threads > 0) thread_counts.insert(arguments.extra_threads);
  std::printf("%d characters, %.1f s at 60 Hz (%d frames each)\n", options.characters,
              options.seconds, clamped_integer<int>(std::ceil(options.seconds * 60.0f)));
  // The update cost over the first and the last window of game time, and their ratio: a cost
  // that grows over a long run shows there.
  auto window_label = [](const char* which) {
    std::string label = which;  // appended: see the -Wrestrict note below
    return label.append(window_seconds()).append(" s us");
  };
  const std::string first = window_label("first ");
  const std::string last = window_label("last ");
  std::printf("%8s %14s %14s %13s %13s %14s %13s %16s %12s %12s %10s\n", "threads",
              "update us mean", "update us p99", "search share", "world share", "frame ms mean",
              "frame ms p99", "max chars 60 Hz", first.c_str(), last.c_str(), "last/first");
  std::vector<glm::vec3> reference;
  std::vector<Transform> reference_poses;
  bool same = true;
  for (int threads : thread_counts) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(shared, options);
    if (!run) {
      std::fprintf(stderr, "mm crowd-bench: %s\n", run.message().c_str());
      return std::nullopt;
    }
    json["runs"].push_back(report_run(*run));
    if (options.lod && !arguments.frames_csv_path.empty() &&
        !write_frame_records(arguments.frames_csv_path, *run, reference.empty())) {
      std::fprintf(stderr, "mm crowd-bench: could not write %s\n",
                   arguments.frames_csv_path.c_str());
      return std::nullopt;
    }
    if (options.lod) {
      std::printf(
          "%8s tiers at the end: full %d, half %d, quarter %d, move_only %d; fewest at "
          "full %d; planned %.2f ms of work per frame\n"
          "%8s frame ms: plan %.3f, steps (longest thread) %.3f, the rest (hand-off, waits) "
          "%.3f; work (CPU ms, all threads) mean %.3f, p99 %.3f\n",
          "", run->tier_counts[0], run->tier_counts[1], run->tier_counts[2], run->tier_counts[3],
          run->full_min, run->planned_cost_us_mean * 1e-3, "", run->plan_ms_mean,
          run->steps_ms_mean, run->sync_ms_mean, run->work_ms_mean, run->work_ms_p99);
    }
    if (reference.empty()) {
      reference = run->final_positions;
      reference_poses = std::move(run->final_poses);
    } else {
      same = same && reference == run->final_positions && same_poses(reference_poses, *run);
    }
    // The figures of the run with the most threads.
    json["frame_ms_mean"] = run->frame_ms_mean;
    json["frame_ms_p99"] = run->frame_ms_p99;
    json["tier_counts"] = tier_counts_json(run->tier_counts);
    // Built with append: GCC 12 gives a false -Wrestrict on chains of operator+ with literals.
    std::string key = "max_characters_60hz_";
    key.append(std::to_string(threads)).append(threads == 1 ? "_thread" : "_threads");
    json[key] = run->max_characters_60hz;
    if (threads == 1) {
      json["update_us_mean"] = run->update_us_mean;
      json["update_us_p99"] = run->update_us_p99;
      json["search_share"] = run->search_share;
      json["update_us_first_window"] = run->update_us_first_window;
      json["update_us_last_window"] = run->update_us_last_window;
      json["update_us_window_ratio"] = run->update_us_last_window / run->update_us_first_window;
    }
  }
  return same;
}

// The budget's cost model: given, or measured on this machine now.
std::optional<std::array<float, kCrowdTierCount>> tier_costs(
    const std::shared_ptr<const ControllerDatabase>& shared, const Arguments& arguments) {
  std::array<float, kCrowdTierCount> costs{};
  if (arguments.tier_costs_us.size() == costs.size()) {
    std::copy(arguments.tier_costs_us.begin(), arguments.tier_costs_us.end(), costs.begin());
    return costs;
  }
  std::printf("calibrating the cost model (the crowd, 2 s at each tier on %d threads)...\n",
              arguments.options.lod->threads);
  std::fflush(stdout);
  Result<std::array<float, kCrowdTierCount>> measured =
      calibrate_crowd_tiers(shared, arguments.options, arguments.options.characters);
  if (!measured) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", measured.message().c_str());
    return std::nullopt;
  }
  return *measured;
}

// The ground metrics of each tier's displayed poses, printed and as JSON.
std::optional<nlohmann::json> report_tier_quality(
    const std::shared_ptr<const ControllerDatabase>& shared, const CrowdOptions& options) {
  Result<std::array<CrowdTierQuality, kCrowdTierCount>> quality =
      crowd_tier_quality(shared, options, kQualityCharacters, kQualitySeconds);
  if (!quality) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", quality.message().c_str());
    return std::nullopt;
  }
  std::printf("quality per tier (%d characters, %.0f s, all at the tier, displayed poses):\n",
              kQualityCharacters, static_cast<double>(kQualitySeconds));
  std::printf("%10s %18s %17s %16s %16s %18s\n", "tier", "geom skate cm/s", "penetration cm",
              "penetration max", "toe clear. min", "hips vert acc p99");
  nlohmann::json json = nlohmann::json::object();
  for (int t = 0; t < kCrowdTierCount; ++t) {
    const CrowdTierQuality& q = (*quality)[static_cast<size_t>(t)];
    const std::string name(crowd_tier_name(static_cast<CrowdTier>(t)));
    std::printf("%10s %18.3f %17.3f %16.3f %16.3f %18.2f\n", name.c_str(),
                q.foot_skate_geom_cm_s_mean, q.foot_penetration_cm_mean, q.foot_penetration_cm_max,
                q.toe_clearance_cm_min, q.hips_vertical_accel_p99_m_s2);
    json[name] = {{"foot_skate_geom_cm_s_mean", q.foot_skate_geom_cm_s_mean},
                  {"foot_penetration_cm_mean", q.foot_penetration_cm_mean},
                  {"foot_penetration_cm_max", q.foot_penetration_cm_max},
                  {"toe_clearance_cm_min", q.toe_clearance_cm_min},
                  {"hips_vertical_accel_p99_m_s2", q.hips_vertical_accel_p99_m_s2}};
  }
  return json;
}

// The crowd under --budget-ms on every thread count, planned for the most of them, into `json`;
// returns whether every run ended with the same poses, or nothing when a run failed.
std::optional<bool> run_budget(const std::shared_ptr<const ControllerDatabase>& shared,
                               const Arguments& arguments, nlohmann::json& json) {
  Arguments budgeted = arguments;
  CrowdSchedulerSettings lod;
  lod.budget_ms = static_cast<float>(arguments.budget_ms);
  lod.threads = std::max(2, arguments.extra_threads);
  lod.headroom = static_cast<float>(arguments.budget_headroom);
  budgeted.options.lod = lod;
  const std::optional<std::array<float, kCrowdTierCount>> costs = tier_costs(shared, budgeted);
  if (!costs) return std::nullopt;
  lod.cost_us = *costs;
  budgeted.options.lod = lod;
  if (Status valid = lod.validate(); !valid) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", valid.message().c_str());
    return std::nullopt;
  }
  nlohmann::json costs_json = nlohmann::json::object();
  for (int t = 0; t < kCrowdTierCount; ++t) {
    costs_json[std::string(crowd_tier_name(static_cast<CrowdTier>(t)))] =
        (*costs)[static_cast<size_t>(t)];
  }
  std::printf(
      "under a budget of %.2f ms per frame, planned for %d threads, %.0f%% of it held back; cost "
      "model (us per character per frame): full %.2f, half %.2f, quarter %.2f, move_only %.2f\n",
      arguments.budget_ms, lod.threads, 100.0 * arguments.budget_headroom,
      static_cast<double>((*costs)[0]), static_cast<double>((*costs)[1]),
      static_cast<double>((*costs)[2]), static_cast<double>((*costs)[3]));
  nlohmann::json runs;
  const std::optional<bool> same = run_thread_counts(shared, budgeted, runs);
  if (!same) return std::nullopt;
  json["budget_ms"] = arguments.budget_ms;
  json["budget_threads"] = lod.threads;
  json["budget_headroom"] = arguments.budget_headroom;
  json["tier_cost_us"] = costs_json;
  json["budget_runs"] = runs["runs"];
  for (const char* key : {"frame_ms_mean", "frame_ms_p99", "tier_counts"}) json[key] = runs[key];
  json["full_min"] = runs["runs"].back()["full_min"];
  std::optional<nlohmann::json> quality = report_tier_quality(shared, budgeted.options);
  if (!quality) return std::nullopt;
  json["tier_quality"] = *quality;
  return same;
}

// The level's bounds in x and z, 2 m in from each side: where a crowd starts in it.
glm::vec4 inner_area(const Level& level) {
  glm::dvec2 low(1e300), high(-1e300);
  for (const glm::vec3& p : level.positions) {
    const glm::dvec3 w = level.origin + glm::dvec3(p);
    low = glm::min(low, glm::dvec2(w.x, w.z));
    high = glm::max(high, glm::dvec2(w.x, w.z));
  }
  return glm::vec4(low.x + 2.0, low.y + 2.0, high.x - 2.0, high.y - 2.0);
}

int run_crowd_bench(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;

  Result<std::shared_ptr<const ControllerDatabase>> shared =
      load_controller_database(arguments.db_path);
  if (!shared) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", shared.message().c_str());
    return 1;
  }
  // Build the searcher before timing anything.
  if (Result<const Searcher*> s = (*shared)->searcher(arguments.options.settings.search_method);
      !s) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", s.message().c_str());
    return 1;
  }

  nlohmann::json json;
  json["characters"] = arguments.options.characters;
  json["seconds"] = arguments.options.seconds;
  std::optional<BulletWorld> world;
  if (!arguments.world_path.empty()) {
    Result<Level> level = load_level(arguments.world_path);
    Result<BulletWorld> made =
        level ? BulletWorld::create(*level) : Result<BulletWorld>(level.error());
    if (!made) {
      std::fprintf(stderr, "mm crowd-bench: %s\n", made.message().c_str());
      return 1;
    }
    world.emplace(std::move(made).value());
    arguments.options.start_area = inner_area(*level);
  }
  // Beside a budget, the full-rate runs are short (kFullRateSecondsBesideBudget).
  Arguments full_rate = arguments;
  std::optional<bool> same = true;
  if (!(arguments.budget_only && arguments.budget_ms > 0.0)) {
    if (arguments.budget_ms > 0.0) {
      full_rate.options.seconds = std::min(arguments.options.seconds, kFullRateSecondsBesideBudget);
      std::printf("at full rate:\n");
    }
    same = run_thread_counts(*shared, full_rate, json);
  }
  if (!same) return 1;
  if (arguments.budget_ms > 0.0) {
    const std::optional<bool> same_budgeted = run_budget(*shared, arguments, json);
    if (!same_budgeted) return 1;
    same = *same && *same_budgeted;
  }
  if (world) {
    // The same crowd in the level: its cost against the flat runs above (1 thread).
    std::printf("in %s (Bullet):\n", arguments.world_path.c_str());
    nlohmann::json flat = json;
    arguments.options.world = &*world;
    nlohmann::json in_world;
    const std::optional<bool> same_in_world = run_thread_counts(*shared, arguments, in_world);
    if (!same_in_world) return 1;
    same = *same && *same_in_world;
    json["world"] = arguments.world_path;
    json["world_runs"] = in_world["runs"];
    json["world_update_us_mean"] = in_world["update_us_mean"];
    json["world_share"] = in_world["runs"][0]["world_share"];
    json["world_cost_ratio"] =
        in_world["update_us_mean"].get<double>() / flat["update_us_mean"].get<double>();
    std::printf(
        "update cost in the world / on flat ground (1 thread): %.2f; the world's queries "
        "%.1f%% of it\n",
        json["world_cost_ratio"].get<double>(), 100.0 * json["world_share"].get<double>());
  }
  json["same_result_every_thread_count"] = *same;
  std::printf("final positions %s across thread counts\n", *same ? "identical" : "DIFFER");
  if (!arguments.json_path.empty()) {
    std::ofstream file(arguments.json_path);
    file << json.dump(2) << "\n";
    if (!file) {
      std::fprintf(stderr, "mm crowd-bench: could not write %s\n", arguments.json_path.c_str());
      return 1;
    }
  }
  return *same ? 0 : 1;
}

const bool registered = register_command(
    {"crowd-bench", "many controllers at 60 Hz: cost per character, crowd size", &run_crowd_bench});

}  // namespace
}  // namespace mm::cli
