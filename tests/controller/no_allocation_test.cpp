// update() never allocates: every operator new of this program is counted
// (allocation_counter.hpp) while controllers walk, run, turn, strafe, stop, request tags and get
// bad input, with and without a world.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>

#include "allocation_counter.hpp"
#include "analytic_world.hpp"
#include "controller_support.hpp"
#include "mm/controller/crowd_scheduler.hpp"

namespace mm {
namespace {

using test::g_allocations;

// 3000 updates of varied input (turns, runs, stops, strafes, a tag, a NaN stick, two rates) on
// a controller, with or without a world; fails if any of them allocated.
void expect_updates_never_allocate(const WorldQueries* world) {
  const auto shared = test::normal_controller_database();
  ControllerSettings settings;
  Result<Controller> made = Controller::create(shared, settings);
  ASSERT_TRUE(made.ok()) << made.message();
  Controller& c = *made;
  c.set_world(world);
  // The counter can see allocations at all.
  const long probe = g_allocations.load();
  ::operator delete(::operator new(16));
  ASSERT_GT(g_allocations.load(), probe);

  const long before = g_allocations.load();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 3000; ++i) {
    ControllerInput input = test::push_toward(static_cast<float>((i / 120) * 75), (i / 400) % 2);
    if ((i / 300) % 4 == 3) input.left_stick = glm::vec2(0.0f);
    if ((i / 500) % 3 == 1) {
      input.strafe = true;
      input.right_stick = glm::vec2(1.0f, 0.0f);
    }
    if (i > 2500 && i < 2700) input.tag = "wave";
    if (i == 1000) input.left_stick = glm::vec2(nan, nan);
    input.camera_yaw = 0.001f * static_cast<float>(i);
    c.update(i % 7 == 0 ? 1.0f / 30.0f : 1.0f / 60.0f, input);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(c.debug().searches, 100);
  EXPECT_GT(c.debug().transitions, 10);
}

TEST(ControllerNoAllocationTest, UpdateNeverAllocates) {
  expect_updates_never_allocate(nullptr);
}

// In a world of walls, a ramp and steps, the moves through it (character_mover.hpp) use the
// controller's fixed buffers too (the test world's own answers allocate nothing).
TEST(ControllerNoAllocationTest, UpdateInAWorldNeverAllocates) {
  test::AnalyticWorld world;
  world.height = [](double x, double) { return std::clamp(x - 2.0, 0.0, 3.0) * 0.2; };
  world.boxes.push_back(
      test::AnalyticBox{glm::vec2(0.0f, 6.0f), glm::vec2(8.0f, 0.2f), 0.3f, 3.0f});
  world.boxes.push_back(
      test::AnalyticBox{glm::vec2(-3.0f, 0.0f), glm::vec2(1.0f, 1.0f), 0.0f, 0.17f});
  expect_updates_never_allocate(&world);
  EXPECT_GT(world.sweeps.load(), 3000);
}

// The crowd's scheduler (crowd_scheduler.hpp) plans and steps a budgeted crowd whose
// significances keep changing, so characters change tiers every few frames (updates at every
// rate, holds, moves, promotions with their blends): none of it allocates.
TEST(ControllerNoAllocationTest, TheCrowdSchedulerNeverAllocates) {
  const auto shared = test::normal_controller_database();
  constexpr size_t kCharacters = 12;
  std::vector<Controller> crowd;
  for (size_t i = 0; i < kCharacters; ++i) {
    // Half without skinning, as a drawn crowd has them (a move carries the held pose), half
    // with it (a move settles the whole pose).
    ControllerSettings controller_settings;
    controller_settings.compute_skinning = i % 2 == 0;
    Result<Controller> made = Controller::create(shared, controller_settings);
    ASSERT_TRUE(made.ok()) << made.message();
    made->teleport(glm::vec3(static_cast<float>(i) * 3.0f, 0.0f, 0.0f), 0.0f);
    crowd.push_back(std::move(made).value());
  }
  CrowdSchedulerSettings settings;
  // 22.25 us: one at full rate, one at half, four at quarter, six moved (the tests of
  // crowd_scheduler_test.cpp work these out).
  settings.cost_us = {8.0f, 3.0f, 2.0f, 0.5f};
  settings.budget_ms = 0.02225f;
  Result<CrowdScheduler> made =
      CrowdScheduler::create(kCharacters, crowd[0].global_transforms().size(), settings);
  ASSERT_TRUE(made.ok()) << made.message();
  CrowdScheduler& scheduler = *made;
  std::vector<float> significance(kCharacters);
  std::array<bool, kCrowdTierCount> seen{};
  int changes = 0;
  std::vector<uint8_t> before(kCharacters, 0);

  const long start = g_allocations.load();
  for (int f = 0; f < 1200; ++f) {
    for (size_t i = 0; i < kCharacters; ++i) {
      // A camera sweeping back and forth along the row.
      const float camera = 18.0f + 18.0f * std::sin(0.01f * static_cast<float>(f));
      significance[i] = -std::abs(static_cast<float>(i) * 3.0f - camera);
    }
    scheduler.plan(significance);
    for (size_t i = 0; i < kCharacters; ++i) {
      const ControllerInput input =
          test::push_toward(static_cast<float>(f / 90 * 60 + i), f % 400 > 300);
      if (i + 2 < kCharacters) scheduler.prefetch_ahead(i + 2, crowd[i + 2]);
      if (i + 1 < kCharacters) scheduler.prefetch(i + 1, crowd[i + 1]);
      scheduler.step(i, crowd[i], 1.0f / 60.0f, input);
      const uint8_t t = static_cast<uint8_t>(scheduler.tier(i));
      seen[t] = true;
      changes += t != before[i];
      before[i] = t;
    }
  }
  EXPECT_EQ(g_allocations.load() - start, 0);
  for (int t = 0; t < kCrowdTierCount; ++t) {
    EXPECT_TRUE(seen[static_cast<size_t>(t)]) << crowd_tier_name(static_cast<CrowdTier>(t));
  }
  EXPECT_GT(changes, 20);
}

}  // namespace
}  // namespace mm
