// BulletWorld's queries never allocate: every operator new of this program
// (allocation_counter.hpp) and every allocation Bullet makes (its btAlignedAlloc, routed here) is
// counted while probes and sweeps run over the test course, from the very first query.

#include <gtest/gtest.h>

#include <LinearMath/btAlignedAllocator.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "allocation_counter.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/course.hpp"
#include "mm/world/level.hpp"

namespace {
std::atomic<long> g_bullet_allocations{0};

void* bullet_alloc(size_t size) {
  g_bullet_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size ? size : 1);
}
void bullet_free(void* p) {
  std::free(p);
}
}  // namespace

namespace mm {
namespace {

using test::g_allocations;

TEST(BulletWorldNoAllocation, QueriesNeverAllocate) {
  // Before Bullet allocates anything, so that every block it frees came from bullet_alloc.
  btAlignedAllocSetCustom(&bullet_alloc, &bullet_free);
  const std::vector<unsigned char> bytes = course_glb();
  Result<Level> level = parse_level(bytes, "course.glb");
  ASSERT_TRUE(level.ok()) << level.message();
  Result<BulletWorld> made = BulletWorld::create(*level);
  ASSERT_TRUE(made.ok()) << made.message();
  BulletWorld& world = *made;
  ASSERT_TRUE(world.add_box({{3.0, 0.5, -1.0}, {0.5f, 0.5f, 0.5f}, 0.3f}).ok());
  // Both counters see allocations at all.
  EXPECT_GT(g_bullet_allocations.load(), 0);
  EXPECT_GT(g_allocations.load(), 0);

  // Batches of 16 probes and 16 sweeps over the whole course, in the caller's buffers.
  constexpr size_t kBatch = 16;
  std::vector<GroundProbe> probes(kBatch);
  std::vector<ShapeSweep> sweeps(kBatch);
  std::vector<GroundHit> ground(kBatch);
  std::vector<SweepHit> swept(kBatch);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> x(-2.0f, 34.0f);
  std::uniform_real_distribution<float> z(-2.0f, 19.0f);
  std::uniform_real_distribution<float> step(-1.5f, 1.5f);
  const long before = g_allocations.load();
  const long bullet_before = g_bullet_allocations.load();
  int probe_hits = 0;
  int sweep_hits = 0;
  for (int batch = 0; batch < 500; ++batch) {
    for (size_t i = 0; i < kBatch; ++i) {
      probes[i] = {{x(rng), 2.5f, z(rng)}, 3.0f, 0.7f};
      const glm::vec3 from(x(rng), 0.35f, z(rng));
      sweeps[i] = {from, from + glm::vec3(step(rng), 0.0f, step(rng)), 0.3f, 1.7f};
    }
    world.probe_ground(glm::dvec3(0.0), probes, ground);
    world.sweep(glm::dvec3(0.0), sweeps, swept);
    for (size_t i = 0; i < kBatch; ++i) {
      probe_hits += ground[i].hit ? 1 : 0;
      sweep_hits += swept[i].hit ? 1 : 0;
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(g_bullet_allocations.load() - bullet_before, 0);
  EXPECT_EQ(probe_hits, 500 * 16);  // the ground is everywhere
  EXPECT_GT(sweep_hits, 200);       // and the sweeps meet ramps, steps, walls and boxes
}

}  // namespace
}  // namespace mm
