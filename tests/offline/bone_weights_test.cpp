#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "mm/offline/bone_weights.hpp"

namespace mm {
namespace {

constexpr WeightMethod kAllMethods[] = {WeightMethod::Distance, WeightMethod::Envelope,
                                        WeightMethod::HeatDiffusion, WeightMethod::Geodesic};

// ---------------------------------------------------------------------------------------------
// Generated meshes: tubes of rings around bone segments, sharing a ring where bones meet.

// A ring of vertices around an axis, with the direction its vertex 0 lies in (carried from
// ring to ring so consecutive rings line up without twisting).
struct Ring {
  std::vector<uint32_t> vertices;
  glm::vec3 center{0.0f};
  glm::vec3 start_direction{1.0f, 0.0f, 0.0f};
};

struct MeshBuilder {
  TriangleMesh mesh;
  int around = 16;        // vertices per ring
  float spacing = 0.02f;  // metres between rings

  Ring add_ring(const glm::vec3& center, const glm::vec3& axis, glm::vec3 start, float radius) {
    start -= glm::dot(start, axis) * axis;  // into the ring's plane
    if (glm::length(start) < 1e-3f)
      start = std::abs(axis.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    start = glm::normalize(start - glm::dot(start, axis) * axis);
    const glm::vec3 side = glm::cross(axis, start);
    Ring ring{{}, center, start};
    for (int k = 0; k < around; ++k) {
      const float phi = glm::two_pi<float>() * static_cast<float>(k) / static_cast<float>(around);
      const glm::vec3 out = std::cos(phi) * start + std::sin(phi) * side;
      ring.vertices.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(center + radius * out);
      mesh.normals.push_back(out);
    }
    return ring;
  }

  void triangle(uint32_t a, uint32_t b, uint32_t c) {
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
  }

  void connect(const Ring& a, const Ring& b) {
    const size_t n = a.vertices.size();
    for (size_t k = 0; k < n; ++k) {
      const size_t k1 = (k + 1) % n;
      triangle(a.vertices[k], a.vertices[k1], b.vertices[k1]);
      triangle(a.vertices[k], b.vertices[k1], b.vertices[k]);
    }
  }

  // Closes a ring with a fan to a tip vertex.
  void cap(const Ring& ring, const glm::vec3& tip) {
    const uint32_t t = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.push_back(tip);
    mesh.normals.push_back(glm::normalize(tip - ring.center));
    const size_t n = ring.vertices.size();
    for (size_t k = 0; k < n; ++k) triangle(ring.vertices[(k + 1) % n], ring.vertices[k], t);
  }

  // A tube around bone head -> tail, from `start` (a ring at the head shared with another
  // tube) or from a new ring. Returns the rings at both ends.
  std::pair<Ring, Ring> tube(const BoneSegment& bone, const Ring* start) {
    const glm::vec3 axis = glm::normalize(bone.tail - bone.head);
    const float length = glm::distance(bone.head, bone.tail);
    const int steps = std::max(1, static_cast<int>(std::round(length / spacing)));
    const Ring first =
        start ? *start : add_ring(bone.head, axis, glm::vec3(1, 0, 0), bone.head_radius);
    Ring previous = first;
    for (int i = 1; i <= steps; ++i) {
      const float t = static_cast<float>(i) / static_cast<float>(steps);
      const Ring next = add_ring(glm::mix(bone.head, bone.tail, t), axis, previous.start_direction,
                                 glm::mix(bone.head_radius, bone.tail_radius, t));
      connect(previous, next);
      previous = next;
    }
    return {first, previous};
  }
};

BoneSegment bone(glm::vec3 head, glm::vec3 tail, float radius, int joint) {
  return {head, tail, radius, radius, joint};
}

// A mesh with the bones it was built around.
struct Model {
  TriangleMesh mesh;
  std::vector<BoneSegment> bones;
};

// Where a bone's tube starts: a new ring capped at its head, or a ring of an earlier bone.
constexpr int kNewRing = -1;
constexpr int head_ring(int bone) {
  return 2 * bone;
}
constexpr int tail_ring(int bone) {
  return 2 * bone + 1;
}

// Bone b's tube starts at ring start[b]; rings no other tube starts from are capped a radius
// beyond the segment, on the capsule's surface.
Model build_model(std::vector<BoneSegment> bones, const std::vector<int>& start, int around,
                  float spacing) {
  MeshBuilder builder;
  builder.around = around;
  builder.spacing = spacing;
  std::vector<Ring> rings;  // head and tail ring of every bone
  std::vector<bool> shared(2 * bones.size(), false);
  for (size_t b = 0; b < bones.size(); ++b) {
    const int from = start[b];
    if (from != kNewRing) shared[static_cast<size_t>(from)] = true;
    const auto [first, last] =
        builder.tube(bones[b], from == kNewRing ? nullptr : &rings[static_cast<size_t>(from)]);
    rings.push_back(first);
    rings.push_back(last);
  }
  for (size_t b = 0; b < bones.size(); ++b) {
    const BoneSegment& s = bones[b];
    const glm::vec3 axis = glm::normalize(s.tail - s.head);
    if (start[b] == kNewRing && !shared[2 * b])
      builder.cap(rings[2 * b], s.head - s.head_radius * axis);
    if (!shared[2 * b + 1]) builder.cap(rings[2 * b + 1], s.tail + s.tail_radius * axis);
  }
  return {builder.mesh, std::move(bones)};
}

// A bent three-bone chain (a leg: thigh, shin, foot) with joint values that are not 0..2.
Model chain_model(int around = 16, float spacing = 0.02f) {
  const glm::vec3 hip(0.0f, 1.0f, 0.0f), knee(0.0f, 0.55f, 0.04f), ankle(0.0f, 0.1f, -0.03f),
      toe(0.0f, 0.05f, 0.18f);
  return build_model({{hip, knee, 0.07f, 0.05f, 2},
                      {knee, ankle, 0.05f, 0.04f, 5},
                      {ankle, toe, 0.04f, 0.035f, 9}},
                     {kNewRing, tail_ring(0), tail_ring(1)}, around, spacing);
}

// A straight two-bone limb, rings every `spacing` (about as far apart around), so edges
// shrink with `spacing` everywhere (a bend would leave a wedge of long edges at the joint).
Model straight_limb(float spacing) {
  const glm::vec3 hip(0.0f, 1.0f, 0.0f), knee(0.0f, 0.55f, 0.0f), ankle(0.0f, 0.12f, 0.0f);
  return build_model({{hip, knee, 0.06f, 0.05f, 0}, {knee, ankle, 0.05f, 0.04f, 1}},
                     {kNewRing, tail_ring(0)}, static_cast<int>(0.32f / spacing), spacing);
}

// A pelvis: the spine up from the centre, and two hip segments of ONE joint (3) out to the
// legs, which go down. Three tubes share the ring at the centre.
Model pelvis_model() {
  const glm::vec3 centre(0.0f, 1.0f, 0.0f), left(0.1f, 0.95f, 0.0f), right(-0.1f, 0.95f, 0.0f);
  return build_model({bone(centre, {0.0f, 1.4f, 0.0f}, 0.06f, 4), bone(centre, left, 0.06f, 3),
                      bone(centre, right, 0.06f, 3), bone(left, {0.1f, 0.5f, 0.0f}, 0.05f, 5),
                      bone(right, {-0.1f, 0.5f, 0.0f}, 0.05f, 6)},
                     {kNewRing, head_ring(0), head_ring(0), tail_ring(1), tail_ring(2)}, 16, 0.02f);
}

// Two separate components: the chain, and an arm-like tube of two bones off to the side; plus
// a third component, a small closed tube far from every bone.
Model components_model() {
  Model model = chain_model();
  const Model arm = build_model({bone({0.4f, 1.0f, 0.0f}, {0.4f, 1.3f, 0.0f}, 0.04f, 11),
                                 bone({0.4f, 1.3f, 0.0f}, {0.4f, 1.55f, 0.0f}, 0.035f, 12)},
                                {kNewRing, tail_ring(0)}, 12, 0.02f);
  const Model stray =
      build_model({bone({1.5f, 2.0f, 1.0f}, {1.6f, 2.0f, 1.0f}, 0.03f, 99)}, {kNewRing}, 8, 0.02f);
  for (const Model* part : {&arm, &stray}) {
    const uint32_t base = static_cast<uint32_t>(model.mesh.positions.size());
    model.mesh.positions.insert(model.mesh.positions.end(), part->mesh.positions.begin(),
                                part->mesh.positions.end());
    model.mesh.normals.insert(model.mesh.normals.end(), part->mesh.normals.begin(),
                              part->mesh.normals.end());
    for (uint32_t i : part->mesh.indices) model.mesh.indices.push_back(base + i);
  }
  // The stray tube's bone is left out: its vertices must still be bound, to the nearest bone.
  model.bones.insert(model.bones.end(), arm.bones.begin(), arm.bones.end());
  return model;
}

// A body-sized model of about 20k vertices around 19 joints, rings every centimetre: the torso
// (hips, spine, chest, neck, head) is one tube with the hip segments branching off the hips'
// ring; each limb is its own tube starting inside the torso, as a body built of overlapping
// capsules is.
Model body_model() {
  auto v = [](float x, float y, float z) { return glm::vec3(x, y, z); };
  std::vector<BoneSegment> bones = {
      bone(v(0, 1.0f, 0), v(0, 1.15f, 0), 0.13f, 0),               // 0 hips -> spine
      bone(v(0, 1.15f, 0), v(0, 1.3f, 0), 0.14f, 1),               // 1 spine
      {v(0, 1.3f, 0), v(0, 1.45f, 0), 0.15f, 0.07f, 2},            // 2 chest
      bone(v(0, 1.45f, 0), v(0, 1.65f, 0), 0.05f, 3),              // 3 neck
      bone(v(0, 1.65f, 0), v(0, 1.85f, 0), 0.09f, 4),              // 4 head
      bone(v(0, 1.0f, 0), v(0.1f, 0.95f, 0), 0.1f, 0),             // 5 hips -> left hip
      bone(v(0, 1.0f, 0), v(-0.1f, 0.95f, 0), 0.1f, 0),            // 6 hips -> right hip
      bone(v(0.1f, 0.95f, 0), v(0.1f, 0.52f, 0), 0.07f, 5),        // 7 left thigh
      bone(v(0.1f, 0.52f, 0), v(0.1f, 0.1f, 0), 0.05f, 6),         // 8 left shin
      bone(v(0.1f, 0.1f, 0), v(0.1f, 0.03f, 0.15f), 0.04f, 7),     // 9 left foot
      bone(v(-0.1f, 0.95f, 0), v(-0.1f, 0.52f, 0), 0.07f, 8),      // 10 right thigh
      bone(v(-0.1f, 0.52f, 0), v(-0.1f, 0.1f, 0), 0.05f, 9),       // 11 right shin
      bone(v(-0.1f, 0.1f, 0), v(-0.1f, 0.03f, 0.15f), 0.04f, 10),  // 12 right foot
      bone(v(0.05f, 1.42f, 0), v(0.18f, 1.42f, 0), 0.05f, 11),     // 13 left clavicle
      bone(v(0.18f, 1.42f, 0), v(0.46f, 1.42f, 0), 0.05f, 12),     // 14 left upper arm
      bone(v(0.46f, 1.42f, 0), v(0.72f, 1.42f, 0), 0.04f, 13),     // 15 left forearm
      bone(v(0.72f, 1.42f, 0), v(0.82f, 1.42f, 0), 0.035f, 14),    // 16 left hand
      bone(v(-0.05f, 1.42f, 0), v(-0.18f, 1.42f, 0), 0.05f, 15),   // 17 right clavicle
      bone(v(-0.18f, 1.42f, 0), v(-0.46f, 1.42f, 0), 0.05f, 16),   // 18 right upper arm
      bone(v(-0.46f, 1.42f, 0), v(-0.72f, 1.42f, 0), 0.04f, 17),   // 19 right forearm
      bone(v(-0.72f, 1.42f, 0), v(-0.82f, 1.42f, 0), 0.035f, 18),  // 20 right hand
  };
  const std::vector<int> start = {
      kNewRing,      tail_ring(0),  tail_ring(1),  tail_ring(2),  tail_ring(3),  head_ring(0),
      head_ring(0),  kNewRing,      tail_ring(7),  tail_ring(8),  kNewRing,      tail_ring(10),
      tail_ring(11), kNewRing,      tail_ring(13), tail_ring(14), tail_ring(15), kNewRing,
      tail_ring(17), tail_ring(18), tail_ring(19)};
  return build_model(std::move(bones), start, 40, 0.01f);
}

// ---------------------------------------------------------------------------------------------
// Independent measurements (not the library's) for the checks below.

BoneWeightOptions with_method(WeightMethod method) {
  BoneWeightOptions options;
  options.method = method;
  return options;
}

std::string method_name(const ::testing::TestParamInfo<WeightMethod>& info) {
  return std::string(weight_method_name(info.param));
}

// The distance from p to the capsule's surface (negative inside), as the header defines it.
float surface_distance(const glm::vec3& p, const BoneSegment& b) {
  const glm::vec3 d = b.tail - b.head;
  const float t = glm::clamp(glm::dot(p - b.head, d) / glm::dot(d, d), 0.0f, 1.0f);
  return glm::distance(p, b.head + t * d) - glm::mix(b.head_radius, b.tail_radius, t);
}

int nearest_joint(const glm::vec3& p, const std::vector<BoneSegment>& bones) {
  size_t best = 0;
  for (size_t b = 1; b < bones.size(); ++b) {
    if (surface_distance(p, bones[b]) < surface_distance(p, bones[best])) best = b;
  }
  return bones[best].joint;
}

float weight_of(const VertexInfluences& inf, int joint) {
  float sum = 0.0f;
  for (int k = 0; k < 4; ++k) sum += inf.joints[k] == joint ? inf.weights[k] : 0.0f;
  return sum;
}

float largest_weight(const VertexInfluences& inf) {
  return std::max(std::max(inf.weights.x, inf.weights.y), std::max(inf.weights.z, inf.weights.w));
}

int influence_count(const VertexInfluences& inf) {
  int count = 0;
  for (int k = 0; k < 4; ++k) count += inf.weights[k] > 0.0f ? 1 : 0;
  return count;
}

size_t nearest_vertex(const TriangleMesh& mesh, const glm::vec3& point) {
  size_t best = 0;
  for (size_t v = 1; v < mesh.vertex_count(); ++v) {
    if (glm::distance(mesh.positions[v], point) < glm::distance(mesh.positions[best], point)) {
      best = v;
    }
  }
  return best;
}

// Every rule of the result: one entry per vertex, weights >= 0 summing to 1 within 1e-5, some
// weight, positive weights only on the bones' joints and on each joint once.
::testing::AssertionResult obeys_rules(const Model& model,
                                       const std::vector<VertexInfluences>& influences) {
  if (influences.size() != model.mesh.vertex_count()) {
    return ::testing::AssertionFailure()
           << influences.size() << " influences for " << model.mesh.vertex_count() << " vertices";
  }
  for (size_t v = 0; v < influences.size(); ++v) {
    const VertexInfluences& inf = influences[v];
    float sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const float w = inf.weights[k];
      if (!(w >= 0.0f)) return ::testing::AssertionFailure() << "vertex " << v << " weight " << w;
      sum += w;
      if (w == 0.0f) continue;
      const bool known =
          std::any_of(model.bones.begin(), model.bones.end(),
                      [&](const BoneSegment& b) { return b.joint == inf.joints[k]; });
      if (!known)
        return ::testing::AssertionFailure() << "vertex " << v << " joint " << inf.joints[k];
      for (int m = 0; m < k; ++m) {
        if (inf.weights[m] > 0.0f && inf.joints[m] == inf.joints[k]) {
          return ::testing::AssertionFailure()
                 << "vertex " << v << " has joint " << inf.joints[k] << " twice";
        }
      }
    }
    if (!(std::abs(sum - 1.0f) <= 1e-5f)) {
      return ::testing::AssertionFailure() << "vertex " << v << " weights sum to " << sum;
    }
  }
  return ::testing::AssertionSuccess();
}

// For every bone, the vertex nearest its mid-point has the bone's joint as (tied) largest.
::testing::AssertionResult mid_bones_owned(const Model& model,
                                           const std::vector<VertexInfluences>& influences) {
  for (size_t b = 0; b < model.bones.size(); ++b) {
    const BoneSegment& s = model.bones[b];
    const size_t v = nearest_vertex(model.mesh, 0.5f * (s.head + s.tail));
    if (weight_of(influences[v], s.joint) < largest_weight(influences[v]) - 1e-6f) {
      return ::testing::AssertionFailure()
             << "bone " << b << ": vertex " << v << " has weight "
             << weight_of(influences[v], s.joint) << " of joint " << s.joint;
    }
  }
  return ::testing::AssertionSuccess();
}

std::vector<VertexInfluences> compute_or_fail(const Model& model,
                                              const BoneWeightOptions& options) {
  Result<std::vector<VertexInfluences>> weights =
      compute_bone_weights(model.mesh, model.bones, options);
  EXPECT_TRUE(weights.ok()) << (weights ? "" : weights.message());
  return weights ? *weights : std::vector<VertexInfluences>{};
}

WeightQualityReport check_or_fail(const Model& model,
                                  const std::vector<VertexInfluences>& influences) {
  Result<WeightQualityReport> report = check_bone_weights(model.mesh, model.bones, influences);
  EXPECT_TRUE(report.ok()) << (report ? "" : report.message());
  return report ? *report : WeightQualityReport{};
}

// ---------------------------------------------------------------------------------------------
// Every method on every generated mesh.

class EveryMethod : public ::testing::TestWithParam<WeightMethod> {};

INSTANTIATE_TEST_SUITE_P(BoneWeights, EveryMethod, ::testing::ValuesIn(kAllMethods), method_name);

// The report's findings, for the log (they are measurements, not rules).
void print_report(const char* what, const WeightQualityReport& r) {
  std::printf(
      "%s: largest jump %.3f (joint %d, vertices %zu-%zu), %zu vertices not dominated "
      "by their nearest bone\n",
      what, r.max_neighbor_jump, r.jump_joint, r.jump_vertex_a, r.jump_vertex_b,
      r.not_nearest_vertices.size());
}

TEST_P(EveryMethod, ChainObeysEveryRule) {
  const Model model = chain_model();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  EXPECT_TRUE(obeys_rules(model, weights));
  EXPECT_TRUE(mid_bones_owned(model, weights));
  const WeightQualityReport report = check_or_fail(model, weights);
  print_report("chain", report);
  EXPECT_TRUE(report.rules_hold());
  EXPECT_TRUE(report.mid_bone_failures.empty());
}

TEST_P(EveryMethod, PelvisObeysEveryRule) {
  const Model model = pelvis_model();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  EXPECT_TRUE(obeys_rules(model, weights));
  EXPECT_TRUE(mid_bones_owned(model, weights));
  const WeightQualityReport report = check_or_fail(model, weights);
  print_report("pelvis", report);
  EXPECT_TRUE(report.rules_hold());
}

TEST_P(EveryMethod, ComponentsObeyEveryRule) {
  const Model model = components_model();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  EXPECT_TRUE(obeys_rules(model, weights));
  EXPECT_TRUE(mid_bones_owned(model, weights));
  const WeightQualityReport report = check_or_fail(model, weights);
  print_report("components", report);
  EXPECT_TRUE(report.rules_hold());
}

TEST_P(EveryMethod, BodyObeysEveryRule) {
  const Model model = body_model();
  const auto start = std::chrono::steady_clock::now();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s on %zu vertices, %zu bones: %.1f ms\n",
              std::string(weight_method_name(GetParam())).c_str(), model.mesh.vertex_count(),
              model.bones.size(), ms);
  EXPECT_TRUE(obeys_rules(model, weights));
  EXPECT_TRUE(mid_bones_owned(model, weights));
  const WeightQualityReport report = check_or_fail(model, weights);
  print_report("body", report);
  EXPECT_TRUE(report.rules_hold());
}

TEST_P(EveryMethod, SmoothOnAStraightLimb) {
  // A rigid binding (every vertex wholly to its nearest bone) jumps by 1 across the knee. Each
  // method's default blend is about 5 cm wide or more (distance_softness, envelope_falloff,
  // geodesic_falloff; heat diffuses about a limb radius), so over 1-cm edges no joint's weight
  // may move by more than a quarter of that jump.
  const Model model = straight_limb(0.01f);
  const WeightQualityReport report =
      check_or_fail(model, compute_or_fail(model, with_method(GetParam())));
  print_report("straight limb", report);
  EXPECT_LT(report.max_neighbor_jump, 0.25f);
  EXPECT_GT(report.max_neighbor_jump, 0.0f);  // the limb does blend between its bones
  EXPECT_TRUE(report.jump_joint == 0 || report.jump_joint == 1) << report.jump_joint;
}

TEST_P(EveryMethod, JumpsShrinkWithTheEdges) {
  // Weights that vary continuously over the surface jump across an edge in proportion to its
  // length: halving the edges about halves the largest jump. A discontinuity would not shrink.
  const Model coarse = straight_limb(0.02f);
  const Model fine = straight_limb(0.01f);
  const float coarse_jump =
      check_or_fail(coarse, compute_or_fail(coarse, with_method(GetParam()))).max_neighbor_jump;
  const float fine_jump =
      check_or_fail(fine, compute_or_fail(fine, with_method(GetParam()))).max_neighbor_jump;
  EXPECT_LT(fine_jump, 0.7f * coarse_jump) << coarse_jump << " -> " << fine_jump;
}

TEST_P(EveryMethod, SharedJointIsWeightedOnce) {
  // Joint 3 owns both hip segments of the pelvis; obeys_rules rejects a joint in two slots.
  const Model model = pelvis_model();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  ASSERT_TRUE(obeys_rules(model, weights));
  size_t owned_by_hips = 0;
  for (const VertexInfluences& inf : weights) owned_by_hips += inf.joints.x == 3 ? 1 : 0;
  EXPECT_GT(owned_by_hips, 0u);
}

TEST_P(EveryMethod, EveryComponentIsBoundToItsNearestBone) {
  const Model model = components_model();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  ASSERT_TRUE(obeys_rules(model, weights));
  // The stray tube (the last vertices, beyond every bone's reach) follows its nearest bone.
  const size_t stray_first =
      chain_model().mesh.vertex_count() +
      build_model({bone({0.4f, 1.0f, 0.0f}, {0.4f, 1.3f, 0.0f}, 0.04f, 11),
                   bone({0.4f, 1.3f, 0.0f}, {0.4f, 1.55f, 0.0f}, 0.035f, 12)},
                  {kNewRing, tail_ring(0)}, 12, 0.02f)
          .mesh.vertex_count();
  ASSERT_LT(stray_first, weights.size());
  for (size_t v = stray_first; v < weights.size(); ++v) {
    const int nearest = nearest_joint(model.mesh.positions[v], model.bones);
    EXPECT_EQ(weights[v].joints.x, nearest) << v;
    // Diffusion and geodesics stay inside a component, where only that bone is nearest.
    if (GetParam() == WeightMethod::HeatDiffusion || GetParam() == WeightMethod::Geodesic) {
      EXPECT_EQ(influence_count(weights[v]), 1) << v;
    }
  }
}

TEST_P(EveryMethod, SameInputSameWeights) {
  const Model model = pelvis_model();
  const std::vector<VertexInfluences> a = compute_or_fail(model, with_method(GetParam()));
  const std::vector<VertexInfluences> b = compute_or_fail(model, with_method(GetParam()));
  ASSERT_EQ(a.size(), b.size());
  for (size_t v = 0; v < a.size(); ++v) {
    EXPECT_EQ(a[v].joints, b[v].joints) << v;
    EXPECT_EQ(a[v].weights, b[v].weights) << v;
  }
}

// Two parallel fingers 2 cm apart, separate meshes: close in space, far along the surface.
Model two_fingers() {
  Model a =
      build_model({bone({0.0f, 0.0f, 0.0f}, {0.0f, 0.3f, 0.0f}, 0.05f, 0)}, {kNewRing}, 16, 0.02f);
  const Model b = build_model({bone({0.12f, 0.0f, 0.0f}, {0.12f, 0.3f, 0.0f}, 0.05f, 1)},
                              {kNewRing}, 16, 0.02f);
  const uint32_t base = static_cast<uint32_t>(a.mesh.positions.size());
  a.mesh.positions.insert(a.mesh.positions.end(), b.mesh.positions.begin(), b.mesh.positions.end());
  a.mesh.normals.insert(a.mesh.normals.end(), b.mesh.normals.begin(), b.mesh.normals.end());
  for (uint32_t i : b.mesh.indices) a.mesh.indices.push_back(base + i);
  a.bones.push_back(b.bones[0]);
  return a;
}

TEST_P(EveryMethod, WeightsCrossAGapOnlyThroughSpace) {
  const Model model = two_fingers();
  const std::vector<VertexInfluences> weights = compute_or_fail(model, with_method(GetParam()));
  ASSERT_TRUE(obeys_rules(model, weights));
  size_t crossed = 0;  // vertices weighted by the other finger's joint
  for (size_t v = 0; v < weights.size(); ++v) {
    const int own = model.mesh.positions[v].x < 0.06f ? 0 : 1;
    crossed += weight_of(weights[v], 1 - own) > 0.0f ? 1 : 0;
  }
  const bool along_surface =
      GetParam() == WeightMethod::HeatDiffusion || GetParam() == WeightMethod::Geodesic;
  if (along_surface) {
    EXPECT_EQ(crossed, 0u);
  } else {
    EXPECT_GT(crossed, 0u);  // the 2-cm gap is within the default 5-cm blends
  }
}

// ---------------------------------------------------------------------------------------------
// Each method's own rule.

// Six bones out of the origin along +-x, +-y, +-z, joints 0..5, and points (no triangles).
Model star(std::vector<glm::vec3> points, float radius) {
  Model model;
  const glm::vec3 dirs[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int j = 0; j < 6; ++j)
    model.bones.push_back(bone(0.3f * dirs[j], 0.6f * dirs[j], radius, j));
  model.mesh.positions = std::move(points);
  return model;
}

TEST(BoneWeights, DistanceKeepsTheFourNearestJointsByTheDocumentedLaw) {
  const Model model = star({{0.02f, 0.05f, -0.04f}, {-0.1f, 0.01f, 0.03f}}, 0.02f);
  BoneWeightOptions options = with_method(WeightMethod::Distance);
  options.min_weight = 0.0f;  // keep all four, to compare ratios
  const std::vector<VertexInfluences> weights = compute_or_fail(model, options);
  ASSERT_TRUE(obeys_rules(model, weights));
  for (size_t v = 0; v < weights.size(); ++v) {
    const glm::vec3 p = model.mesh.positions[v];
    std::vector<std::pair<float, int>> by_distance;
    for (const BoneSegment& b : model.bones)
      by_distance.emplace_back(surface_distance(p, b), b.joint);
    std::sort(by_distance.begin(), by_distance.end());
    const float s_min = by_distance[0].first;
    for (int k = 0; k < 4; ++k) {
      ASSERT_EQ(weights[v].joints[k], by_distance[static_cast<size_t>(k)].second) << v << " " << k;
      // w_k / w_0 = (softness / (s_k - s_min + softness))^power
      const float expected =
          std::pow(options.distance_softness / (by_distance[static_cast<size_t>(k)].first - s_min +
                                                options.distance_softness),
                   options.distance_power);
      EXPECT_NEAR(weights[v].weights[k] / weights[v].weights[0], expected, 1e-4f) << v << " " << k;
    }
  }
}

TEST(BoneWeights, EnvelopeIsFullInsideSharedInOverlapsAndFallsBackOutside) {
  // Five fat capsules (0.31) whose heads are 0.3 from the origin, and a thin one along +x.
  Model model =
      star({{0.55f, 0.01f, 0.0f},  // inside the thin +x capsule, beyond the others' falloff
            {0.0f, 0.0f, 0.0f},    // inside the five fat capsules
            {2.0f, 0.1f, 0.0f}},   // outside every envelope, nearest the +x bone
           0.31f);
  model.bones[0].head_radius = model.bones[0].tail_radius = 0.02f;
  const std::vector<VertexInfluences> weights =
      compute_or_fail(model, with_method(WeightMethod::Envelope));
  ASSERT_TRUE(obeys_rules(model, weights));
  EXPECT_EQ(influence_count(weights[0]), 1);
  EXPECT_EQ(weights[0].joints.x, 0);
  // The origin is equally deep inside the five fat capsules: full weight from each.
  EXPECT_EQ(influence_count(weights[1]), 4);  // at most four of the five tied, lower joints first
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(weights[1].joints[k], k + 1);
    EXPECT_NEAR(weights[1].weights[k], 0.25f, 1e-6f);
  }
  EXPECT_EQ(influence_count(weights[2]), 1);
  EXPECT_EQ(weights[2].joints.x, nearest_joint(model.mesh.positions[2], model.bones));
}

