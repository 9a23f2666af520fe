// `mm eval`: runs a controller on scripted input, headless, and prints its quality metrics
// (definitions in controller/include/mm/programs/evaluation.hpp).

#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/programs/evaluation_json.hpp"
#include "mm/programs/number_parsing.hpp"
#include "mm/programs/shared_options.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/level.hpp"

namespace mm::cli {
namespace {

struct Arguments {
  std::string db;
  std::vector<std::string> scripts;
  EvaluationOptions options;
  std::string json_path;
  std::string dump_path;
  std::string start;  // "X,Z", validated by the parser
  std::string world_path;
  std::string style;  // --style: the style of every script line without one
};

// A sample's clip name and frame within it (empty and -1 when none played).
std::pair<std::string, int> clip_and_frame(const TransitionSample& s, const Database& db) {
  if (s.clip < 0 || static_cast<size_t>(s.clip) >= db.clips().size()) return {"", -1};
  const ClipRange& c = db.clips()[static_cast<size_t>(s.clip)];
  return {c.name, s.frame - c.start};
}

// `--transition-report`: the largest accelerations transition_accel_ratio is taken over, with
// the joint, the time and what played.
void print_transition_samples(const std::string& name, const EvaluationResult& result,
                              const Database& db) {
  const EvaluationMetrics& m = result.metrics;
  std::printf(
      "largest joint accelerations in the transitions' windows%s%s (and as a multiple of "
      "the database's p99, %.1f m/s^2):\n",
      name.empty() ? "" : ", ", name.c_str(), m.database_accel_p99);
  for (const TransitionSample& s : result.transition_samples) {
    const auto [clip, clip_frame] = clip_and_frame(s, db);
    std::printf("  t %9.4f s  %-16s %9.1f m/s^2  %6.2f x  windows %d  clip %s frame %d\n", s.t,
                db.skeleton().name(s.joint).c_str(), s.acceleration,
                m.database_accel_p99 > 0.0 ? s.acceleration / m.database_accel_p99 : 0.0, s.windows,
                clip.empty() ? "-" : clip.c_str(), clip_frame);
  }
}

nlohmann::json transition_samples_json(const EvaluationResult& result, const Database& db) {
  nlohmann::json list = nlohmann::json::array();
  for (const TransitionSample& s : result.transition_samples) {
    const auto [clip, clip_frame] = clip_and_frame(s, db);
    list.push_back({{"t", s.t},
                    {"joint", db.skeleton().name(s.joint)},
                    {"m_s2", s.acceleration},
                    {"windows", s.windows},
                    {"clip", clip},
                    {"clip_frame", clip_frame}});
  }
  return list;
}

// --start farther than this (m) is a typo, not a world: even a planet is smaller.
constexpr double kMaxStartMetres = 1e7;

// Parses the arguments into `out`; returns an exit code to stop with, or -1 to go on.
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  CLI::App app(
      "Runs one character controller on a script of timed stick and button states (see "
      "controller/include/mm/controller/script.hpp; examples in scripts/input/), headless, at a "
      "fixed dt, and prints its quality metrics. Several --script options print one row per "
      "script. Runs are bounded: script times at most " +
          std::to_string(static_cast<int>(kMaxScriptSeconds)) + " s, at most " +
          std::to_string(kMaxRunFrames) +
          " updates a run (8 hours at 1/144 s); a longer run is refused before it starts. "
          "Memory does not grow with the run's length, --dump included (rows are written as "
          "they are made).",
      "mm eval");
  set_up_app(app);
  app.footer("exit status: 0 fine, 1 bad database or script, 2 bad usage");
  app.add_option("--db", out.db, "the database")->required()->type_name("FILE");
  app.add_option("--style", out.style,
                 "request this style on every script line without a style=NAME (an unknown "
                 "style is an error listing the database's styles)")
      ->type_name("NAME");
  app.add_option("--script", out.scripts, "the input script; repeatable")
      ->required()
      ->type_name("FILE")
      ->allow_extra_args(false);
  add_dt_option(app, out.options.dt, "default 1/60");
  add_ik_option(app, out.options.settings);
  add_set_option(app, out.options.settings);
  app.add_option("--start", out.start,
                 "where the character stands at t = 0, world X and Z in metres (default 0,0); "
                 "the dump's positions include it")
      ->type_name("X,Z")
      ->check(number_pair_in("X,Z", -kMaxStartMetres, kMaxStartMetres));
  app.add_option("--world", out.world_path,
                 "a level (.gltf or .glb, Y up, metres; every mesh is static collision geometry) "
                 "the controller runs in, through Bullet (docs/world.md); the ground metrics are "
                 "measured against its surfaces")
      ->type_name("LEVEL");
  app.add_option("--json", out.json_path,
                 "also write the metrics as JSON (one script: the keys at the top level; "
                 "several: a list under \"runs\")")
      ->type_name("FILE");
  app.add_option("--dump", out.dump_path,
                 "one CSV row per frame (one script only): t, simulation, root, desired motion, "
                 "transition, contacts, the playing clip (index) and database frame, every joint's "
                 "global position, then the ground under the toes and the hips, the wall depth (m) "
                 "and whether the simulation was stuck")
      ->type_name("FILE");
  app.add_option("--transition-report", out.options.transition_report,
                 "list the N largest joint accelerations transition_accel_ratio is taken over "
                 "(time, joint, m/s^2, times the database's p99, the clip playing); in the JSON "
                 "as transition_accel_largest")
      ->type_name("N")
      ->check(CLI::Range(0, kMaxTransitionReport));
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  if (const auto start = parse_number_pair(out.start)) {
    out.options.start = glm::dvec2(start->first, start->second);
  }
  if (!out.dump_path.empty() && out.scripts.size() != 1) {
    return usage_error(app, "--dump takes one script");
  }
  return check_settings(app, out.options.settings);
}

void print_table_header() {
  std::printf("%-22s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s\n", "script", "skate",
              "skate95", "rootsim", "rs_max", "facing", "speed_s", "head_s", "stand_r", "stand_f",
              "trans/s", "accel", "accel=", "search", "update");
  std::printf("%-22s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s\n", "", "cm/s", "cm/s",
              "cm", "cm", "deg", "s", "s", "cm/s", "cm/s", "", "ratio", "ratio", "us", "us");
}

void print_table_row(const std::string& name, const EvaluationMetrics& m) {
  std::printf(
      "%-22s %7.2f %7.2f %7.2f %7.2f %7.2f %7.3f %7.3f %7.2f %7.2f %7.2f %7.3f %7.3f %7.2f "
      "%7.2f\n",
      name.c_str(), m.foot_skate_cm_s_mean, m.foot_skate_cm_s_p95, m.root_sim_distance_cm_mean,
      m.root_sim_distance_cm_max, m.facing_error_deg_mean, m.speed_response_s, m.heading_response_s,
      m.stand_root_speed_cm_s_mean, m.stand_foot_speed_cm_s_mean, m.transitions_per_s,
      m.transition_accel_ratio, m.transition_accel_ratio_same_sampling, m.search_us_mean,
      m.update_us_mean);
}

// The body metrics of issue 17, a second table: the first has no room left.
void print_body_table_header() {
  std::printf("%-22s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s\n", "script", "turn99",
              "turnmax", "pivot", "sturns", "unsettl", "sturn_s", "sturn_e", "sturn_r", "strafe",
              "idlehd", "toemin", "geomsk", "geomdat");
  std::printf("%-22s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s\n", "", "deg/s", "deg/s",
              "deg/s", "", "", "s", "deg", "deg/s", "deg", "cm/s", "cm", "cm/s", "cm/s");
}

void print_body_table_row(const std::string& name, const EvaluationMetrics& m) {
  std::printf("%-22s %7.1f %7.1f %7.2f %7d %7d %7.3f %7.2f %7.1f %7.2f %7.3f %7.2f %7.2f %7.2f\n",
              name.c_str(), m.body_turn_rate_deg_s_p99, m.body_turn_rate_deg_s_max,
              m.foot_pivot_deg_s_mean, m.stand_turns, m.stand_turn_unsettled,
              m.stand_turn_response_s, m.stand_turn_final_error_deg_mean,
              m.stand_turn_peak_rate_deg_s_max, m.strafe_chest_error_deg_mean,
              m.idle_head_speed_cm_s_mean, m.toe_height_min_cm, m.ground.foot_skate_geom_cm_s_mean,
              m.foot_skate_geom_data_cm_s_mean);
}

void print_body_metrics(const EvaluationMetrics& m) {
  std::printf("body_turn_rate_deg_s_p99    %10.3f\n", m.body_turn_rate_deg_s_p99);
  std::printf("body_turn_rate_deg_s_max    %10.3f\n", m.body_turn_rate_deg_s_max);
  std::printf("foot_pivot_deg_s_mean       %10.3f   (%d toe frames)\n", m.foot_pivot_deg_s_mean,
              m.foot_pivot_frames);
  std::printf("stand_turns                 %10d\n", m.stand_turns);
  std::printf("stand_turn_unsettled        %10d\n", m.stand_turn_unsettled);
  std::printf("stand_turn_response_s       %10.3f\n", m.stand_turn_response_s);
  std::printf("stand_turn_final_error_deg_mean %6.3f\n", m.stand_turn_final_error_deg_mean);
  std::printf("stand_turn_interrupted      %10d\n", m.stand_turn_interrupted);
  std::printf("stand_turn_final_error_deg_max %7.3f   (turns given %.1f s)\n",
              m.stand_turn_final_error_deg_max, static_cast<double>(kStandTurnJudgeSeconds));
  std::printf("stand_turn_peak_rate_deg_s_max %7.3f\n", m.stand_turn_peak_rate_deg_s_max);
  std::printf("strafe_chest_error_deg_mean %10.3f   (%d strafing frames)\n",
              m.strafe_chest_error_deg_mean, m.strafe_chest_frames);
  std::printf("idle_head_speed_cm_s_mean   %10.3f   (%d idle frames)\n",
              m.idle_head_speed_cm_s_mean, m.idle_head_frames);
  std::printf("toe_height_min_cm           %10.3f\n", m.toe_height_min_cm);
}

// Feet and body against the ground (ground_metrics.hpp).
void print_ground_metrics(const EvaluationMetrics& m) {
  const GroundMetrics& g = m.ground;
  std::printf("foot_skate_geom_cm_s_mean   %10.3f   (%d toe frames; the data's own %.3f)\n",
              g.foot_skate_geom_cm_s_mean, g.foot_skate_geom_frames,
              m.foot_skate_geom_data_cm_s_mean);
  std::printf("toe_clearance_cm_min        %10.3f   (p1 %.3f)\n", g.toe_clearance_cm_min,
              g.toe_clearance_cm_p1);
  std::printf("foot_penetration_cm_mean    %10.3f   (max %.3f)\n", g.foot_penetration_cm_mean,
              g.foot_penetration_cm_max);
  std::printf("foot_float_cm_mean          %10.3f   (the played clips' own %.3f)\n",
              g.foot_float_cm_mean, g.foot_float_data_cm_mean);
  std::printf("hips_height_cm_mean         %10.3f   (std %.3f)\n", g.hips_height_cm_mean,
              g.hips_height_cm_std);
  std::printf("hips_vertical_accel_p99_m_s2 %9.3f\n", g.hips_vertical_accel_p99_m_s2);
  std::printf("knee_overextension_frames   %10d\n", g.knee_overextension_frames);
  std::printf("wall_depth_cm_max           %10.3f\n", g.wall_depth_cm_max);
  std::printf("stuck_s                     %10.3f\n", g.stuck_s);
}

void print_metrics(const EvaluationMetrics& m) {
  if (m.style_requests > 0) {
    std::printf("style_match                 %10.3f   (%d moving frames with a style request)\n",
                m.style_match, m.style_frames);
    std::printf("style_response_s            %10.3f   (%d of %d requests reached; slowest %.3f)\n",
                m.style_response_s, m.style_requests_reached, m.style_requests,
                m.style_response_s_max);
  }
  std::printf("foot_skate_cm_s_mean        %10.3f\n", m.foot_skate_cm_s_mean);
  std::printf("foot_skate_cm_s_p95         %10.3f\n", m.foot_skate_cm_s_p95);
  std::printf("root_sim_distance_cm_mean   %10.3f\n", m.root_sim_distance_cm_mean);
  std::printf("root_sim_distance_cm_max    %10.3f\n", m.root_sim_distance_cm_max);
  std::printf("facing_error_deg_mean       %10.3f\n", m.facing_error_deg_mean);
  std::printf("speed_response_s            %10.3f   (%d of %d changes reached)\n",
              m.speed_response_s, m.speed_events_reached, m.speed_events);
  std::printf("heading_response_s          %10.3f   (%d of %d turns reached)\n",
              m.heading_response_s, m.heading_events_reached, m.heading_events);
  std::printf("stand_root_speed_cm_s_mean  %10.3f   (%d standing frames)\n",
              m.stand_root_speed_cm_s_mean, m.stand_frames);
  std::printf("stand_foot_speed_cm_s_mean  %10.3f\n", m.stand_foot_speed_cm_s_mean);
  std::printf("transitions_per_s           %10.3f\n", m.transitions_per_s);
  std::printf(
      "transition_accel_ratio      %10.3f   (%.1f / %.1f m/s^2; %.3f against the data "
      "played with the controller's sampling, %.1f m/s^2)\n",
      m.transition_accel_ratio, m.transition_accel_p99, m.database_accel_p99,
      m.transition_accel_ratio_same_sampling, m.database_accel_p99_same_sampling);
  std::printf(
      "transition_accel_ratio_played %8.3f   (against the playing clips on their own at the "
      "same moments, %.1f m/s^2)\n",
      m.transition_accel_ratio_played, m.played_accel_p99);
  std::printf(
      "leg_accel_ratio             %10.3f   (%.1f m/s^2 at %.3f s, outside transitions; the "
      "playing clips' legs at the same moments %.1f m/s^2)\n",
      m.leg_accel_ratio, m.leg_accel_max, m.leg_accel_max_t, m.leg_accel_played_max);
  std::printf("search_us_mean              %10.3f\n", m.search_us_mean);
  std::printf("update_us_mean              %10.3f\n", m.update_us_mean);
  print_body_metrics(m);
  print_ground_metrics(m);
}

int run_eval(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;

  Result<std::shared_ptr<const ControllerDatabase>> shared = load_controller_database(arguments.db);
  if (!shared) {
    std::fprintf(stderr, "mm eval: %s\n", shared.message().c_str());
    return 1;
  }

  // The level and its Bullet world, for the whole run.
  std::optional<BulletWorld> world;
  if (!arguments.world_path.empty()) {
    Result<Level> level = load_level(arguments.world_path);
    if (!level) {
      std::fprintf(stderr, "mm eval: %s\n", level.message().c_str());
      return 1;
    }
    Result<BulletWorld> made = BulletWorld::create(*level);
    if (!made) {
      std::fprintf(stderr, "mm eval: %s\n", made.message().c_str());
      return 1;
    }
    world.emplace(std::move(made).value());
    arguments.options.world = &*world;
  }

  // Opened before the run, which writes its rows as it goes.
  std::ofstream dump;
  if (!arguments.dump_path.empty()) {
    dump.open(arguments.dump_path);
    if (!dump) {
      std::fprintf(stderr, "mm eval: could not write %s\n", arguments.dump_path.c_str());
      return 1;
    }
    arguments.options.dump = &dump;
  }

  const bool table = arguments.scripts.size() > 1;
  if (table) print_table_header();
  nlohmann::json runs = nlohmann::json::array();
  std::vector<std::pair<std::string, EvaluationMetrics>> rows;
  std::vector<std::pair<std::string, EvaluationResult>> reports;
  nlohmann::json single;
  int default_style = -1;
  if (!arguments.style.empty()) {
    Result<int> id = (*shared)->style_id(arguments.style);
    if (!id) {
      std::fprintf(stderr, "mm eval: --style: %s\n", id.message().c_str());
      return 1;
    }
    default_style = *id;
    const ControllerDatabase& cdb = **shared;
    std::string order;
    for (int rank = 0; rank < 2; ++rank) {
      const int f = cdb.style_fallback(default_style, rank);
      if (f >= 0) order += ", " + std::string(cdb.database().style_names()[static_cast<size_t>(f)]);
    }
    std::printf("style %s (%s), fallback order: own%s, any other\n", arguments.style.c_str(),
                cdb.style_rich(default_style) ? "rich" : "thin", order.c_str());
  }
  for (const std::string& path : arguments.scripts) {
    Result<InputScript> script = load_input_script(path);
    if (script) {
      if (Status s = script->resolve_styles(**shared, path, default_style); !s)
        script = Error{s.message()};
    }
    if (!script) {
      std::fprintf(stderr, "mm eval: %s\n", script.message().c_str());
      return 1;
    }
    Result<EvaluationResult> result = evaluate_script(*shared, *script, arguments.options);
    if (!result) {
      std::fprintf(stderr, "mm eval: %s\n", result.message().c_str());
      return 1;
    }
    const std::string name = std::filesystem::path(path).stem().string();
    nlohmann::json json = evaluation_run_json(result->metrics, path, arguments.options);
    if (world) json["world"] = arguments.world_path;
    const Database& db = (*shared)->database();
    if (arguments.options.transition_report > 0) {
      json["transition_accel_largest"] = transition_samples_json(*result, db);
    }
    if (table) {
      print_table_row(name, result->metrics);
      rows.emplace_back(name, result->metrics);
      if (arguments.options.transition_report > 0) reports.emplace_back(name, *result);
      runs.push_back(json);
    } else {
      std::printf("script %s, dt %.5f s, IK %s, %d frames (%.1f s)%s%s\n", path.c_str(),
                  arguments.options.dt, arguments.options.settings.ik_enabled ? "on" : "off",
                  result->metrics.frames, result->metrics.seconds, world ? ", world " : "",
                  world ? arguments.world_path.c_str() : "");
      print_metrics(result->metrics);
      if (arguments.options.transition_report > 0) print_transition_samples("", *result, db);
      single = json;
    }
    if (!arguments.dump_path.empty()) {
      dump.flush();
      if (!dump) {
        std::fprintf(stderr, "mm eval: could not write %s\n", arguments.dump_path.c_str());
        return 1;
      }
    }
  }
  if (table) {
    std::printf("\n");
    print_body_table_header();
    for (const auto& [name, metrics] : rows) print_body_table_row(name, metrics);
    for (const auto& [name, result] : reports) {
      std::printf("\n");
      print_transition_samples(name, result, (*shared)->database());
    }
  }
  if (!arguments.json_path.empty()) {
    std::ofstream file(arguments.json_path);
    file << (table ? nlohmann::json{{"runs", runs}} : single).dump(2) << "\n";
    if (!file) {
      std::fprintf(stderr, "mm eval: could not write %s\n", arguments.json_path.c_str());
      return 1;
    }
  }
  return 0;
}

const bool registered =
    register_command({"eval", "scripted controller run and its quality metrics", &run_eval});

}  // namespace
}  // namespace mm::cli
