#include "mm/controller/character_mover.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analytic_world.hpp"

namespace mm {
namespace {

using test::AnalyticBox;
using test::AnalyticWorld;

constexpr float kTolerance = 1e-4f;

CharacterShape shape() {
  return CharacterShape{};
}  // r 0.3, step 0.35, down 0.5, slope 0.7

// A wall across +Z: its near face at z = `face`, tall.
AnalyticBox wall_across_z(float face) {
  return AnalyticBox{glm::vec2(0.0f, face + 0.1f), glm::vec2(10.0f, 0.1f), 0.0f, 3.0f};
}

TEST(CharacterMover, OnFlatGroundAMoveGoesWhereItWasSentInTwoCalls) {
  AnalyticWorld world;
  CharacterMover mover;
  const MoveResult m =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(1, 0, 2), glm::vec3(1.5f, 7, 2.25f));
  EXPECT_NEAR(m.position.x, 1.5f, kTolerance);
  EXPECT_NEAR(m.position.y, 0.0f, kTolerance);  // the goal's y is ignored: on the ground
  EXPECT_NEAR(m.position.z, 2.25f, kTolerance);
  EXPECT_FALSE(m.blocked);
  EXPECT_FALSE(m.no_ground);
  EXPECT_EQ(world.sweep_calls.load(), 1);  // nothing hit: no slide
  EXPECT_EQ(world.probe_calls.load(), 1);
}

TEST(CharacterMover, HeadOnIntoAWallItStopsTheRadiusAndTheSkinShort) {
  AnalyticWorld world;
  world.boxes.push_back(wall_across_z(2.0f));
  CharacterMover mover;
  const MoveResult m =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0, 0, 1.0f), glm::vec3(0, 0, 3.0f));
  EXPECT_TRUE(m.blocked);
  EXPECT_NEAR(m.position.z, 2.0f - 0.3f - CharacterMover::kSkin, 1e-3f);
  EXPECT_NEAR(m.position.x, 0.0f, kTolerance);
  EXPECT_NEAR(m.normal.z, -1.0f, kTolerance);
  // Pushing again from there goes nowhere, and never into the wall.
  const MoveResult again =
      mover.move(world, glm::dvec3(0.0), shape(), m.position, m.position + glm::vec3(0, 0, 0.5f));
  EXPECT_LE(again.position.z, 2.0f - 0.3f + kTolerance);
  EXPECT_NEAR(again.position.x, 0.0f, kTolerance);
}

TEST(CharacterMover, DiagonallyIntoAWallItSlidesAlongIt) {
  AnalyticWorld world;
  // A wall along a line 30 degrees off +Z: pushing along +Z runs into it at an angle.
  const float yaw = glm::radians(30.0f);
  world.boxes.push_back(AnalyticBox{glm::vec2(1.0f, 0.0f), glm::vec2(0.1f, 20.0f), yaw, 3.0f});
  CharacterMover mover;
  glm::vec3 p(0.0f, 0.0f, -3.0f);
  float along = 0.0f;
  const glm::vec3 tangent(std::sin(yaw), 0.0f, std::cos(yaw));
  const glm::vec3 wall_normal(std::cos(yaw), 0.0f, -std::sin(yaw));  // toward the walker
  for (int step = 0; step < 200; ++step) {
    const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0, 0, 0.05f));
    along += glm::dot(m.position - p, tangent);
    p = m.position;
    // The capsule never enters the wall's grown footprint.
    const float distance = glm::dot(p - glm::vec3(1.0f, 0.0f, 0.0f), wall_normal);
    ASSERT_GE(distance, 0.1f + 0.3f - 1e-3f) << step;
  }
  // 200 pushes of 5 cm, blocked after about 9: it keeps moving along the wall at cos(30) of the
  // push, which gains cos(30)^2 of it in z.
  EXPECT_GT(along, 0.9f * 200 * 0.05f * std::cos(yaw));
  EXPECT_NEAR(p.z, -3.0f + 0.45f + 191 * 0.05f * 0.75f, 0.1f);
}

