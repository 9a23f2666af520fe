#include <gtest/gtest.h>

#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "mm/runtime/pose.hpp"
#include "mm/runtime/skeleton.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;
using test::same_rotation;

Transform at(float x, float y, float z) {
  Transform t;
  t.translation = {x, y, z};
  return t;
}

// The example: Hip (0,1,0) -> Spine (0,0.5,0) -> Chest (0,0.6,0).
struct ThreeJoints {
  std::vector<int> parents{-1, 0, 1};
  std::vector<Transform> local{at(0, 1, 0), at(0, 0.5f, 0), at(0, 0.6f, 0)};
};

TEST(ForwardKinematics, ThreeJointExampleGivesPositionsAndLengths) {
  ThreeJoints s;
  std::vector<Transform> global(3);
  forward_kinematics(s.parents, s.local, global);
  EXPECT_TRUE(near_vec3(global[0].translation, {0, 1, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(global[1].translation, {0, 1.5f, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(global[2].translation, {0, 2.1f, 0}, 1e-6f));
  std::vector<float> lengths(3);
  bone_lengths(s.parents, global, lengths);
  EXPECT_NEAR(lengths[0], 1.0f, 1e-6f);
  EXPECT_NEAR(lengths[1], 0.5f, 1e-6f);
  EXPECT_NEAR(lengths[2], 0.6f, 1e-6f);
}

TEST(ForwardKinematics, RotatedParentMovesDescendantsAndKeepsLengths) {
  ThreeJoints s;
  // Turning the hip 90 degrees about +Z swings the spine and chest from +Y to -X.
  s.local[0].rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0, 0, 1));
  std::vector<Transform> global(3);
  forward_kinematics(s.parents, s.local, global);
  EXPECT_TRUE(near_vec3(global[0].translation, {0, 1, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(global[1].translation, {-0.5f, 1, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(global[2].translation, {-1.1f, 1, 0}, 1e-6f));
  std::vector<float> lengths(3);
  bone_lengths(s.parents, global, lengths);
  EXPECT_NEAR(lengths[1], 0.5f, 1e-6f);
  EXPECT_NEAR(lengths[2], 0.6f, 1e-6f);

  // Now the spine bends 90 degrees about +X as well: only the chest moves, to +Z of the spine
  // in the hip's turned frame.
  s.local[1].rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(1, 0, 0));
  forward_kinematics(s.parents, s.local, global);
  EXPECT_TRUE(near_vec3(global[1].translation, {-0.5f, 1, 0}, 1e-6f));
  // Spine global rotation = Rz(90) * Rx(90): local +Y -> Rx: +Z -> Rz: +Z.
  EXPECT_TRUE(near_vec3(global[2].translation, {-0.5f, 1, 0.6f}, 1e-6f));
  bone_lengths(s.parents, global, lengths);
  EXPECT_NEAR(lengths[2], 0.6f, 1e-6f);

  // Random rotations on every joint never change any length.
  for (int i = 0; i < 20; ++i) {
    for (Transform& t : s.local) t.rotation = test::random_rotation();
    forward_kinematics(s.parents, s.local, global);
    bone_lengths(s.parents, global, lengths);
    EXPECT_NEAR(lengths[0], 1.0f, 1e-6f);
    EXPECT_NEAR(lengths[1], 0.5f, 1e-6f);
    EXPECT_NEAR(lengths[2], 0.6f, 1e-6f);
  }
}

// A branching skeleton: hips with a spine chain and two legs.
struct Branching {
  std::vector<int> parents{-1, 0, 1, 2, 0, 4, 5, 0, 7, 8};
  std::vector<Transform> local;
  Branching() {
    local.resize(parents.size());
    for (size_t i = 0; i < local.size(); ++i) {
      local[i] = test::random_transform(0.5f);
    }
  }
};

// The 4x4 matrix of a transform built from GLM's matrix functions, not from mm::to_matrix.
glm::mat4 hand_matrix(const Transform& t) {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), t.translation);
  m = m * glm::mat4_cast(t.rotation);
  m = glm::scale(m, t.scale);
  return m;
}

TEST(ForwardKinematics, MatchesHandComputationWithMatrices) {
  Branching s;
  s.local[3].scale = glm::vec3(1.5f);  // a uniform scale on one joint is carried to its children
  std::vector<Transform> global(s.parents.size());
  forward_kinematics(s.parents, s.local, global);
  for (size_t i = 0; i < s.parents.size(); ++i) {
    // Multiply the chain of matrices from the root down to joint i.
    glm::mat4 m(1.0f);
    std::vector<int> chain;
    for (int j = static_cast<int>(i); j >= 0; j = s.parents[j]) chain.push_back(j);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) m = m * hand_matrix(s.local[*it]);
    EXPECT_TRUE(near_vec3(global[i].translation, glm::vec3(m[3]), 1e-5f)) << "joint " << i;
    // A point in the joint's frame lands where the matrix product puts it.
    const glm::vec3 p(0.1f, -0.2f, 0.3f);
    EXPECT_TRUE(near_vec3(transform_point(global[i], p), glm::vec3(m * glm::vec4(p, 1.0f)), 1e-5f));
    // And the mm matrix agrees with the hand one.
    const glm::mat4 mm_matrix = to_matrix(global[i]);
    for (int c = 0; c < 4; ++c) {
      EXPECT_TRUE(near_vec3(glm::vec3(mm_matrix[c]), glm::vec3(m[c]), 1e-5f)) << i << " " << c;
    }
  }
}

TEST(ForwardKinematics, SingleJointChainEqualsFullPass) {
  Branching s;
  std::vector<Transform> global(s.parents.size());
  forward_kinematics(s.parents, s.local, global);
  for (int j = 0; j < static_cast<int>(s.parents.size()); ++j) {
    const Transform partial = forward_kinematics_joint(s.parents, s.local, j);
    EXPECT_TRUE(same_rotation(partial.rotation, global[j].rotation, 1e-6f)) << j;
    EXPECT_TRUE(near_vec3(partial.translation, global[j].translation, 1e-5f)) << j;
  }
}

// The position-only and rotation-only walks are the full walk's parts to the bit: callers swap
// one for the other without changing a result.
TEST(ForwardKinematics, PositionAndRotationWalksEqualTheFullWalkExactly) {
  Branching s;
  for (size_t j = 0; j < s.local.size(); ++j) {
    s.local[j].scale = glm::vec3(1.0f + 0.1f * static_cast<float>(j), 0.9f, 1.1f);
  }
  for (int j = 0; j < static_cast<int>(s.parents.size()); ++j) {
    const Transform full = forward_kinematics_joint(s.parents, s.local, j);
    const glm::vec3 position = forward_kinematics_position(s.parents, s.local, j);
    const glm::quat rotation = forward_kinematics_rotation(s.parents, s.local, j);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(position[k], full.translation[k]) << j;
    for (int k = 0; k < 4; ++k) EXPECT_EQ(rotation[k], full.rotation[k]) << j;
  }
}

// The two-joint walk gives each joint's own walk to the bit, for every pair of joints (siblings,
// a joint and its ancestor, the same joint twice, chains that meet only at the root).
TEST(ForwardKinematics, ThePairWalkEqualsTwoPositionWalksExactly) {
  Branching s;
  for (size_t j = 0; j < s.local.size(); ++j) {
    s.local[j].scale = glm::vec3(1.0f + 0.1f * static_cast<float>(j), 0.9f, 1.1f);
  }
  const int n = static_cast<int>(s.parents.size());
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const auto both = forward_kinematics_positions(s.parents, s.local, a, b);
      const glm::vec3 pa = forward_kinematics_position(s.parents, s.local, a);
      const glm::vec3 pb = forward_kinematics_position(s.parents, s.local, b);
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(both[0][k], pa[k]) << a << " " << b;
        EXPECT_EQ(both[1][k], pb[k]) << a << " " << b;
      }
    }
  }
}

