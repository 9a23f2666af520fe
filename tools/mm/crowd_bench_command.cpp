// `mm crowd-bench`: many controllers over one database at 60 Hz; cost per character and the
// largest crowd one frame holds, on 1 and 2 threads.

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

struct Arguments {
  std::string db_path;
  std::string json_path;
  std::string world_path;
  CrowdOptions options;
  int extra_threads = 0;
};

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
  app.add_option("--json", out.json_path, "also write the results as JSON")->type_name("FILE");
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  return check_settings(app, out.options.settings);
}

// The JSON of one run, and its figures printed as a table row.
nlohmann::json report_run(const CrowdResult& run) {
  const double ratio = run.update_us_last_window / run.update_us_first_window;
  std::printf("%8d %14.2f %14.2f %12.1f%% %12.1f%% %14.3f %16d %12.2f %12.2f %10.2f\n", run.threads,
              run.update_us_mean, run.update_us_p99, 100.0 * run.search_share,
              100.0 * run.world_share, run.frame_ms_mean, run.max_characters_60hz,
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
          {"max_characters_60hz", run.max_characters_60hz}};
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
  std::printf("%8s %14s %14s %13s %13s %14s %16s %12s %12s %10s\n", "threads", "update us mean",
              "update us p99", "search share", "world share", "frame ms mean", "max chars 60 Hz",
              first.c_str(), last.c_str(), "last/first");
  std::vector<glm::vec3> reference;
  bool same = true;
  for (int threads : thread_counts) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(shared, options);
    if (!run) {
      std::fprintf(stderr, "mm crowd-bench: %s\n", run.message().c_str());
      return std::nullopt;
    }
    json["runs"].push_back(report_run(*run));
    if (reference.empty()) {
      reference = run->final_positions;
    } else {
      same = same && reference == run->final_positions;
    }
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
  std::optional<bool> same = run_thread_counts(*shared, arguments, json);
  if (!same) return 1;
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
