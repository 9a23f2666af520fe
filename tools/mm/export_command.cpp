// `mm export`: writes one clip of a BVH, glTF or database file as glTF, for Blender and other
// viewers.

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "database_summary.hpp"
#include "mm/database/character_body.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/database/io/bvh.hpp"
#include "mm/database/io/gltf.hpp"

namespace mm::cli {
namespace {

namespace fs = std::filesystem;

const char* const kUsage =
    R"(usage: mm export <file.bvh|file.gltf|file.glb|file.mmdb> -o <out.glb|out.gltf> [options]

Writes one clip with its skeleton as glTF (metres, Y up): ".glb" binary or ".gltf" JSON with
the buffer embedded. From a database the clip is rebuilt from its stored per-frame local
positions and rotations at the database rate, joint 0 (the simulation root) included as an
ordinary root joint.

With --body (database input only) the file also holds the character's generated body: a
surface around the bones in an A-pose bind pose, skinned with the chosen weights, so the
clip plays on a character in Blender or any glTF viewer (and mm-viewer --body loads it).

options:
  -o, --output FILE   the .glb or .gltf file to write (required)
  --clip NAME|INDEX   which clip (default 0): an index, or a clip / animation name
  --scale S           BVH units to metres (default 0.01: centimetres)
  --body              write the generated, skinned body with the clip (database input)
  --weights METHOD    the body's skinning weights: distance, envelope, heat (default) or
                      geodesic
  --voxel METRES      the body surface's grid spacing (default 0.012; smaller: more vertices)
  -h, --help          this text

exit status: 0 written, 1 bad input or clip not found, 2 bad usage
)";

int usage_error(const std::string& message) {
  std::fprintf(stderr, "mm export: %s\n\n%s", message.c_str(), kUsage);
  return 2;
}

// The index of the clip `selector` names among `names` (an index or an exact name), or an error
// listing what exists.
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

// A database clip as a pose sequence: the stored local positions and rotations, unit scale.
std::vector<Transform> database_clip_frames(const Database& db, const ClipRange& range) {
  const int joints = db.joint_count();
  std::vector<Transform> frames(static_cast<size_t>(range.frame_count()) * joints);
  for (int f = 0; f < range.frame_count(); ++f) {
    for (int j = 0; j < joints; ++j) {
      const size_t from = static_cast<size_t>(range.start + f) * joints + j;
      Transform& t = frames[static_cast<size_t>(f) * joints + j];
      t.translation = db.local_positions[from];
      t.rotation = db.local_rotations[from];
    }
  }
  return frames;
}

Status export_database_clip(const Database& db, size_t clip, const fs::path& out) {
  const ClipRange& range = db.clips[clip];
  const std::vector<Transform> frames = database_clip_frames(db, range);
  return save_gltf(db.skeleton, frames, range.frame_count(), db.frame_time, range.name, out);
}

// The clip with the generated body; says what was made and how long it took on stdout.
Status export_database_body(const Database& db, size_t clip, const CharacterBodyOptions& options,
                            const fs::path& out) {
  Result<CharacterBody> body = build_character_body(db, options);
  if (!body) return Error{body.message()};
  const TriangleMesh& mesh = body->skinned.mesh;
  std::printf(
      "body: %zu vertices, %zu triangles around %zu bone segments; surface %.2f s, "
      "%s weights %.2f s\n",
      mesh.vertex_count(), mesh.triangle_count(), body->segments.size(), body->mesh_seconds,
      std::string(weight_method_name(options.weights.method)).c_str(), body->weight_seconds);
  const ClipRange& range = db.clips[clip];
  const std::vector<Transform> frames = database_clip_frames(db, range);
  return save_skinned_gltf(db.skeleton, body->skinned, frames, range.frame_count(), db.frame_time,
                           range.name, out);
}

int run_export(const std::vector<std::string>& args) {
  std::string input, output, clip_selector;
  BvhOptions bvh;
  bool with_body = false;
  CharacterBodyOptions body;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string* { return i + 1 < args.size() ? &args[++i] : nullptr; };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      const std::string* v = value();
      if (!v) return usage_error(a + " needs a file name");
      output = *v;
    } else if (a == "--clip") {
      const std::string* v = value();
      if (!v || v->empty()) return usage_error("--clip needs a clip name or index");
      clip_selector = *v;
    } else if (a == "--scale") {
      const std::string* v = value();
      const std::optional<double> s = v ? parse_number(*v) : std::nullopt;
      if (!s || *s <= 0.0) return usage_error("--scale needs a positive number");
      bvh.scale = static_cast<float>(*s);
    } else if (a == "--body") {
      with_body = true;
    } else if (a == "--weights") {
      const std::string* v = value();
      const std::optional<WeightMethod> method = v ? parse_weight_method(*v) : std::nullopt;
      if (!method) return usage_error("--weights needs distance, envelope, heat or geodesic");
      body.weights.method = *method;
    } else if (a == "--voxel") {
      const std::string* v = value();
      const std::optional<double> size = v ? parse_number(*v) : std::nullopt;
      if (!size || !(*size > 0.0)) return usage_error("--voxel needs a positive number of metres");
      body.mesh.voxel_size = static_cast<float>(*size);
    } else if (!a.empty() && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (input.empty()) {
      input = a;
    } else {
      return usage_error("one input file at a time (got '" + input + "' and '" + a + "')");
    }
  }
  if (input.empty()) return usage_error("no input file");
  if (output.empty()) return usage_error("no output file (-o <out.glb|out.gltf>)");
  const std::string out_ext = lower_extension(output);
  if (out_ext != ".glb" && out_ext != ".gltf") {
    return usage_error("the output must end in .glb or .gltf, not '" + output + "'");
  }

