// The crowd's level of detail (crowd_scheduler.hpp): the settings refused by message, the tiers
// the cost model gives under a budget (worked out by hand), the most significant at full rate,
// hysteresis, the reduced rates' staggered updates, the move-only step, and a promotion to full
// rate without a pop.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "controller_support.hpp"
#include "mm/controller/crowd_scheduler.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;

// Costs whose sums are exact in float: full 8, half 3, quarter 2, move_only 0.5 us.
CrowdSchedulerSettings budgeted(float budget_us) {
  CrowdSchedulerSettings settings;
  settings.cost_us = {8.0f, 3.0f, 2.0f, 0.5f};
  settings.budget_ms = budget_us * 1e-3f;
  return settings;
}

CrowdScheduler make_scheduler(size_t characters, const CrowdSchedulerSettings& settings,
                              size_t joints = 1) {
  Result<CrowdScheduler> made = CrowdScheduler::create(characters, joints, settings);
  EXPECT_TRUE(made.ok()) << (made.ok() ? "" : made.message());
  return std::move(made).value();
}

std::array<int, kCrowdTierCount> counts(int full, int half, int quarter, int move_only) {
  return {full, half, quarter, move_only};
}

TEST(CrowdScheduler, RefusesBadSettingsByMessage) {
  auto message = [](const CrowdSchedulerSettings& settings) {
    Result<CrowdScheduler> made = CrowdScheduler::create(4, 4, settings);
    EXPECT_FALSE(made.ok());
    return made.ok() ? std::string() : made.message();
  };
  CrowdSchedulerSettings s;
  s.budget_ms = -1.0f;
  EXPECT_EQ(message(s), "crowd scheduler: budget_ms must be >= 0");
  s = {};
  s.threads = 0;
  EXPECT_EQ(message(s), "crowd scheduler: threads in [1, 1024]");
  s = {};
  s.cost_us[2] = 5.0f;
  EXPECT_EQ(message(s), "crowd scheduler: the cost of tier quarter is above the cost of tier half");
  s = {};
  s.cost_us[3] = 0.0f;
  EXPECT_EQ(message(s),
            "crowd scheduler: the cost of tier move_only must be a positive number of us");
  s = {};
  s.full_share = 1.5f;
  EXPECT_EQ(message(s), "crowd scheduler: full_share must be in [0, 1]");
  s = {};
  s.headroom = 1.0f;
  EXPECT_EQ(message(s), "crowd scheduler: headroom must be in [0, 1)");
  s.headroom = -0.1f;
  EXPECT_EQ(message(s), "crowd scheduler: headroom must be in [0, 1)");
  s = {};
  s.blend_halflife = 0.0f;
  EXPECT_EQ(message(s), "crowd scheduler: blend_halflife must be a positive number of seconds");
  Result<CrowdScheduler> none = CrowdScheduler::create(0, 4, CrowdSchedulerSettings{});
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.message(), "crowd scheduler: at least one character (and fewer than 2^32)");
  EXPECT_EQ(crowd_tier_name(CrowdTier::Full), "full");
  EXPECT_EQ(crowd_tier_name(CrowdTier::MoveOnly), "move_only");
}

// 12 characters at 22.25 us: the floor is move_only (12 * 2 = 24 > 22.25), 6 us; full rate gets
// at most 0.4 * 22.25 = 8.9 us: one character (+7.5, 13.5); quarters +1.5 each: five (21), a
// sixth would be 22.5; then a half +1: 22; another would be 23.
TEST(CrowdScheduler, TheBudgetIsSpentByTheCostModel) {
  CrowdScheduler scheduler = make_scheduler(12, budgeted(22.25f));
  std::vector<float> significance(12);
  for (size_t i = 0; i < 12; ++i) significance[i] = -static_cast<float>(i);
  scheduler.plan(significance);
  EXPECT_EQ(scheduler.tier_counts(), counts(1, 1, 4, 6));
  EXPECT_DOUBLE_EQ(scheduler.planned_cost_us(), 22.0);
  // Budgets that hold all at quarter (24 us: the floor) or all at full (96 us), or none.
  CrowdScheduler quarter = make_scheduler(12, budgeted(24.0f));
  quarter.plan(significance);
  EXPECT_EQ(quarter.tier_counts(), counts(0, 0, 12, 0));
  CrowdScheduler full = make_scheduler(12, budgeted(96.0f));
  full.plan(significance);
  EXPECT_EQ(full.tier_counts(), counts(12, 0, 0, 0));
  CrowdScheduler unbudgeted = make_scheduler(12, budgeted(0.0f));
  unbudgeted.plan(significance);
  EXPECT_EQ(unbudgeted.tier_counts(), counts(12, 0, 0, 0));
  // Over budget even with every character moved only: all move only.
  CrowdScheduler over = make_scheduler(12, budgeted(5.0f));
  over.plan(significance);
  EXPECT_EQ(over.tier_counts(), counts(0, 0, 0, 12));
  // Two threads hold twice the work.
  CrowdSchedulerSettings two = budgeted(11.125f);
  two.threads = 2;
  CrowdScheduler doubled = make_scheduler(12, two);
  doubled.plan(significance);
  EXPECT_EQ(doubled.tier_counts(), counts(1, 1, 4, 6));
}

