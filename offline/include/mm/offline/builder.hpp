#pragma once
// The database builder: files (or in-memory clips) in, one Database out.
//
// Four phases. 1, parallel over inputs (workers pull input indices from a shared counter):
// import (BVH or glTF), validate, resample to the database rate, find the joint roles. 2, in
// input order: refuse failed inputs, retarget the clips of skeletons other than the first
// input's (or BuildOptions::target's) onto it (retarget.hpp; one line per source skeleton in the
// report), pass the import warnings (Clip::warnings) of the target and of every input used on to
// BuildReport::warnings, lay out the clip ranges (a mirrored copy right after its original), their
// tags and the database arrays. 3, parallel over clips, each worker with its own reusable buffers:
// preprocess (simulation root, velocities, contacts; see preprocess.hpp) and extract the raw
// features (feature_extraction.hpp) straight into the database arrays at the clip's frames. 4:
// normalize the features over the searchable frames of the whole database and validate the
// result. Every per-clip step is independent of the others and the statistics are summed in
// frame order, so the output is byte-for-byte the same whatever the number of threads.
//
// Idle clips of the data (tagged "idle" by name, e.g. ReActIdle's; see tags.hpp) keep joint 0
// still at their mean place and facing (SimulationRootOptions::fixed), and replace the
// synthesized idle clip. Without them, the synthesized one (idle.hpp): unless
// options.idle_seconds is 0, phase 2 also reserves one clip
// named "idle" and tagged "idle" after every other clip, and between phases 3 and 4 it is
// filled with the calmest frame that stands on both feet, held still, and its raw features are
// extracted like any clip's, so phase 4 normalizes them with the rest. When no frame
// qualifies the reserved frames are given back and a warning says why.
//
// Inputs are files or folders. Folders are scanned recursively for .bvh, .gltf and .glb files
// (extensions compared case-insensitively), sorted by path; files given by name are taken in
// the given order, whatever their extension (".gltf"/".glb" are read as glTF, anything else as
// BVH). A path given twice is read once. Clips appear in the database in input order, a
// glTF file's animations in file order, and a clip's mirrored copy right after it.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/features.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/clip.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/offline/tags.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// Everything the builder can be told.
struct BuildOptions {
  // Database frames per second; every clip is resampled to it. Finite, in (0, 1000].
  float rate = 30.0f;
  // Adds a mirrored copy of every clip (named "<name>_mirror", tagged "mirrored"). The idle
  // clip is never mirrored.
  bool mirror = false;
  // Length in seconds of the idle clip (see idle.hpp); 0 for none. Finite, in [0, 60], and
  // when not 0 long enough for at least one of its frames to be searchable (the default
  // schema looks 1 s ahead, so a little over 1 s).
  float idle_seconds = 3.0f;
  // Left/right joint pairs that override the name-pattern detection when mirroring.
  std::vector<MirrorPair> mirror_pairs;
  // Optional tag manifest (see tags.hpp); empty for none.
  std::filesystem::path tags_file;
  // Tag rules applied in addition to the manifest's (for programs that build in memory).
  std::vector<TagRule> tag_rules;
  // The name candidates of every joint role (joint_roles.hpp).
  JointRoles roles;
  // Roles named by a map file or --role: each makes its joint the role's only candidate, and a
  // joint it names must exist in every clip's skeleton.
  std::vector<JointRoleAssignment> role_map;
  // How the simulation root (joint 0) is derived.
  SimulationRootOptions root;
  // How foot contacts are detected.
  ContactOptions contacts;
  // The feature channels of the database.
  FeatureSchema schema = FeatureSchema::default_schema();
  // Refuse bad inputs (listed in the report) and build from the rest, instead of failing.
  bool skip_bad = false;
  // Worker threads; 0 uses every hardware thread. Never more than there are inputs.
  int threads = 0;
  // Called with (done, total) as the build advances, from the worker threads but never two at
  // a time; total = 2 x inputs: each input counts once when imported and once when processed.
  // May be empty.
  std::function<void(size_t done, size_t total)> progress;
  // Settings of the BVH importer (its scale turns file units into metres).
  BvhOptions bvh;
  // The database skeleton, when set: this clip's skeleton (joint names, hierarchy, rest
  // offsets) instead of the first input's, with its roles (found with `roles` and
  // target_role_map) and its rest pose and ground for retargeting; every input of another
  // skeleton is retargeted onto it. Its frames are not added to the database.
  std::optional<Clip> target;
  // Roles named for the target's skeleton, as role_map does for the inputs'.
  std::vector<JointRoleAssignment> target_role_map;
};

// An input the builder refused, and why.
struct RefusedInput {
  std::filesystem::path path;  // the file (or "<clip name>" for in-memory clips)
  std::string message;         // what was wrong, naming the file
};

// What happened during a build.
struct BuildReport {
  int inputs = 0;                     // files (or in-memory clips) offered
  int clips = 0;                      // clips in the database (mirrored copies and idle too)
  int frames = 0;                     // database frames
  int searchable_frames = 0;          // frames the search may return
  double duration_s = 0.0;            // frames / rate
  uint64_t bytes_read = 0;            // bytes of the files that were read
  int threads = 0;                    // worker threads used
  double load_seconds = 0.0;          // wall time of phase 1: import, validation, resampling
  double layout_seconds = 0.0;        // phase 2: checks, clip ranges, tags, array allocation
  double process_seconds = 0.0;       // phase 3: preprocessing and raw features
  double finish_seconds = 0.0;        // phase 4: normalization and the final validation
  double total_seconds = 0.0;         // wall time of the whole build
  int idle_frames = 0;                // frames of the idle clip, 0 when there is none
  std::string idle_source_clip;       // the clip whose frame the idle clip holds
  int idle_source_frame = -1;         // that frame, counted from the start of its clip
  std::vector<std::string> warnings;  // import warnings (Clip::warnings) first, then the build's
  // One line per source skeleton retargeted onto the database's: its first input, clips,
  // joints matched, scale and the database joints left at rest.
  std::vector<std::string> retargeted;
  // How the idle takes of the data were cut into calm segments; empty without idle takes.
  std::string idle_summary;
  // Clips moved up or down to stand on y = 0, and how far; empty when every clip already did.
  std::string ground_summary;
  std::vector<RefusedInput> refused;  // inputs left out (only with skip_bad)
};

// The files a list of inputs stands for (see the top of this file). Fails on a path that does
// not exist or when no file is found.
Result<std::vector<std::filesystem::path>> collect_input_files(
    std::span<const std::filesystem::path> inputs);

// Builds a database from files and folders. On failure the message names the file and what was
// wrong with it. `report` may be null.
Result<Database> build_database(std::span<const std::filesystem::path> inputs,
                                const BuildOptions& options, BuildReport* report = nullptr);

// Builds a database from clips already in memory (any frame time; resampled to options.rate).
// Clip names stand in for file names in messages and tags.
Result<Database> build_database_from_clips(std::span<const Clip> clips, const BuildOptions& options,
                                           BuildReport* report = nullptr);

}  // namespace mm
