// The crowd of `mm-viewer --crowd` without a window: where the characters stand, and how their
// bones are packed into the instance buffer the renderer draws in one call.

#include "crowd_view.hpp"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm::viewer {
namespace {

glm::vec3 apply(const BoneInstance& bone, const glm::vec3& p) {
  const glm::mat4 model(bone.model[0], bone.model[1], bone.model[2], bone.model[3]);
  return glm::vec3(model * glm::vec4(p, 1.0f));
}

void expect_near(const glm::vec3& a, const glm::vec3& b, const char* what) {
  EXPECT_LT(glm::length(a - b), 1e-5f) << what << ": (" << a.x << ", " << a.y << ", " << a.z
                                       << ") against (" << b.x << ", " << b.y << ", " << b.z << ")";
}

TEST(CrowdStart, CharactersStandApartOnADiscThatGrowsWithTheCrowd) {
  constexpr float kSpacing = 2.0f;
  constexpr size_t kCount = 600;
  std::vector<glm::vec3> at;
  for (size_t i = 0; i < kCount; ++i) at.push_back(crowd_start_position(i, kSpacing));
  float nearest = 1e9f;
  for (size_t i = 0; i < kCount; ++i) {
    EXPECT_EQ(at[i].y, 0.0f);
    // The disc of kCount characters at kSpacing^2 of ground each.
    EXPECT_LE(glm::length(at[i]), kSpacing * std::sqrt((i + 1.0f) / glm::pi<float>()) + 1e-3f);
    for (size_t k = 0; k < i; ++k) nearest = std::min(nearest, glm::distance(at[i], at[k]));
  }
  // Nobody starts inside a neighbour: at least most of the spacing apart.
  EXPECT_GT(nearest, 0.8f * kSpacing);
  // The same character always stands in the same place and faces the same way; neighbours
  // face different ways.
  EXPECT_EQ(crowd_start_position(123, kSpacing), at[123]);
  EXPECT_EQ(crowd_start_yaw(7), crowd_start_yaw(7));
  EXPECT_NE(crowd_start_yaw(7), crowd_start_yaw(8));
  for (size_t i = 0; i < 100; ++i) {
    EXPECT_GE(crowd_start_yaw(i), -glm::pi<float>());
    EXPECT_LE(crowd_start_yaw(i), glm::pi<float>());
  }
}

TEST(CrowdInstances, EachBoneRunsFromItsParentToItsJointUnderTheCarry) {
  // A chain root -> (0, 1, 0) -> (1, 1, 0), the last joint the head.
  const std::vector<int> parents = {-1, 0, 1};
  std::vector<Transform> pose(3);
  pose[1].translation = glm::vec3(0.0f, 1.0f, 0.0f);
  pose[2].translation = glm::vec3(1.0f, 1.0f, 0.0f);
  // Carried a quarter turn to the left about +Y and 5 m along +X: (x, y, z) -> (z + 5, y, -x).
  Transform carry;
  carry.rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0.0f, 1.0f, 0.0f));
  carry.translation = glm::vec3(5.0f, 0.0f, 0.0f);
  const glm::vec4 colour(0.1f, 0.2f, 0.3f, 1.0f);
  ASSERT_EQ(crowd_bones_per_character(parents), 3u);
  std::vector<BoneInstance> bones(3);
  pack_bone_instances(pose, carry, parents, 2, colour, bones);

  expect_near(apply(bones[0], {0, 0, 0}), {5, 0, 0}, "bone 1 starts at the root");
  expect_near(apply(bones[0], {0, 1, 0}), {5, 1, 0}, "bone 1 ends at joint 1");
  expect_near(apply(bones[1], {0, 0, 0}), {5, 1, 0}, "bone 2 starts at joint 1");
  expect_near(apply(bones[1], {0, 1, 0}), {5, 1, -1}, "bone 2 ends at joint 2");
  // The head goes on from the head joint the way the neck points.
  expect_near(apply(bones[2], {0, 0, 0}), {5, 1, -1}, "the head starts at its joint");
  const glm::vec3 head_axis = apply(bones[2], {0, 1, 0}) - apply(bones[2], {0, 0, 0});
  EXPECT_GT(glm::length(head_axis), 0.1f);
  expect_near(glm::normalize(head_axis), {0, 0, -1}, "the head along the neck");
  for (const BoneInstance& bone : bones) {
    EXPECT_EQ(bone.colour, colour);
    // Width axes square to the length and to each other, and a box has some width.
    const glm::vec3 x(bone.model[0]), y(bone.model[1]), z(bone.model[2]);
    EXPECT_NEAR(glm::dot(x, y), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(z, y), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(x, z), 0.0f, 1e-5f);
    EXPECT_GT(glm::length(x), 0.02f);
    EXPECT_NEAR(glm::length(x), glm::length(z), 1e-5f);
    // Right-handed, so the box's triangles keep their winding (face culling).
    EXPECT_GT(glm::dot(glm::cross(x, y), z), 0.0f);
  }
}

TEST(CrowdInstances, TierColoursAreDistinct) {
  for (int a = 0; a < kCrowdTierCount; ++a) {
    for (int b = 0; b < a; ++b) {
      EXPECT_GT(glm::distance(crowd_tier_colour(static_cast<CrowdTier>(a)),
                              crowd_tier_colour(static_cast<CrowdTier>(b))),
                0.3f);
    }
  }
}

}  // namespace
}  // namespace mm::viewer
