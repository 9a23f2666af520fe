#include <gtest/gtest.h>

#include "mm/runtime/pose.hpp"
#include "mm/runtime/skeleton.hpp"

namespace mm {
namespace {

Transform at(float x, float y, float z) {
  Transform t;
  t.translation = {x, y, z};
  return t;
}

TEST(Skeleton, ComputesSubtreeSizesAndFindsByName) {
  auto sk =
      Skeleton::create({"Hips", "Spine", "Chest", "LeftLeg", "LeftFoot"}, {-1, 0, 1, 0, 3},
                       {at(0, 1, 0), at(0, .5f, 0), at(0, .6f, 0), at(.1f, 0, 0), at(0, -.4f, 0)});
  ASSERT_TRUE(sk.ok()) << sk.message();
  EXPECT_EQ(sk->subtree_sizes(), (std::vector<int>{5, 2, 1, 2, 1}));
  EXPECT_EQ(sk->find("Chest"), 2);
  EXPECT_EQ(sk->find("Missing"), -1);
}

TEST(Skeleton, RefusesEachInvalidShape) {
  const std::vector<Transform> rest3(3);
  struct Case {
    std::vector<std::string> names;
    std::vector<int> parents;
    const char* expected;
  };
  const Case cases[] = {
      {{"a", "b", "c"}, {-1, 0, 5}, "out of range"},
      {{"a", "b", "c"}, {-1, 2, 0}, "before its parent"},
      {{"a", "b", "c"}, {2, 0, 1}, "cycle"},
      {{"a", "b", "c"}, {-1, 1, 0}, "its own parent"},
      {{"a", "b", "a"}, {-1, 0, 1}, "duplicate joint name 'a'"},
      {{"a", "", "c"}, {-1, 0, 1}, "empty name"},
      {{"a", "b"}, {-1, 0}, "same length"},
  };
  for (const Case& c : cases) {
    auto sk = Skeleton::create(c.names, c.parents, rest3);
    ASSERT_FALSE(sk.ok()) << c.expected;
    EXPECT_NE(sk.message().find(c.expected), std::string::npos) << sk.message();
  }
}

}  // namespace
}  // namespace mm
