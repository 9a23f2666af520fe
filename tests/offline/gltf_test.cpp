#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "base64.hpp"
#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/runtime/pose.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Helpers

// The file's bytes, or none when it cannot be read (the assertions on them then fail).
std::vector<unsigned char> read_bytes(const fs::path& path) {
  auto contents = read_whole_file(path);
  if (!contents) return {};
  const auto* bytes = reinterpret_cast<const unsigned char*>(contents->data.get());
  return {bytes, bytes + contents->size};
}

void write_bytes(const fs::path& path, const void* data, size_t size) {
  std::ofstream file(path, std::ios::binary);
  file.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void write_text(const fs::path& path, const std::string& text) {
  write_bytes(path, text.data(), text.size());
}

using test::base64;

std::vector<Transform> globals_of(const Clip& clip, int frame) {
  std::vector<Transform> global(static_cast<size_t>(clip.joint_count()));
  forward_kinematics(clip.skeleton.parents(), clip.pose(frame), global);
  return global;
}

// Largest distance between the global joint positions of two clips over all frames and joints.
// Both clips must have the same joints and frame count (checked).
float max_global_position_error(const Clip& expected, const Clip& actual) {
  EXPECT_EQ(expected.frame_count, actual.frame_count);
  EXPECT_TRUE(expected.skeleton.same_topology(actual.skeleton));
  if (expected.frame_count != actual.frame_count ||
      !expected.skeleton.same_topology(actual.skeleton)) {
    return std::numeric_limits<float>::infinity();
  }
  float worst = 0.0f;
  for (int f = 0; f < expected.frame_count; ++f) {
    const std::vector<Transform> a = globals_of(expected, f);
    const std::vector<Transform> b = globals_of(actual, f);
    for (size_t j = 0; j < a.size(); ++j) {
      worst = std::max(worst, glm::distance(a[j].translation, b[j].translation));
    }
  }
  return worst;
}

// 1 - |dot|: zero when two unit quaternions are the same rotation (q and -q included).
float rotation_gap(const glm::quat& a, const glm::quat& b) {
  return 1.0f - std::abs(glm::dot(a, b));
}

void expect_vec3_near(const glm::vec3& actual, const glm::vec3& expected, float tolerance,
                      const std::string& what) {
  EXPECT_NEAR(actual.x, expected.x, tolerance) << what;
  EXPECT_NEAR(actual.y, expected.y, tolerance) << what;
  EXPECT_NEAR(actual.z, expected.z, tolerance) << what;
}

// Error text must name the file and contain the given fragment.
void expect_refused(const Result<GltfAsset>& result, const fs::path& path,
                    const std::string& fragment) {
  ASSERT_FALSE(result.ok()) << "expected " << path << " to be refused (" << fragment << ")";
  EXPECT_NE(result.message().find(path.string()), std::string::npos) << result.message();
  EXPECT_NE(result.message().find(fragment), std::string::npos)
      << "message '" << result.message() << "' lacks '" << fragment << "'";
}

// ---------------------------------------------------------------------------------------------
// A synthetic clip: 6 joints, moving root, rotations about mixed axes, a scaled head.

Clip synthetic_clip() {
  const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  std::vector<std::string> names = {"root", "hips", "spine", "head", "nose", "leg"};
  std::vector<int> parents = {-1, 0, 1, 2, 3, 1};
  std::vector<Transform> rest(6);
  rest[1].translation = {0.0f, 0.9f, 0.0f};
  rest[1].rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 1, 0)));
  rest[2].translation = {0.0f, 0.2f, 0.05f};
  rest[3].translation = {0.0f, 0.3f, 0.0f};
  rest[4].translation = {0.0f, 0.1f, 0.1f};
  rest[5].translation = {0.1f, -0.4f, 0.0f};
  rest[5].rotation = glm::angleAxis(-0.2f, x);

  Clip clip;
  clip.name = "synthetic";
  clip.skeleton = Skeleton::create(names, parents, rest).value();
  clip.frame_time = 1.0f / 30.0f;
  clip.frame_count = 40;
  clip.local.resize(40 * 6);
  for (int f = 0; f < clip.frame_count; ++f) {
    const float t = static_cast<float>(f) * clip.frame_time;
    std::span<Transform> pose = clip.pose(f);
    for (int j = 0; j < 6; ++j) pose[j] = rest[j];
    pose[0].translation = {0.8f * t, 0.0f, 0.1f * std::sin(t)};
    pose[0].rotation = glm::angleAxis(0.5f * t, y);
    pose[1].translation = {0.0f, 0.9f + 0.05f * std::sin(4.0f * t), 0.0f};
    pose[1].rotation =
        glm::angleAxis(0.4f * std::sin(3.0f * t), glm::normalize(glm::vec3(0.2f, 1, 0.3f))) *
        rest[1].rotation;
    pose[2].rotation = glm::angleAxis(2.0f * t, x);
    pose[3].rotation = glm::angleAxis(-1.5f * t, z);
    pose[3].scale = glm::vec3(1.0f + 0.2f * std::sin(5.0f * t));
    // Alternate signs: the same rotations, as a careless exporter might store them.
    const glm::quat leg =
        glm::angleAxis(3.0f * t, glm::normalize(glm::vec3(1, 0.5f, 0.2f))) * rest[5].rotation;
    pose[5].rotation = f % 2 == 0 ? leg : -leg;
  }
  EXPECT_TRUE(clip.validate().ok());
  return clip;
}

