#pragma once
// What the two glTF fuzz targets share (gltf_fuzz.cpp: any bytes; gltf_structure_fuzz.cpp:
// GLB files mutated chunk by chunk): the importer's contract on one input, and the seeds.
//
// Contract: parse_gltf (from memory, external files refused) returns; an accepted file is a
// non-empty skeleton with one inverse bind matrix per joint, valid clips on that skeleton and,
// when asked for, a skinned mesh whose indices and influences are in range; a refused one gets
// a message starting with the file name. Each accepted input is parsed again with the skinned
// mesh asked for, which reaches the mesh reader.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "fuzz_checks.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/runtime/pose.hpp"

namespace mm::fuzz {

inline constexpr const char* kGltfName = "fuzz.gltf";

inline void check_mesh(const SkinnedMesh& body, size_t joints) {
  const size_t vertices = body.mesh.positions.size();
  if (body.influences.size() != vertices) fail("influences per vertex", std::to_string(vertices));
  if (body.bind_global.size() != joints) fail("bind pose per joint", std::to_string(joints));
  if (!body.mesh.normals.empty() && body.mesh.normals.size() != vertices) {
    fail("normals per vertex", std::to_string(body.mesh.normals.size()));
  }
  if (body.mesh.indices.size() % 3 != 0) fail("index count", std::to_string(vertices));
  for (uint32_t index : body.mesh.indices) {
    if (index >= vertices) fail("index out of range", std::to_string(index));
  }
  for (const VertexInfluences& v : body.influences) {
    for (int k = 0; k < 4; ++k) {
      if (v.joints[k] < 0 || static_cast<size_t>(v.joints[k]) >= joints) {
        fail("influence joint out of range", std::to_string(v.joints[k]));
      }
    }
  }
}

inline void check(const Result<GltfAsset>& asset, bool with_mesh) {
  if (!asset.ok()) {
    const std::string prefix = std::string(kGltfName) + ": ";
    if (asset.message().rfind(prefix, 0) != 0) fail("message without the file", asset.message());
    return;
  }
  const size_t joints = static_cast<size_t>(asset->skeleton.joint_count());
  if (joints == 0) fail("accepted an empty skeleton", "");
  if (asset->inverse_bind_matrices.size() != joints) fail("inverse bind matrices", "");
  for (const Clip& clip : asset->clips) {
    if (const Status valid = clip.validate(); !valid.ok()) fail("invalid clip", valid.message());
    if (static_cast<size_t>(clip.joint_count()) != joints) fail("clip skeleton", clip.name);
  }
  if (with_mesh != asset->skinned_mesh.has_value()) fail("skinned mesh presence", "");
  if (with_mesh) check_mesh(*asset->skinned_mesh, joints);
}

// Parses the bytes as a file from memory, then (if accepted) again with its skinned mesh.
inline void parse_and_check(std::span<const unsigned char> bytes) {
  GltfImportOptions options;
  options.allow_external_files = false;
  const Result<GltfAsset> asset = parse_gltf(bytes, kGltfName, options);
  check(asset, false);
  if (!asset.ok()) return;
  options.read_skinned_mesh = true;
  const Result<GltfAsset> with_mesh = parse_gltf(bytes, kGltfName, options);
  if (with_mesh.ok()) check(with_mesh, true);
}

// The folder libFuzzer writes its corpus to (the first positional argument), or empty.
inline std::filesystem::path corpus_folder(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-') continue;
    std::error_code error;
    return std::filesystem::is_directory(argv[i], error) ? argv[i] : "";
  }
  return {};
}

// Writes the seeds into the corpus folder, if there is one and they are not there yet: a
// three-joint skeleton walking for three frames as .glb (and .gltf when text_too), and the
// same with a skinned one-triangle body, all written by the exporter (nothing binary is
// committed).
inline void write_seeds(int argc, char** argv, bool text_too) {
  const std::filesystem::path folder = corpus_folder(argc, argv);
  std::error_code error;
  if (folder.empty() || std::filesystem::exists(folder / "seed_clip.glb", error)) return;
  std::vector<Transform> rest(3);
  rest[1].translation = {0.0f, 0.9f, 0.0f};
  rest[2].translation = {0.1f, -0.8f, 0.0f};
  auto skeleton = Skeleton::create({"Root", "Hips", "Foot_L"}, {-1, 0, 1}, rest);
  if (!skeleton) fail("seed skeleton", skeleton.message());
  Clip clip;
  clip.name = "walk";
  clip.skeleton = *skeleton;
  clip.frame_count = 3;
  for (int f = 0; f < clip.frame_count; ++f) {
    for (Transform t : rest) {
      t.translation.z += 0.1f * static_cast<float>(f);
      t.rotation = glm::angleAxis(0.2f * static_cast<float>(f), glm::vec3(0.0f, 1.0f, 0.0f));
      clip.local.push_back(t);
    }
  }
  SkinnedMesh body;
  body.mesh.positions = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.9f, 0.0f}, {0.1f, 0.1f, 0.0f}};
  body.mesh.indices = {0, 1, 2};
  body.influences.resize(3);
  for (int v = 0; v < 3; ++v)
    body.influences[static_cast<size_t>(v)] = {{v, 0, 0, 0}, {1, 0, 0, 0}};
  body.bind_global.resize(3);
  forward_kinematics(skeleton->parents(), rest, body.bind_global);
  Status saved = save_gltf(clip, folder / "seed_clip.glb");
  if (saved && text_too) saved = save_gltf(clip, folder / "seed_clip.gltf");
  if (saved) {
    saved = save_skinned_gltf(*skeleton, body, clip.local, clip.frame_count, clip.frame_time,
                              "walk", folder / "seed_body.glb");
  }
  if (!saved) fail("writing the seeds", saved.message());
}

}  // namespace mm::fuzz
