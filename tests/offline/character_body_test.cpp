// The generated character body on the real Bandai skeleton: its shape, pose and weights, the
// glTF round trip the issue asks for (export, reload, same skinned vertices), the loader that
// maps a body onto a database skeleton by joint name, and generic skeletons.

#include <gtest/gtest.h>

#include <optional>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "mesh_checks.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/character_body.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/runtime/pose.hpp"
#include "mm/runtime/skinning.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

struct Built {
  std::optional<Database> db;
  CharacterBody body;
};

// A database of two real takes (the builder adds the idle clip) and its body, made once.
const Built& built() {
  static const Built b = [] {
    Built out;
    const std::vector<fs::path> inputs = {test::clip_path("dataset-2_wave-left-hand_normal_001"),
                                          test::clip_path("dataset-2_walk_normal_001")};
    Result<Database> db = build_database(inputs, BuildOptions{});
    EXPECT_TRUE(db.ok()) << db.message();
    if (!db) return out;
    out.db.emplace(std::move(db).value());
    Result<CharacterBody> body = build_character_body(*out.db);
    EXPECT_TRUE(body.ok()) << body.message();
    if (body) out.body = std::move(body).value();
    return out;
  }();
  return b;
}

const glm::vec3& bind_position(const std::string& joint) {
  const Built& b = built();
  return b.body.skinned.bind_global[static_cast<size_t>(b.db->skeleton().find(joint))].translation;
}

// The database clip's locals of one frame (unit scale).
std::vector<Transform> clip_frame(const DatabaseView& db, const ClipRange& clip, int frame) {
  const int joints = db.joint_count();
  std::vector<Transform> local(static_cast<size_t>(joints));
  for (int j = 0; j < joints; ++j) {
    const size_t i = static_cast<size_t>(clip.start + frame) * joints + j;
    local[static_cast<size_t>(j)].translation = db.local_positions[i];
    local[static_cast<size_t>(j)].rotation = db.local_rotations[i];
  }
  return local;
}

// Linear blend skinning of a body by a pose (global transforms).
std::vector<glm::vec3> skin(const SkinnedMesh& body, std::span<const Transform> global) {
  std::vector<Transform> inverse_bind(body.bind_global.size());
  inverse_bind_transforms(body.bind_global, inverse_bind);
  std::vector<glm::mat4> matrices(global.size());
  skinning_matrices(global, inverse_bind, matrices);
  std::vector<glm::vec3> out(body.mesh.positions.size());
  skin_linear_blend(matrices, body.mesh.positions, {}, body.influences, out, {});
  return out;
}

TEST(CharacterBody, IsOneClosedComponentOfAHumanSize) {
  const SkinnedMesh& body = built().body.skinned;
  const TriangleMesh& mesh = body.mesh;
  EXPECT_GT(mesh.vertex_count(), 8000u);
  EXPECT_LT(mesh.vertex_count(), 30000u);
  EXPECT_EQ(test::connected_components(mesh), 1);
  const test::EdgeReport edges = test::edge_report(mesh);
  EXPECT_EQ(edges.edges_not_shared_by_two, 0u);
  EXPECT_EQ(edges.directed_edges_repeated, 0u);
  // A body of 1.6 m holds some tens of litres.
  const double volume = test::signed_volume(mesh);
  EXPECT_GT(volume, 0.03);
  EXPECT_LT(volume, 0.09);
}