// Global rest matrices by chaining 4x4 matrices (independent of mm::compose).
std::vector<glm::mat4> rest_global_matrices(const Skeleton& skeleton) {
  std::vector<glm::mat4> global(static_cast<size_t>(skeleton.joint_count()));
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    const Transform& r = skeleton.rest(j);
    const glm::mat4 local = glm::translate(glm::mat4(1.0f), r.translation) *
                            glm::mat4_cast(r.rotation) * glm::scale(glm::mat4(1.0f), r.scale);
    const int p = skeleton.parent(j);
    global[static_cast<size_t>(j)] = p < 0 ? local : global[static_cast<size_t>(p)] * local;
  }
  return global;
}

void check_round_trip(const Clip& original, const fs::path& path) {
  ASSERT_TRUE(save_gltf(original, path).ok());
  auto asset = load_gltf(path, {.sample_rate = 1.0f / original.frame_time});
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  const Clip& clip = asset->clips[0];
  EXPECT_EQ(clip.name, original.name);
  EXPECT_EQ(clip.source_path, path.string());
  EXPECT_EQ(asset->skeleton.names(), original.skeleton.names());
  EXPECT_EQ(asset->skeleton.parents(), original.skeleton.parents());
  ASSERT_EQ(clip.frame_count, original.frame_count);
  EXPECT_NEAR(clip.frame_time, original.frame_time, 1e-7f);

  EXPECT_LT(max_global_position_error(original, clip), 1e-4f) << path;
  float worst_rotation = 0.0f;
  float worst_scale = 0.0f;
  for (int f = 0; f < clip.frame_count; ++f) {
    const std::vector<Transform> a = globals_of(original, f);
    const std::vector<Transform> b = globals_of(clip, f);
    for (size_t j = 0; j < a.size(); ++j) {
      worst_rotation = std::max(worst_rotation, rotation_gap(a[j].rotation, b[j].rotation));
      worst_scale = std::max(worst_scale, glm::length(a[j].scale - b[j].scale));
    }
  }
  EXPECT_LT(worst_rotation, 1e-6f);
  EXPECT_LT(worst_scale, 1e-5f);

  // Inverse bind matrices undo the rest globals.
  const std::vector<glm::mat4> rest_global = rest_global_matrices(original.skeleton);
  ASSERT_EQ(asset->inverse_bind_matrices.size(), rest_global.size());
  for (size_t j = 0; j < rest_global.size(); ++j) {
    const glm::mat4 product = asset->inverse_bind_matrices[j] * rest_global[j];
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) {
        EXPECT_NEAR(product[c][r], c == r ? 1.0f : 0.0f, 1e-5f) << "joint " << j;
      }
    }
  }
}

TEST(GltfRoundTrip, SyntheticClipAsBinaryGlb) {
  const fs::path dir = test::scratch_dir();
  check_round_trip(synthetic_clip(), dir / "synthetic.glb");
  const std::vector<unsigned char> bytes = read_bytes(dir / "synthetic.glb");
  ASSERT_GE(bytes.size(), 4u);
  EXPECT_EQ(std::memcmp(bytes.data(), "glTF", 4), 0);
}

