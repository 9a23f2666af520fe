// The obstacles the animated root met lately, held as half-planes (character_mover.hpp,
// HeldContacts): the end of a move pushing past one stays on its line and slides along it, the
// same way on every update, until the obstacle is kMemory unmet or the move goes kRelease away.

#include <gtest/gtest.h>

#include "mm/controller/character_mover.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;

// A move that met a wall whose face runs along z, at x = 1.01 (its normal -x), ending kSkin short.
MoveResult met_wall_at(float z) {
  MoveResult m;
  m.position = glm::vec3(1.0f, 0.0f, z);
  m.blocked = true;
  m.normal = glm::vec3(-1.0f, 0.0f, 0.0f);
  return m;
}

MoveResult free_move_to(const glm::vec3& end) {
  MoveResult m;
  m.position = end;
  return m;
}

TEST(HeldContacts, AMovePushingPastAWallItMetSlidesAlongItsLineOnEveryUpdate) {
  HeldContacts held;
  glm::vec3 end = met_wall_at(0.0f).position;
  held.hold(end, met_wall_at(0.0f), kDt);
  ASSERT_EQ(held.count(), 1);
  // The next updates' moves miss the face (they start inside the skin and stop short of it):
  // free moves 5 mm past the line and 1 cm along it are held on the line, their part along kept.
  for (int update = 1; update <= 10; ++update) {
    const glm::vec3 goal(1.005f, 0.0f, 0.01f * static_cast<float>(update));
    end = goal;
    held.hold(end, free_move_to(goal), kDt);
    EXPECT_FLOAT_EQ(end.x, 1.0f) << update;
    EXPECT_FLOAT_EQ(end.z, goal.z) << update;
  }
}

TEST(HeldContacts, AMoveAwayOrAlongIsNotHeld) {
  HeldContacts held;
  glm::vec3 end = met_wall_at(0.0f).position;
  held.hold(end, met_wall_at(0.0f), kDt);
  const glm::vec3 along(1.0f, 0.0f, 0.3f), away(0.99f, 0.0f, 0.0f);
  for (const glm::vec3& goal : {along, away}) {
    end = goal;
    held.hold(end, free_move_to(goal), kDt);
    EXPECT_EQ(end, goal);
  }
}

TEST(HeldContacts, AnObstacleUnmetForItsMemoryOrLeftBehindIsForgotten) {
  {
    HeldContacts held;
    glm::vec3 end = met_wall_at(0.0f).position;
    held.hold(end, met_wall_at(0.0f), kDt);
    // Pushed against but never met again (the wall ended): held until kMemory, then free.
    int held_updates = 0;
    for (int update = 0; update < 60; ++update) {
      const glm::vec3 goal(1.005f, 0.0f, 0.0f);
      end = goal;
      held.hold(end, free_move_to(goal), kDt);
      if (end.x == 1.0f) ++held_updates;
    }
    EXPECT_EQ(held.count(), 0);
    EXPECT_NEAR(static_cast<float>(held_updates) * kDt, HeldContacts::kMemory, 1.5f * kDt);
  }
  {
    HeldContacts held;
    glm::vec3 end = met_wall_at(0.0f).position;
    held.hold(end, met_wall_at(0.0f), kDt);
    const glm::vec3 away(1.0f - 1.5f * HeldContacts::kRelease, 0.0f, 0.0f);
    end = away;
    held.hold(end, free_move_to(away), kDt);
    EXPECT_EQ(held.count(), 0);
  }
}

// A corner: a wall met, then a ledge's edge beside it (a cancelled move reports the edge): the
// end is held inside both, and the same wall met again moves its line rather than adding one.
TEST(HeldContacts, InACornerTheEndIsHeldInsideBoth) {
  HeldContacts held;
  glm::vec3 end = met_wall_at(0.0f).position;
  held.hold(end, met_wall_at(0.0f), kDt);
  MoveResult ledge;
  ledge.position = glm::vec3(1.0f, 0.0f, 2.0f);
  ledge.no_ground = true;
  ledge.edge_normal = glm::vec3(0.0f, 0.0f, -1.0f);
  end = ledge.position;
  held.hold(end, ledge, kDt);
  EXPECT_EQ(held.count(), 2);
  const glm::vec3 into_both(1.004f, 0.0f, 2.004f);
  end = into_both;
  held.hold(end, free_move_to(into_both), kDt);
  EXPECT_FLOAT_EQ(end.x, 1.0f);
  EXPECT_FLOAT_EQ(end.z, 2.0f);
  end = met_wall_at(1.99f).position;
  held.hold(end, met_wall_at(1.99f), kDt);
  EXPECT_EQ(held.count(), 2);
}

TEST(HeldContacts, AMovePushingPastALineReachesDeeperToMeetItAgain) {
  HeldContacts held;
  glm::vec3 end = met_wall_at(0.0f).position;
  held.hold(end, met_wall_at(0.0f), kDt);
  const glm::vec3 into(1.003f, 0.0f, 0.01f), away(0.99f, 0.0f, 0.01f);
  EXPECT_FLOAT_EQ(held.reach(into).x, into.x + HeldContacts::kReach);
  EXPECT_EQ(held.reach(away), away);
  // Moved with the origin, the line stays where it is in the world.
  held.shift(glm::vec3(-1.0f, 0.0f, 0.0f));
  end = glm::vec3(0.005f, 0.0f, 0.0f);
  held.hold(end, free_move_to(end), kDt);
  EXPECT_FLOAT_EQ(end.x, 0.0f);
}

}  // namespace
}  // namespace mm