TEST(CharacterBody, StandsAtTheOriginFacingZInAnAPose) {
  const Built& b = built();
  const std::vector<glm::vec3>& positions = b.body.skinned.mesh.positions;
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 hips = bind_position("Hips");
  EXPECT_NEAR(hips.x, 0.0f, 1e-4f);
  EXPECT_NEAR(hips.z, 0.0f, 1e-4f);
  EXPECT_GT(hi.y, hips.y + 0.5f);  // the head is well above the hips
  EXPECT_NEAR(lo.y, 0.0f, 0.03f);  // the soles touch the ground
  EXPECT_LT(bind_position("Foot_L").y, 0.15f);
  EXPECT_LT(bind_position("Toes_R").y, 0.08f);
  EXPECT_GT(bind_position("Toes_L").z, bind_position("Foot_L").z);  // feet point forward (+Z)
  // Arms out and down: the left hand on +X, both below the shoulders and clear of the hips.
  const glm::vec3 left = bind_position("Hand_L"), right = bind_position("Hand_R");
  EXPECT_GT(left.x, 0.35f);
  EXPECT_LT(right.x, -0.35f);
  EXPECT_LT(left.y, bind_position("UpperArm_L").y - 0.2f);
  EXPECT_GT(bind_position("Foot_L").x - bind_position("Foot_R").x, 0.2f);  // legs apart
  // The joints above the hips are at the origin with no rotation, and carry no geometry.
  for (const char* name : {"Simulation", "joint_Root"}) {
    const Transform& t =
        b.body.skinned.bind_global[static_cast<size_t>(b.db->skeleton().find(name))];
    EXPECT_EQ(t.translation, glm::vec3(0.0f)) << name;
    EXPECT_NEAR(std::abs(t.rotation.w), 1.0f, 1e-6f) << name;
  }
}

TEST(CharacterBody, EveryVertexIsWeightedAndEveryBodyPartOwnsVertices) {
  const Built& b = built();
  std::vector<int> dominant(static_cast<size_t>(b.db->joint_count()), 0);
  std::vector<bool> weighted(dominant.size(), false);
  for (const VertexInfluences& in : b.body.skinned.influences) {
    float sum = 0.0f;
    int best = 0;
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(in.weights[k], 0.0f);
      sum += in.weights[k];
      if (in.weights[k] > in.weights[best]) best = k;
      if (in.weights[k] > 0.0f) weighted[static_cast<size_t>(in.joints[k])] = true;
    }
    EXPECT_NEAR(sum, 1.0f, 1e-4f);
    ++dominant[static_cast<size_t>(in.joints[best])];
  }
  for (int j = 0; j < b.db->joint_count(); ++j) {
    const std::string& name = b.db->skeleton().name(j);
    if (name == "Simulation" || name == "joint_Root") {
      EXPECT_FALSE(weighted[static_cast<size_t>(j)]) << name;
    } else {
      EXPECT_GT(dominant[static_cast<size_t>(j)], 20) << name;
    }
  }
  for (const BoneSegment& s : b.body.segments) EXPECT_GE(s.joint, 2);
}

// The test: export the body with a clip, reload it, and skin both at several frames.
TEST(CharacterBody, ExportedWithAClipItReloadsToTheSameSkinnedVertices) {
  const Built& b = built();
  const ClipRange& clip = b.db->clips()[1];  // the walk
  std::vector<Transform> frames;
  for (int f = 0; f < clip.frame_count(); ++f) {
    const std::vector<Transform> pose = clip_frame(*b.db, clip, f);
    frames.insert(frames.end(), pose.begin(), pose.end());
  }
  const fs::path out = test::scratch_dir() / "walk_body.glb";
  ASSERT_TRUE(save_skinned_gltf(b.db->skeleton(), b.body.skinned, frames, clip.frame_count(),
                                b.db->frame_time(), clip.name, out)
                  .ok());
  GltfImportOptions options;
  options.sample_rate = 1.0f / b.db->frame_time();
  options.read_skinned_mesh = true;
  Result<GltfAsset> asset = load_gltf(out, options);
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_TRUE(asset->skinned_mesh.has_value());
  ASSERT_TRUE(asset->skeleton.same_topology(b.db->skeleton()));
  ASSERT_EQ(asset->clips.size(), 1u);
  ASSERT_EQ(asset->clips[0].frame_count, clip.frame_count());
  ASSERT_EQ(asset->skinned_mesh->mesh.vertex_count(), b.body.skinned.mesh.vertex_count());
  EXPECT_EQ(asset->skinned_mesh->mesh.indices, b.body.skinned.mesh.indices);

  const int joints = b.db->joint_count();
  for (int f : {0, clip.frame_count() / 2, clip.frame_count() - 1}) {
    std::vector<Transform> global(static_cast<size_t>(joints)), reloaded(global.size());
    forward_kinematics(b.db->skeleton().parents(), clip_frame(*b.db, clip, f), global);
    forward_kinematics(asset->skeleton.parents(), asset->clips[0].pose(f), reloaded);
    const std::vector<glm::vec3> expected = skin(b.body.skinned, global);
    const std::vector<glm::vec3> actual = skin(*asset->skinned_mesh, reloaded);
    float worst = 0.0f;
    for (size_t v = 0; v < expected.size(); ++v) {
      worst = std::max(worst, glm::distance(expected[v], actual[v]));
    }
    EXPECT_LT(worst, 1e-4f) << "frame " << f;
  }
}