TEST(GltfRoundTrip, SyntheticClipAsSingleFileGltf) {
  const fs::path dir = test::scratch_dir();
  check_round_trip(synthetic_clip(), dir / "synthetic.gltf");
  const std::vector<unsigned char> bytes = read_bytes(dir / "synthetic.gltf");
  const std::string text(bytes.begin(), bytes.end());
  EXPECT_EQ(text.find_first_not_of(" \t\r\n"), text.find('{'));
  EXPECT_NE(text.find("data:application/octet-stream;base64,"), std::string::npos);
  // One file: nothing written beside it.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(GltfRoundTrip, ExportedFileHasSkinnedAnchorMeshAndOneChannelPerJointProperty) {
  const fs::path dir = test::scratch_dir();
  const Clip clip = synthetic_clip();
  ASSERT_TRUE(save_gltf(clip, dir / "anchor.gltf").ok());
  const std::vector<unsigned char> bytes = read_bytes(dir / "anchor.gltf");
  const std::string text(bytes.begin(), bytes.end());
  for (const char* key : {"\"POSITION\"", "\"JOINTS_0\"", "\"WEIGHTS_0\"", "\"skins\"",
                          "\"inverseBindMatrices\"", "\"scenes\""}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
  auto count = [&](const std::string& needle) {
    size_t n = 0;
    for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
      ++n;
    return n;
  };
  EXPECT_EQ(count("\"translation\""), 6u + 6u);  // node rest TRS + one channel per joint
  EXPECT_EQ(count("\"path\": \"rotation\""), 6u);
  EXPECT_EQ(count("\"path\": \"scale\""), 1u);  // only the head's scale moves
}

TEST(GltfExport, RefusesBadInput) {
  const fs::path dir = test::scratch_dir();
  Clip clip = synthetic_clip();
  Status wrong_ext = save_gltf(clip, dir / "clip.fbx");
  ASSERT_FALSE(wrong_ext.ok());
  EXPECT_NE(wrong_ext.message().find(".glb"), std::string::npos);

  Status short_frames = save_gltf(clip.skeleton, std::span<const Transform>(clip.local).first(7), 2,
                                  clip.frame_time, "x", dir / "x.glb");
  ASSERT_FALSE(short_frames.ok());
  EXPECT_NE(short_frames.message().find("expected 12"), std::string::npos)
      << short_frames.message();

  clip.local[9].translation.x = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(save_gltf(clip, dir / "inf.glb").ok());
  EXPECT_FALSE(fs::exists(dir / "inf.glb"));

  EXPECT_FALSE(save_gltf(synthetic_clip(), dir / "no_such_dir" / "x.glb").ok());
}

TEST(GltfExport, SavesAnyPoseSequence) {
  // Two frames of a two-joint chain, written through the span overload.
  const Skeleton skeleton =
      Skeleton::create({"a", "b"}, {-1, 0},
                       {Transform{}, Transform{glm::quat(1, 0, 0, 0), {0, 1, 0}}})
          .value();
  std::vector<Transform> frames(4);
  frames[1].translation = {0, 1, 0};
  frames[2].rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  frames[3].translation = {0, 1, 0};
  const fs::path path = test::scratch_dir() / "sequence.glb";
  ASSERT_TRUE(save_gltf(skeleton, frames, 2, 0.5f, "recorded", path).ok());
  auto asset = load_gltf(path, {.sample_rate = 2.0f});
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  EXPECT_EQ(asset->clips[0].name, "recorded");
  ASSERT_EQ(asset->clips[0].frame_count, 2);
  // Frame 1: a rotated 90 degrees about Z carries b from (0, 1, 0) to (-1, 0, 0).
  const std::vector<Transform> g = globals_of(asset->clips[0], 1);
  expect_vec3_near(g[1].translation, {-1, 0, 0}, 1e-6f, "b at frame 1");
}

// ---------------------------------------------------------------------------------------------
// A hand-written glTF with STEP, LINEAR and CUBICSPLINE samplers.

// The fixture's JSON, in pieces that the malformed-file tests replace one at a time.
struct Fixture {
  std::vector<float> buffer = {
      // accessor 0 (byte 0): key times 0 and 1
      0, 1,
      // accessor 1 (byte 8): root translation keys
      0, 0, 0, 2, 4, -6,
      // accessor 2 (byte 32): root rotation keys: identity, then 90 degrees about +Y stored
      // with a negative w (the same rotation; slerp must take the short way)
      0, 0, 0, 1, 0, -0.70710678f, 0, -0.70710678f,
      // accessor 3 (byte 64): child translation keys (STEP)
      0, 1, 0, 0, 3, 0,
      // accessor 4 (byte 88): key times 0 and 2
      0, 2,
      // accessor 5 (byte 96): tip translation CUBICSPLINE: a0, v0, b0, a1, v1, b1
      9, 9, 9, 0, 1, 0, 1, 0, 0, 0, 0, 3, 2, 1, 0, 9, 9, 9};
  std::string accessors = R"([
    {"bufferView":0,"byteOffset":0,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},
    {"bufferView":0,"byteOffset":8,"componentType":5126,"count":2,"type":"VEC3"},
    {"bufferView":0,"byteOffset":32,"componentType":5126,"count":2,"type":"VEC4"},
    {"bufferView":0,"byteOffset":64,"componentType":5126,"count":2,"type":"VEC3"},
    {"bufferView":0,"byteOffset":88,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[2]},
    {"bufferView":0,"byteOffset":96,"componentType":5126,"count":6,"type":"VEC3"}])";
  std::string nodes = R"([
    {"name":"root","children":[1]},
    {"name":"child","translation":[0,1,0],"rotation":[0.70710678,0,0,0.70710678],"children":[2]},
    {"name":"tip","translation":[0,0.5,0]},
    {"name":"prop"},
    {"name":"armature","translation":[0,0,10],"children":[0,3]}])";
  std::string skins = R"([{"joints":[0,1,2]}])";
  std::string animations = R"([{"name":"fixture_anim",
    "samplers":[
      {"input":0,"output":1,"interpolation":"LINEAR"},
      {"input":0,"output":2,"interpolation":"LINEAR"},
      {"input":0,"output":3,"interpolation":"STEP"},
      {"input":4,"output":5,"interpolation":"CUBICSPLINE"}],
    "channels":[
      {"sampler":0,"target":{"node":0,"path":"translation"}},
      {"sampler":1,"target":{"node":0,"path":"rotation"}},
      {"sampler":2,"target":{"node":1,"path":"translation"}},
      {"sampler":3,"target":{"node":2,"path":"translation"}},
      {"sampler":0,"target":{"node":3,"path":"translation"}}]}])";
  std::string buffer_view_length;  // empty: the buffer's length

  std::string json() const {
    std::vector<unsigned char> bytes(buffer.size() * sizeof(float));
    std::memcpy(bytes.data(), buffer.data(), bytes.size());
    const std::string length = std::to_string(bytes.size());
    std::string text = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[4]}],)";
    text += R"("buffers":[{"byteLength":)" + length +
            R"(,"uri":"data:application/octet-stream;base64,)" + base64(bytes) + R"("}],)";
    text += R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" +
            (buffer_view_length.empty() ? length : buffer_view_length) + "}],";
    text += "\"accessors\":" + accessors + ",\"nodes\":" + nodes;
    if (!skins.empty()) text += ",\"skins\":" + skins;
    if (!animations.empty()) text += ",\"animations\":" + animations;
    return text + "}";
  }

  fs::path write(const fs::path& path) const {
    write_text(path, json());
    return path;
  }
};