TEST(CharacterMover, StepsUpToTheStepHeightAndNoHigher) {
  AnalyticWorld world;
  world.boxes.push_back(AnalyticBox{glm::vec2(0.0f, 2.0f), glm::vec2(2.0f, 1.0f), 0.0f, 0.17f});
  world.boxes.push_back(AnalyticBox{glm::vec2(5.0f, 2.0f), glm::vec2(2.0f, 1.0f), 0.0f, 0.5f});
  CharacterMover mover;
  const MoveResult up =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0, 0, 0.9f), glm::vec3(0, 0, 1.1f));
  EXPECT_FALSE(up.blocked);
  EXPECT_NEAR(up.position.y, 0.17f, kTolerance);
  EXPECT_NEAR(up.position.z, 1.1f, kTolerance);
  const MoveResult high =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(5, 0, 0.5f), glm::vec3(5, 0, 1.1f));
  EXPECT_TRUE(high.blocked);
  EXPECT_NEAR(high.position.y, 0.0f, kTolerance);
  EXPECT_NEAR(high.position.z, 1.0f - 0.3f - CharacterMover::kSkin, 1e-3f);
}

TEST(CharacterMover, StepsDownUpToMaxStepDownAndStopsAtALedge) {
  AnalyticWorld world;
  world.height = [](double, double z) { return z < 1.0 ? 0.0 : (z < 2.0 ? -0.3 : -1.5); };
  CharacterMover mover;
  const MoveResult down =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0, 0, 0.9f), glm::vec3(0, 0, 1.1f));
  EXPECT_NEAR(down.position.y, -0.3f, kTolerance);
  EXPECT_FALSE(down.no_ground);
  const MoveResult ledge =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0, -0.3f, 1.9f), glm::vec3(0, 0, 2.1f));
  EXPECT_TRUE(ledge.no_ground);
  EXPECT_EQ(ledge.position, glm::vec3(0, -0.3f, 1.9f));  // stays where it was
}

TEST(CharacterMover, AtALedgeDeeperThanAStepItStopsBackFromTheEdge) {
  // A 0.45 m drop at z = 1: within max_step_down (0.5) but deeper than step_height (0.35).
  // Stepped off, the lifted capsule would overlap the edge and walk back through its side.
  AnalyticWorld world;
  world.height = [](double, double z) { return z < 1.0 ? 0.0 : -0.45; };
  CharacterMover mover;
  glm::vec3 p(0.0f, 0.0f, 0.0f);
  bool stopped = false;
  for (int step = 0; step < 100; ++step) {
    const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0, 0, 0.02f));
    stopped = stopped || (m.blocked && m.edge);
    p = m.position;
  }
  EXPECT_TRUE(stopped);
  EXPECT_EQ(p.y, 0.0f);
  // Held a radius back, where the ring around the capsule first met the drop (the probe ahead,
  // half a radius out, never did): the centre, and with it the feet, stay back from the edge.
  const float r = shape().radius;
  EXPECT_LE(p.z, 1.0f - r);
  EXPECT_GT(p.z, 1.0f - CharacterMover::kEdgeRing * r - 0.021f);
  // A trajectory sample 0.8 m away, three 14 cm steps down (0.42 m, deeper than a step), is on
  // no ledge: only the ground ahead of a move's end, against the end's own, makes one.
  AnalyticWorld stairs;
  stairs.height = [](double, double z) {
    return z < 0.0 ? 0.0 : -0.14 * (1.0 + std::floor(z / 0.3));
  };
  const MoveResult far =
      mover.move(stairs, glm::dvec3(0.0), shape(), glm::vec3(0, 0, -0.1f), glm::vec3(0, 0, 0.7f));
  EXPECT_FALSE(far.no_ground);
  EXPECT_NEAR(far.position.y, -0.42f, kTolerance);
}

// A platform's side edge at x = 1 (a 0.64 m drop beyond, as the second course's platforms).
void platform_edge_at_x1(AnalyticWorld& world) {
  world.height = [](double x, double) { return x < 1.0 ? 0.0 : -0.64; };
}

TEST(CharacterMover, AlongALedgesEdgeTheCentreStaysARadiusFromIt) {
  // With the probe ahead only, a move along the edge let the centre come within centimetres of
  // it, a foot planted on air.
  AnalyticWorld world;
  platform_edge_at_x1(world);
  CharacterMover mover;
  const float r = shape().radius;
  // Slanting toward the edge at 22 degrees: it goes on along it, its centre a radius back.
  glm::vec3 p(0.5f, 0.0f, 0.0f);
  for (int step = 0; step < 100; ++step) {
    const MoveResult m =
        mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0.02f, 0, 0.05f));
    ASSERT_FALSE(m.no_ground) << step;
    p = m.position;
    ASSERT_LE(p.x, 1.0f - r + 1e-4f) << step;
  }
  EXPECT_EQ(p.y, 0.0f);
  EXPECT_NEAR(p.z, 100 * 0.05f, 1e-3f);  // the part along the edge is never held back
  // Met: blocked by the edge, its normal pointing away from the drop.
  const MoveResult m =
      mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0.02f, 0, 0.05f));
  EXPECT_TRUE(m.blocked && m.edge);
  EXPECT_NEAR(m.normal.x, -1.0f, kTolerance);
  EXPECT_NEAR(m.edge_normal.x, -1.0f, kTolerance);
}