TEST(ForwardKinematics, BoneLengthsOfRootIsItsTranslationLength) {
  const std::vector<int> parents{-1, 0};
  std::vector<Transform> local{at(3, 4, 0), at(0, 0, 2)};
  local[0].rotation = glm::angleAxis(0.3f, glm::vec3(0, 1, 0));
  std::vector<Transform> global(2);
  forward_kinematics(parents, local, global);
  std::vector<float> lengths(2);
  bone_lengths(parents, global, lengths);
  EXPECT_NEAR(lengths[0], 5.0f, 1e-6f);
  EXPECT_NEAR(lengths[1], 2.0f, 1e-6f);
}

TEST(ForwardKinematics, SkeletonRestPoseThroughFk) {
  auto sk = Skeleton::create({"Hip", "Spine", "Chest"}, {-1, 0, 1},
                             {at(0, 1, 0), at(0, 0.5f, 0), at(0, 0.6f, 0)});
  ASSERT_TRUE(sk.ok()) << sk.message();
  std::vector<Transform> global(3);
  forward_kinematics(sk->parents(), sk->rest(), global);
  EXPECT_TRUE(near_vec3(global[sk->find("Chest")].translation, {0, 2.1f, 0}, 1e-6f));
  EXPECT_EQ(sk->subtree_size(sk->find("Hip")), 3);
}

}  // namespace
}  // namespace mm