// 20 characters at 60 us with half of it held back: 30 us to spend. The floor is move_only (20 *
// 2 = 40 > 30), 10 us; full rate may take 0.4 of the whole 60 us (three characters) but the
// third would bring the plan to 32.5: two (25); then quarters +1.5 each: three (29.5). The same
// crowd under a plain 30 us budget gets one at full rate (full_share of 30 is 12 us) and eight at
// quarter: the headroom comes out of the tiers below full.
TEST(CrowdScheduler, TheHeadroomIsTakenFromTheTiersBelowFull) {
  CrowdSchedulerSettings held = budgeted(60.0f);
  held.headroom = 0.5f;
  CrowdScheduler scheduler = make_scheduler(20, held);
  std::vector<float> significance(20);
  for (size_t i = 0; i < 20; ++i) significance[i] = -static_cast<float>(i);
  scheduler.plan(significance);
  EXPECT_EQ(scheduler.tier_counts(), counts(2, 0, 3, 15));
  EXPECT_DOUBLE_EQ(scheduler.planned_cost_us(), 29.5);
  CrowdScheduler plain = make_scheduler(20, budgeted(30.0f));
  plain.plan(significance);
  EXPECT_EQ(plain.tier_counts(), counts(1, 0, 8, 11));
  EXPECT_DOUBLE_EQ(plain.planned_cost_us(), 29.5);
  // A budget that holds everyone at full rate only without the headroom: not all at full.
  CrowdSchedulerSettings tight = budgeted(160.0f);
  tight.headroom = 0.25f;
  CrowdScheduler below = make_scheduler(20, tight);
  below.plan(significance);
  EXPECT_LT(below.tier_counts()[0], 20);
  EXPECT_LE(below.planned_cost_us(), 120.0);
}

// Any budget, any crowd: the plan never exceeds the budget once the floor fits, and tiers never
// rise as significance falls.
TEST(CrowdScheduler, TiersFollowSignificanceWithinTheBudget) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    const size_t n = 1 + random() % 300;
    const float budget_us = static_cast<float>(random() % 3000) * 0.5f + 1.0f;
    CrowdScheduler scheduler = make_scheduler(n, budgeted(budget_us));
    std::vector<float> significance(n);
    for (float& s : significance) s = static_cast<float>(random() % 100000) * 0.01f;
    scheduler.plan(significance);
    int sum = 0;
    for (const int c : scheduler.tier_counts()) sum += c;
    EXPECT_EQ(sum, static_cast<int>(n));
    if (static_cast<double>(n) * 0.5 <= budget_us) {
      EXPECT_LE(scheduler.planned_cost_us(), budget_us * (1.0 + 1e-6)) << n << " " << budget_us;
    }
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return significance[a] > significance[b]; });
    for (size_t r = 1; r < n; ++r) {
      if (significance[order[r]] == significance[order[r - 1]]) continue;
      EXPECT_LE(static_cast<int>(scheduler.tier(order[r - 1])),
                static_cast<int>(scheduler.tier(order[r])));
    }
  }
}

