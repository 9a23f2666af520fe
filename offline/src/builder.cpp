#include "mm/offline/builder.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <set>

#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/internal/database_assembly.hpp"
#include "mm/internal/workers.hpp"
#include "mm/offline/feature_extraction.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/offline/idle.hpp"
#include "mm/offline/retarget.hpp"
#include "mm/runtime/float_to_integer.hpp"

namespace mm {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// printf into a string: the build report's lines and messages.
template <class... Args>
std::string formatted(const char* format, Args... args) {
  char buffer[320];
  std::snprintf(buffer, sizeof buffer, format, args...);
  return buffer;
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool is_motion_file(const fs::path& path) {
  return has_extension(path, {".bvh", ".gltf", ".glb"});
}

bool is_gltf_file(const fs::path& path) {
  return has_extension(path, {".gltf", ".glb"});
}

// What phase 1 made of one input (a file or an in-memory clip): its clips at the database
// rate, and the joint roles of their (shared) skeleton.
struct InputResult {
  bool processed = false;  // false when skipped after an earlier input failed, or refused
  Status status;
  std::vector<Clip> clips;
  JointRoleIndices roles;  // in the source skeleton
  uint64_t bytes = 0;
  // The importer's warnings of its clips (Clip::warnings, each message once), taken before
  // resampling makes new clips; they join BuildReport::warnings when the input is used.
  std::vector<std::string> warnings;
};

// Moves the clips' import warnings into `warnings`, each message once (a glTF file's clips may
// share one).
void take_import_warnings(std::vector<Clip>& clips, std::vector<std::string>& warnings) {
  for (Clip& clip : clips) {
    for (std::string& w : clip.warnings) {
      if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) {
        warnings.push_back(std::move(w));
      }
    }
    clip.warnings.clear();
  }
}

// One unit of phase 2: a clip (or its mirror) and where its frames go in the database.
struct ClipJob {
  size_t input = 0;       // index into the inputs
  size_t clip = 0;        // index into the input's clips
  bool mirrored = false;  // process the mirrored copy
  size_t range = 0;       // index of its ClipRange in the database
};

// Buffers one worker reuses for every clip it processes.
struct WorkerScratch {
  PreprocessScratch preprocess;
  FeatureScratch features;
};

// What every worker reads; set up once before the workers start.
struct BuildContext {
  const BuildOptions& options;
  std::vector<TagRule> tag_rules;
  PreprocessOptions preprocess;
  int dims = 0;
};

// Validates an imported clip, brings it to the database rate and finds its joint roles.
Status prepare_clip(Clip& clip, const std::string& input_name, const BuildOptions& options,
                    InputResult& result) {
  if (Status s = clip.validate(); !s) return Error{input_name + ": " + s.message()};
  if (needs_resampling(clip, options.rate)) {
    clip = resample_clip(clip, options.rate);
  } else {
    clip.frame_time = 1.0f / options.rate;
  }
  if (Status s = check_joint_map(clip.skeleton, options.role_map); !s) {
    return Error{input_name + ": clip '" + clip.name + "': " + s.message()};
  }
  JointRoles names = options.roles;
  apply_joint_map(names, options.role_map);
  Result<JointRoleIndices> roles = find_joint_roles(clip.skeleton, names);
  if (!roles) return Error{input_name + ": clip '" + clip.name + "': " + roles.message()};
  if (clip.skeleton.find(kSimulationJointName) >= 0) {
    return Error{input_name + ": clip '" + clip.name + "': has a joint named '" +
                 kSimulationJointName + "', the name the builder gives the simulation root"};
  }
  result.roles = *roles;
  return Status::success();
}

// Imports one file into clips at the database rate (glTF is sampled at it directly).
Result<std::vector<Clip>> import_file(const fs::path& path, const BuildOptions& options,
                                      uint64_t& bytes) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  bytes = ec ? 0 : static_cast<uint64_t>(size);
  std::vector<Clip> clips;
  if (is_gltf_file(path)) {
    GltfImportOptions gltf;
    gltf.sample_rate = options.rate;
    Result<GltfAsset> asset = load_gltf(path, gltf);
    if (!asset) return Error{asset.message()};
    if (asset->clips.empty()) {
      return Error{path.string() + ": the file has no animation that moves its skeleton"};
    }
    clips = std::move(asset->clips);
  } else {
    Result<Clip> clip = load_bvh(path, options.bvh);
    if (!clip) return Error{clip.message()};
    clips.push_back(std::move(clip).value());
  }
  return clips;
}

// Sets db.tag_names (sorted) and every clip's tag bits from its tag list (one per clip), and
// db.style_names (sorted) and every clip's style from its style name ("" for none).
using Assembly = detail::DatabaseAssembly;

