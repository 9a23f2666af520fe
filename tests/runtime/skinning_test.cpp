#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/skinning.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

using test::near_vec3;

const glm::vec3 kZ{0.0f, 0.0f, 1.0f};

// A cylinder of radius 0.1 m along +x from 0 to 2 m around a two-bone chain: bone 0 from the
// origin to the joint at (1,0,0), bone 1 from there to (2,0,0). Rings every 0.125 m with 24
// vertices; the weight of bone 1 ramps linearly from 0 at x = 0.75 to 1 at x = 1.25, so the
// ring at the joint (x = 1) is bound half and half.
struct Cylinder {
  static constexpr float kRadius = 0.1f;
  static constexpr int kAround = 24;
  static constexpr int kRings = 17;
  static constexpr int kJointRing = 8;  // x = 1
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<VertexInfluences> influences;
  std::array<Transform, 2> bind_global;
  std::array<Transform, 2> inverse_bind;

  Cylinder() {
    for (int ring = 0; ring < kRings; ++ring) {
      const float x = 0.125f * ring;
      const float w1 = std::clamp((x - 0.75f) / 0.5f, 0.0f, 1.0f);
      for (int k = 0; k < kAround; ++k) {
        const float phi = glm::two_pi<float>() * k / kAround;
        positions.push_back({x, kRadius * std::cos(phi), kRadius * std::sin(phi)});
        normals.push_back({0.0f, std::cos(phi), std::sin(phi)});
        VertexInfluences inf;
        inf.joints = {0, 1, 0, 0};
        inf.weights = {1.0f - w1, w1, 0.0f, 0.0f};
        influences.push_back(inf);
      }
    }
    bind_global[1].translation = {1.0f, 0.0f, 0.0f};
    inverse_bind_transforms(bind_global, inverse_bind);
  }

  size_t index(int ring, int k) const { return static_cast<size_t>(ring * kAround + k); }

  // Bends bone 1 by `angle` about +Z at the joint.
  static std::array<Transform, 2> bent(float angle) {
    std::array<Transform, 2> global;
    global[1].translation = {1.0f, 0.0f, 0.0f};
    global[1].rotation = glm::angleAxis(angle, kZ);
    return global;
  }

  struct Skinned {
    std::vector<glm::vec3> positions, normals;
  };

  Skinned linear(const std::array<Transform, 2>& global) const {
    std::array<glm::mat4, 2> skin;
    skinning_matrices(global, inverse_bind, skin);
    Skinned out{std::vector<glm::vec3>(positions.size()), std::vector<glm::vec3>(positions.size())};
    skin_linear_blend(skin, positions, normals, influences, out.positions, out.normals);
    return out;
  }

  Skinned dual(const std::array<Transform, 2>& global) const {
    std::array<DualQuat, 2> skin;
    skinning_dual_quats(global, inverse_bind, skin);
    Skinned out{std::vector<glm::vec3>(positions.size()), std::vector<glm::vec3>(positions.size())};
    skin_dual_quaternion(skin, positions, normals, influences, out.positions, out.normals);
    return out;
  }
};

TEST(Skinning, IdentityPoseGivesRestPositions) {
  const Cylinder cyl;
  const auto lbs = cyl.linear(cyl.bind_global);
  const auto dqs = cyl.dual(cyl.bind_global);
  for (size_t v = 0; v < cyl.positions.size(); ++v) {
    EXPECT_TRUE(near_vec3(lbs.positions[v], cyl.positions[v], 1e-6f)) << v;
    EXPECT_TRUE(near_vec3(dqs.positions[v], cyl.positions[v], 1e-6f)) << v;
    EXPECT_TRUE(near_vec3(lbs.normals[v], cyl.normals[v], 1e-6f)) << v;
    EXPECT_TRUE(near_vec3(dqs.normals[v], cyl.normals[v], 1e-6f)) << v;
  }
}

