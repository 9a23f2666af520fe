// `mm crowd-bench`: many controllers over one database at 60 Hz; cost per character and the
// largest crowd one frame holds, on 1 and 2 threads.

#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "controller_options.hpp"
#include "database_summary.hpp"
#include "mm/controller/crowd.hpp"

namespace mm::cli {
namespace {

const char* const kUsage =
    R"(usage: mm crowd-bench --db FILE.mmdb --characters N --seconds S [options]

Updates N character controllers over one shared database at 60 Hz for S seconds of game
time, each with its own varied scripted input (walks, turns, runs, stops, strafes, camera
turns), and prints the update cost per character per frame (mean, p99, the share spent in
search) and the largest crowd a 1/60 s frame holds at that cost, on 1 and on 2 threads (and
on --threads T when it is another count). Every run ends with the same character positions
whatever the thread count; the tool checks that.

options:
  --db FILE          the database (required)
  --characters N     characters (required, 1 to 100000)
  --seconds S        seconds of game time (required, > 0)
  --threads T        also run on T threads (default: only 1 and 2)
  --set NAME=VALUE   a controller setting by name (see mm eval --help); repeatable
  --json FILE        also write the results as JSON
  -h, --help         this text

exit status: 0 fine, 1 bad database or a run that differs between thread counts, 2 bad usage
)";

int usage_error(const std::string& message) {
  std::fprintf(stderr, "mm crowd-bench: %s\n\n%s", message.c_str(), kUsage);
  return 2;
}

int run_crowd_bench(const std::vector<std::string>& args) {
  std::string db_path, json_path;
  CrowdOptions options;
  options.characters = 0;
  options.seconds = 0.0f;
  int extra_threads = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string* { return i + 1 < args.size() ? &args[++i] : nullptr; };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--db" || a == "--json") {
      const std::string* v = value();
      if (!v) return usage_error(a + " needs a file name");
      (a == "--db" ? db_path : json_path) = *v;
    } else if (a == "--characters" || a == "--threads") {
      const std::string* v = value();
      const std::optional<long long> count = v ? parse_count(*v) : std::nullopt;
      if (!count || *count < 1 || *count > 100000) {
        return usage_error(a + " needs a whole number from 1 to 100000");
      }
      (a == "--characters" ? options.characters : extra_threads) = static_cast<int>(*count);
    } else if (a == "--seconds") {
      const std::string* v = value();
      const std::optional<double> s = v ? parse_number(*v) : std::nullopt;
      if (!s || *s <= 0.0 || *s > 3600.0)
        return usage_error("--seconds needs a number in (0, 3600]");
      options.seconds = static_cast<float>(*s);
    } else if (a == "--set") {
      if (Status s = apply_set_option(value(), options.settings); !s) {
        return usage_error(s.message());
      }
    } else {
      return usage_error("unknown argument '" + a + "'");
    }
  }
  if (db_path.empty()) return usage_error("--db is required");
  if (options.characters == 0) return usage_error("--characters is required");
  if (options.seconds == 0.0f) return usage_error("--seconds is required");
  if (Status s = options.settings.validate(); !s) return usage_error(s.message());

  Result<std::shared_ptr<const ControllerDatabase>> shared = load_controller_database(db_path);
  if (!shared) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", shared.message().c_str());
    return 1;
  }
  // Build the searcher before timing anything.
  if (Result<const Searcher*> s = (*shared)->searcher(options.settings.search_method); !s) {
    std::fprintf(stderr, "mm crowd-bench: %s\n", s.message().c_str());
    return 1;
  }

  std::set<int> thread_counts = {1, 2};
  if (extra_threads > 0) thread_counts.insert(extra_threads);
  std::printf("%d characters, %.1f s at 60 Hz (%d frames each)\n", options.characters,
              options.seconds, static_cast<int>(std::ceil(options.seconds * 60.0f)));
  std::printf("%8s %14s %14s %13s %14s %16s\n", "threads", "update us mean", "update us p99",
              "search share", "frame ms mean", "max chars 60 Hz");
  nlohmann::json json;
  json["characters"] = options.characters;
  json["seconds"] = options.seconds;
  std::vector<glm::vec3> reference;
  bool same = true;
  for (int threads : thread_counts) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(*shared, options);
    if (!run) {
      std::fprintf(stderr, "mm crowd-bench: %s\n", run.message().c_str());
      return 1;
    }
    std::printf("%8d %14.2f %14.2f %12.1f%% %14.3f %16d\n", run->threads, run->update_us_mean,
                run->update_us_p99, 100.0 * run->search_share, run->frame_ms_mean,
                run->max_characters_60hz);
    std::fflush(stdout);
    if (reference.empty()) {
      reference = run->final_positions;
    } else {
      same = same && reference == run->final_positions;
    }
    // Built with append: GCC 12 gives a false -Wrestrict on chains of operator+ with literals.
    std::string key = "max_characters_60hz_";
    key.append(std::to_string(threads)).append(threads == 1 ? "_thread" : "_threads");
    json[key] = run->max_characters_60hz;
    json["runs"].push_back({{"threads", run->threads},
                            {"update_us_mean", run->update_us_mean},
                            {"update_us_p99", run->update_us_p99},
                            {"search_share", run->search_share},
                            {"frame_ms_mean", run->frame_ms_mean},
                            {"max_characters_60hz", run->max_characters_60hz}});
    if (threads == 1) {
      json["update_us_mean"] = run->update_us_mean;
      json["update_us_p99"] = run->update_us_p99;
      json["search_share"] = run->search_share;
    }
  }
  json["same_result_every_thread_count"] = same;
  std::printf("final positions %s across thread counts\n", same ? "identical" : "DIFFER");
  if (!json_path.empty()) {
    std::ofstream file(json_path);
    file << json.dump(2) << "\n";
    if (!file) {
      std::fprintf(stderr, "mm crowd-bench: could not write %s\n", json_path.c_str());
      return 1;
    }
  }
  return same ? 0 : 1;
}

const bool registered = register_command(
    {"crowd-bench", "many controllers at 60 Hz: cost per character, crowd size", &run_crowd_bench});

}  // namespace
}  // namespace mm::cli
