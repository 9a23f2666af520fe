// `mm build`: makes a database file from BVH / glTF files and folders, with a progress bar and
// a summary.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "database_summary.hpp"
#include "mm/database/builder.hpp"
#include "mm/database/database_file.hpp"
#include "mm/database/files.hpp"
#include "progress_bar.hpp"

namespace mm::cli {
namespace {

const char* const kUsage = R"(usage: mm build <files or folders...> -o <out.mmdb> [options]

Builds a motion database: every clip is resampled, given a simulation root (joint 0),
velocities, foot contacts and tags, and the feature matrix is extracted and normalized.
Folders are scanned recursively for .bvh, .gltf and .glb files (sorted by path).

options:
  -o, --output FILE   the database file to write (required)
  --rate HZ           database frame rate (default 30)
  --mirror            also add a left/right mirrored copy of every clip (tagged "mirrored")
  --idle SECONDS      length of the idle clip (default 3; 0: none): the calmest frame that
                      stands on both feet, held still at the origin, as one more clip named
                      and tagged "idle" (a little over 1 s at least, for the features)
  --tags FILE         tag manifest: lines "<glob> <tag> <tag> ..." matched against clip
                      names; '#' starts a comment (tags from Bandai file names are automatic)
  --skip-bad          build from the good files and list the refused ones, instead of failing
  --threads N         worker threads (default 0: all hardware threads)
  --scale S           BVH units to metres (default 0.01: centimetres)
  --role ROLE=JOINT   the joint playing a role (hips, left_foot, right_foot, left_toe,
                      right_toe, head), instead of the name-based default; repeatable
  --mirror-pair L=R   two joints that swap when mirroring, besides the detected _L/_R,
                      Left/Right, .L/.R, l_/r_ pairs; repeatable
  --forward-axis X,Y,Z  the hips' bone-local forward axis (default 0,0,1, the Bandai hips')
  --contact-height M      a foot is in contact when its ankle is below M metres (default 0.15)
  --contact-toe-height M  ... or its toe is below M metres (default 0.06)
  --contact-speed V       ... and that joint moves slower than V m/s (default 0.6)
  --quiet             no progress and no summary
  -h, --help          this text

exit status: 0 built, 1 bad input (the message names the file), 2 bad usage
)";

int usage_error(const std::string& message) {
  std::fprintf(stderr, "mm build: %s\n\n%s", message.c_str(), kUsage);
  return 2;
}