Status assign_tags(Assembly::Parts db, const std::vector<std::vector<std::string>>& clip_tag_lists,
                   const std::vector<std::string>& clip_styles) {
  std::set<std::string> style_set(clip_styles.begin(), clip_styles.end());
  style_set.erase(std::string());
  if (style_set.size() > kMaxStyles) {
    return Error{"build: " + std::to_string(style_set.size()) + " distinct styles, at most " +
                 std::to_string(kMaxStyles) + " fit a database"};
  }
  db.style_names.assign(style_set.begin(), style_set.end());
  for (size_t r = 0; r < db.clips.size(); ++r) {
    const std::string& style = clip_styles[r];
    db.clips[r].style = style.empty()
                            ? -1
                            : static_cast<int>(std::lower_bound(db.style_names.begin(),
                                                                db.style_names.end(), style) -
                                               db.style_names.begin());
  }
  std::set<std::string> tag_set;
  for (const std::vector<std::string>& tags : clip_tag_lists)
    tag_set.insert(tags.begin(), tags.end());
  if (tag_set.size() > kMaxTags) {
    std::string some;
    for (const std::string& t : tag_set) some += (some.empty() ? "" : ", ") + t;
    return Error{"build: " + std::to_string(tag_set.size()) + " distinct tags, at most " +
                 std::to_string(kMaxTags) + " fit a database (" + some + ")"};
  }
  db.tag_names.assign(tag_set.begin(), tag_set.end());
  for (size_t r = 0; r < db.clips.size(); ++r) {
    db.clips[r].tags = 0;
    for (const std::string& tag : clip_tag_lists[r]) {
      const auto bit =
          std::lower_bound(db.tag_names.begin(), db.tag_names.end(), tag) - db.tag_names.begin();
      db.clips[r].tags |= uint64_t{1} << bit;
    }
  }
  return Status::success();
}

// The frames of the idle clip options.idle_seconds asks for (0 for none), or why it cannot
// have them. The options' rate and schema are already known to be valid.
Result<int> idle_frame_count(const BuildOptions& options) {
  const float seconds = options.idle_seconds;
  if (!std::isfinite(seconds) || seconds < 0.0f || seconds > 60.0f) {
    return Error{"build: the idle clip must last from 0 to 60 seconds (0: no idle clip), found " +
                 std::to_string(seconds)};
  }
  if (seconds == 0.0f) return 0;
  const int frames = clamped_integer<int>(std::round(static_cast<double>(seconds) * options.rate));
  // A frame is searchable only when every feature time lies inside its clip; an idle clip with
  // no searchable frame could never be chosen by the search.
  const FeatureFrameMargins margins = feature_frame_margins(options.schema, 1.0f / options.rate);
  const int least = margins.before + margins.after + 1;
  if (frames < least) {
    return Error{formatted(
        "build: an idle clip of %g s is %d frames at %g Hz, but the feature times need at least "
        "%d frames (%.3g s) for one of them to be searchable; ask for at least that, or 0 for no "
        "idle clip",
        static_cast<double>(seconds), frames, static_cast<double>(options.rate), least,
        least / static_cast<double>(options.rate))};
  }
  return frames;
}

// Checks the options before any input is read; returns the idle clip's frame count.
Result<int> check_build_options(const BuildOptions& options, size_t input_count) {
  if (!(options.rate > 0.0f) || !(options.rate <= 1000.0f)) {
    return Error{"build: the rate must be a number of frames per second in (0, 1000], found " +
                 std::to_string(options.rate)};
  }
  if (Status s = options.schema.validate(); !s) return Error{"build: " + s.message()};
  const Result<int> idle_frames = idle_frame_count(options);
  if (!idle_frames) return Error{idle_frames.message()};
  if (input_count == 0) return Error{"build: no inputs"};
  return *idle_frames;
}

// The tag rules (manifest first, then the options' own) and the preprocessing options.
Status make_context(const BuildOptions& options, BuildContext& context) {
  if (!options.tags_file.empty()) {
    Result<std::vector<TagRule>> rules = load_tag_manifest(options.tags_file);
    if (!rules) return Error{rules.message()};
    context.tag_rules = std::move(rules).value();
  }
  context.tag_rules.insert(context.tag_rules.end(), options.tag_rules.begin(),
                           options.tag_rules.end());
  context.preprocess.root = options.root;
  context.preprocess.contacts = options.contacts;
  return Status::success();
}

// Everything the phases of one build share.
struct BuildState {
  BuildState(const std::vector<std::string>& names, const BuildOptions& build_options,
             BuildReport& report, size_t input_count)
      : input_names(names),
        options(build_options),
        rep(report),
        context{build_options, {}, {}, build_options.schema.dims()},
        threads(detail::worker_threads(build_options.threads)),
        scratch(static_cast<size_t>(threads)),
        results(input_count),
        progress_total(2 * input_count) {}