TEST(BoneWeights, HeatWithoutEdgesIsTheNearestBone) {
  // No triangles: L is zero, so (L + H) w = H p gives w = p exactly.
  const Model model =
      star({{0.02f, 0.05f, -0.04f}, {-0.1f, 0.01f, 0.03f}, {0.0f, 0.7f, 0.1f}}, 0.02f);
  const std::vector<VertexInfluences> weights =
      compute_or_fail(model, with_method(WeightMethod::HeatDiffusion));
  ASSERT_TRUE(obeys_rules(model, weights));
  for (size_t v = 0; v < weights.size(); ++v) {
    EXPECT_EQ(influence_count(weights[v]), 1) << v;
    EXPECT_EQ(weights[v].joints.x, nearest_joint(model.mesh.positions[v], model.bones)) << v;
  }
}

TEST(BoneWeights, GeodesicWeightEndsAFalloffAlongTheSurfaceFromTheOtherRegion) {
  // On the straight limb the regions meet at the knee ring (y = 0.55). A vertex farther than
  // geodesic_falloff along the surface from every vertex of the other region (at least that
  // far from the knee ring in height) has one influence; those next to the ring have two.
  const Model model = straight_limb(0.01f);
  const BoneWeightOptions options = with_method(WeightMethod::Geodesic);
  const std::vector<VertexInfluences> weights = compute_or_fail(model, options);
  ASSERT_TRUE(obeys_rules(model, weights));
  size_t near_ring = 0;
  for (size_t v = 0; v < weights.size(); ++v) {
    const float height = std::abs(model.mesh.positions[v].y - 0.55f);
    if (height > options.geodesic_falloff + 0.011f) {
      EXPECT_EQ(influence_count(weights[v]), 1) << v;
    }
    if (height < 0.005f) {
      EXPECT_EQ(influence_count(weights[v]), 2) << v;
      ++near_ring;
    }
  }
  EXPECT_GT(near_ring, 0u);
}

