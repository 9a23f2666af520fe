// `mm eval` and `mm crowd-bench` as scripts use them: the metric keys, the dump's exact header,
// determinism, refused scripts and usage errors, and the crowd's thread-count independence.

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "run_tool.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

using test::CommandRun;
using test::run_mm;

// The file's text, or "" when it cannot be read (the assertions on the text then fail).
std::string read_text(const fs::path& path) {
  auto contents = read_whole_file(path);
  return contents ? std::string(contents->text()) : std::string();
}

// A small real database (walks, turns, runs, a wave and the idle clip), built once per test
// program. ctest runs every test as its own process, in parallel: each gets its own folder.
const fs::path& small_database() {
  static const fs::path path = [] {
    const fs::path dir =
        fs::path(MM_BINARY_DIR) / "test-scratch" / ("controller-cli-" + std::to_string(getpid()));
    fs::create_directories(dir);
    std::string files;
    for (const char* stem : {"dataset-2_walk_normal_001", "dataset-2_walk_normal_002",
                             "dataset-2_walk_normal_003", "dataset-2_walk-turn-left_normal_001",
                             "dataset-2_walk-turn-right_normal_001", "dataset-2_run_normal_001",
                             "dataset-2_run_normal_002", "dataset-2_wave-left-hand_normal_001"}) {
      files.append("'").append(test::clip_path(stem).string()).append("' ");
    }
    // Removed when the test program exits.
    static const struct Cleanup {
      fs::path dir;
      ~Cleanup() {
        std::error_code ec;
        fs::remove_all(dir, ec);
      }
    } cleanup{dir};
    const fs::path db = dir / "small.mmdb";
    const CommandRun run = run_mm("build " + files + "-o '" + db.string() + "' --quiet");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return db;
  }();
  return path;
}

fs::path write_script(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path;
}

const char* const kScript =
    "# walk, turn, run, stop\n"
    "0 0 1 0 0\n"
    "2 1 0 0 0\n"
    "4 0 1 0 0 run\n"
    "6 0 0 0 0\n";

std::string eval_arguments(const fs::path& script, const std::string& extra) {
  return "eval --db '" + small_database().string() + "' --script '" + script.string() + "' " +
         extra;
}