  // Progress counts every input twice: once imported (phase 1), once processed (phase 3).
  void step() {
    if (!options.progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    options.progress(++progress_done, progress_total);
  }

  const std::vector<std::string>& input_names;
  const BuildOptions& options;
  BuildReport& rep;
  BuildContext context;
  int threads;
  std::vector<WorkerScratch> scratch;
  std::vector<InputResult> results;
  size_t progress_total;
  std::mutex progress_mutex;
  size_t progress_done = 0;

  // Phase 2 on: the database, filled in place.
  Database db = Assembly::empty();
  // Phases 3a and 3b: the database's pose per joint (frame * joints + joint), as preprocessing
  // and the idle clip write it; laid out in the database's lanes when final, then freed.
  std::vector<glm::vec3> pose_positions, pose_velocities, pose_angular_velocities;
  std::vector<glm::quat> pose_rotations;
  Assembly::WritablePose pose() {
    return {pose_positions, pose_rotations, pose_velocities, pose_angular_velocities};
  }
  // The database as the build side reads it: its pose from the per-joint arrays above.
  DatabaseView view() const {
    DatabaseView v(db);
    v.local_positions = JointValues<glm::vec3>(pose_positions);
    v.local_rotations = JointValues<glm::quat>(pose_rotations);
    v.local_velocities = JointValues<glm::vec3>(pose_velocities);
    v.local_angular_velocities = JointValues<glm::vec3>(pose_angular_velocities);
    return v;
  }
  std::vector<int> bones;       // the joint of every feature channel
  std::vector<int> mirror_map;  // per source joint (only with options.mirror)
  std::vector<ClipJob> jobs;
  std::vector<std::vector<std::string>> clip_tag_lists;  // per database clip
  std::vector<std::string> clip_styles;                  // per database clip, "" for none
  size_t total_frames = 0;
  // BuildOptions::target with its roles, when given: the database skeleton's input.
  std::optional<InputResult> target;
  // The skeleton other skeletons are retargeted onto (the target's or the reference input's),
  // once needed.
  std::optional<RetargetSkeleton> retarget_target;
  // Per retargeted source skeleton: its line in rep.retargeted and its clip count.
  std::map<std::string, std::pair<size_t, size_t>> retargeted;
  // The "idle" tag bit when clips of the data carry it (then no idle clip is synthesized).
  uint64_t data_idle_tag = 0;
  bool synthesize_idle = false;
};

// Phase 1, parallel over inputs: import, validate, resample, find roles.
template <class Load>
void import_inputs(BuildState& state, const Load& load) {
  const size_t input_count = state.results.size();
  // Without skip_bad the first failing input (in input order) is the answer: inputs after a
  // known failure are skipped, inputs before it still run so the reported one is always the same.
  std::atomic<size_t> first_failure{input_count};
  state.rep.threads = detail::run_workers(input_count, state.threads, [&](int, size_t i) {
    InputResult& result = state.results[i];
    if (!state.options.skip_bad && i > first_failure.load()) return;
    try {
      result.status = load(i, result);
      take_import_warnings(result.clips, result.warnings);
      for (size_t c = 0; c < result.clips.size() && result.status; ++c) {
        result.status = prepare_clip(result.clips[c], state.input_names[i], state.options, result);
        if (result.status && c > 0 &&
            !result.clips[c].skeleton.same_topology(result.clips[0].skeleton)) {
          result.status = Error{state.input_names[i] + ": its clips do not share one skeleton"};
        }
      }
    } catch (const std::exception& e) {
      result.status = Error{state.input_names[i] + ": " + e.what()};
    }
    result.processed = true;
    if (!result.status) {
      result.clips.clear();
      size_t expected = first_failure.load();
      while (i < expected && !first_failure.compare_exchange_weak(expected, i)) {
      }
    }
    state.step();
  });
}

// Joint names and parents: equal for skeletons of the same topology.
std::string topology_key(const RetargetSkeleton& s) {
  std::string key;
  for (int j = 0; j < s.skeleton.joint_count(); ++j) {
    key += s.skeleton.name(j) + "/" + std::to_string(s.skeleton.parent(j)) + ";";
  }
  return key;
}

// One summary line per source skeleton that was retargeted.
std::string retarget_summary(const std::string& input, size_t clips, const RetargetReport& r) {
  std::string line = "skeleton of " + input + ": " + std::to_string(clips) +
                     " clip(s) retargeted, " + std::to_string(r.matched.size()) +
                     " joints matched, scale " + std::to_string(r.scale) + ", left at rest:";
  for (const std::string& joint : r.left_at_rest) line += " " + joint;
  return r.left_at_rest.empty() ? line + " none" : line;
}

// The target clip in messages: its file, or its name when it was made in memory.
std::string target_name(const Clip& target) {
  return "target " + (target.source_path.empty() ? "'" + target.name + "'" : target.source_path);
}

// The input of the database skeleton in messages: the target, or the reference input.
std::string skeleton_input_name(const BuildState& state, size_t reference_index) {
  return state.target ? target_name(state.target->clips[0]) : state.input_names[reference_index];
}

// The input whose skeleton, roles and rest pose the database takes.
const InputResult& skeleton_input(const BuildState& state, size_t reference_index) {
  return state.target ? *state.target : state.results[reference_index];
}

// Phase 2a, before the inputs: the target's roles (BuildOptions::target), when there is one.
Status prepare_target(BuildState& state) {
  const std::optional<Clip>& target = state.options.target;
  if (!target) return Status::success();
  InputResult result;
  result.clips.assign(1, *target);
  take_import_warnings(result.clips, state.rep.warnings);
  const std::string name = target_name(*target);
  if (Status s = result.clips[0].validate(); !s) return Error{name + ": " + s.message()};
  if (Status s = check_joint_map(target->skeleton, state.options.target_role_map); !s) {
    return Error{name + ": " + s.message()};
  }
  JointRoles names = state.options.roles;
  apply_joint_map(names, state.options.target_role_map);
  Result<JointRoleIndices> roles = find_joint_roles(target->skeleton, names);
  if (!roles) return Error{name + ": " + roles.message()};
  result.roles = *roles;
  state.target = std::move(result);
  return Status::success();
}

// Phase 2a for an input on another skeleton than the database's: its clips become clips of the
// database skeleton (retarget.hpp).
Status retarget_input(BuildState& state, size_t reference_index, size_t i) {
  const InputResult& reference = skeleton_input(state, reference_index);
  InputResult& result = state.results[i];
  if (!state.retarget_target) {
    Result<RetargetSkeleton> target = describe_for_retargeting(reference.clips[0], reference.roles);
    if (!target) {
      return Error{skeleton_input_name(state, reference_index) + ": " + target.message()};
    }
    state.retarget_target = std::move(target).value();
  }
  Result<RetargetSkeleton> source = describe_for_retargeting(result.clips[0], result.roles);
  if (!source) return Error{state.input_names[i] + ": " + source.message()};
  RetargetReport report;
  for (Clip& clip : result.clips) {
    Result<Clip> moved = retarget_clip(clip, *source, *state.retarget_target, &report);
    if (!moved) return Error{state.input_names[i] + ": " + moved.message()};
    clip = std::move(moved).value();
  }
  result.roles = reference.roles;
  // One line per source skeleton: inputs on a skeleton already reported add their clips to it.
  const std::string key = topology_key(*source);
  auto& [line_index, clips] = state.retargeted[key];
  if (clips == 0) {
    line_index = state.rep.retargeted.size();
    state.rep.retargeted.emplace_back();
  }
  clips += result.clips.size();
  state.rep.retargeted[line_index] = retarget_summary(state.input_names[i], clips, report);
  return Status::success();
}

// Phase 2a, in input order: refuses what failed and retargets inputs of other skeletons onto
// the target's, or without a target the first usable input's; returns the index of the first
// usable input (whose skeleton the database takes when there is no target).
Result<size_t> choose_reference_input(BuildState& state) {
  if (Status s = prepare_target(state); !s) return Error{s.message()};
  const InputResult* reference = state.target ? &*state.target : nullptr;
  std::optional<size_t> reference_index;
  for (size_t i = 0; i < state.results.size(); ++i) {
    InputResult& result = state.results[i];
    if (!result.processed) continue;
    state.rep.bytes_read += result.bytes;
    Status status = result.status;
    if (status && reference &&
        !reference->clips[0].skeleton.same_topology(result.clips[0].skeleton)) {
      status = retarget_input(state, reference_index.value_or(0), i);
    }
    if (!status) {
      if (!state.options.skip_bad) return Error{status.message()};
      state.rep.refused.push_back({state.input_names[i], status.message()});
      result.clips.clear();
      result.processed = false;
      continue;
    }
    state.rep.warnings.insert(state.rep.warnings.end(), result.warnings.begin(),
                              result.warnings.end());
    if (!reference_index) {
      reference_index = i;
      if (!reference) reference = &result;
    }
  }
  if (!reference_index) {
    return Error{"build: no usable input: all " + std::to_string(state.results.size()) +
                 " were refused (the first: " + state.rep.refused.front().message + ")"};
  }
  return *reference_index;
}

// The database's ground is y = 0. Data farther than this (m) above or below it stands on another
// ground; nearer, it is left where it is: a foot's end is a joint, above the sole (Bandai's toe
// joints stop 2.5 cm above their ground; an ankle, where a skeleton has nothing lower, stands
// several centimetres up).
constexpr float kGroundTolerance = 0.15f;

// Phase 2a, after retargeting (every clip on the database skeleton): a clip whose feet never come
// near y = 0 stands on another ground (ReActIdle's people stand 0.7 to 1 m below their root, which
// is at y = 0, each as tall as they are) and is moved up or down as a whole to put its lowest
// foot end (lowest_foot_end) on y = 0.
void stand_on_ground(BuildState& state) {
  int moved = 0;
  float least = std::numeric_limits<float>::infinity(), most = 0.0f;
  for (InputResult& result : state.results) {
    if (!result.processed) continue;
    for (Clip& clip : result.clips) {
      const float lowest = lowest_foot_end(clip, result.roles);
      if (!std::isfinite(lowest) || std::abs(lowest) <= kGroundTolerance) continue;
      for (int f = 0; f < clip.frame_count; ++f) clip.pose(f)[0].translation.y -= lowest;
      ++moved;
      least = std::min(least, -lowest);
      most = std::max(most, -lowest);
    }
  }
  if (moved == 0) return;
  state.rep.ground_summary = formatted(
      "%d clip(s) whose feet never came within %.2f m of y = 0 moved by %+.3f to %+.3f m to stand "
      "on it",
      moved, static_cast<double>(kGroundTolerance), static_cast<double>(least),
      static_cast<double>(most));
}

// Phase 2a, after retargeting: idle takes of the data become their calm segments (idle.hpp).
void split_idle_clips(BuildState& state) {
  int takes = 0;
  size_t segments = 0;
  double kept = 0.0, total = 0.0;
  for (InputResult& result : state.results) {
    std::vector<Clip> clips;
    for (Clip& clip : result.clips) {
      const std::vector<std::string> tags = tags_from_name(clip.name);
      if (std::find(tags.begin(), tags.end(), kIdleTag) == tags.end()) {
        clips.push_back(std::move(clip));
        continue;
      }
      ++takes;
      total += clip.frame_count * static_cast<double>(clip.frame_time);
      for (Clip& segment : calm_idle_segments(clip, result.roles)) {
        kept += segment.frame_count * static_cast<double>(segment.frame_time);
        ++segments;
        clips.push_back(std::move(segment));
      }
    }
    result.clips = std::move(clips);
  }
  if (takes == 0) return;
  state.rep.idle_summary = formatted(
      "%d idle takes: %zu calm segments kept (%.0f s of %.0f s; feet planted, facing steady)",
      takes, segments, kept, total);
}

// Phase 2b: the database skeleton (simulation root + the reference's joints), its roles, the
// feature channels' joints and the mirror map.
Status start_database(BuildState& state, size_t reference_index) {
  const InputResult& reference = skeleton_input(state, reference_index);
  const Skeleton& source_skeleton = reference.clips[0].skeleton;
  Assembly::Parts db = Assembly::parts(state.db);
  db.frame_time = 1.0f / state.options.rate;
  db.schema = state.options.schema;
  Result<Skeleton> skeleton = add_simulation_root(source_skeleton);
  if (!skeleton) {
    return Error{skeleton_input_name(state, reference_index) + ": " + skeleton.message()};
  }
  db.skeleton = std::move(skeleton).value();
  for (const JointRoleInfo& role : kJointRoles) {
    const int j = reference.roles.*role.index;
    db.roles.*role.index = j < 0 ? -1 : j + 1;  // behind the inserted simulation root
  }
  Result<std::vector<int>> bones = resolve_feature_bones(db.schema, db.skeleton, db.roles);
  if (!bones) return Error{"build: " + bones.message()};
  state.bones = std::move(bones).value();
  if (state.options.mirror) {
    Result<std::vector<int>> map = mirror_joint_map(source_skeleton, state.options.mirror_pairs);
    if (!map) return Error{"build: " + map.message()};
    state.mirror_map = std::move(map).value();
  }
  return Status::success();
}

// Phase 2c: clip ranges (a mirrored copy right after its original, the idle clip last) and
// their tags.
Status lay_out_clips(BuildState& state, int idle_frames) {
  Assembly::Parts db = Assembly::parts(state.db);
  for (size_t i = 0; i < state.results.size(); ++i) {
    if (!state.results[i].processed) continue;
    for (size_t c = 0; c < state.results[i].clips.size(); ++c) {
      const Clip& clip = state.results[i].clips[c];
      for (const bool mirrored : {false, true}) {
        if (mirrored && !state.options.mirror) continue;
        ClipRange range;
        range.name = mirrored ? clip.name + "_mirror" : clip.name;
        range.start = static_cast<int>(state.total_frames);
        range.end = range.start + clip.frame_count;
        range.mirrored = mirrored;
        state.total_frames += static_cast<size_t>(clip.frame_count);
        if (state.total_frames > kMaxDatabaseFrames) {
          return Error{"build: more than " + std::to_string(kMaxDatabaseFrames) +
                       " frames, the most a database holds"};
        }
        state.jobs.push_back({i, c, mirrored, db.clips.size()});
        db.clips.push_back(std::move(range));
        state.clip_tag_lists.push_back(clip_tags(clip.name, mirrored, state.context.tag_rules));
        state.clip_styles.push_back(clip_style(clip.name, state.context.tag_rules));
      }
    }
  }
  // Real idle clips in the data replace the synthesized one, which is only the fallback.
  const bool data_idles = std::any_of(
      state.clip_tag_lists.begin(), state.clip_tag_lists.end(),
      [](const auto& tags) { return std::find(tags.begin(), tags.end(), kIdleTag) != tags.end(); });
  state.synthesize_idle = idle_frames > 0 && !data_idles;
  // The idle clip's frames are reserved now so that the arrays are allocated once; which pose
  // they hold is known only after phase 3 (it needs the contacts and velocities).
  if (state.synthesize_idle) {
    ClipRange range;
    range.name = kIdleClipName;
    range.start = static_cast<int>(state.total_frames);
    range.end = range.start + idle_frames;
    state.total_frames += static_cast<size_t>(idle_frames);
    if (state.total_frames > kMaxDatabaseFrames) {
      return Error{"build: more than " + std::to_string(kMaxDatabaseFrames) +
                   " frames with the idle clip, the most a database holds"};
    }
    db.clips.push_back(std::move(range));
    // Manifest rules match the name "idle" like any clip name.
    std::vector<std::string> tags = clip_tags(kIdleClipName, false, state.context.tag_rules);
    tags.emplace_back(kIdleTag);
    std::sort(tags.begin(), tags.end());
    tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
    state.clip_tag_lists.push_back(std::move(tags));
    state.clip_styles.push_back(clip_style(kIdleClipName, state.context.tag_rules));
  }
  if (Status s = assign_tags(db, state.clip_tag_lists, state.clip_styles); !s) return s;
  if (data_idles) {
    state.data_idle_tag = state.db.tag_mask(std::vector<std::string>{kIdleTag});
  }
  return Status::success();
}

// Phase 2d: the database arrays, sized; processing writes every value of every clip.
void allocate_arrays(BuildState& state) {
  Assembly::Parts db = Assembly::parts(state.db);
  const size_t frames = state.total_frames;
  db.frame_count = static_cast<int>(frames);
  Assembly::allocate(state.db, frames);
  Assembly::derive_frame_clip(state.db);
  const size_t samples = frames * static_cast<size_t>(db.joint_count());
  state.pose_positions.resize(samples);
  state.pose_rotations.resize(samples);
  state.pose_velocities.resize(samples);
  state.pose_angular_velocities.resize(samples);
}

// Phase 3c: the pose's frames are final (the idle clip's too, or given back): laid out in the
// database's lanes, the per-joint arrays freed.
void lay_out_pose(BuildState& state) {
  Assembly::lay_out_pose(
      state.db, PoseFrameView{state.pose_rotations, state.pose_positions, state.pose_velocities,
                              state.pose_angular_velocities});
  state.pose_positions = {};
  state.pose_rotations = {};
  state.pose_velocities = {};
  state.pose_angular_velocities = {};
}

// Phase 3a, parallel over clips: preprocess and extract raw features straight into the
// database's arrays at each clip's frames.
Status process_clips(BuildState& state) {
  Assembly::Parts db = Assembly::parts(state.db);
  const Assembly::WritablePose pose = state.pose();
  const DatabaseFill fill = Assembly::fill(state.db, pose);
  const size_t joints = static_cast<size_t>(db.joint_count());
  std::vector<Status> job_status(state.jobs.size());
  std::vector<std::atomic<int>> jobs_left(state.results.size());
  for (const ClipJob& job : state.jobs) jobs_left[job.input].fetch_add(1);
  detail::run_workers(state.jobs.size(), state.threads, [&](int worker, size_t k) {
    const ClipJob& job = state.jobs[k];
    const ClipRange& range = db.clips[job.range];
    try {
      const Clip& source = state.results[job.input].clips[job.clip];
      Clip mirrored;
      if (job.mirrored) mirrored = mirror_clip(source, state.mirror_map);
      const Clip& clip = job.mirrored ? mirrored : source;
      PreprocessOptions preprocess = state.context.preprocess;
      preprocess.root.fixed = (range.tags & state.data_idle_tag) != 0;
      const size_t first = static_cast<size_t>(range.start) * joints;
      const size_t count = static_cast<size_t>(range.frame_count()) * joints;
      const std::span<glm::vec3> positions = pose.positions.subspan(first, count);
      const std::span<glm::quat> rotations = pose.rotations.subspan(first, count);
      const std::span<glm::vec3> velocities = pose.velocities.subspan(first, count);
      const std::span<glm::vec3> angular = pose.angular_velocities.subspan(first, count);
      const ClipMotionOutput out{positions, rotations, velocities, angular,
                                 std::span(db.contacts)
                                     .subspan(static_cast<size_t>(range.start) * 2,
                                              static_cast<size_t>(range.frame_count()) * 2)};
      Status status = preprocess_clip(clip, state.results[job.input].roles, preprocess, out,
                                      state.scratch[static_cast<size_t>(worker)].preprocess);
      if (status) {
        extract_range_features(fill, range, state.bones,
                               state.scratch[static_cast<size_t>(worker)].features);
      } else {
        status = Error{state.input_names[job.input] + ": " + status.message()};
      }
      job_status[k] = std::move(status);
    } catch (const std::exception& e) {
      job_status[k] =
          Error{state.input_names[job.input] + ": clip '" + range.name + "': " + e.what()};
    }
    if (jobs_left[job.input].fetch_sub(1) == 1) state.step();
  });
  for (const Status& s : job_status) {
    if (!s) return Error{s.message()};
  }
  state.results.clear();  // the imported clips are no longer needed
  return Status::success();
}

// Phase 3b: the idle clip, one pass in frame order over the finished clips, then a copy; or,
// when no frame qualifies, the reserved frames given back.
Status add_idle_clip(BuildState& state) {
  Assembly::Parts db = Assembly::parts(state.db);
  BuildReport& rep = state.rep;
  const ClipRange& idle = db.clips.back();
  const IdleSourceSearch found = search_idle_source(state.view());
  if (found.frame >= 0) {
    const DatabaseFill fill = Assembly::fill(state.db, state.pose());
    fill_idle_clip(fill, idle, found.frame);
    extract_range_features(fill, idle, state.bones, state.scratch[0].features);
    const ClipRange& source = *std::find_if(
        db.clips.begin(), db.clips.end(), [&](const ClipRange& c) { return found.frame < c.end; });
    rep.idle_frames = idle.frame_count();
    rep.idle_source_clip = source.name;
    rep.idle_source_frame = found.frame - source.start;
    return Status::success();
  }
  rep.warnings.push_back("no idle clip: " + idle_search_failure(found));
  // The reserved frames are the last ones: give them back and drop the clip's tags.
  state.total_frames -= static_cast<size_t>(idle.frame_count());
  db.clips.pop_back();
  state.clip_tag_lists.pop_back();
  state.clip_styles.pop_back();
  if (Status s = assign_tags(db, state.clip_tag_lists, state.clip_styles); !s)
    return Error{s.message()};
  Assembly::keep_frames(state.db, state.total_frames);
  return Status::success();
}

// Phase 4: normalization over the whole database.
Status normalize_and_check(BuildState& state) {
  Assembly::Parts db = Assembly::parts(state.db);
  BuildReport& rep = state.rep;
  for (const ClipRange& range : db.clips) {
    if (std::find(db.searchable.begin() + range.start, db.searchable.begin() + range.end,
                  uint8_t{1}) == db.searchable.begin() + range.end) {
      rep.warnings.push_back("clip '" + range.name + "' (" + std::to_string(range.frame_count()) +
                             " frames) is shorter than the feature times need: none of its "
                             "frames can be matched (it can still be played into)");
    }
  }
  FeatureNormalization normalization =
      compute_feature_normalization(db.schema, db.features, db.searchable);
  // Normalizing is element-wise, so splitting the rows between threads changes nothing.
  const size_t dims = static_cast<size_t>(state.context.dims);
  const size_t frames = state.total_frames;
  const size_t chunk_rows = 4096;
  const size_t chunks = (frames + chunk_rows - 1) / chunk_rows;
  detail::run_workers(chunks, state.threads, [&](int, size_t chunk) {
    const size_t first = chunk * chunk_rows;
    const size_t rows = std::min(chunk_rows, frames - first);
    normalize_features(std::span(db.features).subspan(first * dims, rows * dims),
                       normalization.offset, normalization.scale);
  });
  std::copy(normalization.offset.begin(), normalization.offset.end(), db.feature_offset.begin());
  std::copy(normalization.scale.begin(), normalization.scale.end(), db.feature_scale.begin());
  rep.warnings.insert(rep.warnings.end(), normalization.warnings.begin(),
                      normalization.warnings.end());

  rep.clips = static_cast<int>(db.clips.size());
  rep.frames = db.frame_count;
  rep.duration_s = static_cast<double>(db.frame_count) / static_cast<double>(state.options.rate);
  rep.searchable_frames =
      static_cast<int>(std::count(db.searchable.begin(), db.searchable.end(), uint8_t{1}));
  return Status::success();
}

// The shared part of both entry points: `load(i, result)` imports input i into result.clips.
//
// Phase 1 (parallel over inputs): import, validate, resample, find roles.
// Phase 2 (in input order): refuse failures and foreign skeletons, lay out the clip ranges,
//   tags and arrays of the database.
// Phase 3 (parallel over clips): preprocess and extract raw features straight into the
//   database's arrays (the pose per joint beside it) at each clip's frames; then the idle clip
//   (one pass in frame order); then the pose laid out in the database's lanes.
// Phase 4: normalization statistics (one pass in frame order), normalization, validation.
template <class Load>
Result<Database> build(size_t input_count, const std::vector<std::string>& input_names,
                       const BuildOptions& options, BuildReport* report, const Load& load) {
  const Clock::time_point start = Clock::now();
  BuildReport local_report;
  BuildReport& rep = report ? *report : local_report;
  rep = BuildReport{};
  rep.inputs = static_cast<int>(input_count);
  const Result<int> idle_frames = check_build_options(options, input_count);
  if (!idle_frames) return Error{idle_frames.message()};
  BuildState state(input_names, options, rep, input_count);
  if (Status s = make_context(options, state.context); !s) return Error{s.message()};

  import_inputs(state, load);
  rep.load_seconds = seconds_since(start);
  Clock::time_point phase_start = Clock::now();

  const Result<size_t> reference = choose_reference_input(state);
  if (!reference) return Error{reference.message()};
  stand_on_ground(state);
  split_idle_clips(state);
  if (Status s = start_database(state, *reference); !s) return Error{s.message()};
  if (Status s = lay_out_clips(state, *idle_frames); !s) return Error{s.message()};
  allocate_arrays(state);
  rep.layout_seconds = seconds_since(phase_start);
  phase_start = Clock::now();

  if (Status s = process_clips(state); !s) return Error{s.message()};
  if (state.synthesize_idle) {
    if (Status s = add_idle_clip(state); !s) return Error{s.message()};
  }
  lay_out_pose(state);
  rep.process_seconds = seconds_since(phase_start);
  phase_start = Clock::now();

  if (Status s = normalize_and_check(state); !s) return Error{s.message()};
  if (Status s = state.db.validate(); !s) {
    return Error{
        "build: the assembled database is inconsistent (a bug or a non-finite input "
        "value): " +
        s.message()};
  }
  rep.finish_seconds = seconds_since(phase_start);
  rep.total_seconds = seconds_since(start);
  return std::move(state.db);
}

}  // namespace