TEST(BoneWeights, DistanceAndEnvelopeFollowTheNearestBoneEverywhere) {
  // Both give the nearest bone the largest raw weight, so no vertex is reported.
  const Model model = chain_model();
  for (WeightMethod method : {WeightMethod::Distance, WeightMethod::Envelope}) {
    const WeightQualityReport report =
        check_or_fail(model, compute_or_fail(model, with_method(method)));
    EXPECT_TRUE(report.not_nearest_vertices.empty()) << weight_method_name(method);
  }
}

// ---------------------------------------------------------------------------------------------
// The check finds what is wrong.

TEST(BoneWeightsCheck, CleanWeightsPassEveryRule) {
  const Model model = chain_model();
  const WeightQualityReport report =
      check_or_fail(model, compute_or_fail(model, with_method(WeightMethod::Distance)));
  EXPECT_TRUE(report.rules_hold());
  EXPECT_TRUE(report.mid_bone_failures.empty());
  EXPECT_TRUE(report.not_nearest_vertices.empty());
}

TEST(BoneWeightsCheck, FindsBrokenVertices) {
  const Model model = chain_model();
  std::vector<VertexInfluences> w = compute_or_fail(model, with_method(WeightMethod::Distance));
  w[5] = {{2, 5, 0, 0}, {1.2f, -0.2f, 0.0f, 0.0f}};   // sums to 1, one negative
  w[7].weights *= 0.9f;                               // sums to 0.9
  w[9] = {{2, 0, 0, 0}, {0.0f, 0.0f, 0.0f, 0.0f}};    // no weight (and sums to 0)
  w[11] = {{42, 0, 0, 0}, {1.0f, 0.0f, 0.0f, 0.0f}};  // a joint no bone has
  w[13] = {{2, 5, 0, 0}, {std::numeric_limits<float>::quiet_NaN(), 1.0f, 0.0f, 0.0f}};
  const WeightQualityReport report = check_or_fail(model, w);
  EXPECT_FALSE(report.rules_hold());
  EXPECT_EQ(report.negative_weight_vertices, (std::vector<size_t>{5, 13}));
  EXPECT_EQ(report.unnormalized_vertices, (std::vector<size_t>{7, 9, 13}));
  EXPECT_EQ(report.weightless_vertices, (std::vector<size_t>{9}));
  EXPECT_EQ(report.bad_joint_vertices, (std::vector<size_t>{11}));
}

