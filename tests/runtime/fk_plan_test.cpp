// ForwardKinematicsPlan: four joints a block, against forward_kinematics joint by joint, to the
// bit, on skeletons of every shape (chains, fans, several roots) and with scaled joints.

#include <gtest/gtest.h>

#include <vector>

#include "mm/runtime/fk_plan.hpp"
#include "mm/runtime/pose.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

// Random parents (each before its joint, joint 0 a root, a few more roots), random locals.
struct Skeleton {
  std::vector<int> parents;
  std::vector<Transform> local;
};

Skeleton random_skeleton(int joints, int trial) {
  Skeleton s;
  for (int j = 0; j < joints; ++j) {
    int p = -1;
    if (j > 0 && (j + trial) % 11 != 0) {
      // Mostly the joint before (long chains), sometimes any earlier one (fans).
      p = trial % 3 == 0 ? j - 1 : static_cast<int>(test::uniform(0.0f, static_cast<float>(j)));
      p = std::min(p, j - 1);
    }
    s.parents.push_back(p);
    Transform t = test::random_transform(1.0f);
    if (trial % 4 == 1) t.scale = test::random_vec3(0.5f, 2.0f);
    s.local.push_back(t);
  }
  return s;
}

TEST(ForwardKinematicsPlan, EqualsForwardKinematicsToTheBit) {
  for (const int joints : {1, 2, 5, 23, 40}) {
    for (int trial = 0; trial < 12; ++trial) {
      const Skeleton s = random_skeleton(joints, trial);
      const ForwardKinematicsPlan plan(s.parents);
      ASSERT_EQ(plan.joint_count(), static_cast<size_t>(joints));
      std::vector<Transform> expected(s.local.size()), global(s.local.size());
      forward_kinematics(s.parents, s.local, expected);
      plan.run(s.local, global);
      for (size_t j = 0; j < global.size(); ++j) {
        SCOPED_TRACE(testing::Message() << joints << " joints, trial " << trial << ", joint " << j);
        EXPECT_EQ(global[j].rotation, expected[j].rotation);
        EXPECT_EQ(global[j].translation, expected[j].translation);
        EXPECT_EQ(global[j].scale, expected[j].scale);
      }
    }
  }
}

TEST(ForwardKinematicsPlan, UnitScaleEqualsForwardKinematicsToTheBit) {
  for (const int joints : {1, 2, 5, 23, 40}) {
    for (int trial = 0; trial < 12; ++trial) {
      Skeleton s = random_skeleton(joints, trial);
      for (Transform& t : s.local) t.scale = glm::vec3(1.0f);
      const ForwardKinematicsPlan plan(s.parents);
      std::vector<Transform> expected(s.local.size()), global(s.local.size());
      forward_kinematics(s.parents, s.local, expected);
      // Scales other than one in the output beforehand: run_unit_scale writes every global.
      for (Transform& g : global) g.scale = glm::vec3(3.0f);
      plan.run_unit_scale(s.local, global);
      for (size_t j = 0; j < global.size(); ++j) {
        SCOPED_TRACE(testing::Message() << joints << " joints, trial " << trial << ", joint " << j);
        EXPECT_EQ(global[j].rotation, expected[j].rotation);
        EXPECT_EQ(global[j].translation, expected[j].translation);
        EXPECT_EQ(global[j].scale, glm::vec3(1.0f));
      }
    }
  }
}

}  // namespace
}  // namespace mm