TEST(CharacterMover, SlowlyIntoALedgesEdgeItSlidesAlongIt) {
  // Probes turned with the move pointed a new way on every update of a slow move, each took
  // another part of the velocity away, and the character stood at the edge (1.7 s circling
  // on a platform). The ring is fixed: the slide goes on at the speed along the edge.
  AnalyticWorld world;
  platform_edge_at_x1(world);
  CharacterMover mover;
  glm::vec3 p(0.75f, 0.0f, 0.0f);
  for (int step = 0; step < 50; ++step) {
    const glm::vec3 push =
        step % 2 == 0 ? glm::vec3(0.004f, 0, 0.001f) : glm::vec3(0.003f, 0, 0.0012f);
    const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), p, p + push);
    ASSERT_TRUE(m.blocked) << step;
    ASSERT_NEAR(m.normal.x, -1.0f, kTolerance) << step;
    ASSERT_NEAR(m.position.z - p.z, push.z, 1e-5f) << step;
    ASSERT_NEAR(m.position.x, p.x, 1e-5f) << step;
    p = m.position;
  }
}

TEST(CharacterMover, WalkingAwayFromALedgesEdgeIsNeverBlocked) {
  AnalyticWorld world;
  platform_edge_at_x1(world);
  CharacterMover mover;
  // Started nearer than a radius (stepped there where the drop was lower, or placed; not within
  // half a radius, where the probe ahead cancels a move toward the edge): every move with no
  // part toward the edge goes the whole way, and says where the edge is.
  for (const glm::vec3& away : {glm::vec3(-0.05f, 0, 0), glm::vec3(-0.05f, 0, 0.05f),
                                glm::vec3(-0.01f, 0, -0.05f), glm::vec3(0, 0, 0.05f)}) {
    const glm::vec3 p(0.8f, 0.0f, 0.0f);
    const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), p, p + away);
    EXPECT_FALSE(m.blocked || m.no_ground || m.edge);
    EXPECT_NEAR(m.position.x, p.x + away.x, 1e-5f);
    EXPECT_NEAR(m.position.z, p.z + away.z, 1e-5f);
    EXPECT_NEAR(m.edge_normal.x, -1.0f, kTolerance);
  }
  // Toward it from there: held where it is across, the part along goes on.
  const glm::vec3 p(0.8f, 0.0f, 0.0f);
  const MoveResult m =
      mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0.05f, 0, 0.05f));
  EXPECT_TRUE(m.blocked && m.edge);
  EXPECT_NEAR(m.position.x, 0.8f, 1e-5f);
  EXPECT_NEAR(m.position.z, 0.05f, 1e-5f);
}

TEST(CharacterMover, AFarMoveSeesNoEdgeAndALedgeAheadGivesItsDirection) {
  AnalyticWorld world;
  platform_edge_at_x1(world);
  CharacterMover mover;
  // A trajectory sample a metre away is judged by its own ground only: no ring around it.
  const MoveResult far =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0, 0, 0), glm::vec3(0.65f, 0, 1.0f));
  EXPECT_FALSE(far.blocked || far.no_ground);
  EXPECT_EQ(far.edge_normal, glm::vec3(0.0f));
  // Straight at the edge from within half a radius: the move is cancelled (no ground ahead),
  // and the edge faces back along it, for the trajectory.
  const MoveResult ahead =
      mover.move(world, glm::dvec3(0.0), shape(), glm::vec3(0.8f, 0, 0), glm::vec3(0.9f, 0, 0));
  EXPECT_TRUE(ahead.no_ground);
  EXPECT_NEAR(ahead.edge_normal.x, -1.0f, kTolerance);
}

TEST(CharacterMover, DownSteepStairsNoTreadIsALedge) {
  // 20 cm risers on 25 cm treads: the ring's probes, a radius out, see two risers down (40 cm,
  // deeper than a step), each of their two hops one riser at most.
  AnalyticWorld world;
  world.height = [](double, double z) {
    return z < 0.0 ? 0.0 : -0.2 * (1.0 + std::floor(z / 0.25));
  };
  CharacterMover mover;
  glm::vec3 p(0.0f, 0.0f, -0.505f);  // no end on an edge, where the analytic normal is steep
  for (int step = 0; step < 100; ++step) {
    const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0, 0, 0.02f));
    ASSERT_FALSE(m.blocked || m.no_ground) << step;
    ASSERT_EQ(m.edge_normal, glm::vec3(0.0f)) << step;
    p = m.position;
  }
  EXPECT_NEAR(p.z, 1.495f, 1e-3f);
  EXPECT_NEAR(p.y, -0.2f * 6.0f, kTolerance);
}