void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

TEST(GltfImport, SamplesStepLinearAndCubicSplineAtTheFixedRate) {
  const fs::path path = Fixture{}.write(test::scratch_dir() / "fixture.gltf");
  auto asset = load_gltf(path, {.sample_rate = 4.0f});
  ASSERT_TRUE(asset.ok()) << asset.message();

  // The armature and the prop are not joints: three joints, depth-first.
  EXPECT_EQ(asset->skeleton.names(), (std::vector<std::string>{"root", "child", "tip"}));
  EXPECT_EQ(asset->skeleton.parents(), (std::vector<int>{-1, 0, 1}));
  for (const glm::mat4& m : asset->inverse_bind_matrices)
    EXPECT_EQ(m, glm::mat4(1.0f));  // none in file

  ASSERT_EQ(asset->clips.size(), 1u);
  const Clip& clip = asset->clips[0];
  EXPECT_EQ(clip.name, "fixture_anim");
  EXPECT_FLOAT_EQ(clip.frame_time, 0.25f);
  // Keys span [0, 2] s (the cubic track ends at 2): 0, 0.25, ..., 2.0.
  ASSERT_EQ(clip.frame_count, 9);
  const float tol = 1e-5f;
  const glm::vec3 y(0, 1, 0);

  // LINEAR translation, plus the armature's (0, 0, 10) folded into the root.
  expect_vec3_near(clip.pose(1)[0].translation, {0.5f, 1.0f, 10.0f - 1.5f}, tol, "root t=0.25");
  expect_vec3_near(clip.pose(2)[0].translation, {1.0f, 2.0f, 10.0f - 3.0f}, tol, "root t=0.5");
  expect_vec3_near(clip.pose(8)[0].translation, {2.0f, 4.0f, 10.0f - 6.0f}, tol,
                   "root holds after its last key");

  // LINEAR rotation: 22.5 and 45 degrees about Y, the short way despite the negated key.
  EXPECT_LT(rotation_gap(clip.pose(1)[0].rotation, glm::angleAxis(glm::radians(22.5f), y)), 1e-6f);
  EXPECT_LT(rotation_gap(clip.pose(2)[0].rotation, glm::angleAxis(glm::radians(45.0f), y)), 1e-6f);
  EXPECT_LT(rotation_gap(clip.pose(4)[0].rotation, glm::angleAxis(glm::radians(90.0f), y)), 1e-6f);

  // STEP holds the first key until the second key's time.
  expect_vec3_near(clip.pose(2)[1].translation, {0, 1, 0}, tol, "child t=0.5");
  expect_vec3_near(clip.pose(3)[1].translation, {0, 1, 0}, tol, "child t=0.75");
  expect_vec3_near(clip.pose(4)[1].translation, {0, 3, 0}, tol, "child t=1");
  // No rotation channel: the node's rest rotation (90 degrees about X) stays.
  EXPECT_LT(rotation_gap(clip.pose(5)[1].rotation,
                         glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0))),
            1e-6f);

  // CUBICSPLINE on [0, 2] (dt = 2): p(s) = h00 v0 + h10 dt b0 + h01 v1 + h11 dt a1 with
  // v0 = (0,1,0), b0 = (1,0,0), v1 = (2,1,0), a1 = (0,0,3).
  // t = 0.5, s = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875
  //   -> x = 0.140625*2 + 0.15625*2 = 0.59375, y = 0.84375 + 0.15625 = 1, z = -0.046875*2*3 =
  //   -0.28125
  expect_vec3_near(clip.pose(2)[2].translation, {0.59375f, 1.0f, -0.28125f}, tol, "tip t=0.5");
  // t = 1, s = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125 -> (1.25, 1, -0.75)
  expect_vec3_near(clip.pose(4)[2].translation, {1.25f, 1.0f, -0.75f}, tol, "tip t=1");
  expect_vec3_near(clip.pose(8)[2].translation, {2.0f, 1.0f, 0.0f}, tol, "tip t=2");

  // The whole chain at t = 0.5, by hand: root at (1, 2, 7) turned 45 degrees about Y; child one
  // up; the tip's offset turned 90 degrees about X to (0.59375, 0.28125, 1), then 45 about Y.
  const std::vector<Transform> g = globals_of(clip, 2);
  expect_vec3_near(g[1].translation, {1.0f, 3.0f, 7.0f}, tol, "child global");
  expect_vec3_near(g[2].translation, {2.1269514f, 3.28125f, 7.2872621f}, tol, "tip global");
}