Result<std::vector<fs::path>> collect_input_files(std::span<const fs::path> inputs) {
  std::vector<fs::path> files;
  std::set<fs::path> seen;
  auto add = [&](const fs::path& path) {
    if (seen.insert(path.lexically_normal()).second) files.push_back(path);
  };
  for (const fs::path& input : inputs) {
    std::error_code ec;
    const fs::file_status status = fs::status(input, ec);
    if (ec || !fs::exists(status)) {
      return Error{input.string() + ": no such file or folder"};
    }
    if (fs::is_directory(status)) {
      std::vector<fs::path> found;
      fs::recursive_directory_iterator it(input, fs::directory_options::skip_permission_denied, ec);
      if (ec) return Error{input.string() + ": cannot list the folder: " + ec.message()};
      for (; it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (ec) return Error{input.string() + ": cannot list the folder: " + ec.message()};
        if (it->is_regular_file(ec) && is_motion_file(it->path())) found.push_back(it->path());
      }
      std::sort(found.begin(), found.end());
      for (const fs::path& f : found) add(f);
    } else {
      add(input);
    }
  }
  if (files.empty()) {
    std::string list;
    for (const fs::path& input : inputs) list += (list.empty() ? "" : ", ") + input.string();
    return Error{"no .bvh, .gltf or .glb files found in " + list};
  }
  return files;
}

