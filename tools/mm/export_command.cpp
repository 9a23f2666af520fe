// `mm export`: writes one clip of a BVH, glTF or database file as glTF, for Blender and other
// viewers.

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/character_body.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/shared_options.hpp"
#include "motion_files.hpp"

namespace mm::cli {
namespace {

namespace fs = std::filesystem;

struct Arguments {
  std::string input;
  std::string output;
  std::string clip_selector;
  BvhOptions bvh;
  bool with_body = false;
  CharacterBodyOptions body;
};

// Parses the arguments into `out`; returns an exit code to stop with, or -1 to go on.
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  CLI::App app(
      "Writes one clip with its skeleton as glTF (metres, Y up): \".glb\" binary or \".gltf\" "
      "JSON with the buffer embedded. From a database the clip is rebuilt from its stored "
      "per-frame local positions and rotations at the database rate, joint 0 (the simulation "
      "root) included as an ordinary root joint.\n\n"
      "With --body (database input only) the file also holds the character's generated body: a "
      "surface around the bones in an A-pose bind pose, skinned with the chosen weights, so the "
      "clip plays on a character in Blender or any glTF viewer (and mm-viewer --body loads it).",
      "mm export");
  set_up_app(app);
  app.footer("exit status: 0 written, 1 bad input or clip not found, 2 bad usage");
  app.add_option("input", out.input, "the clip's file: .bvh, .gltf, .glb or .mmdb")
      ->required()
      ->type_name("FILE");
  app.add_option("-o,--output", out.output, "the .glb or .gltf file to write")
      ->required()
      ->type_name("FILE");
  app.add_option("--clip", out.clip_selector,
                 "which clip (default 0): an index, or a clip / animation name")
      ->check(CLI::Validator(
          [](std::string& text) { return text.empty() ? "needs a clip name or index" : ""; }, ""))
      ->type_name("NAME|INDEX");
  add_bvh_scale_option(app, out.bvh.scale);
  app.add_flag("--body", out.with_body,
               "write the generated, skinned body with the clip (database input)");
  add_weights_option(app, out.body.weights.method, "the body's skinning weights (default heat)");
  app.add_option("--voxel", out.body.mesh.voxel_size,
                 "the body surface's grid spacing (default 0.012; smaller: more vertices)")
      ->check(number_over(0.0, 1.0))
      ->type_name("METRES");
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  const std::string out_ext = lower_extension(out.output);
  if (out_ext != ".glb" && out_ext != ".gltf") {
    return usage_error(app, "the output must end in .glb or .gltf, not '" + out.output + "'");
  }
  if (out.with_body && lower_extension(out.input) != ".mmdb") {
    return usage_error(app,
                       "--body needs a database (.mmdb): the body is posed from its idle pose");
  }
  return -1;
}

// What was written, for the last line: "'<name>', N frames, J joints".
std::string clip_description(const std::string& name, int frames, int joints) {
  return "'" + name + "', " + std::to_string(frames) + " frames, " + std::to_string(joints) +
         " joints";
}

// A database clip as a pose sequence: the stored local positions and rotations, unit scale.
std::vector<Transform> database_clip_frames(const Database& db, const ClipRange& range) {
  const int joints = db.joint_count();
  std::vector<Transform> frames(static_cast<size_t>(range.frame_count()) * joints);
  for (int f = 0; f < range.frame_count(); ++f) {
    for (int j = 0; j < joints; ++j) {
      const size_t from = static_cast<size_t>(range.start + f) * joints + j;
      Transform& t = frames[static_cast<size_t>(f) * joints + j];
      t.translation = db.local_positions()[from];
      t.rotation = db.local_rotations()[from];
    }
  }
  return frames;
}

Status export_database_clip(const Database& db, size_t clip, const fs::path& out) {
  const ClipRange& range = db.clips()[clip];
  const std::vector<Transform> frames = database_clip_frames(db, range);
  return save_gltf(db.skeleton(), frames, range.frame_count(), db.frame_time(), range.name, out);
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
  const ClipRange& range = db.clips()[clip];
  const std::vector<Transform> frames = database_clip_frames(db, range);
  return save_skinned_gltf(db.skeleton(), body->skinned, frames, range.frame_count(),
                           db.frame_time(), range.name, out);
}

// The clip the arguments' --clip selects among `clips` (a database's or a glTF file's).
template <typename Clips>
Result<size_t> select_clip_in(const Clips& clips, const Arguments& arguments) {
  std::vector<std::string> names;
  for (const auto& c : clips) names.push_back(c.name);
  return select_clip(arguments.clip_selector, names, arguments.input);
}

// Each exporter writes the selected clip of its kind of file and says what it wrote.
Result<std::string> export_from_database(const Arguments& arguments) {
  Result<Database> db = load_database(arguments.input);
  if (!db) return Error{db.message()};
  Result<size_t> clip = select_clip_in(db->clips(), arguments);
  if (!clip) return Error{clip.message()};
  const Status written = arguments.with_body
                             ? export_database_body(*db, *clip, arguments.body, arguments.output)
                             : export_database_clip(*db, *clip, arguments.output);
  if (!written) return Error{written.message()};
  const ClipRange& range = db->clips()[*clip];
  return clip_description(range.name, range.frame_count(), db->joint_count()) +
         (arguments.with_body ? ", with the body" : "");
}

Result<std::string> export_from_gltf(const Arguments& arguments) {
  Result<GltfAsset> asset = load_gltf(arguments.input);
  if (!asset) return Error{asset.message()};
  Result<size_t> clip = select_clip_in(asset->clips, arguments);
  if (!clip) return Error{clip.message()};
  const Clip& c = asset->clips[*clip];
  print_import_warnings("mm export", c);
  if (Status written = save_gltf(c, arguments.output); !written) return Error{written.message()};
  return clip_description(c.name, c.frame_count, c.joint_count());
}

Result<std::string> export_from_bvh(const Arguments& arguments) {
  Result<Clip> clip = load_bvh(arguments.input, arguments.bvh);
  if (!clip) return Error{clip.message()};
  print_import_warnings("mm export", *clip);
  const std::string& selector = arguments.clip_selector;
  if (!selector.empty() && selector != "0" && selector != clip->name) {
    return Error{arguments.input + ": a BVH file holds one clip, '" + clip->name + "' (index 0)"};
  }
  if (Status written = save_gltf(*clip, arguments.output); !written) {
    return Error{written.message()};
  }
  return clip_description(clip->name, clip->frame_count, clip->joint_count());
}

int run_export(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;
  const std::string in_ext = lower_extension(arguments.input);
  const Result<std::string> what = in_ext == ".mmdb" ? export_from_database(arguments)
                                   : in_ext == ".gltf" || in_ext == ".glb"
                                       ? export_from_gltf(arguments)
                                       : export_from_bvh(arguments);
  if (!what) {
    std::fprintf(stderr, "mm export: %s\n", what.message().c_str());
    return 1;
  }
  std::printf("wrote %s (%s)\n", arguments.output.c_str(), what->c_str());
  return 0;
}

const bool registered =
    register_command({"export", "write one clip of a BVH/glTF/database file as glTF", &run_export});

}  // namespace
}  // namespace mm::cli
