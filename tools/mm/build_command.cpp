// `mm build`: makes a database file from BVH / glTF files and folders, with a progress bar and
// a summary.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "command.hpp"
#include "database_summary.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "mm/database/joint_roles.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/programs/command_line.hpp"
#include "mm/programs/number_parsing.hpp"
#include "mm/programs/progress_bar.hpp"
#include "mm/programs/shared_options.hpp"
#include "motion_files.hpp"

namespace mm::cli {
namespace {

struct Arguments {
  std::vector<std::string> inputs;
  std::string output;
  std::string map_file;
  std::string target_file;
  std::string target_map_file;
  BuildOptions options;
  bool quiet = false;
};

// "X,Y,Z": three finite numbers, not all zero.
std::optional<glm::vec3> parse_axis(const std::string& text) {
  glm::vec3 axis(0.0f);
  size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const size_t comma = k < 2 ? text.find(',', start) : text.size();
    if (comma == std::string::npos) return std::nullopt;
    const std::optional<double> x = parse_number(text.substr(start, comma - start));
    if (!x) return std::nullopt;
    axis[k] = static_cast<float>(*x);
    start = comma + 1;
  }
  if (glm::length(axis) < 1e-6f) return std::nullopt;
  return axis;
}

void add_input_options(CLI::App& app, Arguments& out) {
  app.add_option("inputs", out.inputs, "BVH / glTF files, or folders scanned for them")
      ->required()
      ->type_name("FILES");
  app.add_option("-o,--output", out.output, "the database file to write")
      ->required()
      ->type_name("FILE");
  app.add_option("--rate", out.options.rate, "database frame rate (default 30)")
      ->check(number_over(0.0, 1000.0))
      ->type_name("HZ");
  app.add_flag("--mirror", out.options.mirror,
               "also add a left/right mirrored copy of every clip (tagged \"mirrored\")");
  app.add_option("--idle", out.options.idle_seconds,
                 "length of the idle clip (default 3; 0: none): the calmest frame that stands "
                 "on both feet, held still at the origin, as one more clip named and tagged "
                 "\"idle\" (a little over 1 s at least, for the features)")
      ->check(number_in(0.0, 60.0))
      ->type_name("SECONDS");
  app.add_option_function<std::string>(
         "--tags", [&out](const std::string& file) { out.options.tags_file = file; },
         "tag manifest: lines \"<glob> <tag> <tag> ...\" matched against clip names; '#' "
         "starts a comment (tags from Bandai file names are automatic)")
      ->type_name("FILE");
  app.add_flag("--skip-bad", out.options.skip_bad,
               "build from the good files and list the refused ones, instead of failing");
  app.add_option("--threads", out.options.threads,
                 "worker threads (default 0: all hardware threads)")
      ->check(integer_in(0, 256))
      ->type_name("N");
  add_bvh_scale_option(app, out.options.bvh.scale);
}

void add_skeleton_options(CLI::App& app, Arguments& out) {
  app.add_option("--map", out.map_file,
                 "joint map: lines \"role=Joint\" naming the joint of a role ('#' starts a "
                 "comment); roles: " +
                     joint_role_names())
      ->type_name("FILE");
  CLI::Option* target =
      app.add_option(
             "--target", out.target_file,
             "the database skeleton: a .bvh, .gltf or .glb file whose joints, hierarchy and "
             "rest offsets the database takes instead of the first input's (its frames are "
             "not added); inputs of another skeleton are retargeted onto it")
          ->type_name("FILE");
  app.add_option("--target-map", out.target_map_file,
                 "joint map of the --target skeleton (lines \"role=Joint\")")
      ->needs(target)
      ->type_name("FILE");
  app.add_option_function<std::vector<std::string>>(
         "--role",
         [&out](const std::vector<std::string>& values) {
           for (const std::string& value : values) {
             const auto [role, joint] = *split_assignment(value);
             out.options.role_map.push_back({role, joint, 0, {}});
           }
         },
         "the joint playing a role (" + joint_role_names() +
             "), instead of the name-based default; repeatable")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            const auto assignment = split_assignment(value);
            if (!assignment) return "'" + value + "' is not ROLE=JOINT";
            if (find_joint_role(assignment->first)) return {};
            return "unknown role '" + assignment->first + "' (roles: " + joint_role_names() + ")";
          },
          ""))
      ->type_name("ROLE=JOINT")
      ->allow_extra_args(false);
  app.add_option_function<std::vector<std::string>>(
         "--mirror-pair",
         [&out](const std::vector<std::string>& values) {
           for (const std::string& value : values) {
             const auto [left, right] = *split_assignment(value);
             out.options.mirror_pairs.push_back({left, right});
           }
         },
         "two joints that swap when mirroring, besides the detected _L/_R, Left/Right, .L/.R, "
         "l_/r_ pairs; repeatable")
      ->check(assignment("LEFT=RIGHT"))
      ->type_name("L=R")
      ->allow_extra_args(false);
  app.add_option_function<std::string>(
         "--forward-axis",
         [&out](const std::string& text) {
           out.options.root.hips_forward_axis = *parse_axis(text);
         },
         "the hips' bone-local forward axis (default 0,0,1, the Bandai hips')")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return parse_axis(text) ? ""
                                    : "'" + text + "' is not three numbers X,Y,Z, not all zero";
          },
          ""))
      ->type_name("X,Y,Z");
}

