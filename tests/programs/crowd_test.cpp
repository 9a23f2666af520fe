// Controllers on several threads over one shared database: the crowd run on 2 and 4 threads
// against 1, and controllers created (their searchers built on first use) concurrently against
// the same controllers made one after another. The suites' names end in "Threads": the
// ThreadSanitizer pass of scripts/test.sh runs exactly those (tests/CMakeLists.txt).

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "analytic_world.hpp"
#include "mm/controller/controller.hpp"
#include "mm/offline/builder.hpp"
#include "mm/programs/crowd.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;

// A few walks, turns and runs: enough for the controller to move, small enough to build in
// seconds under ThreadSanitizer.
std::shared_ptr<const Database> small_database() {
  static const std::shared_ptr<const Database> shared = [] {
    std::vector<std::filesystem::path> inputs;
    for (const char* stem : {"dataset-2_walk_normal_001", "dataset-2_walk_normal_002",
                             "dataset-2_walk-turn-left_normal_001",
                             "dataset-2_walk-turn-right_normal_001", "dataset-2_run_normal_001"}) {
      inputs.push_back(test::clip_path(stem));
    }
    Result<Database> db = build_database(inputs, BuildOptions{});
    EXPECT_TRUE(db.ok()) << (db.ok() ? "" : db.message());
    return db.ok() ? std::make_shared<const Database>(std::move(db).value()) : nullptr;
  }();
  return shared;
}

// A controller database of its own, with no searcher built yet.
std::shared_ptr<const ControllerDatabase> fresh_controller_database() {
  Result<std::shared_ptr<const ControllerDatabase>> made =
      ControllerDatabase::create(small_database());
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.message());
  return made.ok() ? *made : nullptr;
}

TEST(CrowdThreads, TwoAndFourThreadsGiveTheOneThreadCrowd) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  CrowdOptions options;
  options.characters = 12;
  options.seconds = 3.0f;
  std::vector<glm::vec3> reference;
  for (const int threads : {1, 2, 4}) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(shared, options);
    ASSERT_TRUE(run.ok()) << run.message();
    EXPECT_EQ(run->threads, threads);
    ASSERT_EQ(run->final_positions.size(), 12u);
    // The run is shorter than one window: nothing to replay, one window.
    EXPECT_TRUE(run->replay_final_positions.empty()) << threads << " threads";
    EXPECT_EQ(run->update_us_first_window, run->update_us_last_window) << threads << " threads";
    if (threads == 1) {
      reference = run->final_positions;
      continue;
    }
    for (size_t i = 0; i < reference.size(); ++i) {
      EXPECT_EQ(run->final_positions[i], reference[i]) << threads << " threads, character " << i;
    }
  }
  // The characters walked away from their grid cells (3 m apart), so the comparison is of
  // motion, not of characters standing where they were put.
  int moved = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    const glm::vec3 start(static_cast<float>(i % 32) * 3.0f, 0.0f, 0.0f);
    moved += glm::distance(reference[i], start) > 0.5f;
  }
  EXPECT_GE(moved, 9);
}

// In a world (here the analytic test world: a wall across the start area and a step), the
// crowd on 2 threads ends where it does on 1, inside the start area's walls, and the world's
// queries take a measured share of the update.
TEST(CrowdThreads, InAWorldTwoThreadsGiveTheOneThreadCrowd) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  test::AnalyticWorld world;
  world.boxes.push_back(
      test::AnalyticBox{glm::vec2(5.0f, 4.5f), glm::vec2(10.0f, 0.2f), 0.0f, 2.0f});
  world.boxes.push_back(
      test::AnalyticBox{glm::vec2(3.0f, 1.0f), glm::vec2(1.0f, 1.0f), 0.0f, 0.15f});
  CrowdOptions options;
  options.characters = 8;
  options.seconds = 3.0f;
  options.world = &world;
  options.start_area = glm::vec4(0.0f, 0.0f, 9.0f, 3.0f);
  std::vector<glm::vec3> reference;
  for (const int threads : {1, 2}) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(shared, options);
    ASSERT_TRUE(run.ok()) << run.message();
    EXPECT_GT(run->world_share, 0.0);
    EXPECT_LT(run->world_share, 1.0);
    for (const glm::vec3& p : run->final_positions) {
      EXPECT_LT(p.z, 4.3f - 0.3f + 1e-3f);  // never through the wall's face
    }
    if (threads == 1) {
      reference = run->final_positions;
    } else {
      EXPECT_EQ(run->final_positions, reference);
    }
  }
}

