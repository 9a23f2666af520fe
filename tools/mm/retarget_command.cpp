// `mm retarget`: one clip of one skeleton played on another skeleton, written as BVH or glTF.

#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "command.hpp"
#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/gltf.hpp"
#include "mm/offline/preprocess.hpp"
#include "mm/offline/retarget.hpp"
#include "mm/programs/command_line.hpp"
#include "motion_files.hpp"

namespace mm::cli {
namespace {

struct Arguments {
  std::string source;
  std::string target;
  std::string output;
  std::string map_file;
  std::string target_map_file;
  std::string clip_selector;
  int rest_frame = -1;
  float rate = 0.0f;  // 0: the source's own frame time
};

void add_options(CLI::App& app, Arguments& out) {
  app.add_option("source", out.source, "the clip to retarget: .bvh, .gltf or .glb")
      ->required()
      ->type_name("SOURCE");
  app.add_option("--to", out.target,
                 "the skeleton to play it on: .bvh, .gltf, .glb or a database (.mmdb)")
      ->required()
      ->type_name("TARGET");
  app.add_option("-o,--output", out.output,
                 "the file to write: .bvh (in the target's units) or "
                 ".glb / .gltf (metres)")
      ->required()
      ->type_name("OUT");
  app.add_option("--map", out.map_file, "joint map of the source skeleton (lines \"role=Joint\")")
      ->type_name("FILE");
  app.add_option("--target-map", out.target_map_file, "joint map of the target skeleton")
      ->type_name("FILE");
  app.add_option("--rest-frame", out.rest_frame,
                 "the source frame whose pose stands for its rest pose (default: the bind pose "
                 "when it stands, else frame 0)")
      ->check(integer_in(0, std::numeric_limits<int>::max()))
      ->type_name("N");
  app.add_option("--rate", out.rate,
                 "resample the result to HZ frames per second (default: "
                 "the source's frame time)")
      ->check(number_over(0.0, 1000.0))
      ->type_name("HZ");
  app.add_option("--clip", out.clip_selector,
                 "which animation of a glTF source (default 0): an index or a name")
      ->type_name("NAME|INDEX");
}

// Parses the arguments into `out`; returns an exit code to stop with, or -1 to go on.
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  CLI::App app(
      "Plays a clip on another skeleton: joints are matched by role (names, a map file, or the "
      "structure), each matched bone follows the source's direction once the two rest poses are "
      "aligned, bones keep the target's lengths, the root moves as the source's hips scaled by "
      "the ratio of leg lengths, and the feet stand on the target's ground. The result has the "
      "target's joints, hierarchy and rest offsets and the source's duration.",
      "mm retarget");
  set_up_app(app);
  app.footer("exit status: 0 written, 1 bad input (the message names the file), 2 bad usage");
  add_options(app, out);
  if (const int code = parse_command_line(app, args); code >= 0) return code;
  if (!is_motion_file_name(out.source, false)) {
    return usage_error(app,
                       "the source must be a .bvh, .gltf or .glb file, not '" + out.source + "'");
  }
  if (!is_motion_file_name(out.target, true)) {
    return usage_error(app, "the target (--to) must be a .bvh, .gltf, .glb or .mmdb file, not '" +
                                out.target + "'");
  }
  const std::string out_ext = lower_extension(out.output);
  if (out_ext != ".bvh" && out_ext != ".glb" && out_ext != ".gltf") {
    return usage_error(app, "the output must end in .bvh, .glb or .gltf, not '" + out.output + "'");
  }
  return -1;
}

// The roles of a file's skeleton: found by name and structure (with its map file if any), or
// those a database stores when no map overrides them.
Result<JointRoleIndices> roles_of(const MotionFile& file, const std::string& map_file) {
  if (map_file.empty() && file.stored_roles) return *file.stored_roles;
  JointRoles names;
  if (!map_file.empty()) {
    Result<std::vector<JointRoleAssignment>> map = load_joint_map(map_file);
    if (!map) return Error{map.message()};
    if (Status s = check_joint_map(file.clip.skeleton, *map); !s) return Error{s.message()};
    apply_joint_map(names, *map);
  }
  Result<JointRoleIndices> roles = find_joint_roles(file.clip.skeleton, names);
  if (!roles) return Error{file.clip.source_path + ": " + roles.message()};
  return roles;
}

// One side of the retargeting, described from its file; `rest_frame` -1 lets the file decide.
Result<RetargetSkeleton> describe(const MotionFile& file, const std::string& map_file,
                                  int rest_frame) {
  Result<JointRoleIndices> roles = roles_of(file, map_file);
  if (!roles) return Error{roles.message()};
  Result<RetargetSkeleton> side =
      describe_for_retargeting(file.clip, *roles, rest_frame >= 0 ? rest_frame : file.rest_frame);
  if (!side) return Error{file.clip.source_path + ": " + side.message()};
  return side;
}

void print_side(const char* label, const std::string& path, const MotionFile& file,
                const RetargetSkeleton& side) {
  std::printf("%s %s: %d joints, %d frames, rest pose: %s\n", label, path.c_str(),
              file.clip.joint_count(), file.clip.frame_count, side.rest_description.c_str());
}

void print_report(const RetargetReport& report) {
  for (const std::string& line : report.matched) std::printf("matched:      %s\n", line.c_str());
  std::string rest;
  for (const std::string& joint : report.left_at_rest) rest += " " + joint;
  std::printf("left at rest:%s\n", rest.empty() ? " none" : rest.c_str());
  std::printf("scale:        %g (target leg length / source leg length), ground shift %+.4f m\n",
              static_cast<double>(report.scale), static_cast<double>(report.ground_shift));
}

// The clip in the target file's units on the target's skeleton as its file states it, so the
// written OFFSETs are the target's own numbers (metres and back would change the last digits).
Clip in_file_units(Clip clip, const MotionFile& target) {
  for (Transform& t : clip.local) t.translation *= target.units_per_metre;
  clip.skeleton = *target.file_skeleton;
  clip.end_sites = target.file_end_sites;
  return clip;
}

Status write_clip(const Clip& clip, const std::string& out, const MotionFile& target) {
  if (lower_extension(out) != ".bvh") return save_gltf(clip, out);
  if (!target.file_skeleton) return save_bvh(clip, out, target.units_per_metre);
  return save_bvh(in_file_units(clip, target), out, 1.0f);
}

// Reads both files, retargets and writes; says what it did on stdout.
Status retarget(const Arguments& arguments) {
  MotionFileOptions source_options;
  source_options.clip_selector = arguments.clip_selector;
  if (arguments.rate > 0.0f) source_options.gltf_rate = arguments.rate;
  Result<MotionFile> source = read_motion_file(arguments.source, source_options);
  if (!source) return Error{source.message()};
  print_import_warnings("mm retarget", source->clip);
  MotionFileOptions target_options;
  target_options.allow_database = true;
  Result<MotionFile> target = read_motion_file(arguments.target, target_options);
  if (!target) return Error{target.message()};
  print_import_warnings("mm retarget", target->clip);

  Result<RetargetSkeleton> from = describe(*source, arguments.map_file, arguments.rest_frame);
  if (!from) return Error{from.message()};
  Result<RetargetSkeleton> to = describe(*target, arguments.target_map_file, -1);
  if (!to) return Error{to.message()};
  print_side("source:      ", arguments.source, *source, *from);
  print_side("target:      ", arguments.target, *target, *to);

  // Resampled before retargeting: the rest pose and ground were taken from the source's own
  // frames, so --rest-frame counts those.
  const Clip& clip = source->clip;
  const bool resample = arguments.rate > 0.0f && needs_resampling(clip, arguments.rate);
  RetargetReport report;
  Result<Clip> out =
      retarget_clip(resample ? resample_clip(clip, arguments.rate) : clip, *from, *to, &report);
  if (!out) return Error{out.message()};
  print_report(report);
  if (Status s = write_clip(*out, arguments.output, *target); !s) return s;
  std::printf("wrote %s: %d frames, %.3f s at %g Hz, %d joints\n", arguments.output.c_str(),
              out->frame_count, static_cast<double>(out->duration()),
              1.0 / static_cast<double>(out->frame_time), out->joint_count());
  return Status::success();
}

int run_retarget(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;
  if (Status s = retarget(arguments); !s) {
    std::fprintf(stderr, "mm retarget: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}

const bool registered = register_command(
    {"retarget", "play a clip on another skeleton, written as BVH or glTF", &run_retarget});

}  // namespace
}  // namespace mm::cli
