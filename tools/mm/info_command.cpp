// `mm info`: the summary and feature statistics of an existing database file.

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "command.hpp"
#include "database_summary.hpp"
#include "mm/database/database_file.hpp"
#include "mm/programs/command_line.hpp"

namespace mm::cli {
namespace {

void print_clips(const Database& db) {
  std::printf("clips:\n");
  for (size_t c = 0; c < db.clips().size(); ++c) {
    const ClipRange& clip = db.clips()[c];
    std::string tags;
    for (size_t t = 0; t < db.tag_names().size() && t < 64; ++t) {
      if (clip.tags & (uint64_t{1} << t)) tags += (tags.empty() ? "" : " ") + db.tag_names()[t];
    }
    std::printf("  %4zu  %6d frames  %-48s %s\n", c, clip.frame_count(), clip.name.c_str(),
                tags.c_str());
  }
}

int run_info(const std::vector<std::string>& args) {
  std::string path;
  bool list_clips = false;
  CLI::App app(
      "Loads a database file (checking its checksum and every array) and prints its clips, "
      "frames, joints, tags with counts, feature dimensions, searchable frames and file size, "
      "then the feature statistics per channel: name, kind, bone or times, columns, weight, and "
      "the mean and standard deviation per column.",
      "mm info");
  set_up_app(app);
  app.footer("exit status: 0 fine, 1 unreadable or corrupt file, 2 bad usage");
  app.add_option("file", path, "the database file (.mmdb)")->required()->type_name("FILE");
  app.add_flag("--clips", list_clips, "also list every clip: index, frames, name, tags");
  if (const int code = parse_command_line(app, args); code >= 0) return code;

  Result<Database> db = load_database(path);
  if (!db) {
    std::fprintf(stderr, "mm info: %s\n", db.message().c_str());
    return 1;
  }
  std::error_code ec;
  const uintmax_t size = std::filesystem::file_size(path, ec);
  std::printf("database:    %s (format version %u)\n", path.c_str(), kDatabaseFormatVersion);
  print_database_summary(stdout, *db, ec ? 0 : static_cast<uint64_t>(size));
  print_feature_statistics(stdout, *db);
  if (list_clips) print_clips(*db);
  return 0;
}

const bool registered =
    register_command({"info", "summary and feature statistics of a database file", &run_info});

}  // namespace
}  // namespace mm::cli