TEST(CharacterBody, LoadBodyMapsJointsByNameAndListsMissingOnes) {
  const Built& b = built();
  const fs::path out = test::scratch_dir() / "body.glb";
  const std::vector<Transform> pose = clip_frame(*b.db, b.db->clips()[0], 0);
  ASSERT_TRUE(
      save_skinned_gltf(b.db->skeleton(), b.body.skinned, pose, 1, b.db->frame_time(), "pose", out)
          .ok());

  // Mapped back onto the database skeleton by name, it skins as the body it was made from.
  std::vector<std::string> names = b.db->skeleton().names();
  Result<SkinnedMesh> loaded = load_body_gltf(out, b.db->skeleton());
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  std::vector<Transform> global(static_cast<size_t>(b.db->joint_count()));
  forward_kinematics(b.db->skeleton().parents(), pose, global);
  const std::vector<glm::vec3> expected = skin(b.body.skinned, global);
  const std::vector<glm::vec3> actual = skin(*loaded, global);
  for (size_t v = 0; v < expected.size(); v += 97) {
    EXPECT_LT(glm::distance(expected[v], actual[v]), 1e-4f) << v;
  }

  // A skeleton without two of the weighted joints is refused with both names.
  std::replace(names.begin(), names.end(), std::string("Hand_L"), std::string("LeftHand"));
  std::replace(names.begin(), names.end(), std::string("Head"), std::string("Skull"));
  const Skeleton renamed =
      Skeleton::create(names, b.db->skeleton().parents(), b.db->skeleton().rest()).value();
  Result<SkinnedMesh> refused = load_body_gltf(out, renamed);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find(out.string()), std::string::npos) << refused.message();
  EXPECT_NE(refused.message().find("lacks: Head, Hand_L"), std::string::npos) << refused.message();

  Result<SkinnedMesh> missing = load_body_gltf(out.parent_path() / "none.glb", b.db->skeleton());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("none.glb: cannot open the glTF file (No such file"),
            std::string::npos);
}

// Skeletons the roles do not describe still get a body: capsules by bone length.
TEST(CharacterBody, AGenericSkeletonGetsABodyToo) {
  std::vector<Transform> rest(5);
  rest[1].translation = {0.0f, 0.3f, 0.0f};
  rest[2].translation = {0.0f, 0.3f, 0.0f};
  rest[3].translation = {0.2f, 0.0f, 0.0f};
  rest[4].translation = {0.0f, 0.0f, 0.25f};
  const Skeleton tree =
      Skeleton::create({"base", "mid", "top", "side", "front"}, {-1, 0, 1, 1, 0}, rest).value();
  CharacterBodyOptions options;
  options.weights.method = WeightMethod::Distance;
  Result<CharacterBody> body = build_character_body(tree, rest, JointRoleIndices{}, options);
  ASSERT_TRUE(body.ok()) << body.message();
  EXPECT_EQ(test::connected_components(body->skinned.mesh), 1);
  EXPECT_EQ(body->skinned.influences.size(), body->skinned.mesh.vertex_count());
  // make_bind_pose leaves a pose without roles as it is.
  const std::vector<Transform> same = make_bind_pose(tree, rest, JointRoleIndices{});
  EXPECT_EQ(same[3].translation, rest[3].translation);
}

