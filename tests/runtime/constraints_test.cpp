#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "mm/runtime/constraints.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;

TEST(DistanceConstraint, EqualWeightsMoveBothEndsEqually) {
  glm::vec3 a(0.0f), b(2.0f, 0.0f, 0.0f);
  ASSERT_TRUE(relax_distance_constraint(a, b, 1.0f, 1.0f, 1.0f));
  EXPECT_TRUE(near_vec3(a, {0.5f, 0, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(b, {1.5f, 0, 0}, 1e-6f));
  // Any equal weights, any direction: the midpoint stays and the distance becomes rest.
  for (int i = 0; i < 20; ++i) {
    glm::vec3 p = test::random_vec3(-1, 1), q = test::random_vec3(-1, 1);
    const glm::vec3 mid = 0.5f * (p + q);
    const glm::vec3 dir = glm::normalize(q - p);
    ASSERT_TRUE(relax_distance_constraint(p, q, 0.3f, 2.5f, 2.5f));
    EXPECT_TRUE(near_vec3(0.5f * (p + q), mid, 1e-6f));
    EXPECT_NEAR(glm::distance(p, q), 0.3f, 1e-6f);
    EXPECT_TRUE(near_vec3(glm::normalize(q - p), dir, 1e-5f));  // moved along the difference
  }
}

TEST(DistanceConstraint, ZeroWeightPinsThatEnd) {
  glm::vec3 a(1.0f, 1.0f, 1.0f), b(1.0f, 4.0f, 1.0f);
  ASSERT_TRUE(relax_distance_constraint(a, b, 1.0f, 0.0f, 1.0f));
  EXPECT_EQ(a, glm::vec3(1.0f, 1.0f, 1.0f));
  EXPECT_TRUE(near_vec3(b, {1, 2, 1}, 1e-6f));
  glm::vec3 c(0.0f), d(0.0f, 0.0f, 0.5f);
  ASSERT_TRUE(relax_distance_constraint(c, d, 2.0f, 3.0f, 0.0f));  // compressed: pushed apart
  EXPECT_EQ(d, glm::vec3(0.0f, 0.0f, 0.5f));
  EXPECT_TRUE(near_vec3(c, {0, 0, -1.5f}, 1e-6f));
}

TEST(DistanceConstraint, CorrectionSharedInProportionToWeights) {
  // Distance 2, rest 1: a correction of 1 m shared 1:3.
  glm::vec3 a(0.0f), b(2.0f, 0.0f, 0.0f);
  ASSERT_TRUE(relax_distance_constraint(a, b, 1.0f, 1.0f, 3.0f));
  EXPECT_TRUE(near_vec3(a, {0.25f, 0, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(b, {1.25f, 0, 0}, 1e-6f));
  // Compressed by 0.6 m, shared 0.2 : 0.8.
  glm::vec3 c(0.0f, 1.0f, 0.0f), d(0.0f, 1.4f, 0.0f);
  ASSERT_TRUE(relax_distance_constraint(c, d, 1.0f, 0.5f, 2.0f));
  EXPECT_TRUE(near_vec3(c, {0, 1.0f - 0.12f, 0}, 1e-6f));
  EXPECT_TRUE(near_vec3(d, {0, 1.4f + 0.48f, 0}, 1e-6f));
  // Negative weights count as zero.
  glm::vec3 e(0.0f), f(3.0f, 0.0f, 0.0f);
  ASSERT_TRUE(relax_distance_constraint(e, f, 1.0f, -5.0f, 1.0f));
  EXPECT_EQ(e, glm::vec3(0.0f));
  EXPECT_TRUE(near_vec3(f, {1, 0, 0}, 1e-6f));
}

TEST(DistanceConstraint, SkipsZeroTotalWeightCoincidentEndsAndNonFinite) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  struct Case {
    glm::vec3 a, b;
    float rest, wa, wb;
  };
  const Case cases[] = {
      {{0, 0, 0}, {2, 0, 0}, 1.0f, 0.0f, 0.0f},    // both pinned
      {{0, 0, 0}, {2, 0, 0}, 1.0f, -1.0f, -2.0f},  // both "negative" = pinned
      {{1, 2, 3}, {1, 2, 3}, 1.0f, 1.0f, 1.0f},    // coincident: no direction
      {{0, 0, 0}, {2, 0, 0}, nan, 1.0f, 1.0f},    {{0, 0, 0}, {2, 0, 0}, 1.0f, nan, 1.0f},
  };
  for (const Case& c : cases) {
    glm::vec3 a = c.a, b = c.b;
    EXPECT_FALSE(relax_distance_constraint(a, b, c.rest, c.wa, c.wb));
    EXPECT_EQ(a, c.a);
    EXPECT_EQ(b, c.b);
  }
  // The same through the solver, next to a constraint that does apply.
  std::vector<glm::vec3> points{{0, 0, 0}, {0, 0, 0}, {3, 0, 0}};
  const std::array<DistanceConstraint, 2> constraints{DistanceConstraint{0, 1, 1.0f, 1.0f, 1.0f},
                                                      DistanceConstraint{1, 2, 1.0f, 0.0f, 0.0f}};
  relax_distance_constraints(points, constraints, 10);
  EXPECT_EQ(points[0], glm::vec3(0.0f));
  EXPECT_EQ(points[1], glm::vec3(0.0f));
  EXPECT_EQ(points[2], glm::vec3(3, 0, 0));
}

// A chain of n points along +x with spacing `spacing`, constraints of rest length 1 between
// neighbours, the root pinned (weight 0) and every other end weight 1.
struct Chain {
  std::vector<glm::vec3> points;
  std::vector<DistanceConstraint> constraints;
  Chain(int n, float spacing) {
    for (int i = 0; i < n; ++i) points.push_back({spacing * i, 0.0f, 0.0f});
    for (int i = 0; i + 1 < n; ++i) {
      constraints.push_back({i, i + 1, 1.0f, i == 0 ? 0.0f : 1.0f, 1.0f});
    }
  }
};

TEST(DistanceConstraints, StretchedChainWithPinnedRootConverges) {
  Chain chain(5, 1.8f);
  const glm::vec3 root = chain.points[0];
  EXPECT_NEAR(max_distance_constraint_error(chain.points, chain.constraints), 0.8f, 1e-6f);
  float previous = std::numeric_limits<float>::infinity();
  for (int round = 0; round < 10; ++round) {
    relax_distance_constraints(chain.points, chain.constraints, 10);
    const float error = max_distance_constraint_error(chain.points, chain.constraints);
    EXPECT_LE(error, previous);  // never gets worse
    previous = error;
  }
  EXPECT_LT(previous, 1e-4f);
  EXPECT_EQ(chain.points[0], root);  // pinned exactly
  // Each distance is the rest length and the chain stays on its line.
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(glm::distance(chain.points[i], chain.points[i + 1]), 1.0f, 1e-4f);
    EXPECT_EQ(chain.points[i + 1].y, 0.0f);
  }
}

TEST(DistanceConstraints, BentChainAndZeroIterations) {
  // A random 3D zig-zag chain, pinned root, converges to its rest lengths too.
  Chain chain(6, 1.0f);
  for (size_t i = 1; i < chain.points.size(); ++i) {
    chain.points[i] = chain.points[i - 1] + test::uniform(0.3f, 2.5f) * test::random_unit_vec3();
  }
  const std::vector<glm::vec3> start = chain.points;
  relax_distance_constraints(chain.points, chain.constraints, 0);
  EXPECT_EQ(chain.points, start);
  relax_distance_constraints(chain.points, chain.constraints, 200);
  EXPECT_LT(max_distance_constraint_error(chain.points, chain.constraints), 1e-4f);
  EXPECT_EQ(chain.points[0], start[0]);
}

TEST(DistanceConstraints, OnePassWithRootPinnedAndLeafFreeSolvesChainExactly) {
  // With the root side pinned in every constraint (weight_a = 0), one ordered pass fixes each
  // point in turn: a forward-reaching chain.
  std::vector<glm::vec3> points{{0, 0, 0}, {0, 3, 0}, {0, 3, 4}};
  const std::array<DistanceConstraint, 2> constraints{DistanceConstraint{0, 1, 1.0f, 0.0f, 1.0f},
                                                      DistanceConstraint{1, 2, 2.0f, 0.0f, 1.0f}};
  relax_distance_constraints(points, constraints, 1);
  EXPECT_TRUE(near_vec3(points[1], {0, 1, 0}, 1e-6f));
  // Point 2 moves toward the new point 1 along their difference: from (0,3,4), which is
  // distance sqrt(4 + 16) from (0,1,0); it ends 2 m from (0,1,0) on that line.
  const glm::vec3 dir = glm::normalize(glm::vec3(0, 2, 4));
  EXPECT_TRUE(near_vec3(points[2], glm::vec3(0, 1, 0) + 2.0f * dir, 1e-5f));
}

}  // namespace
}  // namespace mm