TEST(GltfImport, NonJointNodeBetweenJointsBecomesAJoint) {
  // Skin lists b before a; the unnamed node 1 sits between them and must be kept.
  const std::string json = R"({"asset":{"version":"2.0"},"nodes":[
      {"name":"a","children":[1]},
      {"translation":[0,1,0],"children":[2]},
      {"name":"a","translation":[0,2,0]}],
    "skins":[{"joints":[2,0]}]})";
  const fs::path path = test::scratch_dir() / "between.gltf";
  write_text(path, json);
  auto asset = load_gltf(path);
  ASSERT_TRUE(asset.ok()) << asset.message();
  // Depth-first from the root; duplicate and empty names disambiguated by node index.
  EXPECT_EQ(asset->skeleton.names(), (std::vector<std::string>{"a_0", "node_1", "a_2"}));
  EXPECT_EQ(asset->skeleton.parents(), (std::vector<int>{-1, 0, 1}));
  EXPECT_TRUE(asset->clips.empty());
  // The inserted joint binds at its rest global (0, 1, 0); the skin's joints have no matrices.
  ASSERT_EQ(asset->inverse_bind_matrices.size(), 3u);
  const glm::vec4 moved = asset->inverse_bind_matrices[1] * glm::vec4(0, 1, 0, 1);
  expect_vec3_near(glm::vec3(moved), {0, 0, 0}, 1e-6f, "inverse bind of node_1");
  EXPECT_EQ(asset->inverse_bind_matrices[2], glm::mat4(1.0f));
}