void add_contact_options(CLI::App& app, Arguments& out) {
  app.add_option("--contact-height", out.options.contacts.foot_height,
                 "a foot is in contact when its ankle is below M metres (default 0.15)")
      ->check(number_in(0.0, 10.0))
      ->type_name("M");
  app.add_option("--contact-toe-height", out.options.contacts.toe_height,
                 "... or its toe is below M metres (default 0.06)")
      ->check(number_in(0.0, 10.0))
      ->type_name("M");
  app.add_option("--contact-speed", out.options.contacts.speed,
                 "... and that joint moves slower than V m/s (default 0.6)")
      ->check(number_in(0.0, 100.0))
      ->type_name("V");
  app.add_flag("--quiet", out.quiet, "no progress and no summary");
}

// Parses the arguments into `out`; returns an exit code to stop with, or -1 to go on.
int parse_arguments(const std::vector<std::string>& args, Arguments& out) {
  CLI::App app(
      "Builds a motion database: every clip is resampled, given a simulation root (joint 0), "
      "velocities, foot contacts and tags, and the feature matrix is extracted and normalized. "
      "Folders are scanned recursively for .bvh, .gltf and .glb files (sorted by path).",
      "mm build");
  set_up_app(app);
  app.footer("exit status: 0 built, 1 bad input (the message names the file), 2 bad usage");
  add_input_options(app, out);
  add_skeleton_options(app, out);
  add_contact_options(app, out);
  return parse_command_line(app, args);
}

// Builds and writes the database; null (with the message printed) on a failure.
std::optional<Database> build_and_save(Arguments& arguments, BuildReport& report) {
  ProgressBar progress("mm build", !arguments.quiet);
  arguments.options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  const std::vector<std::filesystem::path> inputs(arguments.inputs.begin(), arguments.inputs.end());
  Result<Database> db = build_database(inputs, arguments.options, &report);
  if (!db) {
    // The builder's own messages start with "build: ", which the prefix here already says.
    std::string message = db.message();
    if (message.rfind("build: ", 0) == 0) message.erase(0, 7);
    std::fprintf(stderr, "mm build: %s\n", message.c_str());
    return std::nullopt;
  }
  if (Status s = save_database(*db, arguments.output); !s) {
    std::fprintf(stderr, "mm build: %s\n", s.message().c_str());
    return std::nullopt;
  }
  return std::move(db).value();
}

void print_warnings(const BuildReport& report) {
  for (const std::string& w : report.warnings)
    std::fprintf(stderr, "mm build: warning: %s\n", w.c_str());
  if (!report.refused.empty()) {
    std::fprintf(stderr, "mm build: refused %zu of %d files:\n", report.refused.size(),
                 report.inputs);
    for (const RefusedInput& r : report.refused) {
      std::fprintf(stderr, "  %s\n    %s\n", r.path.string().c_str(), r.message.c_str());
    }
  }
}

void print_summary(const std::string& output, const Database& db, const BuildReport& report,
                   double seconds) {
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(output, ec);
  std::printf("wrote %s\n", output.c_str());
  for (const std::string& line : report.retargeted) std::printf("retargeted:  %s\n", line.c_str());
  if (!report.idle_summary.empty()) std::printf("idle takes:  %s\n", report.idle_summary.c_str());
  if (!report.ground_summary.empty()) {
    std::printf("ground:      %s\n", report.ground_summary.c_str());
  }
  std::printf("input:       %d files, %s read, %d refused\n", report.inputs,
              format_bytes(report.bytes_read).c_str(), static_cast<int>(report.refused.size()));
  const std::string idle_source =
      report.idle_frames > 0
          ? "frame " + std::to_string(report.idle_source_frame) + " of " + report.idle_source_clip
          : std::string();
  print_database_summary(stdout, db, ec ? 0 : static_cast<uint64_t>(size), idle_source);
  std::printf(
      "time:        %.2f s on %d threads (reading %.2f s, layout %.2f s, processing %.2f s, "
      "normalizing %.2f s, writing %.2f s)\n",
      seconds, report.threads, report.load_seconds, report.layout_seconds, report.process_seconds,
      report.finish_seconds, seconds - report.total_seconds);
}

// Reads the map files and the target into the build options.
Status read_skeleton_files(Arguments& arguments) {
  BuildOptions& options = arguments.options;
  if (!arguments.map_file.empty()) {
    Result<std::vector<JointRoleAssignment>> map = load_joint_map(arguments.map_file);
    if (!map) return Error{map.message()};
    // The map file first: --role on the command line overrides its lines.
    map->insert(map->end(), options.role_map.begin(), options.role_map.end());
    options.role_map = std::move(map).value();
  }
  if (!arguments.target_map_file.empty()) {
    Result<std::vector<JointRoleAssignment>> map = load_joint_map(arguments.target_map_file);
    if (!map) return Error{map.message()};
    options.target_role_map = std::move(map).value();
  }
  if (!arguments.target_file.empty()) {
    MotionFileOptions read;
    read.bvh_scale = options.bvh.scale;
    Result<MotionFile> target = read_motion_file(arguments.target_file, read);
    if (!target) return Error{target.message()};
    // Its import warnings reach BuildReport::warnings, which print_warnings prints.
    options.target = std::move(target->clip);
  }
  return Status::success();
}

int run_build(const std::vector<std::string>& args) {
  Arguments arguments;
  if (const int code = parse_arguments(args, arguments); code >= 0) return code;
  if (Status s = read_skeleton_files(arguments); !s) {
    std::fprintf(stderr, "mm build: %s\n", s.message().c_str());
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  BuildReport report;
  const std::optional<Database> db = build_and_save(arguments, report);
  if (!db) return 1;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  print_warnings(report);
  if (!arguments.quiet) print_summary(arguments.output, *db, report, seconds);
  return 0;
}

const bool registered = register_command(
    {"build", "make a motion database from BVH/glTF files and folders", &run_build});

}  // namespace
}  // namespace mm::cli