TEST(ControllerCli, EvalWritesEveryMetricUnderItsKey) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  const fs::path json_path = dir / "out.json";
  const CommandRun run = run_mm(eval_arguments(script, "--json '" + json_path.string() + "'"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json json = nlohmann::json::parse(read_text(json_path));
  for (const char* key : {"foot_skate_cm_s_mean",
                          "foot_skate_cm_s_p95",
                          "root_sim_distance_cm_mean",
                          "root_sim_distance_cm_max",
                          "facing_error_deg_mean",
                          "speed_response_s",
                          "heading_response_s",
                          "stand_root_speed_cm_s_mean",
                          "stand_foot_speed_cm_s_mean",
                          "transitions_per_s",
                          "transition_accel_ratio",
                          "leg_accel_ratio",
                          "search_us_mean",
                          "update_us_mean",
                          "body_turn_rate_deg_s_p99",
                          "body_turn_rate_deg_s_max",
                          "foot_pivot_deg_s_mean",
                          "stand_turns",
                          "stand_turn_unsettled",
                          "stand_turn_response_s",
                          "stand_turn_final_error_deg_mean",
                          "stand_turn_peak_rate_deg_s_max",
                          "strafe_chest_error_deg_mean",
                          "idle_head_speed_cm_s_mean"}) {
    ASSERT_TRUE(json.contains(key)) << key;
    EXPECT_TRUE(json[key].is_number()) << key;
    EXPECT_GE(json[key].get<double>(), 0.0) << key;
    // The terminal shows the same figures under the same names.
    EXPECT_NE(run.output.find(key), std::string::npos) << key;
  }
  EXPECT_LE(json["root_sim_distance_cm_mean"].get<double>(),
            json["root_sim_distance_cm_max"].get<double>() + 1e-9);
  // The script's last line is at 6 s, and the run goes on 2 s past it: 8 s at 60 Hz. The stick
  // is released for the last 2 s.
  EXPECT_EQ(json["frames"].get<int>(), 480);
  EXPECT_GT(json["stand_frames"].get<int>(), 60);
  EXPECT_GT(json["transitions_per_s"].get<double>(), 0.0);
  // The lowest toe may be below the ground (a sinking foot), so only its presence is checked.
  ASSERT_TRUE(json.contains("toe_height_min_cm"));
  EXPECT_TRUE(json["toe_height_min_cm"].is_number());
  EXPECT_NE(run.output.find("toe_height_min_cm"), std::string::npos);
  EXPECT_LE(json["body_turn_rate_deg_s_p99"].get<double>(),
            json["body_turn_rate_deg_s_max"].get<double>() + 1e-9);
  // The script walks, turns and runs, and stands its last 2 s.
  EXPECT_GT(json["body_turn_rate_deg_s_max"].get<double>(), 0.0);
  EXPECT_GT(json["idle_head_frames"].get<int>(), 0);
}

TEST(ControllerCli, EvalIsDeterministicAndTheDumpHasTheDocumentedColumns) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  nlohmann::json runs[2];
  std::string dumps[2];
  for (int i = 0; i < 2; ++i) {
    const fs::path json = dir / ("run" + std::to_string(i) + ".json");
    const fs::path dump = dir / ("run" + std::to_string(i) + ".csv");
    const CommandRun run = run_mm(eval_arguments(
        script, "--dt 0.02 --json '" + json.string() + "' --dump '" + dump.string() + "'"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    runs[i] = nlohmann::json::parse(read_text(json));
    dumps[i] = read_text(dump);
  }
  EXPECT_EQ(dumps[0], dumps[1]);
  // Wall-clock timings are the only figures that may differ.
  for (nlohmann::json& j : runs) {
    j.erase("search_us_mean");
    j.erase("update_us_mean");
  }
  EXPECT_EQ(runs[0], runs[1]);

  Result<Database> db = load_database(small_database());
  ASSERT_TRUE(db.ok()) << db.message();
  std::string header =
      "t,sim_x,sim_z,sim_yaw_deg,root_x,root_z,root_yaw_deg,desired_vx,desired_vz,desired_yaw_deg,"
      "transition,contact_l,contact_r,clip,frame";
  for (const std::string& joint : db->skeleton().names()) {
    header.append(",").append(joint).append("_x,").append(joint).append("_y,").append(joint).append(
        "_z");
  }
  header.append(",toe_ground_l,toe_ground_r,hips_ground,wall_depth,stuck,locked_l,locked_r");
  header.append(",toe_support_l,toe_support_r");
  header.append(",body_ground,placed_toe_ground_l,placed_toe_ground_r,pelvis_drop,playback_rate");
  std::istringstream lines(dumps[0]);
  std::string first;
  std::getline(lines, first);
  EXPECT_EQ(first, header);
  int rows = 0;
  for (std::string line; std::getline(lines, line);) {
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','),
              std::count(header.begin(), header.end(), ','));
  }
  EXPECT_EQ(rows, 400);  // 8 s at dt 0.02
}

TEST(ControllerCli, EvalRefusesABadScriptLineByFileAndLine) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "bad.txt", "0 0 1 0 0\n1 0 1\n");
  const CommandRun run = run_mm(eval_arguments(script, ""));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("bad.txt:2:"), std::string::npos) << run.output;
}

// Bounded runs (script.hpp): a time step that would need millions of frames for a few seconds
// is a usage error; a script time past the longest script is refused by file and line, where it
// used to run "0 frames" (a float-to-int overflow) or abort allocating every frame.
TEST(ControllerCli, EvalRefusesRunsPastTheLimits) {
  const fs::path dir = test::scratch_dir();
  const fs::path walk = write_script(dir, "walk.txt", kScript);
  CommandRun run = run_mm(eval_arguments(walk, "--dt 0.000001"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--dt: 0.000001 is outside [0.0001, 1]"), std::string::npos)
      << run.output;

  const fs::path far = write_script(dir, "far.txt", "0 0 1 0 0\n1e30 0 0 0 0\n");
  run = run_mm(eval_arguments(far, ""));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("mm eval: " + far.string() +
                            ":2: expected the time in seconds (a number in [0, 28800], the "
                            "longest script), found '1e30'"),
            std::string::npos)
      << run.output;
}

TEST(ControllerCli, EvalUsageErrorsExitWith2) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  for (const std::string& arguments :
       {std::string("eval --script '") + script.string() + "'",
        eval_arguments(script, "--ik maybe"), eval_arguments(script, "--dt 0"),
        eval_arguments(script, "--set warp_speed=9"),
        eval_arguments(script, "--set inertialization_halflife=-1"),
        eval_arguments(script, "--transition-report -1"),
        eval_arguments(script, "--transition-report 10001")}) {
    const CommandRun run = run_mm(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
  }
  const CommandRun missing = run_mm(eval_arguments(dir / "none.txt", ""));
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("none.txt"), std::string::npos) << missing.output;
}