// The distance of each joint-ring vertex from the joint, whose bend axis passes through it.
std::vector<float> joint_ring_radii(const Cylinder& cyl, const std::vector<glm::vec3>& positions) {
  std::vector<float> radii;
  for (int k = 0; k < Cylinder::kAround; ++k) {
    radii.push_back(
        glm::distance(positions[cyl.index(Cylinder::kJointRing, k)], glm::vec3(1, 0, 0)));
  }
  return radii;
}

// The area enclosed by the joint ring: the length of its vector area about the joint.
double ring_area(const Cylinder& cyl, const std::vector<glm::vec3>& positions) {
  glm::dvec3 sum(0.0);
  const glm::dvec3 joint(1.0, 0.0, 0.0);
  for (int k = 0; k < Cylinder::kAround; ++k) {
    const glm::dvec3 p(positions[cyl.index(Cylinder::kJointRing, k)]);
    const glm::dvec3 q(positions[cyl.index(Cylinder::kJointRing, (k + 1) % Cylinder::kAround)]);
    sum += glm::cross(p - joint, q - joint);
  }
  return 0.5 * glm::length(sum);
}

TEST(Skinning, DualQuaternionKeepsTheJointRadiusWhereLinearBlendCollapses) {
  const Cylinder cyl;
  for (float degrees : {45.0f, 90.0f, 135.0f, 170.0f}) {
    SCOPED_TRACE(degrees);
    const float angle = glm::radians(degrees);
    const auto lbs = cyl.linear(Cylinder::bent(angle));
    const auto dqs = cyl.dual(Cylinder::bent(angle));
    const std::vector<float> lbs_radii = joint_ring_radii(cyl, lbs.positions);
    const std::vector<float> dqs_radii = joint_ring_radii(cyl, dqs.positions);
    // DQS: the joint ring is the rest ring turned by half the bend about the joint.
    for (float r : dqs_radii) EXPECT_NEAR(r, Cylinder::kRadius, 1e-5f);
    // LBS, by hand: the vertex at angle phi around the bone averages d and R d, with
    // d = r (0, cos phi, sin phi); |(d + R d)/2|^2 = r^2 (cos^2 phi cos^2(a/2) + sin^2 phi).
    for (int k = 0; k < Cylinder::kAround; ++k) {
      const double phi = glm::two_pi<double>() * k / Cylinder::kAround;
      const double expected =
          Cylinder::kRadius * std::sqrt(std::pow(std::cos(phi) * std::cos(0.5 * angle), 2) +
                                        std::pow(std::sin(phi), 2));
      EXPECT_NEAR(lbs_radii[k], expected, 1e-5) << k;
    }
    // In the bend plane it shrinks to cos(a/2) of the rest radius: 71 % at 90 degrees.
    const float lbs_min = *std::min_element(lbs_radii.begin(), lbs_radii.end());
    EXPECT_NEAR(lbs_min, Cylinder::kRadius * std::cos(0.5f * angle), 1e-5f);
    if (degrees >= 90.0f) {
      EXPECT_LT(lbs_min, 0.75f * Cylinder::kRadius);
    }
    // The ring's enclosed area (the length of its vector area, sum of p_i x p_i+1 / 2) tells
    // the same story for volume: DQS keeps it, LBS scales it by cos(a/2) (the linear map
    // d -> (d + R d)/2 shrinks the in-plane axis by cos(a/2) and keeps the other).
    const double rest_area = 0.5 * Cylinder::kAround * Cylinder::kRadius * Cylinder::kRadius *
                             std::sin(glm::two_pi<double>() / Cylinder::kAround);
    EXPECT_NEAR(ring_area(cyl, dqs.positions), rest_area, 1e-5 * rest_area);
    EXPECT_NEAR(ring_area(cyl, lbs.positions), rest_area * std::cos(0.5 * angle), 1e-5 * rest_area);
  }
}