// A skeleton without hands (ReActIdle's: the lower arms are leaves, the wrist only an End Site)
// still gets whole arms: the forearm, as long as the upper arm, and a hand, out and down with
// the upper arm in the A-pose.
TEST(CharacterBody, ASkeletonWithoutHandsGetsForearmsAndHands) {
  const fs::path take = test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh";
  BuildOptions build;
  build.bvh.scale = 0.0f;
  Result<Database> db = build_database(std::span(&take, 1), build);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_LT(db->roles().left_hand, 0);
  const std::vector<Transform> pose = clip_frame(*db, db->clips()[0], 0);
  const std::vector<Transform> bind = make_bind_pose(db->skeleton(), pose, db->roles());
  std::vector<Transform> global(bind.size());
  forward_kinematics(db->skeleton().parents(), bind, global);
  const std::vector<BoneSegment> segments =
      character_bone_segments(db->skeleton(), global, db->roles(), 0.0f);
  for (const auto& [lower, upper] :
       {std::pair{db->roles().left_lower_arm, db->roles().left_upper_arm},
        std::pair{db->roles().right_lower_arm, db->roles().right_upper_arm}}) {
    const glm::vec3 shoulder = global[static_cast<size_t>(upper)].translation;
    const glm::vec3 elbow = global[static_cast<size_t>(lower)].translation;
    float reach = 0.0f;
    glm::vec3 tip(0.0f);
    for (const BoneSegment& segment : segments) {
      if (segment.joint != lower || glm::distance(segment.tail, elbow) <= reach) continue;
      reach = glm::distance(segment.tail, elbow);
      tip = segment.tail;
    }
    // Longer than the upper arm (forearm and hand), and on from the elbow as the upper arm goes.
    EXPECT_GT(reach, glm::distance(shoulder, elbow)) << db->skeleton().name(lower);
    EXPECT_GT(glm::dot(glm::normalize(tip - elbow), glm::normalize(elbow - shoulder)), 0.95f)
        << db->skeleton().name(lower);
  }
}

TEST(CharacterBody, RefusesWhatItCannotBuildByMessage) {
  std::vector<Transform> rest(2);
  rest[1].translation = {0.0f, 0.3f, 0.0f};
  const Skeleton two = Skeleton::create({"a", "b"}, {-1, 0}, rest).value();
  auto expect_error = [](const Result<CharacterBody>& r, const std::string& fragment) {
    ASSERT_FALSE(r.ok()) << fragment;
    EXPECT_NE(r.message().find(fragment), std::string::npos) << r.message();
  };
  expect_error(build_character_body(two, std::span(rest).first(1), JointRoleIndices{}),
               "the bind pose has 1 transforms for a skeleton of 2 joints");
  JointRoleIndices roles;
  roles.head = 7;
  expect_error(build_character_body(two, rest, roles),
               "the head role is joint 7, out of range (the skeleton has 2 joints)");
  const std::vector<Transform> flat(2);  // both joints at the origin: no bone has length
  expect_error(build_character_body(two, flat, JointRoleIndices{}),
               "no bone of the skeleton has any length");
  CharacterBodyOptions options;
  options.mesh.voxel_size = -1.0f;
  expect_error(build_character_body(two, rest, JointRoleIndices{}, options),
               "voxel size must be a positive");
  expect_error(build_character_body(DatabaseContents{}), "the database has no frames");
}

}  // namespace
}  // namespace mm
