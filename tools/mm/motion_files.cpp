#include "motion_files.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/character_body.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/programs/number_parsing.hpp"

namespace mm::cli {
namespace {

namespace fs = std::filesystem;

// The largest distance from the root of a joint or End Site of a BVH skeleton in its rest pose
// (BVH rest rotations are the identity, so positions are sums of offsets; roots at the origin,
// as the importer measures it).
float rest_extent(const Clip& clip) {
  const Skeleton& s = clip.skeleton;
  std::vector<glm::vec3> position(static_cast<size_t>(s.joint_count()));
  float extent = 0.0f;
  for (int j = 0; j < s.joint_count(); ++j) {
    const int parent = s.parent(j);
    position[j] = parent < 0 ? glm::vec3(0.0f) : position[parent] + s.rest(j).translation;
    const glm::vec3 tip = static_cast<size_t>(j) < clip.end_sites.size()
                              ? position[j] + clip.end_sites[static_cast<size_t>(j)]
                              : position[j];
    extent = std::max({extent, glm::length(position[j]), glm::length(tip)});
  }
  return extent;
}

// A BVH file in metres and its units. With automatic units the file is read twice, once in its
// own units to learn which the importer picks: the importer does not say, and a clip in metres
// no longer tells inches from metres by its size alone.
Result<MotionFile> read_bvh(const std::string& path, float scale) {
  MotionFile file;
  if (scale <= 0.0f) {
    Result<Clip> raw = load_bvh(path, BvhOptions{1.0f});
    if (!raw) return Error{raw.message()};
    scale = bvh_units_to_metres(rest_extent(*raw));
    file.file_skeleton = raw->skeleton;
    file.file_end_sites = raw->end_sites;
    if (scale == 1.0f) file.clip = std::move(raw).value();
  }
  if (file.clip.joint_count() == 0) {
    Result<Clip> clip = load_bvh(path, BvhOptions{scale});
    if (!clip) return Error{clip.message()};
    file.clip = std::move(clip).value();
  }
  file.units_per_metre = 1.0f / scale;
  return file;
}

// One frame of the skeleton's rest pose, for a glTF file that has no animation.
Clip rest_pose_clip(const Skeleton& skeleton, const std::string& path) {
  Clip clip;
  clip.name = fs::path(path).stem().string();
  clip.source_path = path;
  clip.skeleton = skeleton;
  clip.frame_count = 1;
  clip.local = skeleton.rest();
  return clip;
}

Result<MotionFile> read_gltf(const std::string& path, const MotionFileOptions& options) {
  GltfImportOptions gltf;
  gltf.sample_rate = options.gltf_rate;
  Result<GltfAsset> asset = load_gltf(path, gltf);
  if (!asset) return Error{asset.message()};
  MotionFile file;
  if (asset->clips.empty() && options.clip_selector.empty()) {
    file.clip = rest_pose_clip(asset->skeleton, path);
    return file;
  }
  std::vector<std::string> names;
  for (const Clip& c : asset->clips) names.push_back(c.name);
  Result<size_t> index = select_clip(options.clip_selector, names, path);
  if (!index) return Error{index.message()};
  file.clip = std::move(asset->clips[*index]);
  return file;
}

// The database skeleton without joint 0: its children become roots.
Result<Skeleton> skeleton_without_simulation_root(const Skeleton& s) {
  std::vector<std::string> names(s.names().begin() + 1, s.names().end());
  std::vector<int> parents;
  for (int j = 1; j < s.joint_count(); ++j) parents.push_back(std::max(s.parent(j) - 1, -1));
  std::vector<Transform> rest(s.rest().begin() + 1, s.rest().end());
  return Skeleton::create(std::move(names), std::move(parents), std::move(rest));
}

// Every database frame on that skeleton; the joints under joint 0 take on its transform.
std::vector<Transform> frames_without_simulation_root(const Database& db) {
  const int joints = db.joint_count();
  std::vector<Transform> local(static_cast<size_t>(db.frame_count()) * (joints - 1));
  for (int f = 0; f < db.frame_count(); ++f) {
    const size_t row = static_cast<size_t>(f) * joints;
    const Transform simulation{db.local_rotations()[row], db.local_positions()[row],
                               glm::vec3(1.0f)};
    for (int j = 1; j < joints; ++j) {
      const Transform t{db.local_rotations()[row + j], db.local_positions()[row + j],
                        glm::vec3(1.0f)};
      local[static_cast<size_t>(f) * (joints - 1) + (j - 1)] =
          db.skeleton().parent(j) == 0 ? compose(simulation, t) : t;
    }
  }
  return local;
}

Result<MotionFile> read_database(const std::string& path) {
  Result<Database> db = load_database(path);
  if (!db) return Error{db.message()};
  Result<Skeleton> skeleton = skeleton_without_simulation_root(db->skeleton());
  if (!skeleton) return Error{path + ": " + skeleton.message()};
  MotionFile file;
  file.clip.name = fs::path(path).stem().string();
  file.clip.source_path = path;
  file.clip.skeleton = std::move(skeleton).value();
  file.clip.frame_time = db->frame_time();
  file.clip.frame_count = db->frame_count();
  file.clip.local = frames_without_simulation_root(*db);
  file.rest_frame = std::max(bind_source_frame(*db), 0);
  JointRoleIndices roles;
  for (const JointRoleInfo& role : kJointRoles) {
    const int j = db->roles().*role.index;
    roles.*role.index = j > 0 ? j - 1 : -1;
  }
  file.stored_roles = roles;
  return file;
}

}  // namespace

bool is_motion_file_name(const std::string& path, bool allow_database) {
  const std::string ext = lower_extension(path);
  return ext == ".bvh" || ext == ".gltf" || ext == ".glb" || (allow_database && ext == ".mmdb");
}

Result<MotionFile> read_motion_file(const std::string& path, const MotionFileOptions& options) {
  if (!is_motion_file_name(path, options.allow_database)) {
    return Error{path + ": not a motion file (expected .bvh, .gltf or .glb" +
                 std::string(options.allow_database ? " or .mmdb)" : ")")};
  }
  const std::string ext = lower_extension(path);
  if (ext == ".mmdb") return read_database(path);
  if (ext == ".gltf" || ext == ".glb") return read_gltf(path, options);
  if (!options.clip_selector.empty() && options.clip_selector != "0") {
    return Error{path + ": a BVH file holds one clip (index 0)"};
  }
  return read_bvh(path, options.bvh_scale);
}

void print_import_warnings(const char* command, const Clip& clip) {
  for (const std::string& w : clip.warnings)
    std::fprintf(stderr, "%s: warning: %s\n", command, w.c_str());
}

Result<size_t> select_clip(const std::string& selector, const std::vector<std::string>& names,
                           const std::string& file) {
  if (names.empty()) return Error{file + ": has no clips"};
  if (selector.empty()) return size_t{0};
  if (std::optional<long long> index = parse_count(selector)) {
    if (*index < static_cast<long long>(names.size())) return static_cast<size_t>(*index);
    return Error{file + ": clip index " + selector + " is out of range (the file has " +
                 std::to_string(names.size()) + " clips, 0 to " + std::to_string(names.size() - 1) +
                 ")"};
  }
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == selector) return i;
  }
  std::string some;
  for (size_t i = 0; i < names.size() && i < 8; ++i) some += (i ? ", " : "") + names[i];
  if (names.size() > 8) some += ", ...";
  return Error{file + ": no clip named '" + selector + "' (clips: " + some + ")"};
}

}  // namespace mm::cli
