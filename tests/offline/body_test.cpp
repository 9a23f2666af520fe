#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mesh_checks.hpp"
#include "mm/offline/body.hpp"

namespace mm {
namespace {

constexpr float kPi = glm::pi<float>();

BoneSegment segment(glm::vec3 head, glm::vec3 tail, float head_radius, float tail_radius,
                    int joint = 0) {
  BoneSegment s;
  s.head = head;
  s.tail = tail;
  s.head_radius = head_radius;
  s.tail_radius = tail_radius;
  s.joint = joint;
  return s;
}

// The closest point of segment a-b to p.
glm::vec3 closest_on_segment(const glm::vec3& a, const glm::vec3& b, const glm::vec3& p) {
  const glm::vec3 ab = b - a;
  const float t = glm::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
  return a + t * ab;
}

void expect_error(const Result<TriangleMesh>& result, const std::string& fragment) {
  ASSERT_FALSE(result.ok()) << "expected an error containing '" << fragment << "'";
  EXPECT_NE(result.message().find(fragment), std::string::npos)
      << "message '" << result.message() << "' lacks '" << fragment << "'";
}

TEST(TaperedCapsuleDistance, MatchesTheGeometryOfCapsulesConesAndSpheres) {
  // A plain capsule: distance to the axis segment minus the radius.
  const BoneSegment capsule = segment({0, 0, 0}, {0, 1, 0}, 0.2f, 0.2f);
  EXPECT_NEAR(tapered_capsule_distance(capsule, {0.5f, 0.5f, 0.0f}), 0.3f, 1e-6f);
  EXPECT_NEAR(tapered_capsule_distance(capsule, {0.0f, 1.5f, 0.0f}), 0.3f, 1e-6f);
  EXPECT_NEAR(tapered_capsule_distance(capsule, {0.0f, -0.5f, 0.0f}), 0.3f, 1e-6f);
  EXPECT_NEAR(tapered_capsule_distance(capsule, {0.0f, 0.5f, 0.0f}), -0.2f, 1e-6f);

  // A tapered one: the side line touches both end spheres, so a point beyond the tangent point
  // of the wide end is measured from that sphere and one beside the middle from the line.
  const BoneSegment cone = segment({0, 0, 0}, {0, 1, 0}, 0.3f, 0.1f);
  EXPECT_NEAR(tapered_capsule_distance(cone, {0.0f, -1.0f, 0.0f}), 0.7f, 1e-6f);
  EXPECT_NEAR(tapered_capsule_distance(cone, {0.0f, 2.0f, 0.0f}), 0.9f, 1e-6f);
  const float s = 0.2f;  // sin of the side's tilt: (0.3 - 0.1) / 1
  const float c = std::sqrt(1.0f - s * s);
  const glm::vec3 on_side = glm::vec3(0.3f * c, 0.3f * s, 0.0f) + 0.5f * glm::vec3(-s, c, 0.0f);
  EXPECT_NEAR(tapered_capsule_distance(cone, on_side), 0.0f, 1e-6f);
  EXPECT_NEAR(tapered_capsule_distance(cone, on_side + 0.25f * glm::vec3(c, s, 0.0f)), 0.25f,
              1e-6f);

  // Zero length, and one end sphere inside the other: spheres.
  const BoneSegment point = segment({1, 2, 3}, {1, 2, 3}, 0.1f, 0.2f);
  EXPECT_NEAR(tapered_capsule_distance(point, {1.0f, 2.0f, 4.0f}), 0.8f, 1e-6f);
  const BoneSegment nested = segment({0, 0, 0}, {0.05f, 0, 0}, 0.1f, 0.5f);
  EXPECT_NEAR(tapered_capsule_distance(nested, {1.05f, 0.0f, 0.0f}), 0.5f, 1e-6f);
}

TEST(BodySignedDistance, TheSmoothUnionFillsTheCreaseAndLeavesFarPointsAlone) {
  const std::vector<BoneSegment> cross = {segment({-1, 0, 0}, {1, 0, 0}, 0.1f, 0.1f),
                                          segment({0, -1, 0}, {0, 1, 0}, 0.1f, 0.1f)};
  // In the crease between the two arms both capsules are equally near: the blend lowers the
  // distance by a quarter of the blend radius.
  const glm::vec3 crease(0.15f, 0.15f, 0.0f);
  const float plain = body_signed_distance(cross, 0.0f, crease);
  EXPECT_NEAR(body_signed_distance(cross, 0.08f, crease), plain - 0.02f, 1e-6f);
  // Far from the crossing only one capsule matters and the blend changes nothing.
  const glm::vec3 along(0.8f, 0.3f, 0.0f);
  EXPECT_FLOAT_EQ(body_signed_distance(cross, 0.08f, along),
                  body_signed_distance(cross, 0.0f, along));
}

// The union skips capsules that cannot change it (body.cpp); it must equal the plain fold of
// the smooth minimum over every capsule, in segment order, inside the body, on it and around it.
TEST(BodySignedDistance, EqualsTheFoldOverEveryCapsule) {
  std::vector<BoneSegment> body;
  for (int i = 0; i < 12; ++i) {  // a fan of limbs of different tapers, some overlapping
    const float angle = 0.5f * static_cast<float>(i);
    const glm::vec3 head(0.1f * std::cos(angle), 0.05f * static_cast<float>(i), 0.0f);
    const glm::vec3 tail = head + glm::vec3(0.4f * std::cos(angle), 0.1f, 0.4f * std::sin(angle));
    body.push_back(segment(head, tail, 0.06f + 0.005f * static_cast<float>(i), 0.03f));
  }
  const float blend = 0.05f;
  int inside = 0, checked = 0;
  for (int x = -12; x <= 12; ++x) {
    for (int y = -4; y <= 16; ++y) {
      for (int z = -12; z <= 12; ++z) {
        const glm::vec3 p(0.05f * static_cast<float>(x), 0.05f * static_cast<float>(y),
                          0.05f * static_cast<float>(z));
        float fold = tapered_capsule_distance(body[0], p);
        for (size_t k = 1; k < body.size(); ++k) {
          const float d = tapered_capsule_distance(body[k], p);
          const float h = std::max(blend - std::abs(fold - d), 0.0f) / blend;
          fold = std::min(fold, d) - h * h * blend * 0.25f;
        }
        ASSERT_NEAR(body_signed_distance(body, blend, p), fold, 1e-6f)
            << p.x << " " << p.y << " " << p.z;
        inside += fold < 0.0f ? 1 : 0;
        ++checked;
      }
    }
  }
  EXPECT_GT(inside, 100);  // points inside the body were checked too
  EXPECT_GT(checked - inside, 1000);
}

TEST(BodyMesh, ACapsuleBecomesAClosedOutwardMeshOnItsSurface) {
  const float radius = 0.05f, length = 0.3f;
  const BoneSegment bone =
      segment({0.1f, 0.2f, -0.05f}, {0.1f, 0.2f + length, -0.05f}, radius, radius);
  BodyMeshOptions options;
  options.voxel_size = 0.01f;
  Result<TriangleMesh> mesh = generate_body_mesh({&bone, 1}, options);
  ASSERT_TRUE(mesh.ok()) << mesh.message();
  ASSERT_GT(mesh->vertex_count(), 100u);
  ASSERT_EQ(mesh->normals.size(), mesh->vertex_count());

  // Vertices are projected onto the surface, so they lie on it far closer than a voxel.
  for (size_t v = 0; v < mesh->vertex_count(); ++v) {
    const glm::vec3 p = mesh->positions[v];
    EXPECT_LT(std::abs(tapered_capsule_distance(bone, p)), 0.05f * options.voxel_size) << v;
    const glm::vec3 out = glm::normalize(p - closest_on_segment(bone.head, bone.tail, p));
    EXPECT_GT(glm::dot(mesh->normals[v], out), 0.95f) << v;
    EXPECT_NEAR(glm::length(mesh->normals[v]), 1.0f, 1e-4f) << v;
  }
  const test::EdgeReport edges = test::edge_report(*mesh);
  EXPECT_EQ(edges.edges_not_shared_by_two, 0u);
  EXPECT_EQ(edges.directed_edges_repeated, 0u);
  EXPECT_EQ(test::connected_components(*mesh), 1);
  const double expected = kPi * radius * radius * length + 4.0 / 3.0 * kPi * std::pow(radius, 3.0);
  EXPECT_NEAR(test::signed_volume(*mesh), expected, 0.03 * expected);
}

TEST(BodyMesh, OverlappingCapsulesMergeIntoOneComponentAndSeparateOnesDoNot) {
  BodyMeshOptions options;
  options.voxel_size = 0.01f;
  const std::vector<BoneSegment> limb = {segment({0, 0, 0}, {0, 0.3f, 0}, 0.06f, 0.05f, 0),
                                         segment({0, 0.3f, 0}, {0.2f, 0.45f, 0}, 0.05f, 0.03f, 1)};
  Result<TriangleMesh> joined = generate_body_mesh(limb, options);
  ASSERT_TRUE(joined.ok()) << joined.message();
  EXPECT_EQ(test::connected_components(*joined), 1);
  EXPECT_EQ(test::edge_report(*joined).edges_not_shared_by_two, 0u);
  EXPECT_GT(test::signed_volume(*joined), 0.0);

  const std::vector<BoneSegment> apart = {segment({0, 0, 0}, {0, 0.2f, 0}, 0.04f, 0.04f),
                                          segment({0.3f, 0, 0}, {0.3f, 0.2f, 0}, 0.04f, 0.04f)};
  Result<TriangleMesh> two = generate_body_mesh(apart, options);
  ASSERT_TRUE(two.ok()) << two.message();
  EXPECT_EQ(test::connected_components(*two), 2);
}

// Oblique thin capsules at many sub-voxel offsets: wherever the surface grazes a grid face
// (cutting it twice), the mesh must still share every edge between exactly two triangles.
TEST(BodyMesh, StaysClosedWhereTheSurfaceGrazesGridFaces) {
  BodyMeshOptions options;
  options.voxel_size = 0.012f;
  for (int i = 0; i < 24; ++i) {
    const float f = static_cast<float>(i);
    const glm::vec3 offset(0.0031f * f, 0.0017f * f, 0.0023f * f);
    const glm::vec3 dir = glm::normalize(glm::vec3(1.0f, 0.3f + 0.05f * f, 0.1f * std::sin(f)));
    const BoneSegment bone = segment(offset, offset + 0.4f * dir, 0.03f, 0.02f);
    Result<TriangleMesh> mesh = generate_body_mesh({&bone, 1}, options);
    ASSERT_TRUE(mesh.ok()) << mesh.message();
    const test::EdgeReport edges = test::edge_report(*mesh);
    EXPECT_EQ(edges.edges_not_shared_by_two, 0u) << "capsule " << i;
    EXPECT_EQ(edges.directed_edges_repeated, 0u) << "capsule " << i;
  }
}

TEST(BodyMesh, IsDeterministic) {
  const std::vector<BoneSegment> limb = {segment({0, 0, 0}, {0, 0.3f, 0.05f}, 0.06f, 0.04f),
                                         segment({0, 0.3f, 0.05f}, {0.15f, 0.4f, 0}, 0.04f, 0.03f)};
  Result<TriangleMesh> a = generate_body_mesh(limb);
  Result<TriangleMesh> b = generate_body_mesh(limb);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_TRUE(a->positions == b->positions);
  EXPECT_TRUE(a->normals == b->normals);
  EXPECT_TRUE(a->indices == b->indices);
}

TEST(BodyMesh, RefusesBadInputNamingWhatIsWrong) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const BoneSegment good = segment({0, 0, 0}, {0, 0.2f, 0}, 0.05f, 0.05f, 3);
  expect_error(generate_body_mesh({}), "no bone segments");