TEST(BoneWeightsCheck, FindsAWrongOwnerAJumpAndVerticesNotNearest) {
  const Model model = chain_model();
  std::vector<VertexInfluences> w = compute_or_fail(model, with_method(WeightMethod::Distance));
  const BoneSegment& shin = model.bones[1];
  const size_t mid = nearest_vertex(model.mesh, 0.5f * (shin.head + shin.tail));
  w[mid] = {{9, 0, 0, 0}, {1.0f, 0.0f, 0.0f, 0.0f}};  // the foot's joint, mid-shin
  const WeightQualityReport report = check_or_fail(model, w);
  EXPECT_TRUE(report.rules_hold());
  ASSERT_EQ(report.mid_bone_failures.size(), 1u);
  EXPECT_EQ(report.mid_bone_failures[0].bone, 1u);
  EXPECT_EQ(report.mid_bone_failures[0].vertex, mid);
  EXPECT_EQ(report.mid_bone_failures[0].joint, 5);
  EXPECT_EQ(report.mid_bone_failures[0].dominant_joint, 9);
  // Its neighbours are wholly the shin's: the shin's and foot's weights both jump by 1.
  EXPECT_FLOAT_EQ(report.max_neighbor_jump, 1.0f);
  EXPECT_TRUE(report.jump_vertex_a == mid || report.jump_vertex_b == mid);
  EXPECT_TRUE(report.jump_joint == 5 || report.jump_joint == 9) << report.jump_joint;
  EXPECT_EQ(report.not_nearest_vertices, (std::vector<size_t>{mid}));
}