TEST(CharacterMover, WalksUpAWalkableSlopeButNotASteepOne) {
  AnalyticWorld world;
  const double gentle = std::tan(glm::radians(20.0));
  const double steep = std::tan(glm::radians(50.0));
  world.height = [=](double x, double z) { return z > 0.0 ? z * (x < 5.0 ? gentle : steep) : 0.0; };
  CharacterMover mover;
  glm::vec3 p(0.0f, 0.0f, -0.5f);
  for (int step = 0; step < 60; ++step) {
    p = mover.move(world, glm::dvec3(0.0), shape(), p, p + glm::vec3(0, 0, 0.05f)).position;
  }
  EXPECT_NEAR(p.z, 2.5f, 1e-3f);
  EXPECT_NEAR(p.y, 2.5 * gentle, 1e-3);
  glm::vec3 q(6.0f, 0.0f, -0.5f);
  for (int step = 0; step < 60; ++step) {
    q = mover.move(world, glm::dvec3(0.0), shape(), q, q + glm::vec3(0, 0, 0.05f)).position;
  }
  // The first step onto a 50-degree slope is too steep: it stays at its foot.
  EXPECT_LT(q.z, 0.05f);
  EXPECT_LT(q.y, 0.05f);
}

TEST(CharacterMover, ABatchIsThreeCallsWhateverItsSize) {
  AnalyticWorld world;
  world.boxes.push_back(wall_across_z(2.0f));
  CharacterMover mover;
  const std::vector<glm::vec3> starts(8, glm::vec3(0.0f));
  std::vector<glm::vec3> goals;
  for (int i = 0; i < 8; ++i) goals.emplace_back(0.3f * i, 0.0f, 0.5f * i);
  std::vector<MoveResult> out(8);
  mover.collide(world, glm::dvec3(0.0), shape(), starts, goals, out);
  EXPECT_EQ(world.sweep_calls.load(), 2);  // the sweeps, then the slides of those that hit
  EXPECT_EQ(world.probe_calls.load(), 1);
  for (int i = 0; i < 8; ++i) {
    EXPECT_LE(out[i].position.z, 2.0f - 0.3f + kTolerance) << i;
    EXPECT_EQ(out[i].blocked, 0.5f * i > 1.7f) << i;
    if (out[i].blocked) {
      // It slid sideways along the wall by what the hit cut off.
      EXPECT_GT(out[i].position.x, 0.3f * i * 1.7f / (0.5f * i) - kTolerance) << i;
    }
  }
}

TEST(CharacterMover, GarbageAnswersAreIgnoredAndCounted) {
  AnalyticWorld world;
  world.garbage = true;
  CharacterMover mover;
  const glm::vec3 start(1.0f, 0.0f, 1.0f);
  const MoveResult m = mover.move(world, glm::dvec3(0.0), shape(), start, glm::vec3(2, 0, 2));
  // The sweep's NaN is no hit; the probe's NaN point is no ground: the move is cancelled.
  EXPECT_EQ(m.position, start);
  EXPECT_TRUE(m.no_ground);
  EXPECT_EQ(mover.rejected(), 2);
}

TEST(CharacterMover, AHundredKilometresOutItMovesAsAtTheOrigin) {
  AnalyticWorld near_world, far_world;
  const double far = 100000.0;
  for (AnalyticWorld* w : {&near_world, &far_world}) {
    w->boxes.push_back(wall_across_z(2.0f));
    w->height = [](double, double z) { return z > 1.0 ? 0.1 * (z - 1.0) : 0.0; };
  }
  far_world.offset = glm::dvec3(far, 0.0, -far);
  CharacterMover mover;
  const glm::vec3 start(0.0f, 0.0f, 0.5f), goal(0.4f, 0.0f, 3.0f);
  const MoveResult a = mover.move(near_world, glm::dvec3(0.0), shape(), start, goal);
  const MoveResult b = mover.move(far_world, glm::dvec3(far, 0.0, -far), shape(), start, goal);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.normal, b.normal);
}

}  // namespace
}  // namespace mm