TEST(GltfImport, AnimatedAncestorsFoldIntoTheRoot) {
  // A Mixamo-like armature node (90 degrees about X, scale 0.01) above the joints, with its own
  // translation animated from (0, 0, 0) to (1, 0, 0) over one second.
  const std::vector<float> floats = {0, 1, 0, 0, 0, 1, 0, 0};
  std::vector<unsigned char> bytes(floats.size() * sizeof(float));
  std::memcpy(bytes.data(), floats.data(), bytes.size());
  const std::string json = R"({"asset":{"version":"2.0"},
    "buffers":[{"byteLength":32,"uri":"data:application/octet-stream;base64,)" +
                           base64(bytes) + R"("}],
    "bufferViews":[{"buffer":0,"byteLength":32}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},
                 {"bufferView":0,"byteOffset":8,"componentType":5126,"count":2,"type":"VEC3"}],
    "nodes":[{"name":"armature","rotation":[0.70710678,0,0,0.70710678],"scale":[0.01,0.01,0.01],"children":[1]},
             {"name":"hips","translation":[0,100,0],"children":[2]},
             {"name":"spine","translation":[0,50,0]}],
    "skins":[{"joints":[1,2]}],
    "animations":[{"samplers":[{"input":0,"output":1}],
                   "channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}]}]})";
  const fs::path path = test::scratch_dir() / "armature.gltf";
  write_text(path, json);
  auto asset = load_gltf(path, {.sample_rate = 2.0f});
  ASSERT_TRUE(asset.ok()) << asset.message();
  EXPECT_EQ(asset->skeleton.names(), (std::vector<std::string>{"hips", "spine"}));
  ASSERT_EQ(asset->clips.size(), 1u);
  const Clip& clip = asset->clips[0];
  EXPECT_EQ(clip.name, "armature");  // unnamed, single animation: the file stem
  ASSERT_EQ(clip.frame_count, 3);
  // Rest: 0.01 * (0, 100, 0) turned 90 degrees about X is (0, 0, 1); the spine 0.5 further.
  std::vector<Transform> rest(2);
  forward_kinematics(asset->skeleton.parents(), asset->skeleton.rest(), rest);
  expect_vec3_near(rest[0].translation, {0, 0, 1}, 1e-5f, "hips rest");
  expect_vec3_near(rest[1].translation, {0, 0, 1.5f}, 1e-5f, "spine rest");
  // t = 0.5 s: the armature has moved halfway to (1, 0, 0).
  const std::vector<Transform> g = globals_of(clip, 1);
  expect_vec3_near(g[0].translation, {0.5f, 0, 1}, 1e-5f, "hips t=0.5");
  expect_vec3_near(g[1].translation, {0.5f, 0, 1.5f}, 1e-5f, "spine t=0.5");
}

TEST(GltfImport, ResamplingAtTheKeyRateReproducesSuddenJumps) {
  // 20 s of a root teleporting 5 m every frame: sampling at the keys' own rate must land on
  // the keys, not blend a sliver of the neighbour because float key times carry rounding.
  Clip clip;
  clip.name = "jumps";
  clip.skeleton = Skeleton::create({"root"}, {-1}, {Transform{}}).value();
  clip.frame_time = 1.0f / 30.0f;
  clip.frame_count = 600;
  clip.local.resize(600);
  for (int f = 0; f < 600; ++f)
    clip.local[static_cast<size_t>(f)].translation.x = f % 2 == 0 ? 0.0f : 5.0f;
  const fs::path path = test::scratch_dir() / "jumps.glb";
  ASSERT_TRUE(save_gltf(clip, path).ok());
  auto asset = load_gltf(path, {.sample_rate = 30.0f});
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips[0].frame_count, 600);
  float worst = 0.0f;
  for (int f = 0; f < 600; ++f) {
    worst = std::max(
        worst, std::abs(asset->clips[0].pose(f)[0].translation.x - clip.pose(f)[0].translation.x));
  }
  EXPECT_LT(worst, 1e-6f);
}

TEST(GltfImport, ReadsRotationsStoredAsNormalizedShorts) {
  // glTF allows normalized integer rotations: 32767 maps to 1.
  Fixture fixture;
  std::vector<int16_t> shorts = {0, 0, 0, 32767, 0, 23170, 0, 23170};  // identity, 90 deg about Y
  std::vector<float> packed(4);
  std::memcpy(packed.data(), shorts.data(), 16);
  fixture.buffer.insert(fixture.buffer.end(), packed.begin(), packed.end());  // byte 168
  replace_once(
      fixture.accessors,
      R"({"bufferView":0,"byteOffset":32,"componentType":5126,"count":2,"type":"VEC4"})",
      R"({"bufferView":0,"byteOffset":168,"componentType":5122,"normalized":true,"count":2,"type":"VEC4"})");
  const fs::path path = fixture.write(test::scratch_dir() / "shorts.gltf");
  auto asset = load_gltf(path, {.sample_rate = 4.0f});
  ASSERT_TRUE(asset.ok()) << asset.message();
  EXPECT_LT(rotation_gap(asset->clips[0].pose(2)[0].rotation,
                         glm::angleAxis(glm::radians(45.0f), glm::vec3(0, 1, 0))),
            1e-6f);
}

// ---------------------------------------------------------------------------------------------
// Malformed files: refused with a message naming the file and the problem; never a crash.