  const std::vector<BoneSegment> bad_point = {good, segment({0, nan, 0}, {0, 1, 0}, 0.1f, 0.1f, 7)};
  expect_error(generate_body_mesh(bad_point), "segment 1 (joint 7): an end point is not finite");
  const BoneSegment flat = segment({0, 0, 0}, {0, 1, 0}, 0.1f, 0.0f, 2);
  expect_error(generate_body_mesh({&flat, 1}),
               "segment 0 (joint 2): tail radius must be a positive");
  const BoneSegment negative = segment({0, 0, 0}, {0, 1, 0}, -0.1f, 0.1f, 2);
  expect_error(generate_body_mesh({&negative, 1}), "head radius must be a positive");

  BodyMeshOptions options;
  options.voxel_size = 0.0f;
  expect_error(generate_body_mesh({&good, 1}, options), "voxel size must be a positive");
  options.voxel_size = nan;
  expect_error(generate_body_mesh({&good, 1}, options), "voxel size must be a positive");
  options = {};
  options.blend_radius = -0.01f;
  expect_error(generate_body_mesh({&good, 1}, options), "blend radius must be a finite number");
  options = {};
  options.voxel_size = 1e-4f;
  options.max_grid_points = 1000000;
  expect_error(generate_body_mesh({&good, 1}, options), "exceeds the limit of 1000000 points");
}

}  // namespace
}  // namespace mm