TEST(CrowdScheduler, HysteresisKeepsTiersUnderSmallChanges) {
  // Two characters, one of which the budget holds at full rate (8 + 0.5 <= 9, 16 > 9, the lower
  // rates nearly as dear as full) and with full_share 1; their significances cross back and
  // forth by 0.5, under the hysteresis of 1.
  CrowdSchedulerSettings settings = budgeted(9.0f);
  settings.cost_us = {8.0f, 7.9f, 7.8f, 0.5f};
  settings.full_share = 1.0f;
  settings.hysteresis = 1.0f;
  CrowdScheduler scheduler = make_scheduler(2, settings);
  std::vector<float> significance = {10.0f, 9.0f};
  scheduler.plan(significance);
  ASSERT_EQ(scheduler.tier(0), CrowdTier::Full);
  ASSERT_EQ(scheduler.tier(1), CrowdTier::MoveOnly);
  for (int f = 0; f < 20; ++f) {
    significance = f % 2 == 0 ? std::vector<float>{9.0f, 9.5f} : std::vector<float>{10.0f, 9.0f};
    scheduler.plan(significance);
    EXPECT_EQ(scheduler.tier(0), CrowdTier::Full) << f;
  }
  // A change beyond the hysteresis (full holds 3 tiers' worth over move_only: 3) swaps them.
  significance = {9.0f, 12.5f};
  scheduler.plan(significance);
  EXPECT_EQ(scheduler.tier(0), CrowdTier::MoveOnly);
  EXPECT_EQ(scheduler.tier(1), CrowdTier::Full);
  // Without hysteresis the small crossing swaps them at once.
  settings.hysteresis = 0.0f;
  CrowdScheduler eager = make_scheduler(2, settings);
  eager.plan(std::vector<float>{10.0f, 9.0f});
  eager.plan(std::vector<float>{9.0f, 9.5f});
  EXPECT_EQ(eager.tier(1), CrowdTier::Full);
}

// Characters of the normal database, 3 m apart in a row.
// Controllers as a scheduled crowd has them: what is drawn is the scheduler's pose, so they
// compute no skinning matrices (with them, a move settles the whole pose every step).
std::vector<Controller> make_row(size_t n) {
  ControllerSettings settings;
  settings.compute_skinning = false;
  std::vector<Controller> row;
  for (size_t i = 0; i < n; ++i) {
    row.push_back(test::make_controller(settings));
    row.back().teleport(glm::vec3(static_cast<float>(i) * 3.0f, 0.0f, 0.0f), 0.0f);
  }
  return row;
}

// The largest distance any joint of the shown pose moved from `before` (m).
float largest_move(std::span<const Transform> before, std::span<const Transform> after) {
  float largest = 0.0f;
  for (size_t j = 0; j < before.size(); ++j) {
    largest = std::max(largest, glm::distance(before[j].translation, after[j].translation));
  }
  return largest;
}

// What character i shows: its pose with its carry applied.
std::vector<Transform> displayed(const CrowdScheduler& scheduler, size_t i) {
  std::vector<Transform> out(scheduler.joints());
  scheduler.displayed_pose(i, out);
  return out;
}

TEST(CrowdScheduler, ReducedRatesUpdateOnStaggeredFramesAndShowTheUpdatesPose) {
  std::vector<Controller> row = make_row(8);
  const size_t joints = row[0].global_transforms().size();
  CrowdScheduler scheduler = make_scheduler(8, CrowdSchedulerSettings{}, joints);
  const ControllerInput walk = test::push_toward(0.0f);
  std::array<int, 8> updates{};
  for (int f = 0; f < 16; ++f) {
    scheduler.plan_all(f < 8 ? CrowdTier::Quarter : CrowdTier::Half);
    int this_frame = 0;
    for (size_t i = 0; i < 8; ++i) {
      const bool updated = scheduler.updates(i);
      this_frame += updated;
      updates[i] += updated;
      scheduler.step(i, row[i], kDt, walk);
    }
    // Staggered: even work per frame (the frame after the change of rate also takes the
    // characters that the half rate finds due at once).
    if (f != 8) {
      EXPECT_EQ(this_frame, f < 8 ? 2 : 4) << "frame " << f;
    }
    if (f == 7) updates.fill(0);
  }
  for (size_t i = 0; i < 8; ++i) EXPECT_GE(updates[i], 4) << i;
  // A half-rate character updated this frame shows half way to its controller's pose, one
  // updated the frame before shows it exactly.
  scheduler.plan_all(CrowdTier::Half);
  for (size_t i = 0; i < 8; ++i) {
    const bool updated = scheduler.updates(i);
    scheduler.step(i, row[i], kDt, walk);
    const float behind = largest_move(scheduler.pose(i), row[i].global_transforms());
    if (updated) {
      EXPECT_GT(behind, 1e-3f) << i;
    } else {
      EXPECT_EQ(behind, 0.0f) << i;
    }
  }
}