// --transition-report lists the largest accelerations the transition metric counts, largest
// first, on the terminal and in the JSON, each a joint of the skeleton in a playing clip; the
// metrics are the same run's.
TEST(ControllerCli, EvalReportsTheLargestTransitionAccelerations) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  const fs::path plain = dir / "plain.json", reported = dir / "reported.json";
  const CommandRun without = run_mm(eval_arguments(script, "--json '" + plain.string() + "'"));
  const CommandRun with =
      run_mm(eval_arguments(script, "--transition-report 5 --json '" + reported.string() + "'"));
  ASSERT_EQ(without.exit_code, 0) << without.output;
  ASSERT_EQ(with.exit_code, 0) << with.output;
  const nlohmann::json a = nlohmann::json::parse(read_text(plain));
  const nlohmann::json b = nlohmann::json::parse(read_text(reported));
  EXPECT_FALSE(a.contains("transition_accel_largest"));
  ASSERT_TRUE(b.contains("transition_accel_largest"));
  const nlohmann::json& list = b["transition_accel_largest"];
  ASSERT_EQ(list.size(), 5u);
  for (size_t i = 0; i < list.size(); ++i) {
    EXPECT_FALSE(list[i]["joint"].get<std::string>().empty());
    EXPECT_FALSE(list[i]["clip"].get<std::string>().empty());
    EXPECT_GE(list[i]["windows"].get<int>(), 1);
    if (i > 0) {
      EXPECT_GE(list[i - 1]["m_s2"].get<double>(), list[i]["m_s2"].get<double>());
    }
  }
  // The 99th percentile is no larger than the largest sample it is taken over.
  EXPECT_LE(b["transition_accel_p99_m_s2"].get<double>(), list[0]["m_s2"].get<double>() + 1e-3);
  EXPECT_EQ(a["transition_accel_ratio"], b["transition_accel_ratio"]);
  EXPECT_NE(with.output.find("largest joint accelerations in the transitions' windows"),
            std::string::npos)
      << with.output;
  EXPECT_NE(with.output.find(list[0]["joint"].get<std::string>()), std::string::npos);
}

// The rows of a --dump file as numbers, the header skipped.
std::vector<std::vector<double>> dump_rows(const std::string& text) {
  std::vector<std::vector<double>> rows;
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) {
    std::vector<double>& row = rows.emplace_back();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
  }
  return rows;
}

