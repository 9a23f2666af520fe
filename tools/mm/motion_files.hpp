#pragma once
// Motion files as the commands that take "any file with a skeleton" read them (`mm retarget`,
// `mm build --target`, `mm export`): a BVH, glTF or database file becomes one Clip in metres,
// with what a retargeting needs to know about it besides (its units, a stored rest frame and
// stored roles).

#include <optional>
#include <string>
#include <vector>

#include "mm/database/joint_roles.hpp"
#include "mm/offline/clip.hpp"
#include "mm/runtime/result.hpp"

namespace mm::cli {

// One clip of a motion file, and how the file measures and describes its skeleton.
struct MotionFile {
  Clip clip;  // metres
  // File units per metre, for a BVH written on this skeleton: what the importer chose for a BVH
  // file (bvh_units_to_metres, or the forced scale), 1 for glTF and databases (metres).
  float units_per_metre = 1.0f;
  // The frame that stands for the rest pose (a database's bind source frame), -1 to let
  // describe_for_retargeting choose.
  int rest_frame = -1;
  // A BVH file read with automatic units: its skeleton and End Sites in the file's own units,
  // as its OFFSET lines state them, so a BVH written on this skeleton repeats them exactly
  // rather than after a round trip through metres. Empty otherwise.
  std::optional<Skeleton> file_skeleton;
  std::vector<glm::vec3> file_end_sites;
  // The roles a database stores (in `clip`'s joints); empty for files whose roles are found by
  // name.
  std::optional<JointRoleIndices> stored_roles;
};

// How to read a motion file.
struct MotionFileOptions {
  // Which clip of a glTF file: an index or an animation name; empty for the first.
  std::string clip_selector;
  // BVH units to metres; 0 picks them from the skeleton's size (bvh_units_to_metres).
  float bvh_scale = 0.0f;
  // The rate a glTF file's animation is sampled at (Hz).
  float gltf_rate = 30.0f;
  // Whether a database (.mmdb) is accepted.
  bool allow_database = false;
};

// True for the extensions read_motion_file takes: .bvh, .gltf, .glb, and .mmdb when allowed.
bool is_motion_file_name(const std::string& path, bool allow_database);

// Reads `path` as its extension says. A database becomes one clip of all its frames on its
// skeleton without the simulation root (joint 0 is folded into the joints below it, so their
// globals stay where the database puts them); a glTF file without animation becomes one frame
// of its rest pose. Errors name the file.
Result<MotionFile> read_motion_file(const std::string& path, const MotionFileOptions& options);

// Prints what the importer accepted but ignored in a file (Clip::warnings) to stderr, one
// "<command>: warning: <warning>" line each, as `mm build` prints its report's warnings.
void print_import_warnings(const char* command, const Clip& clip);

// The index of the clip `selector` names among `names` (an index or an exact name; empty: 0),
// or an error naming `file` and listing what exists.
Result<size_t> select_clip(const std::string& selector, const std::vector<std::string>& names,
                           const std::string& file);

}  // namespace mm::cli
