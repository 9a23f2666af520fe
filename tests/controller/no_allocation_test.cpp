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

}  // namespace
}  // namespace mm