TEST(Skinning, DualQuaternionJointRingIsTheRestRingTurnedByHalfTheBend) {
  const Cylinder cyl;
  const float angle = glm::radians(90.0f);
  const auto dqs = cyl.dual(Cylinder::bent(angle));
  const glm::quat half = glm::angleAxis(0.5f * angle, kZ);
  const glm::vec3 joint(1.0f, 0.0f, 0.0f);
  for (int k = 0; k < Cylinder::kAround; ++k) {
    const size_t v = cyl.index(Cylinder::kJointRing, k);
    EXPECT_TRUE(near_vec3(dqs.positions[v], joint + half * (cyl.positions[v] - joint), 1e-5f)) << k;
    EXPECT_TRUE(near_vec3(dqs.normals[v], half * cyl.normals[v], 1e-5f)) << k;
  }
}

TEST(Skinning, FullyBoundRingsMoveRigidly) {
  const Cylinder cyl;
  const float angle = glm::radians(90.0f);
  const auto lbs = cyl.linear(Cylinder::bent(angle));
  const auto dqs = cyl.dual(Cylinder::bent(angle));
  const glm::quat r = glm::angleAxis(angle, kZ);
  const glm::vec3 joint(1.0f, 0.0f, 0.0f);
  for (int k = 0; k < Cylinder::kAround; ++k) {
    // Ring at x = 0.5 belongs to bone 0 only (which did not move); x = 1.5 to bone 1 only.
    const size_t still = cyl.index(4, k);
    const size_t moved = cyl.index(12, k);
    const glm::vec3 expected = joint + r * (cyl.positions[moved] - joint);
    for (const auto* out : {&lbs, &dqs}) {
      EXPECT_TRUE(near_vec3(out->positions[still], cyl.positions[still], 1e-6f));
      EXPECT_TRUE(near_vec3(out->positions[moved], expected, 1e-5f));
      EXPECT_TRUE(near_vec3(out->normals[moved], r * cyl.normals[moved], 1e-5f));
    }
  }
}

TEST(Skinning, SingleFullInfluenceIsTheExactRigidTransform) {
  // Three joints in random bind and current poses; each vertex bound 100 % to one joint.
  std::array<Transform, 3> bind, global, inverse_bind;
  for (int j = 0; j < 3; ++j) {
    bind[j] = test::random_transform();
    global[j] = test::random_transform();
  }
  inverse_bind_transforms(bind, inverse_bind);
  std::array<glm::mat4, 3> matrices;
  std::array<DualQuat, 3> dual_quats;
  skinning_matrices(global, inverse_bind, matrices);
  skinning_dual_quats(global, inverse_bind, dual_quats);

  std::vector<glm::vec3> positions, normals;
  std::vector<VertexInfluences> influences;
  for (int v = 0; v < 30; ++v) {
    positions.push_back(test::random_vec3(-2.0f, 2.0f));
    normals.push_back(test::random_unit_vec3());
    VertexInfluences inf;
    // The full weight sits in a random slot; the other slots hold junk indices with weight 0.
    const int slot = v % 4;
    inf.joints = {-7, 99, -1, 1000};
    inf.joints[slot] = v % 3;
    inf.weights[slot] = 1.0f;
    influences.push_back(inf);
  }
  std::vector<glm::vec3> lbs(positions.size()), lbs_n(positions.size());
  std::vector<glm::vec3> dqs(positions.size()), dqs_n(positions.size());
  skin_linear_blend(matrices, positions, normals, influences, lbs, lbs_n);
  skin_dual_quaternion(dual_quats, positions, normals, influences, dqs, dqs_n);
  for (size_t v = 0; v < positions.size(); ++v) {
    const int j = static_cast<int>(v % 3);
    // Expected, by transforms alone: into the bind frame, then out of the current one.
    const glm::vec3 expected =
        transform_point(global[j], transform_point(inverse(bind[j]), positions[v]));
    const glm::vec3 expected_normal =
        global[j].rotation * (glm::conjugate(bind[j].rotation) * normals[v]);
    EXPECT_TRUE(near_vec3(lbs[v], expected, 2e-5f)) << v;
    EXPECT_TRUE(near_vec3(dqs[v], expected, 2e-5f)) << v;
    EXPECT_TRUE(near_vec3(lbs_n[v], expected_normal, 1e-5f)) << v;
    EXPECT_TRUE(near_vec3(dqs_n[v], expected_normal, 1e-5f)) << v;
  }
}