Result<Database> build_database(std::span<const fs::path> inputs, const BuildOptions& options,
                                BuildReport* report) try {
  Result<std::vector<fs::path>> files = collect_input_files(inputs);
  if (!files) return Error{files.message()};
  std::vector<std::string> names;
  names.reserve(files->size());
  for (const fs::path& f : *files) names.push_back(f.string());
  return build(files->size(), names, options, report, [&](size_t i, InputResult& result) {
    Result<std::vector<Clip>> clips = import_file((*files)[i], options, result.bytes);
    if (!clips) return Status(Error{clips.message()});
    result.clips = std::move(clips).value();
    return Status::success();
  });
} catch (const std::exception& e) {
  // Out of memory or a thread failure outside the workers: report it, never let it escape.
  return Error{std::string("build: ") + e.what()};
}

Result<Database> build_database_from_clips(std::span<const Clip> clips, const BuildOptions& options,
                                           BuildReport* report) try {
  std::vector<std::string> names;
  for (const Clip& c : clips) names.push_back(c.name);
  return build(clips.size(), names, options, report, [&](size_t i, InputResult& result) {
    result.clips.assign(1, clips[i]);
    return Status::success();
  });
} catch (const std::exception& e) {
  return Error{std::string("build: ") + e.what()};
}

}  // namespace mm