TEST(BoneWeightsCheck, ListsEveryVertexNotBoundToItsNearestBone) {
  // Everything bound to the thigh: every vertex nearer the shin or foot is listed.
  const Model model = chain_model();
  const std::vector<VertexInfluences> w(model.mesh.vertex_count(),
                                        VertexInfluences{{2, 0, 0, 0}, {1.0f, 0.0f, 0.0f, 0.0f}});
  std::vector<size_t> expected;
  for (size_t v = 0; v < w.size(); ++v) {
    if (nearest_joint(model.mesh.positions[v], model.bones) != 2) expected.push_back(v);
  }
  ASSERT_FALSE(expected.empty());
  const WeightQualityReport report = check_or_fail(model, w);
  EXPECT_EQ(report.not_nearest_vertices, expected);
  EXPECT_EQ(report.mid_bone_failures.size(), 2u);  // the shin and the foot
}

// ---------------------------------------------------------------------------------------------
// Bad input is refused with a message.

std::string compute_error(const TriangleMesh& mesh, const std::vector<BoneSegment>& bones,
                          const BoneWeightOptions& options = {}) {
  const Result<std::vector<VertexInfluences>> weights = compute_bone_weights(mesh, bones, options);
  return weights ? "" : weights.message();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(BoneWeightsInput, BadMeshesAreRefused) {
  const Model good = chain_model();
  ASSERT_EQ(compute_error(good.mesh, good.bones), "");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const size_t n = good.mesh.vertex_count();

  std::string e = compute_error(TriangleMesh{}, good.bones);
  EXPECT_TRUE(contains(e, "bone weights: the mesh has no vertices")) << e;

  TriangleMesh mesh = good.mesh;
  mesh.indices.pop_back();
  e = compute_error(mesh, good.bones);
  EXPECT_TRUE(
      contains(e, std::to_string(mesh.indices.size()) + " triangle indices, not a multiple of 3"))
      << e;

  mesh = good.mesh;
  mesh.indices[7] = static_cast<uint32_t>(n);
  e = compute_error(mesh, good.bones);
  EXPECT_TRUE(contains(e, "triangle 2 has vertex index " + std::to_string(n) +
                              ", out of range for " + std::to_string(n) + " vertices"))
      << e;

  mesh = good.mesh;
  mesh.normals.pop_back();
  e = compute_error(mesh, good.bones);
  EXPECT_TRUE(contains(e, std::to_string(n - 1) + " normals for " + std::to_string(n) +
                              " vertices (normals must be empty or one per vertex)"))
      << e;

  mesh = good.mesh;
  mesh.normals.clear();  // allowed
  EXPECT_EQ(compute_error(mesh, good.bones), "");

  mesh = good.mesh;
  mesh.positions[3].y = nan;
  e = compute_error(mesh, good.bones);
  EXPECT_TRUE(contains(e, "vertex 3 has a non-finite position")) << e;

  mesh = good.mesh;
  mesh.normals[4].z = std::numeric_limits<float>::infinity();
  e = compute_error(mesh, good.bones);
  EXPECT_TRUE(contains(e, "vertex 4 has a non-finite normal")) << e;
}

TEST(BoneWeightsInput, BadBonesAreRefused) {
  const Model good = chain_model();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::string e = compute_error(good.mesh, {});
  EXPECT_TRUE(contains(e, "bone weights: no bones")) << e;

  std::vector<BoneSegment> bones = good.bones;
  bones[1].joint = -1;
  e = compute_error(good.mesh, bones);
  EXPECT_TRUE(contains(e, "bone 1 has joint -1 (must be >= 0)")) << e;

  bones = good.bones;
  bones[2].tail.x = nan;
  e = compute_error(good.mesh, bones);
  EXPECT_TRUE(contains(e, "bone 2 has a non-finite head or tail")) << e;

  bones = good.bones;
  bones[0].head_radius = nan;
  e = compute_error(good.mesh, bones);
  EXPECT_TRUE(contains(e, "bone 0 has a non-finite radius")) << e;

  bones = good.bones;
  bones[1].tail_radius = -0.01f;
  e = compute_error(good.mesh, bones);
  EXPECT_TRUE(contains(e, "bone 1 has a negative radius (head 0.050000, tail -0.010000)")) << e;
}

TEST(BoneWeightsInput, BadOptionsAreRefused) {
  const Model good = chain_model();
  BoneWeightOptions options;
  options.distance_power = 0.0f;
  std::string e = compute_error(good.mesh, good.bones, options);
  EXPECT_TRUE(contains(e, "option distance_power must be finite and > 0 (got 0.000000)")) << e;
  options = {};
  options.geodesic_falloff = std::numeric_limits<float>::infinity();
  e = compute_error(good.mesh, good.bones, options);
  EXPECT_TRUE(contains(e, "option geodesic_falloff must be finite and > 0")) << e;
  options = {};
  options.min_weight = 0.25f;
  e = compute_error(good.mesh, good.bones, options);
  EXPECT_TRUE(contains(e, "option min_weight must be in [0, 0.25) (got 0.250000)")) << e;
}

TEST(BoneWeightsInput, CheckRefusesBadInput) {
  const Model good = chain_model();
  const std::vector<VertexInfluences> short_list(good.mesh.vertex_count() - 1);
  Result<WeightQualityReport> report = check_bone_weights(good.mesh, good.bones, short_list);
  ASSERT_FALSE(report.ok());
  EXPECT_TRUE(contains(report.message(), std::to_string(short_list.size()) + " influences for " +
                                             std::to_string(good.mesh.vertex_count()) +
                                             " vertices (one per vertex needed)"))
      << report.message();
  const std::vector<VertexInfluences> none;
  report = check_bone_weights(TriangleMesh{}, good.bones, none);
  ASSERT_FALSE(report.ok());
  EXPECT_TRUE(contains(report.message(), "the mesh has no vertices")) << report.message();
}

TEST(WeightMethodNames, RoundTrip) {
  for (WeightMethod method : kAllMethods) {
    EXPECT_EQ(parse_weight_method(weight_method_name(method)), method);
  }
  EXPECT_EQ(weight_method_name(WeightMethod::HeatDiffusion), "heat");
  EXPECT_EQ(parse_weight_method("Heat"), std::nullopt);
  EXPECT_EQ(parse_weight_method(""), std::nullopt);
}

}  // namespace
}  // namespace mm