int run_build(const std::vector<std::string>& args) {
  std::vector<std::filesystem::path> inputs;
  std::string output;
  BuildOptions options;
  bool quiet = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    // The value after an option, or null when the arguments end.
    auto value = [&]() -> const std::string* { return i + 1 < args.size() ? &args[++i] : nullptr; };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      const std::string* v = value();
      if (!v) return usage_error(a + " needs a file name");
      output = *v;
    } else if (a == "--rate") {
      const std::string* v = value();
      const std::optional<double> rate = v ? parse_number(*v) : std::nullopt;
      if (!rate || *rate <= 0.0 || *rate > 1000.0) {
        return usage_error("--rate needs a frame rate in (0, 1000] Hz");
      }
      options.rate = static_cast<float>(*rate);
    } else if (a == "--mirror") {
      options.mirror = true;
    } else if (a == "--idle") {
      const std::string* v = value();
      const std::optional<double> seconds = v ? parse_number(*v) : std::nullopt;
      if (!seconds || *seconds < 0.0 || *seconds > 60.0) {
        return usage_error("--idle needs a number of seconds from 0 to 60 (0: no idle clip)");
      }
      options.idle_seconds = static_cast<float>(*seconds);
    } else if (a == "--tags") {
      const std::string* v = value();
      if (!v) return usage_error("--tags needs a file name");
      options.tags_file = *v;
    } else if (a == "--skip-bad") {
      options.skip_bad = true;
    } else if (a == "--threads") {
      const std::string* v = value();
      const std::optional<long long> n = v ? parse_count(*v) : std::nullopt;
      if (!n || *n > 256) return usage_error("--threads needs a count from 0 to 256");
      options.threads = static_cast<int>(*n);
    } else if (a == "--scale") {
      const std::string* v = value();
      const std::optional<double> s = v ? parse_number(*v) : std::nullopt;
      if (!s || *s <= 0.0) return usage_error("--scale needs a positive number");
      options.bvh.scale = static_cast<float>(*s);
    } else if (a == "--role") {
      const std::string* v = value();
      const size_t eq = v ? v->find('=') : std::string::npos;
      if (eq == std::string::npos || eq == 0 || eq + 1 == v->size()) {
        return usage_error("--role needs ROLE=JOINT, e.g. --role left_foot=LeftAnkle");
      }
      const std::string role = v->substr(0, eq);
      std::vector<std::string> joint = {v->substr(eq + 1)};
      if (role == "hips") {
        options.roles.hips = joint;
      } else if (role == "left_foot") {
        options.roles.left_foot = joint;
      } else if (role == "right_foot") {
        options.roles.right_foot = joint;
      } else if (role == "left_toe") {
        options.roles.left_toe = joint;
      } else if (role == "right_toe") {
        options.roles.right_toe = joint;
      } else if (role == "head") {
        options.roles.head = joint;
      } else {
        return usage_error("unknown role '" + role +
                           "' (roles: hips, left_foot, right_foot, left_toe, right_toe, head)");
      }
    } else if (a == "--mirror-pair") {
      const std::string* v = value();
      const size_t eq = v ? v->find('=') : std::string::npos;
      if (eq == std::string::npos || eq == 0 || eq + 1 == v->size()) {
        return usage_error("--mirror-pair needs LEFT=RIGHT joint names");
      }
      options.mirror_pairs.push_back({v->substr(0, eq), v->substr(eq + 1)});
    } else if (a == "--forward-axis") {
      const std::string* v = value();
      glm::vec3 axis(0.0f);
      bool good = v != nullptr;
      size_t start = 0;
      for (int k = 0; k < 3 && good; ++k) {
        const size_t comma = k < 2 ? v->find(',', start) : v->size();
        good = comma != std::string::npos;
        if (!good) break;
        const std::optional<double> x = parse_number(v->substr(start, comma - start));
        good = x.has_value();
        if (good) axis[k] = static_cast<float>(*x);
        start = comma + 1;
      }
      if (!good || glm::length(axis) < 1e-6f) {
        return usage_error("--forward-axis needs three numbers X,Y,Z, not all zero");
      }
      options.root.hips_forward_axis = axis;
    } else if (a == "--contact-height" || a == "--contact-toe-height" || a == "--contact-speed") {
      const std::string* v = value();
      const std::optional<double> x = v ? parse_number(*v) : std::nullopt;
      if (!x || *x < 0.0) return usage_error(a + " needs a non-negative number");
      float& field = a == "--contact-height"       ? options.contacts.foot_height
                     : a == "--contact-toe-height" ? options.contacts.toe_height
                                                   : options.contacts.speed;
      field = static_cast<float>(*x);
    } else if (a == "--quiet") {
      quiet = true;
    } else if (!a.empty() && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else {
      inputs.emplace_back(a);
    }
  }
  if (inputs.empty()) return usage_error("no input files or folders");
  if (output.empty()) return usage_error("no output file (-o <out.mmdb>)");

  const auto start = std::chrono::steady_clock::now();
  ProgressBar progress("mm build", !quiet);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  BuildReport report;
  Result<Database> db = build_database(inputs, options, &report);
  if (!db) {
    // The builder's own messages start with "build: ", which the prefix here already says.
    std::string message = db.message();
    if (message.rfind("build: ", 0) == 0) message.erase(0, 7);
    std::fprintf(stderr, "mm build: %s\n", message.c_str());
    return 1;
  }
  if (Status s = save_database(*db, output); !s) {
    std::fprintf(stderr, "mm build: %s\n", s.message().c_str());
    return 1;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  for (const std::string& w : report.warnings)
    std::fprintf(stderr, "mm build: warning: %s\n", w.c_str());
  if (!report.refused.empty()) {
    std::fprintf(stderr, "mm build: refused %zu of %d files:\n", report.refused.size(),
                 report.inputs);
    for (const RefusedInput& r : report.refused) {
      std::fprintf(stderr, "  %s\n    %s\n", r.path.string().c_str(), r.message.c_str());
    }
  }
  if (!quiet) {
    std::error_code ec;
    const uintmax_t size = std::filesystem::file_size(output, ec);
    std::printf("wrote %s\n", output.c_str());
    std::printf("input:       %d files, %s read, %d refused\n", report.inputs,
                format_bytes(report.bytes_read).c_str(), static_cast<int>(report.refused.size()));
    const std::string idle_source =
        report.idle_frames > 0
            ? "frame " + std::to_string(report.idle_source_frame) + " of " + report.idle_source_clip
            : std::string();
    print_database_summary(stdout, *db, ec ? 0 : static_cast<uint64_t>(size), idle_source);
    std::printf(
        "time:        %.2f s on %d threads (reading %.2f s, layout %.2f s, processing %.2f s, "
        "normalizing %.2f s, writing %.2f s)\n",
        seconds, report.threads, report.load_seconds, report.layout_seconds, report.process_seconds,
        report.finish_seconds, seconds - report.total_seconds);
  }
  return 0;
}

const bool registered = register_command(
    {"build", "make a motion database from BVH/glTF files and folders", &run_build});

}  // namespace
}  // namespace mm::cli
