// Big worlds (issue 20): a character far from the world origin moves exactly as well as one at
// it. The controller keeps its state relative to a local origin that follows the character
// (local_origin.hpp); these tests run it 10 km and 100 km away.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "controller_support.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 60.0f;

// The README's showcase script: walk, turn, run, stop and stand, walk back, strafe.
InputScript showcase_script() {
  const auto path = std::filesystem::path(MM_SOURCE_DIR) / "scripts" / "input" / "showcase.txt";
  Result<InputScript> script = load_input_script(path);
  EXPECT_TRUE(script.ok()) << (script.ok() ? "" : script.message());
  return script.ok() ? *script : InputScript{};
}

double foot_skating_from(const glm::dvec2& start) {
  EvaluationOptions options;
  options.start = start;
  Result<EvaluationResult> run =
      evaluate_script(test::normal_controller_database(), showcase_script(), options);
  EXPECT_TRUE(run.ok()) << (run.ok() ? "" : run.message());
  return run.ok() ? run->metrics.foot_skate_cm_s_mean : -1.0;
}

// Floats 10 km out are a millimetre apart and 100 km out 8 mm: without a local origin the feet
// skate by whole centimetres per second there.
TEST(BigWorld, FootSkatingTenAndAHundredKilometresAwayMatchesTheOrigin) {
  const double at_origin = foot_skating_from({0.0, 0.0});
  ASSERT_GT(at_origin, 0.0);  // the script plants feet: there is skating to compare
  // Along both axes at once (6-8-10), in two different quadrants.
  EXPECT_NEAR(foot_skating_from({6000.0, 8000.0}), at_origin, 0.05) << "10 km";
  EXPECT_NEAR(foot_skating_from({-60000.0, 80000.0}), at_origin, 0.05) << "100 km";
}

// The origin moves with the character in whole metres, the local positions stay small, and the
// world transforms, the double root position and the local ones agree.
TEST(BigWorld, TheLocalOriginFollowsTheCharacter) {
  Controller c = test::make_controller();
  const glm::dvec3 start(100000.0, 0.0, -100000.0);
  c.teleport_world(start, 0.0f);
  EXPECT_EQ(c.origin(), start);
  int rebases = 0;
  glm::dvec3 previous_origin = c.origin();
  for (int i = 0; i < 20 * 60; ++i) {
    c.update(kDt, test::push_toward(i < 600 ? 90.0f : 0.0f, /*run=*/true));
    const glm::dvec3 origin = c.origin();
    ASSERT_EQ(origin.y, 0.0) << i;
    ASSERT_EQ(origin.x, std::round(origin.x)) << i;
    ASSERT_EQ(origin.z, std::round(origin.z)) << i;
    rebases += origin != previous_origin ? 1 : 0;
    previous_origin = origin;
    const glm::vec3 local = c.origin_transforms()[0].translation;
    // Rebased at the start of an update, so at most one update's motion past the distance.
    ASSERT_LT(std::hypot(local.x, local.z), kRebaseDistance + 0.2f) << i;
    const glm::dvec3 world = c.world_root_position();
    EXPECT_EQ(world, c.origin() + glm::dvec3(local)) << i;
    EXPECT_EQ(c.debug().origin, origin) << i;
    // The float world transform is the same point rounded to float's 8 mm steps out here.
    EXPECT_LT(glm::length(glm::dvec3(c.root_transform().translation) - world), 0.008) << i;
  }
  // 10 s running along +X, then 10 s along +Z: tens of metres, so several rebases.
  const glm::dvec3 moved = c.world_root_position() - start;
  EXPECT_GT(moved.x, 20.0);
  EXPECT_GT(moved.z, 20.0);
  EXPECT_GE(rebases, 4);
}

// A rebase shifts every stored position by the same amount: the character's world motion goes
// on without a jump (walking past many rebases near the origin, where floats are fine anyway).
TEST(BigWorld, RebasingDoesNotMoveTheCharacter) {
  Controller c = test::make_controller();
  const int toe = c.controller_database().database().roles().left_toe;
  ASSERT_GE(toe, 0);
  glm::dvec3 previous_root = c.world_root_position();
  glm::dvec3 previous_toe = c.origin() + glm::dvec3(c.origin_transforms()[toe].translation);
  bool rebased = false;
  for (int i = 0; i < 15 * 60; ++i) {
    const glm::dvec3 origin = c.origin();
    c.update(kDt, test::push_toward(45.0f, /*run=*/true));
    rebased = rebased || c.origin() != origin;
    const glm::dvec3 root = c.world_root_position();
    const glm::dvec3 toe_world = c.origin() + glm::dvec3(c.origin_transforms()[toe].translation);
    // Running is under 10 m/s for the root and under 20 m/s for a swinging toe.
    EXPECT_LT(glm::length(root - previous_root), 10.0 * kDt) << i;
    EXPECT_LT(glm::length(toe_world - previous_toe), 20.0 * kDt) << i;
    previous_root = root;
    previous_toe = toe_world;
  }
  EXPECT_TRUE(rebased);
}

// Near the world origin nothing changes for a game: no origin, global = local transforms.
TEST(BigWorld, NearTheWorldOriginTheOriginStaysZero) {
  Controller c = test::make_controller();
  c.teleport(glm::vec3(3.0f, 0.0f, -2.5f), 0.0f);
  for (int i = 0; i < 60; ++i) c.update(kDt, test::push_toward(0.0f));
  EXPECT_EQ(c.origin(), glm::dvec3(0.0));
  EXPECT_EQ(c.global_transforms().data(), c.origin_transforms().data());
}

// Far away, a game places and adjusts the character in double precision: a float world position
// there could not even hold the request.
TEST(BigWorld, TeleportAndAdjustRootKeepDoublePrecisionFarAway) {
  Controller c = test::make_controller();
  const glm::dvec3 spot(123456.789, 0.0, -98765.4321);
  c.teleport_world(spot, 0.0f);
  EXPECT_LT(glm::length(c.world_root_position() - spot), 1e-5);
  for (int i = 0; i < 30; ++i) c.update(kDt, test::push_toward(0.0f));
  const glm::dvec3 requested = c.world_root_position() + glm::dvec3(0.0123, 0.0, -0.0456);
  c.adjust_root_world(requested, c.origin_transforms()[0].rotation);
  EXPECT_LT(glm::length(c.world_root_position() - requested), 1e-5);
  // A non-finite teleport goes to the world origin, as teleport() always did.
  c.teleport_world(glm::dvec3(std::nan(""), 0.0, 1.0), 0.0f);
  EXPECT_EQ(c.origin(), glm::dvec3(0.0));
  EXPECT_EQ(c.root_transform().translation, glm::vec3(0.0f));
}

}  // namespace
}  // namespace mm