TEST(CrowdScheduler, AMoveOnlyCharacterMovesWithItsSimulationAndKeepsItsPose) {
  std::vector<Controller> row = make_row(1);
  const size_t joints = row[0].global_transforms().size();
  CrowdScheduler scheduler = make_scheduler(1, CrowdSchedulerSettings{}, joints);
  const ControllerInput walk = test::push_toward(90.0f);  // toward +X
  for (int f = 0; f < 60; ++f) {
    scheduler.plan_all(CrowdTier::Full);
    scheduler.step(0, row[0], kDt, walk);
  }
  const std::vector<Transform> start(row[0].global_transforms().begin(),
                                     row[0].global_transforms().end());
  std::vector<Transform> held;
  for (int f = 0; f < 60; ++f) {
    scheduler.plan_all(CrowdTier::MoveOnly);
    scheduler.step(0, row[0], kDt, walk);
    // Once its blend has died away, the held pose is no longer rewritten: only the carry moves.
    if (f == 50) held.assign(scheduler.pose(0).begin(), scheduler.pose(0).end());
  }
  const std::vector<Transform> moved = displayed(scheduler, 0);
  // A second of walking: the root went on along +X.
  EXPECT_GT(moved[0].translation.x - start[0].translation.x, 0.8f);
  EXPECT_EQ(moved[0].translation, row[0].root_transform().translation);
  // Rigidly: every joint keeps its distance to the root.
  for (size_t j = 1; j < joints; ++j) {
    EXPECT_NEAR(glm::distance(moved[j].translation, moved[0].translation),
                glm::distance(start[j].translation, start[0].translation), 1e-4f)
        << j;
  }
  ASSERT_EQ(held.size(), joints);
  for (size_t j = 0; j < joints; ++j) {
    EXPECT_EQ(scheduler.pose(0)[j].translation, held[j].translation) << j;
  }
  EXPECT_GT(glm::length(scheduler.carry(0).translation), 0.1f);
  // The controller moved only its root; settled, its pose is the one shown.
  EXPECT_TRUE(row[0].pose_carried());
  row[0].settle_carried_pose();
  EXPECT_FALSE(row[0].pose_carried());
  EXPECT_LT(largest_move(moved, row[0].global_transforms()), 1e-4f);
}

// A character at quarter rate (shown one period late) promoted to full rate: on the promotion
// frame the shown pose does not jump, and on the frames after it moves no more than a little
// beyond the most a full-rate character's joints move in a frame.
TEST(CrowdScheduler, APromotionToFullRateDoesNotPop) {
  for (const CrowdTier from : {CrowdTier::Quarter, CrowdTier::Half, CrowdTier::MoveOnly}) {
    std::vector<Controller> row = make_row(2);
    const size_t joints = row[0].global_transforms().size();
    CrowdScheduler scheduler = make_scheduler(2, CrowdSchedulerSettings{}, joints);
    const ControllerInput run = test::push_toward(30.0f, true);
    float full_rate_largest = 0.0f;
    std::vector<Transform> before(joints);
    for (int f = 0; f < 150; ++f) {
      // Character 1 runs at full rate throughout: the reference for a frame's motion.
      scheduler.plan_all(CrowdTier::Full);
      if (f >= 60) {
        std::copy(scheduler.pose(1).begin(), scheduler.pose(1).end(), before.begin());
      }
      scheduler.step(1, row[1], kDt, run);
      if (f >= 60) {
        full_rate_largest = std::max(full_rate_largest, largest_move(before, scheduler.pose(1)));
      }
    }
    // Character 0: a second at full rate, a second at `from`, then promoted.
    scheduler.plan_all(CrowdTier::Full);
    for (int f = 0; f < 60; ++f) scheduler.step(0, row[0], kDt, run);
    scheduler.plan_all(from);
    for (int f = 0; f < 61; ++f) scheduler.step(0, row[0], kDt, run);
    scheduler.plan_all(CrowdTier::Full);
    scheduler.displayed_pose(0, before);
    scheduler.step(0, row[0], kDt, run);
    const float promotion = largest_move(before, displayed(scheduler, 0));
    // Without the blend the pose would jump to its controller's at once: by the frames a
    // reduced rate shows late (more than the most a full-rate joint moves in one frame), or
    // from a moved pose to an animated one.
    const float unblended = largest_move(before, row[0].global_transforms());
    EXPECT_GT(unblended, from == CrowdTier::MoveOnly ? 0.02f : full_rate_largest)
        << crowd_tier_name(from);
    EXPECT_LT(promotion, 1e-5f) << crowd_tier_name(from);
    float after = 0.0f;
    for (int f = 0; f < 30; ++f) {
      scheduler.displayed_pose(0, before);
      scheduler.step(0, row[0], kDt, run);
      after = std::max(after, largest_move(before, displayed(scheduler, 0)));
    }
    EXPECT_LT(after, 2.0f * full_rate_largest) << crowd_tier_name(from);
    // And it has caught up with its controller.
    EXPECT_LT(largest_move(displayed(scheduler, 0), row[0].global_transforms()), 0.01f);
  }
}

}  // namespace
}  // namespace mm