// A budgeted run's frame figures come from its frames as listed, in their order: the mean and
// the nearest-rank p99 of frame_ms, and each frame's record of the same frame. Timings differ
// from run to run; how the figures relate does not.
void expect_frame_figures_add_up(const CrowdResult& run) {
  ASSERT_FALSE(run.frame_ms.empty());
  ASSERT_EQ(run.frame_records.size(), run.frame_ms.size());
  double sum = 0.0;
  for (size_t f = 0; f < run.frame_ms.size(); ++f) {
    sum += run.frame_ms[f];
    EXPECT_EQ(run.frame_records[f].frame_ms, static_cast<float>(run.frame_ms[f])) << "frame " << f;
    EXPECT_GE(run.frame_records[f].frame_ms, run.frame_records[f].plan_ms) << "frame " << f;
  }
  EXPECT_NEAR(run.frame_ms_mean, sum / static_cast<double>(run.frame_ms.size()), 1e-9 * sum);
  std::vector<double> sorted = run.frame_ms;
  std::sort(sorted.begin(), sorted.end());
  const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(sorted.size()))) - 1;
  EXPECT_EQ(run.frame_ms_p99, sorted[rank]);
  EXPECT_GT(run.frame_ms_p99, 0.0);
}

// Under a frame budget (crowd_scheduler.hpp) the crowd runs at every tier, and its displayed
// poses on 2 and 4 threads are exactly those on 1: the tiers come from the cost model, never
// from timings, and the plan is for the settings' thread count, not the run's.
TEST(CrowdThreads, UnderABudgetTwoAndFourThreadsShowTheOneThreadPoses) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  CrowdOptions options;
  options.characters = 40;
  options.seconds = 4.0f;
  CrowdSchedulerSettings lod;
  lod.cost_us = {8.0f, 3.0f, 2.0f, 0.5f};
  lod.threads = 2;
  lod.budget_ms = 0.06f;  // 120 us of work for 40 characters: 320 at full rate, 20 all moved
  options.lod = lod;
  std::vector<Transform> reference;
  for (const int threads : {1, 2, 4}) {
    options.threads = threads;
    Result<CrowdResult> run = run_crowd(shared, options);
    ASSERT_TRUE(run.ok()) << run.message();
    int sum = 0;
    for (const int count : run->tier_counts) sum += count;
    EXPECT_EQ(sum, 40);
    EXPECT_GT(run->tier_counts[0], 0);
    EXPECT_GT(run->tier_counts[2] + run->tier_counts[3], 0);
    EXPECT_LE(run->planned_cost_us_mean, 120.0 * (1.0 + 1e-6));
    expect_frame_figures_add_up(*run);
    ASSERT_EQ(run->final_poses.size(), 40 * shared->database().skeleton().joint_count());
    if (threads == 1) {
      reference = run->final_poses;
      continue;
    }
    for (size_t k = 0; k < reference.size(); ++k) {
      ASSERT_EQ(run->final_poses[k].translation, reference[k].translation)
          << threads << " threads, transform " << k;
      ASSERT_EQ(run->final_poses[k].rotation, reference[k].rotation)
          << threads << " threads, transform " << k;
    }
  }
}

// A budget that holds every character at full rate steps each controller exactly as the plain
// loop does: the budgeted run keeps each character's input line and position itself (as a game
// would) instead of asking the script and the controller, and that must not change any input.
// Its frame figures add up: the plan, the longest thread's steps and the rest make the frame.
TEST(CrowdThreads, AnAmpleBudgetMovesTheCrowdAsTheLoopWithoutOne) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  CrowdOptions options;
  options.characters = 12;
  options.seconds = 6.0f;  // several lines of every character's script
  options.threads = 2;
  Result<CrowdResult> plain = run_crowd(shared, options);
  ASSERT_TRUE(plain.ok()) << plain.message();
  CrowdSchedulerSettings lod;
  lod.budget_ms = 100.0f;
  options.lod = lod;
  Result<CrowdResult> budgeted = run_crowd(shared, options);
  ASSERT_TRUE(budgeted.ok()) << budgeted.message();
  EXPECT_EQ(budgeted->tier_counts[0], 12);
  ASSERT_EQ(budgeted->final_positions.size(), plain->final_positions.size());
  for (size_t i = 0; i < plain->final_positions.size(); ++i) {
    EXPECT_EQ(budgeted->final_positions[i], plain->final_positions[i]) << "character " << i;
  }
  ASSERT_EQ(budgeted->final_poses.size(), plain->final_poses.size());
  for (size_t k = 0; k < plain->final_poses.size(); ++k) {
    ASSERT_EQ(budgeted->final_poses[k].translation, plain->final_poses[k].translation) << k;
  }
  EXPECT_GT(budgeted->plan_ms_mean, 0.0);
  EXPECT_GT(budgeted->steps_ms_mean, 0.0);
  EXPECT_NEAR(budgeted->plan_ms_mean + budgeted->steps_ms_mean + budgeted->sync_ms_mean,
              budgeted->frame_ms_mean, 1e-9);
  EXPECT_GT(budgeted->work_ms_mean, 0.0);
  EXPECT_GE(budgeted->work_ms_p99, budgeted->work_ms_mean * 0.5);
  EXPECT_EQ(budgeted->frame_ms.size(), 6u * 60u - 60u);  // the steady frames: less the first second
  EXPECT_GT(budgeted->update_us_mean, 0.0);              // from the timed sample of the steps
  // The timed sample is kept in fixed memory (sums per frame, a histogram): its p99 and windows.
  EXPECT_GT(budgeted->update_us_p99, 0.0);
  EXPECT_GT(budgeted->update_us_first_window, 0.0);
  EXPECT_GT(budgeted->update_us_last_window, 0.0);
  // Every steady frame's record: all 12 characters updated at full rate, none moved, and the
  // frame's times as the run's.
  ASSERT_EQ(budgeted->frame_records.size(), budgeted->frame_ms.size());
  double work = 0.0;
  int searches = 0;
  for (size_t f = 0; f < budgeted->frame_records.size(); ++f) {
    const CrowdFrameRecord& record = budgeted->frame_records[f];
    EXPECT_EQ(record.steps[0], 12) << f;
    EXPECT_EQ(record.steps[3], 0) << f;
    EXPECT_FLOAT_EQ(record.frame_ms, static_cast<float>(budgeted->frame_ms[f])) << f;
    work += record.work_ms;
    searches += record.searches;
  }
  EXPECT_NEAR(work / static_cast<double>(budgeted->frame_records.size()), budgeted->work_ms_mean,
              1e-3 * budgeted->work_ms_mean);
  EXPECT_GT(searches, 0);
}

