// update() never allocates: every operator new of this program is counted while controllers
// walk, run, turn, strafe, stop, request tags and get bad input.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>

#include "analytic_world.hpp"
#include "controller_support.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// The replacements pair malloc with free; GCC cannot see that and warns about every delete.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, std::align_val_t align) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return operator new(size, align);
}
// The nothrow forms too (std::stable_sort's buffer uses them): every form must come from here,
// or a delete below would free what another allocator made.
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size ? size : 1);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return operator new(size, std::nothrow);
}
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t a = static_cast<std::size_t>(align);
  return std::aligned_alloc(a, (size + a - 1) / a * a);
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  return operator new(size, align, std::nothrow);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

namespace mm {
namespace {

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