// --start places the character: the JSON says where, the dump's world positions start there,
// and the run moves as the same run from the origin does.
TEST(ControllerCli, EvalStartsTheCharacterWhereStartSays) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  std::vector<std::vector<double>> rows[2];
  for (int far = 0; far < 2; ++far) {
    const fs::path json = dir / ("run" + std::to_string(far) + ".json");
    const fs::path dump = dir / ("run" + std::to_string(far) + ".csv");
    const CommandRun run = run_mm(
        eval_arguments(script, std::string(far ? "--start 100000.5,-20000 " : "") + "--json '" +
                                   json.string() + "' --dump '" + dump.string() + "'"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json metrics = nlohmann::json::parse(read_text(json));
    EXPECT_EQ(metrics["start"],
              far ? nlohmann::json({100000.5, -20000.0}) : nlohmann::json({0.0, 0.0}));
    rows[far] = dump_rows(read_text(dump));
    ASSERT_EQ(rows[far].size(), 480u);
  }
  // Columns: t, sim_x, sim_z, sim_yaw_deg, root_x, root_z, ...
  const glm::dvec2 start(100000.5, -20000.0);
  EXPECT_NEAR(rows[1][0][1], start.x, 0.05);
  EXPECT_NEAR(rows[1][0][2], start.y, 0.05);
  // 8 s of walking and running go the same way from either start.
  const std::vector<double>& last_near = rows[0].back();
  const std::vector<double>& last_far = rows[1].back();
  ASSERT_GT(std::hypot(last_near[4], last_near[5]), 5.0);
  EXPECT_NEAR(last_far[4] - start.x, last_near[4], 0.05);
  EXPECT_NEAR(last_far[5] - start.y, last_near[5], 0.05);
}

// A malformed --start is a usage error naming the option and the value.
TEST(ControllerCli, EvalRefusesAMalformedStart) {
  const fs::path dir = test::scratch_dir();
  const fs::path script = write_script(dir, "walk.txt", kScript);
  const std::pair<const char*, const char*> cases[] = {{"abc", "'abc' is not X,Z"},
                                                       {"1,2,3", "'1,2,3' is not X,Z"},
                                                       {"nan,0", "'nan,0' is not X,Z"},
                                                       {"0,NaN", "'0,NaN' is not X,Z"},
                                                       {"5", "'5' is not X,Z"},
                                                       {"1e30,0", "1e30,0 has a number outside"},
                                                       {"0,-2e7", "0,-2e7 has a number outside"}};
  for (const auto& [value, message] : cases) {
    const CommandRun run = run_mm(eval_arguments(script, std::string("--start ") + value));
    EXPECT_EQ(run.exit_code, 2) << value << "\n" << run.output;
    EXPECT_NE(run.output.find("--start"), std::string::npos) << value << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << value << "\n" << run.output;
  }
}

TEST(ControllerCli, CrowdBenchGivesTheSameCrowdOnOneAndTwoThreads) {
  const fs::path dir = test::scratch_dir();
  const fs::path json_path = dir / "crowd.json";
  const CommandRun run =
      run_mm("crowd-bench --db '" + small_database().string() +
             "' --characters 24 --seconds 1 --json '" + json_path.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("final positions identical"), std::string::npos) << run.output;
  const nlohmann::json json = nlohmann::json::parse(read_text(json_path));
  for (const char* key :
       {"update_us_mean", "update_us_p99", "search_share", "update_us_first_window",
        "update_us_last_window", "max_characters_60hz_1_thread", "max_characters_60hz_2_threads"}) {
    ASSERT_TRUE(json.contains(key)) << key;
    EXPECT_GT(json[key].get<double>(), 0.0) << key;
  }
  EXPECT_LE(json["search_share"].get<double>(), 1.0);
  EXPECT_TRUE(json["same_result_every_thread_count"].get<bool>());
  // One second is shorter than a window: both windows are the whole run.
  EXPECT_EQ(json["update_us_first_window"], json["update_us_last_window"]);
  EXPECT_NEAR(json["update_us_first_window"].get<double>(), json["update_us_mean"].get<double>(),
              1e-6 * json["update_us_mean"].get<double>());
  EXPECT_EQ(json["update_us_window_ratio"].get<double>(), 1.0);
  EXPECT_NE(run.output.find("first 20 s us"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("last/first"), std::string::npos) << run.output;

  const CommandRun bad = run_mm("crowd-bench --db '" + small_database().string() + "' --seconds 1");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

// Under --budget-ms the crowd runs at lower tiers too, the same on one and two threads, and the
// JSON says how many characters ran at each tier, the frame time and each tier's quality.
TEST(ControllerCli, CrowdBenchUnderABudgetReportsTiersAndFrameTimes) {
  const fs::path dir = test::scratch_dir();
  const fs::path json_path = dir / "crowd-budget.json";
  const CommandRun run = run_mm("crowd-bench --db '" + small_database().string() +
                                "' --characters 24 --seconds 2 --budget-ms 0.05 --tier-costs-us "
                                "8,3,2,0.5 --budget-headroom 0 --json '" +
                                json_path.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json json = nlohmann::json::parse(read_text(json_path));
  EXPECT_TRUE(json["same_result_every_thread_count"].get<bool>());
  EXPECT_EQ(json["budget_ms"].get<double>(), 0.05);
  EXPECT_EQ(json["budget_headroom"].get<double>(), 0.0);
  for (const char* key : {"frame_ms_mean", "frame_ms_p99", "max_characters_60hz_1_thread"}) {
    ASSERT_TRUE(json.contains(key)) << key;
    EXPECT_GT(json[key].get<double>(), 0.0) << key;
  }
  // 100 us of work (two threads) for 24 characters: all at quarter (48 us), five raised to full
  // within 40 us (+6 each), the next 19 to half (+1 each).
  const nlohmann::json& tiers = json["tier_counts"];
  ASSERT_EQ(tiers.size(), 4u);
  EXPECT_EQ(tiers.begin().key(), "full");
  EXPECT_EQ(tiers["full"].get<int>(), 5);
  EXPECT_EQ(tiers["half"].get<int>(), 19);
  EXPECT_EQ(tiers["quarter"].get<int>(), 0);
  EXPECT_EQ(tiers["move_only"].get<int>(), 0);
  ASSERT_EQ(json["budget_runs"].size(), 2u);
  for (const nlohmann::json& budget_run : json["budget_runs"]) {
    EXPECT_EQ(budget_run["tier_counts"], tiers);
  }
  for (const char* tier : {"full", "half", "quarter", "move_only"}) {
    ASSERT_TRUE(json["tier_quality"].contains(tier)) << tier;
    EXPECT_GE(json["tier_quality"][tier]["foot_skate_geom_cm_s_mean"].get<double>(), 0.0);
  }
  EXPECT_EQ(json["tier_cost_us"]["quarter"].get<double>(), 2.0);
  EXPECT_NE(run.output.find("tiers at the end: full 5, half 19"), std::string::npos) << run.output;

  // The default headroom holds back 30 % of 2 x 51 us: 71.4 us to spend. All at half (72 us)
  // would pass it, so all start at quarter (48 us); three are raised to full (+6 each: 66 us; a
  // fourth would make 72), then five of the rest to half (+1 each: 71 us). --budget-only leaves
  // out the full-rate runs.
  const fs::path held_path = dir / "crowd-headroom.json";
  const CommandRun held = run_mm("crowd-bench --db '" + small_database().string() +
                                 "' --characters 24 --seconds 2 --budget-ms 0.051 --tier-costs-us "
                                 "8,3,2,0.5 --budget-only --json '" +
                                 held_path.string() + "'");
  ASSERT_EQ(held.exit_code, 0) << held.output;
  const nlohmann::json held_json = nlohmann::json::parse(read_text(held_path));
  EXPECT_NEAR(held_json["budget_headroom"].get<double>(), 0.3, 1e-12);
  EXPECT_EQ(held_json["tier_counts"]["full"].get<int>(), 3);
  EXPECT_EQ(held_json["tier_counts"]["half"].get<int>(), 5);
  EXPECT_EQ(held_json["tier_counts"]["quarter"].get<int>(), 16);
  EXPECT_FALSE(held_json.contains("max_characters_60hz_1_thread"));
  EXPECT_EQ(held.output.find("at full rate"), std::string::npos) << held.output;

  const CommandRun bad =
      run_mm("crowd-bench --db '" + small_database().string() +
             "' --characters 4 --seconds 1 --budget-ms 1 --tier-costs-us 1,2,1,1");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(
      bad.output.find("crowd scheduler: the cost of tier half is above the cost of tier full"),
      std::string::npos)
      << bad.output;
}

// `mm eval --world`: the run in the shipped course (Bullet), measured against its ground; a level
// that cannot be read is refused naming the file.
TEST(ControllerCli, EvalRunsInALevelAndRefusesABadOne) {
  const fs::path dir = fs::path(MM_BINARY_DIR) / "test-scratch" /
                       ("controller-cli-world-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path course = fs::path(MM_SOURCE_DIR) / "data/levels/course.glb";
  const fs::path script = fs::path(MM_SOURCE_DIR) / "scripts/input/course-walk.txt";
  const fs::path json = dir / "wall.json";
  // The lane of the wall across it: the character walks into it and stands.
  const CommandRun run =
      run_mm("eval --db " + test::quoted(small_database()) + " --script " + test::quoted(script) +
             " --world " + test::quoted(course) + " --start 17.5,0 --json " + test::quoted(json));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(", world " + course.string()), std::string::npos) << run.output;
  const nlohmann::json metrics = nlohmann::json::parse(read_text(json));
  EXPECT_EQ(metrics["world"], course.string());
  EXPECT_LT(metrics["wall_depth_cm_max"].get<double>(), 2.0);
  EXPECT_GT(metrics["toe_clearance_cm_min"].get<double>(), 0.0);  // flat where the wall is

  const fs::path bad = write_script(dir, "bad.glb", "not a glTF file");
  const CommandRun refused = run_mm("eval --db " + test::quoted(small_database()) + " --script " +
                                    test::quoted(script) + " --world " + test::quoted(bad));
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_NE(refused.output.find("mm eval: " + bad.string()), std::string::npos) << refused.output;
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace mm