TEST(GltfImport, RefusesMalformedFixtures) {
  const fs::path dir = test::scratch_dir();
  struct Case {
    const char* name;
    void (*edit)(Fixture&);
    const char* fragment;
  };
  const Case cases[] = {
      {"no_skin", [](Fixture& f) { f.skins.clear(); }, "no skin"},
      {"accessor_out_of_range",
       [](Fixture& f) {
         replace_once(f.animations, R"({"input":0,"output":1,)", R"({"input":0,"output":99,)");
       },
       "accessor index 99 is out of range"},
      {"wrong_type",
       [](Fixture& f) {
         replace_once(f.accessors, R"("byteOffset":8,"componentType":5126,"count":2,"type":"VEC3")",
                      R"("byteOffset":8,"componentType":5126,"count":2,"type":"VEC4")");
       },
       "has type VEC4, expected VEC3"},
      {"wrong_component_type",
       [](Fixture& f) {
         replace_once(f.accessors, R"("byteOffset":0,"componentType":5126)",
                      R"("byteOffset":0,"componentType":5123)");
       },
       "component type UNSIGNED_SHORT"},
      {"non_finite", [](Fixture& f) { f.buffer[5] = std::numeric_limits<float>::quiet_NaN(); },
       "not finite"},
      {"count_mismatch",
       [](Fixture& f) {
         replace_once(f.accessors, R"("byteOffset":64,"componentType":5126,"count":2)",
                      R"("byteOffset":64,"componentType":5126,"count":1)");
       },
       "2 key times but 1 output values"},
      {"cubic_count_mismatch",
       [](Fixture& f) {
         replace_once(f.accessors, R"("byteOffset":96,"componentType":5126,"count":6)",
                      R"("byteOffset":96,"componentType":5126,"count":2)");
       },
       "expected 6"},
      {"accessor_past_view",
       [](Fixture& f) {
         replace_once(f.accessors, R"("byteOffset":96,"componentType":5126,"count":6)",
                      R"("byteOffset":96,"componentType":5126,"count":600)");
       },
       "do not fit in buffer view 0"},
      {"view_past_buffer", [](Fixture& f) { f.buffer_view_length = "100000"; }, "buffer"},
      {"times_not_increasing", [](Fixture& f) { f.buffer[1] = -1.0f; }, "key times must increase"},
      {"zero_rotation", [](Fixture& f) { f.buffer[11] = 0.0f; }, "rotation key 0 has zero length"},
      {"no_channels",
       [](Fixture& f) { f.animations = R"([{"name":"empty","samplers":[],"channels":[]}])"; },
       "has no channels"},
      {"target_out_of_range",
       [](Fixture& f) { replace_once(f.animations, R"("node":3,"path")", R"("node":42,"path")"); },
       "target node 42 is out of range"},
      {"sampler_out_of_range",
       [](Fixture& f) { replace_once(f.animations, R"({"sampler":3,)", R"({"sampler":7,)"); },
       "sampler 7 is out of range"},
      {"unknown_interpolation",
       [](Fixture& f) {
         replace_once(f.animations, R"("interpolation":"STEP")", R"("interpolation":"SMOOTH")");
       },
       "unknown interpolation 'SMOOTH'"},
      {"duplicate_target",
       [](Fixture& f) { replace_once(f.animations, R"("node":3,"path")", R"("node":0,"path")"); },
       "both animate the translation of node 0 'root'"},
      {"skin_joint_out_of_range", [](Fixture& f) { f.skins = R"([{"joints":[0,1,17]}])"; },
       "node 17, out of range"},
      {"node_cycle",
       [](Fixture& f) {
         replace_once(f.nodes, R"("children":[0,3])", R"("children":[3])");
         replace_once(f.nodes, R"({"name":"tip","translation":[0,0.5,0]})",
                      R"({"name":"tip","translation":[0,0.5,0],"children":[0]})");
       },
       "cycle"},
      {"bad_node_rotation",
       [](Fixture& f) {
         replace_once(f.nodes, R"("rotation":[0.70710678,0,0,0.70710678])", R"("rotation":[1,0])");
       },
       "rotation has 2 numbers, expected 4"},
      {"not_json", [](Fixture& f) { f.nodes = "[{]"; }, "not a valid glTF 2.0 file"},
      {"too_long_to_sample", [](Fixture& f) { f.buffer[23] = 1e9f; }, "would exceed the limit"},
      {"huge_accessor_without_view",
       [](Fixture& f) {
         replace_once(f.accessors,
                      R"({"bufferView":0,"byteOffset":64,"componentType":5126,"count":2,)",
                      R"({"componentType":5126,"count":4000000000,)");
       },
       "has no buffer view and claims 4000000000 elements"},
  };
  for (const Case& c : cases) {
    Fixture fixture;
    c.edit(fixture);
    const fs::path path = fixture.write(dir / (std::string(c.name) + ".gltf"));
    SCOPED_TRACE(c.name);
    expect_refused(load_gltf(path, {.sample_rate = 4.0f}), path, c.fragment);
  }
}

TEST(GltfImport, RefusesBadOptionsAndMissingFiles) {
  const fs::path dir = test::scratch_dir();
  const fs::path path = Fixture{}.write(dir / "fixture.gltf");
  expect_refused(load_gltf(path, {.sample_rate = 0.0f}), path, "sample rate");
  expect_refused(load_gltf(path, {.sample_rate = std::nanf("")}), path, "sample rate");
  expect_refused(load_gltf(path, {.sample_rate = 30.0f, .skin = 3}), path,
                 "skin 3 requested but the file has 1");
  expect_refused(load_gltf(dir / "missing.glb"), dir / "missing.glb", "cannot open");
}

