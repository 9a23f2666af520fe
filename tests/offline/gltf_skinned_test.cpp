// Skinned meshes in glTF: reading one (every malformed case refused by its message, naming the
// file) and writing one (the body checked before anything is written).

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base64.hpp"
#include "mm/offline/gltf.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

using test::base64;

template <class T>
void append(std::vector<unsigned char>& bytes, std::initializer_list<T> values) {
  for (T v : values) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }
}

// A two-joint skin ("root", "child") and one skinned triangle; each field breaks one thing.
struct Fixture {
  bool skinned_node = true;
  bool position = true;
  bool joints = true;
  bool weights = true;
  bool joints_1 = false;
  int mode = 4;
  int normal_count = 3;
  int index_count = 3;
  uint16_t third_index = 2;
  uint8_t third_joint = 1;  // vertex 2's first joint (the skin has two)
  float third_weight = 1.0f;
  const char* joints_component = "5121";  // UNSIGNED_BYTE
};

std::string fixture_gltf(const Fixture& f) {
  std::vector<unsigned char> b;
  append<float>(b, {0, 0, 0, 1, 0, 0, 0, 1, 0});                                // 0: positions
  append<float>(b, {0, 0, 1, 0, 0, 1, 0, 0, 1});                                // 36: normals
  append<uint8_t>(b, {0, 0, 0, 0, 1, 0, 0, 0, f.third_joint, 0, 0, 0});         // 72: joints
  append<float>(b, {1, 0, 0, 0, 0.25f, 0.75f, 0, 0, f.third_weight, 0, 0, 0});  // 84: weights
  append<uint16_t>(b, {0, 1, f.third_index, 0});                                // 132: indices
  std::string attributes;
  auto attribute = [&](bool on, const std::string& name, int accessor) {
    if (!on) return;
    attributes +=
        (attributes.empty() ? "" : ", ") + ("\"" + name + "\": ") + std::to_string(accessor);
  };
  attribute(f.position, "POSITION", 0);
  attribute(true, "NORMAL", 1);
  attribute(f.joints, "JOINTS_0", 2);
  attribute(f.weights, "WEIGHTS_0", 3);
  attribute(f.joints_1, "JOINTS_1", 2);
  return std::string(R"({"asset": {"version": "2.0"},
  "buffers": [{"byteLength": 140, "uri": "data:application/octet-stream;base64,)") +
         base64(b) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 72, "byteLength": 12},
                  {"buffer": 0, "byteOffset": 84, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 132, "byteLength": 8}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5126, "count": )" +
         std::to_string(f.normal_count) + R"(, "type": "VEC3"},
                {"bufferView": 2, "componentType": )" +
         f.joints_component +
         R"(, "count": 3, "type": "VEC4"},
                {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC4"},
                {"bufferView": 4, "componentType": 5123, "count": )" +
         std::to_string(f.index_count) + R"(, "type": "SCALAR"}],
  "meshes": [{"name": "tri", "primitives": [{"attributes": {)" +
         attributes + R"(}, "indices": 4, "mode": )" + std::to_string(f.mode) + R"(}]}],
  "nodes": [{"name": "root", "children": [1], "translation": [0, 1, 0]},
            {"name": "child", "translation": [0, 0.5, 0]},
            {"name": "body", "mesh": 0)" +
         (f.skinned_node ? ", \"skin\": 0" : "") + R"(}],
  "skins": [{"joints": [0, 1]}],
  "scenes": [{"nodes": [0, 2]}], "scene": 0}
)";
}

Result<GltfAsset> load_fixture(const Fixture& f, fs::path* where) {
  *where = test::scratch_dir() / "skinned.gltf";
  std::ofstream(*where, std::ios::binary) << fixture_gltf(f);
  GltfImportOptions options;
  options.read_skinned_mesh = true;
  return load_gltf(*where, options);
}

void expect_refused(const Fixture& f, const std::string& fragment) {
  fs::path path;
  Result<GltfAsset> asset = load_fixture(f, &path);
  ASSERT_FALSE(asset.ok()) << "expected a refusal containing '" << fragment << "'";
  EXPECT_NE(asset.message().find(path.string()), std::string::npos) << asset.message();
  EXPECT_NE(asset.message().find(fragment), std::string::npos)
      << "message '" << asset.message() << "' lacks '" << fragment << "'";
}

TEST(GltfSkinnedMesh, ReadsTheTriangleMappedToSkeletonJoints) {
  fs::path path;
  Result<GltfAsset> asset = load_fixture({}, &path);
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_TRUE(asset->skinned_mesh.has_value());
  const SkinnedMesh& mesh = *asset->skinned_mesh;
  ASSERT_EQ(mesh.mesh.positions.size(), 3u);
  EXPECT_EQ(mesh.mesh.positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(mesh.mesh.normals[2], glm::vec3(0, 0, 1));
  EXPECT_EQ(mesh.mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
  const int child = asset->skeleton.find("child");
  const int root = asset->skeleton.find("root");
  EXPECT_EQ(mesh.influences[2].joints[0], child);
  EXPECT_EQ(mesh.influences[1].joints[0], child);
  EXPECT_EQ(mesh.influences[1].joints[1], root);
  EXPECT_FLOAT_EQ(mesh.influences[1].weights[1], 0.75f);
  // No inverse bind matrices: identity, so every joint is bound at the origin.
  ASSERT_EQ(mesh.bind_global.size(), 2u);
  EXPECT_EQ(mesh.bind_global[1].translation, glm::vec3(0.0f));

  // Without the option, meshes are not looked at.
  Result<GltfAsset> plain = load_gltf(path);
  ASSERT_TRUE(plain.ok()) << plain.message();
  EXPECT_FALSE(plain->skinned_mesh.has_value());
}

TEST(GltfSkinnedMesh, RefusesMalformedMeshesByMessage) {
  Fixture f;
  f.skinned_node = false;
  expect_refused(f, "no mesh is skinned with skin 0");
  f = {};
  f.position = false;
  expect_refused(f, "mesh 0 'tri' primitive 0 has no POSITION attribute");
  f = {};
  f.joints = false;
  expect_refused(f, "has no JOINTS_0 attribute");
  f = {};
  f.weights = false;
  expect_refused(f, "has no WEIGHTS_0 attribute");
  f = {};
  f.joints_1 = true;
  expect_refused(f, "more than four influences per vertex are not supported");
  f = {};
  f.mode = 1;
  expect_refused(f, "has mode 1; only triangles (mode 4) are read");
  f = {};
  f.normal_count = 2;
  expect_refused(f, "has 3 positions but 2 normals");
  f = {};
  f.index_count = 2;
  expect_refused(f, "has 2 indices, not a whole number of triangles");
  f = {};
  f.third_index = 7;
  expect_refused(f, "index 2 is vertex 7, out of range (3 vertices)");
  f = {};
  f.third_joint = 5;
  expect_refused(f, "vertex 2 is weighted to joint 5, out of range (the skin has 2 joints)");
  f = {};
  f.third_weight = 0.0f;
  expect_refused(f, "vertex 2 has no weight");
  f = {};
  f.third_weight = -1.0f;
  expect_refused(f, "vertex 2 has negative weight -1");
  f = {};
  f.joints_component = "5126";
  expect_refused(f,
                 "JOINTS_0: accessor 2 has component type FLOAT, expected UNSIGNED_BYTE or "
                 "UNSIGNED_SHORT");
}

// A two-joint skeleton and a one-triangle body bound to it.
struct Body {
  Skeleton skeleton;
  SkinnedMesh mesh;
};
Body small_body() {
  std::vector<Transform> rest(2);
  rest[1].translation = {0.0f, 0.5f, 0.0f};
  Body b;
  b.skeleton = Skeleton::create({"a", "b"}, {-1, 0}, rest).value();
  b.mesh.mesh.positions = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.6f, 0}};
  b.mesh.mesh.indices = {0, 1, 2};
  b.mesh.influences.resize(3);
  for (VertexInfluences& in : b.mesh.influences) in.weights = {1, 0, 0, 0};
  b.mesh.influences[2].joints = {1, 0, 0, 0};
  b.mesh.bind_global = {rest[0], rest[1]};
  return b;
}

TEST(GltfSkinnedMesh, SavingChecksTheBodyFirst) {
  const fs::path out = test::scratch_dir() / "body.glb";
  const std::vector<Transform> frames(2);  // one frame of two joints
  auto expect_error = [&](const Body& b, const std::string& fragment) {
    Status s = save_skinned_gltf(b.skeleton, b.mesh, frames, 1, 1.0f / 30.0f, "clip", out);
    ASSERT_FALSE(s.ok()) << fragment;
    EXPECT_NE(s.message().find(out.string()), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(fragment), std::string::npos) << s.message();
    EXPECT_FALSE(fs::exists(out));
  };
  Body b = small_body();
  b.mesh.bind_global.pop_back();
  expect_error(b, "the body has 1 bind transforms for 2 joints");
  b = small_body();
  b.mesh.influences.pop_back();
  expect_error(b, "the body has 3 vertices but 2 influences");
  b = small_body();
  b.mesh.mesh.indices[2] = 9;
  expect_error(b, "the body's index 9 is out of range");
  b = small_body();
  b.mesh.influences[1].joints = {2, 0, 0, 0};
  expect_error(b, "body vertex 1 is weighted to joint 2, out of range");
  b = small_body();
  b.mesh.influences[0].weights = {0, 0, 0, 0};
  expect_error(b, "body vertex 0 has no weight");

  b = small_body();
  ASSERT_TRUE(save_skinned_gltf(b.skeleton, b.mesh, frames, 1, 1.0f / 30.0f, "clip", out).ok());
  GltfImportOptions options;
  options.read_skinned_mesh = true;
  Result<GltfAsset> back = load_gltf(out, options);
  ASSERT_TRUE(back.ok()) << back.message();
  ASSERT_TRUE(back->skinned_mesh.has_value());
  EXPECT_EQ(back->skinned_mesh->mesh.positions, b.mesh.mesh.positions);
  EXPECT_EQ(back->skinned_mesh->influences[2].joints[0], 1);
  EXPECT_NEAR(back->skinned_mesh->bind_global[1].translation.y, 0.5f, 1e-6f);
}

}  // namespace
}  // namespace mm
