#include "mm/database/builder.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <set>
#include <thread>

#include "mm/database/database_file.hpp"
#include "mm/database/feature_extraction.hpp"
#include "mm/database/gltf.hpp"

namespace mm {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_motion_file(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".bvh" || ext == ".gltf" || ext == ".glb";
}

bool is_gltf_file(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".gltf" || ext == ".glb";
}

// One preprocessed clip with its raw features and tags, waiting to be concatenated.
struct BuiltClip {
  ProcessedClip motion;
  std::vector<float> raw_features;  // frame_count * dims, not normalized
  std::vector<uint8_t> searchable;  // frame_count
  std::vector<std::string> tags;    // sorted
};

// What a worker made of one input (a file or an in-memory clip).
struct InputResult {
  bool processed = false;  // false when skipped after an earlier input failed
  Status status;
  std::vector<BuiltClip> clips;
  Skeleton source_skeleton;  // the first clip's source skeleton (for the topology check)
  JointRoleIndices source_roles;
  uint64_t bytes = 0;
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

Status process_one(const Clip& clip, bool mirrored, const std::string& original_name,
                   const JointRoleIndices& roles, const Skeleton& db_skeleton,
                   std::span<const int> channel_bones, const BuildContext& context,
                   WorkerScratch& scratch, InputResult& result) {
  BuiltClip built;
  if (Status s = preprocess_clip(clip, roles, context.preprocess, built.motion, scratch.preprocess);
      !s) {
    return s;
  }
  built.motion.mirrored = mirrored;
  const int frames = built.motion.frame_count;
  built.raw_features.resize(static_cast<size_t>(frames) * context.dims);
  built.searchable.resize(frames);
  ClipMotionView view;
  view.parents = db_skeleton.parents();
  view.local_positions = built.motion.local_positions;
  view.local_rotations = built.motion.local_rotations;
  view.local_velocities = built.motion.local_velocities;
  view.local_angular_velocities = built.motion.local_angular_velocities;
  view.frame_count = frames;
  view.frame_time = built.motion.frame_time;
  extract_clip_features(context.options.schema, channel_bones, view, built.raw_features,
                        built.searchable, scratch.features);
  built.tags = clip_tags(original_name, mirrored, context.tag_rules);
  result.clips.push_back(std::move(built));
  return Status::success();
}

// Resamples, preprocesses and extracts the features of one imported clip (and its mirror).
Status process_clip(Clip clip, const std::string& input_name, const BuildContext& context,
                    WorkerScratch& scratch, InputResult& result) {
  const BuildOptions& options = context.options;
  const std::string where = input_name + ": clip '" + clip.name + "': ";
  if (Status s = clip.validate(); !s) return Error{input_name + ": " + s.message()};
  if (needs_resampling(clip, options.rate)) {
    clip = resample_clip(clip, options.rate);
  } else {
    clip.frame_time = 1.0f / options.rate;
  }
  Result<JointRoleIndices> roles = find_joint_roles(clip.skeleton, options.roles);
  if (!roles) return Error{where + roles.message()};
  Result<Skeleton> db_skeleton = add_simulation_root(clip.skeleton);
  if (!db_skeleton) return Error{where + db_skeleton.message()};
  auto shifted = [](int j) { return j < 0 ? -1 : j + 1; };
  JointRoleIndices db_roles;
  db_roles.hips = shifted(roles->hips);
  db_roles.left_foot = shifted(roles->left_foot);
  db_roles.right_foot = shifted(roles->right_foot);
  db_roles.left_toe = shifted(roles->left_toe);
  db_roles.right_toe = shifted(roles->right_toe);
  db_roles.head = shifted(roles->head);
  Result<std::vector<int>> bones = resolve_feature_bones(options.schema, *db_skeleton, db_roles);
  if (!bones) return Error{where + bones.message()};
  if (result.clips.empty()) {
    result.source_skeleton = clip.skeleton;
    result.source_roles = *roles;
  }

  if (Status s = process_one(clip, false, clip.name, *roles, *db_skeleton, *bones, context, scratch,
                             result);
      !s) {
    return Error{input_name + ": " + s.message()};
  }
  if (options.mirror) {
    Result<std::vector<int>> map = mirror_joint_map(clip.skeleton, options.mirror_pairs);
    if (!map) return Error{where + map.message()};
    const Clip mirrored = mirror_clip(clip, *map);
    if (Status s = process_one(mirrored, true, clip.name, *roles, *db_skeleton, *bones, context,
                               scratch, result);
        !s) {
      return Error{input_name + ": " + s.message()};
    }
  }
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

std::string topology_difference(const Skeleton& a, const Skeleton& b) {
  if (a.joint_count() != b.joint_count()) {
    return std::to_string(b.joint_count()) + " joints instead of " +
           std::to_string(a.joint_count());
  }
  for (int j = 0; j < a.joint_count(); ++j) {
    const std::string parent_a = a.parent(j) < 0 ? "none" : a.name(a.parent(j));
    const std::string parent_b = b.parent(j) < 0 ? "none" : b.name(b.parent(j));
    if (a.name(j) != b.name(j) || parent_a != parent_b) {
      return "joint " + std::to_string(j) + " is '" + b.name(j) + "' (parent " + parent_b +
             ") instead of '" + a.name(j) + "' (parent " + parent_a + ")";
    }
  }
  return "the same joints";
}

// Runs `work(worker, item)` for every item on up to `threads` threads (the caller's included)
// that pull item indices from a shared counter. Returns the number of threads used.
template <class Work>
int run_workers(size_t items, int threads, const Work& work) {
  std::atomic<size_t> next{0};
  auto loop = [&](int worker) {
    for (size_t i = next.fetch_add(1); i < items; i = next.fetch_add(1)) work(worker, i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(loop, t);
    } catch (const std::exception&) {
      break;  // no more threads available: the ones running (and this one) do the work
    }
  }
  loop(0);
  for (std::thread& t : pool) t.join();
  return static_cast<int>(pool.size()) + 1;
}

// The shared part of both entry points: `load(i, context, result, scratch)` imports and
// processes input i into `result`.
template <class Load>
Result<Database> build(size_t input_count, const std::vector<std::string>& input_names,
                       const BuildOptions& options, BuildReport* report, const Load& load) {
  const Clock::time_point start = Clock::now();
  BuildReport local_report;
  BuildReport& rep = report ? *report : local_report;
  rep = BuildReport{};
  rep.inputs = static_cast<int>(input_count);

  if (!(options.rate > 0.0f) || !(options.rate <= 1000.0f)) {
    return Error{"build: the rate must be a number of frames per second in (0, 1000], found " +
                 std::to_string(options.rate)};
  }
  if (Status s = options.schema.validate(); !s) return Error{"build: " + s.message()};
  if (input_count == 0) return Error{"build: no inputs"};

  BuildContext context{options, {}, {}, options.schema.dims()};
  if (!options.tags_file.empty()) {
    Result<std::vector<TagRule>> rules = load_tag_manifest(options.tags_file);
    if (!rules) return Error{rules.message()};
    context.tag_rules = std::move(rules).value();
  }
  context.tag_rules.insert(context.tag_rules.end(), options.tag_rules.begin(),
                           options.tag_rules.end());
  context.preprocess.root = options.root;
  context.preprocess.contacts = options.contacts;

  // Phase 1, parallel: import and process every input.
  std::vector<InputResult> results(input_count);
  int threads = options.threads > 0
                    ? options.threads
                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<size_t>(static_cast<size_t>(threads), input_count));
  std::vector<WorkerScratch> scratch(threads);
  // Without skip_bad the first failing input (in input order) is the answer: inputs after a
  // known failure are skipped, inputs before it still run so the reported one is always the same.
  std::atomic<size_t> first_failure{input_count};
  std::mutex progress_mutex;
  size_t done = 0;
  rep.threads = run_workers(input_count, threads, [&](int worker, size_t i) {
    InputResult& result = results[i];
    if (!options.skip_bad && i > first_failure.load()) return;
    try {
      result.status = load(i, context, result, scratch[worker]);
    } catch (const std::exception& e) {
      result.status = Error{input_names[i] + ": " + e.what()};
    }
    result.processed = true;
    if (!result.status) {
      result.clips.clear();
      size_t expected = first_failure.load();
      while (i < expected && !first_failure.compare_exchange_weak(expected, i)) {
      }
    }
    if (options.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      options.progress(++done, input_count);
    }
  });
  rep.load_seconds = seconds_since(start);
  const Clock::time_point assemble_start = Clock::now();

  // Phase 2, in input order: refuse what failed or does not match the first skeleton.
  const InputResult* reference = nullptr;
  size_t reference_index = 0;
  for (size_t i = 0; i < input_count; ++i) {
    InputResult& result = results[i];
    if (!result.processed) continue;
    rep.bytes_read += result.bytes;
    Status status = result.status;
    if (status && reference && !reference->source_skeleton.same_topology(result.source_skeleton)) {
      status = Error{input_names[i] + ": its skeleton differs from that of " +
                     input_names[reference_index] + ": " +
                     topology_difference(reference->source_skeleton, result.source_skeleton) +
                     "; every clip of a database needs the same joints and parents"};
    }
    if (!status) {
      if (!options.skip_bad) return Error{status.message()};
      rep.refused.push_back({input_names[i], status.message()});
      result.clips.clear();
      result.processed = false;
      continue;
    }
    if (!reference) {
      reference = &result;
      reference_index = i;
    }
  }
  if (!reference) {
    return Error{"build: no usable input: all " + std::to_string(input_count) +
                 " were refused (the first: " + rep.refused.front().message + ")"};
  }

  Database db;
  db.frame_time = 1.0f / options.rate;
  db.schema = options.schema;
  Result<Skeleton> skeleton = add_simulation_root(reference->source_skeleton);
  if (!skeleton) return Error{skeleton.message()};
  db.skeleton = std::move(skeleton).value();
  auto shifted = [](int j) { return j < 0 ? -1 : j + 1; };
  const JointRoleIndices& r = reference->source_roles;
  db.roles = {shifted(r.hips),     shifted(r.left_foot), shifted(r.right_foot),
              shifted(r.left_toe), shifted(r.right_toe), shifted(r.head)};

  // Tags: every distinct tag, sorted, one bit each.
  std::set<std::string> tag_set;
  size_t total_frames = 0;
  for (const InputResult& result : results) {
    if (!result.processed) continue;
    for (const BuiltClip& clip : result.clips) {
      tag_set.insert(clip.tags.begin(), clip.tags.end());
      total_frames += static_cast<size_t>(clip.motion.frame_count);
    }
  }
  if (tag_set.size() > kMaxTags) {
    std::string some;
    for (const std::string& t : tag_set) some += (some.empty() ? "" : ", ") + t;
    return Error{"build: " + std::to_string(tag_set.size()) + " distinct tags, at most " +
                 std::to_string(kMaxTags) + " fit a database (" + some + ")"};
  }
  if (total_frames > static_cast<size_t>(kMaxDatabaseFrames)) {
    return Error{"build: " + std::to_string(total_frames) +
                 " frames is more than a database holds"};
  }
  db.tag_names.assign(tag_set.begin(), tag_set.end());

  const int joints = db.joint_count();
  const size_t values = total_frames * static_cast<size_t>(joints);
  const size_t dims = static_cast<size_t>(context.dims);
  db.frame_count = static_cast<int>(total_frames);
  db.local_positions.reserve(values);
  db.local_rotations.reserve(values);
  db.local_velocities.reserve(values);
  db.local_angular_velocities.reserve(values);
  db.contacts.reserve(total_frames * 2);
  db.features.reserve(total_frames * dims);
  db.searchable.reserve(total_frames);
  db.frame_clip.reserve(total_frames);
  for (InputResult& result : results) {
    if (!result.processed) continue;
    for (BuiltClip& clip : result.clips) {
      ClipRange range;
      range.name = clip.motion.name;
      range.start = static_cast<int>(db.local_positions.size() / joints);
      range.end = range.start + clip.motion.frame_count;
      range.mirrored = clip.motion.mirrored;
      for (const std::string& tag : clip.tags) {
        const size_t bit = static_cast<size_t>(
            std::lower_bound(db.tag_names.begin(), db.tag_names.end(), tag) - db.tag_names.begin());
        range.tags |= uint64_t{1} << bit;
      }
      auto append = [](auto& to, auto& from) {
        to.insert(to.end(), from.begin(), from.end());
        std::decay_t<decltype(from)>().swap(from);  // release the clip's copy at once
      };
      append(db.local_positions, clip.motion.local_positions);
      append(db.local_rotations, clip.motion.local_rotations);
      append(db.local_velocities, clip.motion.local_velocities);
      append(db.local_angular_velocities, clip.motion.local_angular_velocities);
      append(db.contacts, clip.motion.contacts);
      append(db.features, clip.raw_features);
      if (std::find(clip.searchable.begin(), clip.searchable.end(), uint8_t{1}) ==
          clip.searchable.end()) {
        rep.warnings.push_back("clip '" + range.name + "' (" + std::to_string(range.frame_count()) +
                               " frames) is shorter than the feature times need: none of its "
                               "frames can be matched (it can still be played into)");
      }
      append(db.searchable, clip.searchable);
      db.frame_clip.insert(db.frame_clip.end(), static_cast<size_t>(range.frame_count()),
                           static_cast<int>(db.clips.size()));
      db.clips.push_back(std::move(range));
    }
    result.clips.clear();
  }

  FeatureNormalization normalization =
      compute_feature_normalization(db.schema, db.features, db.searchable);
  normalize_features(db.features, normalization.offset, normalization.scale);
  db.feature_offset = std::move(normalization.offset);
  db.feature_scale = std::move(normalization.scale);
  rep.warnings.insert(rep.warnings.end(), normalization.warnings.begin(),
                      normalization.warnings.end());

  if (Status s = db.validate(); !s) {
    return Error{
        "build: the assembled database is inconsistent (a bug or a non-finite input "
        "value): " +
        s.message()};
  }

  rep.clips = static_cast<int>(db.clips.size());
  rep.frames = db.frame_count;
  rep.duration_s = static_cast<double>(db.frame_count) / static_cast<double>(options.rate);
  rep.searchable_frames =
      static_cast<int>(std::count(db.searchable.begin(), db.searchable.end(), uint8_t{1}));
  rep.assemble_seconds = seconds_since(assemble_start);
  rep.total_seconds = seconds_since(start);
  return db;
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
  return build(files->size(), names, options, report,
               [&](size_t i, const BuildContext& context, InputResult& result,
                   WorkerScratch& scratch) -> Status {
                 Result<std::vector<Clip>> clips = import_file((*files)[i], options, result.bytes);
                 if (!clips) return Error{clips.message()};
                 for (Clip& clip : *clips) {
                   if (Status s = process_clip(std::move(clip), names[i], context, scratch, result);
                       !s) {
                     return s;
                   }
                 }
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
  return build(clips.size(), names, options, report,
               [&](size_t i, const BuildContext& context, InputResult& result,
                   WorkerScratch& scratch) -> Status {
                 return process_clip(clips[i], names[i], context, scratch, result);
               });
} catch (const std::exception& e) {
  return Error{std::string("build: ") + e.what()};
}

}  // namespace mm