TEST(GltfImport, RefusesTruncatedAndGarbageFiles) {
  const fs::path dir = test::scratch_dir();
  ASSERT_TRUE(save_gltf(synthetic_clip(), dir / "valid.glb").ok());
  const std::vector<unsigned char> glb = read_bytes(dir / "valid.glb");

  const fs::path truncated = dir / "truncated.glb";
  write_bytes(truncated, glb.data(), glb.size() / 2);
  expect_refused(load_gltf(truncated), truncated, "truncated");

  std::mt19937 rng(1234);
  std::vector<unsigned char> garbage(4096);
  for (unsigned char& b : garbage) b = static_cast<unsigned char>(rng());
  const fs::path garbage_gltf = dir / "garbage.gltf";
  write_bytes(garbage_gltf, garbage.data(), garbage.size());
  expect_refused(load_gltf(garbage_gltf), garbage_gltf, "not a valid glTF 2.0 file");
  const fs::path garbage_glb = dir / "garbage.glb";
  write_bytes(garbage_glb, garbage.data(), garbage.size());
  expect_refused(load_gltf(garbage_glb), garbage_glb, "magic");

  std::memcpy(garbage.data(), "glTF", 4);
  const fs::path magic_then_garbage = dir / "magic.glb";
  write_bytes(magic_then_garbage, garbage.data(), garbage.size());
  expect_refused(load_gltf(magic_then_garbage), magic_then_garbage, "binary glTF (GLB)");

  const fs::path empty = dir / "empty.gltf";
  write_bytes(empty, "", 0);
  expect_refused(load_gltf(empty), empty, "not a valid glTF 2.0 file");
}

TEST(GltfImport, SurvivesEveryTruncationAndRandomCorruption) {
  // Every outcome is either a clip or a message; the point is that nothing crashes (run under
  // ASan/UBSan) and no refusal is silent.
  const fs::path dir = test::scratch_dir();
  ASSERT_TRUE(save_gltf(synthetic_clip(), dir / "valid.glb").ok());
  const std::vector<unsigned char> glb = read_bytes(dir / "valid.glb");
  const std::string json = Fixture{}.json();
  const std::vector<unsigned char> text(json.begin(), json.end());

  int refused = 0;
  auto attempt = [&](const std::vector<unsigned char>& bytes, const char* name) {
    auto result = parse_gltf(bytes, dir / name, {.sample_rate = 4.0f});
    if (!result.ok()) {
      EXPECT_FALSE(result.message().empty());
      ++refused;
    }
  };
  for (size_t size = 0; size < glb.size(); size += 13) {
    attempt(
        std::vector<unsigned char>(glb.begin(), glb.begin() + static_cast<std::ptrdiff_t>(size)),
        "cut.glb");
  }
  for (size_t size = 0; size < text.size(); size += 17) {
    attempt(
        std::vector<unsigned char>(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(size)),
        "cut.gltf");
  }
  EXPECT_GT(refused, 0);
  std::mt19937 rng(99);
  for (int i = 0; i < 300; ++i) {
    for (const std::vector<unsigned char>* source : {&glb, &text}) {
      std::vector<unsigned char> bytes = *source;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k)
        bytes[rng() % bytes.size()] = static_cast<unsigned char>(rng());
      attempt(bytes, source == &glb ? "mutated.glb" : "mutated.gltf");
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Real data: BVH -> glTF -> import reproduces every global joint position.

void check_bvh_round_trip(const std::string& stem, const char* extension) {
  auto bvh = load_bvh(test::clip_path(stem));
  ASSERT_TRUE(bvh.ok()) << bvh.message();
  const fs::path path = test::scratch_dir() / (stem + extension);
  ASSERT_TRUE(save_gltf(*bvh, path).ok());
  auto asset = load_gltf(path, {.sample_rate = 1.0f / bvh->frame_time});
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  const Clip& clip = asset->clips[0];
  EXPECT_EQ(clip.name, stem);
  EXPECT_EQ(clip.joint_count(), 22);
  const float error = max_global_position_error(*bvh, clip);
  EXPECT_LT(error, 1e-4f) << stem;
  std::printf("[ measure  ] %s%s: %d frames x %d joints, largest global position error %.3g m\n",
              stem.c_str(), extension, clip.frame_count, clip.joint_count(),
              static_cast<double>(error));
}

TEST(GltfRealData, Set2WalkBvhRoundTripReproducesGlobalPositions) {
  check_bvh_round_trip("dataset-2_walk_normal_001", ".glb");
}

TEST(GltfRealData, Set2RunBvhRoundTripThroughGltfText) {
  check_bvh_round_trip("dataset-2_run_normal_001", ".gltf");
}

TEST(GltfRealData, Set1WalkBackWithTranslatingRootRoundTrips) {
  check_bvh_round_trip("dataset-1_walk-back_normal_001", ".glb");
}

TEST(GltfRealData, Set1WalkLeftRoundTrips) {
  check_bvh_round_trip("dataset-1_walk-left_normal_001", ".glb");
}

}  // namespace
}  // namespace mm