TEST(Skinning, WeightsAreNormalizedAndDualQuatSignDoesNotMatter) {
  const Cylinder cyl;
  const auto global = Cylinder::bent(glm::radians(60.0f));
  std::array<DualQuat, 2> skin;
  skinning_dual_quats(global, cyl.inverse_bind, skin);
  const glm::vec3 p(1.0f, 0.1f, 0.0f);
  VertexInfluences half;
  half.joints = {0, 1, 0, 0};
  half.weights = {0.5f, 0.5f, 0.0f, 0.0f};
  VertexInfluences unnormalized = half;
  unnormalized.weights = {2.0f, 2.0f, 0.0f, -3.0f};  // negative counts as zero, then / 4
  std::array<glm::vec3, 1> a, b, c;
  skin_dual_quaternion(skin, std::span(&p, 1), {}, std::span(&half, 1), a, {});
  skin_dual_quaternion(skin, std::span(&p, 1), {}, std::span(&unnormalized, 1), b, {});
  EXPECT_TRUE(near_vec3(a[0], b[0], 1e-6f));
  // Flipping the sign of one joint's dual quaternion (same motion) changes nothing.
  std::array<DualQuat, 2> flipped = skin;
  flipped[1] = -1.0f * flipped[1];
  skin_dual_quaternion(flipped, std::span(&p, 1), {}, std::span(&half, 1), c, {});
  EXPECT_TRUE(near_vec3(a[0], c[0], 1e-6f));
  // Same for linear blend, and zero weights keep the rest position.
  std::array<glm::mat4, 2> matrices;
  skinning_matrices(global, cyl.inverse_bind, matrices);
  skin_linear_blend(matrices, std::span(&p, 1), {}, std::span(&half, 1), a, {});
  skin_linear_blend(matrices, std::span(&p, 1), {}, std::span(&unnormalized, 1), b, {});
  EXPECT_TRUE(near_vec3(a[0], b[0], 1e-6f));
  VertexInfluences none;
  skin_linear_blend(matrices, std::span(&p, 1), {}, std::span(&none, 1), a, {});
  skin_dual_quaternion(skin, std::span(&p, 1), {}, std::span(&none, 1), b, {});
  EXPECT_EQ(a[0], p);
  EXPECT_EQ(b[0], p);
}

TEST(Skinning, MatrixOverloadsAgreeWithHandProducts) {
  std::array<Transform, 4> bind, global, inverse_bind;
  std::array<glm::mat4, 4> inverse_bind_matrices;
  for (int j = 0; j < 4; ++j) {
    bind[j] = test::random_transform();
    bind[j].scale = glm::vec3(test::uniform(0.5f, 2.0f));
    global[j] = test::random_transform();
    inverse_bind_matrices[j] = glm::inverse(to_matrix(bind[j]));  // as a glTF file would store
  }
  inverse_bind_transforms(bind, inverse_bind);
  std::array<glm::mat4, 4> from_transforms, from_matrices;
  skinning_matrices(global, inverse_bind, from_transforms);
  skinning_matrices(global, inverse_bind_matrices, from_matrices);
  for (int j = 0; j < 4; ++j) {
    // The bind pose maps to the identity, and both overloads agree.
    const glm::mat4 at_bind = to_matrix(bind[j]) * inverse_bind_matrices[j];
    for (int c = 0; c < 4; ++c) {
      EXPECT_TRUE(
          near_vec3(glm::vec3(from_transforms[j][c]), glm::vec3(from_matrices[j][c]), 1e-4f));
      EXPECT_TRUE(near_vec3(glm::vec3(at_bind[c]), glm::vec3(glm::mat4(1.0f)[c]), 1e-5f));
    }
  }
}

}  // namespace
}  // namespace mm