  const std::string in_ext = lower_extension(input);
  if (with_body && in_ext != ".mmdb") {
    return usage_error("--body needs a database (.mmdb): the body is posed from its idle pose");
  }
  Status written;
  std::string what;
  if (in_ext == ".mmdb") {
    Result<Database> db = load_database(input);
    if (!db) {
      std::fprintf(stderr, "mm export: %s\n", db.message().c_str());
      return 1;
    }
    std::vector<std::string> names;
    for (const ClipRange& c : db->clips) names.push_back(c.name);
    Result<size_t> clip = select_clip(clip_selector, names, input);
    if (!clip) {
      std::fprintf(stderr, "mm export: %s\n", clip.message().c_str());
      return 1;
    }
    written = with_body ? export_database_body(*db, *clip, body, output)
                        : export_database_clip(*db, *clip, output);
    what = "'" + names[*clip] + "', " + std::to_string(db->clips[*clip].frame_count()) +
           " frames, " + std::to_string(db->joint_count()) + " joints" +
           (with_body ? ", with the body" : "");
  } else if (in_ext == ".gltf" || in_ext == ".glb") {
    Result<GltfAsset> asset = load_gltf(input);
    if (!asset) {
      std::fprintf(stderr, "mm export: %s\n", asset.message().c_str());
      return 1;
    }
    std::vector<std::string> names;
    for (const Clip& c : asset->clips) names.push_back(c.name);
    Result<size_t> clip = select_clip(clip_selector, names, input);
    if (!clip) {
      std::fprintf(stderr, "mm export: %s\n", clip.message().c_str());
      return 1;
    }
    const Clip& c = asset->clips[*clip];
    written = save_gltf(c, output);
    what = "'" + c.name + "', " + std::to_string(c.frame_count) + " frames, " +
           std::to_string(c.joint_count()) + " joints";
  } else {
    Result<Clip> clip = load_bvh(input, bvh);
    if (!clip) {
      std::fprintf(stderr, "mm export: %s\n", clip.message().c_str());
      return 1;
    }
    if (!clip_selector.empty() && clip_selector != "0" && clip_selector != clip->name) {
      std::fprintf(stderr, "mm export: %s: a BVH file holds one clip, '%s' (index 0)\n",
                   input.c_str(), clip->name.c_str());
      return 1;
    }
    written = save_gltf(*clip, output);
    what = "'" + clip->name + "', " + std::to_string(clip->frame_count) + " frames, " +
           std::to_string(clip->joint_count()) + " joints";
  }
  if (!written) {
    std::fprintf(stderr, "mm export: %s\n", written.message().c_str());
    return 1;
  }
  std::printf("wrote %s (%s)\n", output.c_str(), what.c_str());
  return 0;
}

const bool registered =
    register_command({"export", "write one clip of a BVH/glTF/database file as glTF", &run_export});

}  // namespace
}  // namespace mm::cli