TEST(CrowdThreads, AnInvalidBudgetIsRefusedByMessage) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  CrowdOptions options;
  options.characters = 2;
  CrowdSchedulerSettings lod;
  lod.cost_us = {1.0f, 2.0f, 0.5f, 0.1f};
  options.lod = lod;
  Result<CrowdResult> run = run_crowd(shared, options);
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.message(),
            "crowd: crowd scheduler: the cost of tier half is above the cost of tier full");
}

TEST(CrowdThreads, TheReplayedFirstWindowEndsWhereTheRunsFirstWindowDid) {
  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  CrowdOptions options;
  options.characters = 4;
  options.dt = 0.1f;  // coarse, to cover more than a window in few frames
  options.threads = 2;
  options.seconds = kCrowdWindowSeconds;
  Result<CrowdResult> first_window = run_crowd(shared, options);
  ASSERT_TRUE(first_window.ok()) << first_window.message();
  options.seconds = kCrowdWindowSeconds + 5.0f;
  Result<CrowdResult> longer = run_crowd(shared, options);
  ASSERT_TRUE(longer.ok()) << longer.message();
  EXPECT_EQ(longer->replay_final_positions, first_window->final_positions);
  EXPECT_NE(longer->final_positions, first_window->final_positions);
  EXPECT_GT(longer->update_us_first_window, 0.0);
  EXPECT_GT(longer->update_us_last_window, 0.0);
}

// One character's run: created over `shared` with this search method, then three seconds of
// its varied script. Returns its final global transforms (empty when create failed).
std::vector<Transform> run_character(const std::shared_ptr<const ControllerDatabase>& shared,
                                     const std::string& method, uint32_t seed) {
  ControllerSettings settings;
  settings.search_method = method;
  Result<Controller> made = Controller::create(shared, settings);
  if (!made.ok()) return {};
  Controller& c = *made;
  const InputScript script = varied_input_script(seed, 3.0f);
  for (int f = 1; f <= 180; ++f) c.update(kDt, script.at(static_cast<float>(f) * kDt));
  return {c.global_transforms().begin(), c.global_transforms().end()};
}

TEST(ControllerThreads, ConcurrentlyCreatedControllersMatchSequentialOnes) {
  // Four characters, two of them on one method: the searchers are built on first use while
  // other threads ask for the same one or another.
  const std::array<std::string, 4> methods = {"boxtree", "kdtree", "brute-simd", "boxtree"};
  const std::shared_ptr<const ControllerDatabase> sequential_database = fresh_controller_database();
  ASSERT_NE(sequential_database, nullptr);
  std::array<std::vector<Transform>, 4> sequential, concurrent;
  for (size_t i = 0; i < methods.size(); ++i) {
    sequential[i] = run_character(sequential_database, methods[i], static_cast<uint32_t>(i));
    ASSERT_FALSE(sequential[i].empty()) << methods[i];
  }

  const std::shared_ptr<const ControllerDatabase> shared = fresh_controller_database();
  ASSERT_NE(shared, nullptr);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < methods.size(); ++i) {
    threads.emplace_back(
        [&, i] { concurrent[i] = run_character(shared, methods[i], static_cast<uint32_t>(i)); });
  }
  for (std::thread& t : threads) t.join();

  for (size_t i = 0; i < methods.size(); ++i) {
    ASSERT_EQ(concurrent[i].size(), sequential[i].size()) << methods[i];
    for (size_t j = 0; j < concurrent[i].size(); ++j) {
      EXPECT_EQ(concurrent[i][j].translation, sequential[i][j].translation)
          << "character " << i << ", joint " << j;
      EXPECT_EQ(concurrent[i][j].rotation, sequential[i][j].rotation)
          << "character " << i << ", joint " << j;
    }
  }
  // Different scripts end in different places: each thread ran its own character.
  EXPECT_NE(sequential[0][0].translation, sequential[3][0].translation);
}

}  // namespace
}  // namespace mm
