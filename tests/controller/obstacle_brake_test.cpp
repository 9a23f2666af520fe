// Slowing down before an obstacle (obstacle_brake.hpp): where the trajectory was blocked, how fast
// the simulation object may still go toward it, and garbage.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "mm/controller/obstacle_brake.hpp"

namespace mm {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(ObstacleBrake, TheFirstSampleStoppedShortOfItsGoalIsTheObstacle) {
  // Walking +X and a little +Z toward a wall whose face stops the capsule at x = 1: the first
  // sample reaches its goal, the second and third stop at the wall (the third slid 0.3 m along
  // it, +Z). The way it blocks is the wall's, whichever way the samples were short.
  const std::array<glm::vec3, 3> goals = {glm::vec3(0.5f, 0.0f, 0.1f), glm::vec3(1.4f, 0.0f, 0.3f),
                                          glm::vec3(2.0f, 0.0f, 0.9f)};
  const std::array<glm::vec3, 3> reached = {
      glm::vec3(0.5f, 0.0f, 0.1f), glm::vec3(1.0f, 0.0f, 0.3f), glm::vec3(1.0f, 0.0f, 0.6f)};
  const glm::vec3 wall(-1.0f, 0.0f, 0.0f);
  const std::array<glm::vec3, 3> normals = {glm::vec3(0.0f), wall, wall};
  const ObstacleAhead ahead = obstacle_ahead(goals, reached, normals);
  ASSERT_TRUE(ahead.found);
  EXPECT_EQ(ahead.direction, glm::vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(ahead.stop, reached[1]);
  // Met something but went on to within a few centimetres of the goal (the world's skin, a
  // glancing touch): not blocked. Short of the goal with nothing met (a step's height): neither.
  const std::array<glm::vec3, 2> near_reached = {glm::vec3(0.5f, 0.0f, 0.1f),
                                                 glm::vec3(1.37f, 0.0f, 0.3f)};
  EXPECT_FALSE(
      obstacle_ahead(std::span(goals).first(2), near_reached, std::span(normals).first(2)).found);
  const std::array<glm::vec3, 3> none = {glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  EXPECT_FALSE(obstacle_ahead(goals, reached, none).found);
  EXPECT_FALSE(obstacle_ahead({}, {}, {}).found);
}

TEST(ObstacleBrake, TowardTheObstacleTheSpeedStopsInTheRoomLeft) {
  const ObstacleAhead ahead{true, glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
  constexpr float kDeceleration = 3.0f;
  // 0.5 m left: at most sqrt(2 * 3 * 0.5) = 1.73 m/s toward it; a walk's 1.2 m/s is left alone.
  const glm::vec3 walk(1.2f, 0.0f, 0.0f);
  EXPECT_EQ(braked_velocity(walk, glm::vec3(0.5f, 0.0f, 0.0f), ahead, kDeceleration), walk);
  const glm::vec3 run(3.5f, 0.0f, 0.0f);
  EXPECT_NEAR(braked_velocity(run, glm::vec3(0.5f, 0.0f, 0.0f), ahead, kDeceleration).x,
              std::sqrt(3.0f), 1e-5f);
  // 6 cm left: 0.6 m/s. Along the wall (+Z) the velocity keeps all it had.
  const glm::vec3 slanted(1.2f, 0.0f, 0.5f);
  const glm::vec3 braked =
      braked_velocity(slanted, glm::vec3(0.94f, 0.0f, 0.2f), ahead, kDeceleration);
  EXPECT_NEAR(braked.x, 0.6f, 1e-5f);
  EXPECT_EQ(braked.z, 0.5f);
  // Headed more along the wall than into it (kAlongShare), it slides as the world lets it.
  const glm::vec3 glancing(1.0f, 0.0f, 1.2f);
  EXPECT_EQ(braked_velocity(glancing, glm::vec3(0.94f, 0.0f, 0.2f), ahead, kDeceleration),
            glancing);
  // At or past the stop, nothing toward it; away from it, anything.
  EXPECT_EQ(braked_velocity(walk, glm::vec3(1.1f, 0.0f, 0.0f), ahead, kDeceleration).x, 0.0f);
  const glm::vec3 back(-1.2f, 0.0f, 0.0f);
  EXPECT_EQ(braked_velocity(back, glm::vec3(1.0f, 0.0f, 0.0f), ahead, kDeceleration), back);
  // No obstacle, or no deceleration set: nothing braked.
  EXPECT_EQ(braked_velocity(run, glm::vec3(0.9f, 0.0f, 0.0f), ObstacleAhead{}, kDeceleration), run);
  EXPECT_EQ(braked_velocity(run, glm::vec3(0.9f, 0.0f, 0.0f), ahead, 0.0f), run);
}

TEST(ObstacleBrake, GarbageFindsNoObstacleAndBrakesNothing) {
  const std::array<glm::vec3, 2> goals = {glm::vec3(kNaN), glm::vec3(1.4f, 0.0f, 0.0f)};
  const std::array<glm::vec3, 2> reached = {glm::vec3(0.5f, 0.0f, 0.0f),
                                            glm::vec3(1.0f, 0.0f, 0.0f)};
  const std::array<glm::vec3, 2> normals = {glm::vec3(-1.0f, 0.0f, 0.0f),
                                            glm::vec3(-1.0f, 0.0f, 0.0f)};
  EXPECT_FALSE(obstacle_ahead(goals, reached, normals).found);
  const std::array<glm::vec3, 2> bad_normals = {glm::vec3(kNaN), glm::vec3(-1.0f, 0.0f, 0.0f)};
  EXPECT_FALSE(obstacle_ahead(std::array<glm::vec3, 2>{glm::vec3(1.4f, 0.0f, 0.0f), goals[1]},
                              reached, bad_normals)
                   .found);
  const ObstacleAhead ahead{true, glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
  const glm::vec3 run(3.5f, 0.0f, 0.0f);
  EXPECT_EQ(braked_velocity(run, glm::vec3(kNaN), ahead, 3.0f), run);
  EXPECT_EQ(braked_velocity(run, glm::vec3(0.9f, 0.0f, 0.0f), ahead, kNaN), run);
  const glm::vec3 garbage =
      braked_velocity(glm::vec3(kNaN), glm::vec3(0.9f, 0.0f, 0.0f), ahead, 3.0f);
  EXPECT_TRUE(std::isnan(garbage.x));  // left as it came: the controller sanitizes its input
}

}  // namespace
}  // namespace mm
