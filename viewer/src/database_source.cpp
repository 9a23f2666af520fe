#include "database_source.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/database_writer.hpp"
#include "mm/programs/progress_bar.hpp"

namespace mm::viewer {
namespace fs = std::filesystem;
namespace {

// FNV-1a over the inputs' paths, sizes and times: stable across runs and builds (std::hash
// is not promised to be).
uint64_t fingerprint(const std::vector<fs::path>& files) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const std::string& text) {
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  };
  mix(std::to_string(kDatabaseFormatVersion));
  for (const fs::path& f : files) {
    std::error_code ec;
    mix(fs::absolute(f).string());
    mix(std::to_string(fs::file_size(f, ec)));
    mix(std::to_string(fs::last_write_time(f, ec).time_since_epoch().count()));
  }
  return h;
}

fs::path cache_folder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return (ec ? fs::current_path() : exe.parent_path()) / "viewer-cache";
}

Result<std::shared_ptr<const Database>> build_folder(const fs::path& folder) {
  const fs::path inputs[] = {folder};
  Result<std::vector<fs::path>> files = collect_input_files(inputs);
  if (!files) return files.error();
  char name[32];
  std::snprintf(name, sizeof name, "-%016llx.mmdb",
                static_cast<unsigned long long>(fingerprint(*files)));
  const fs::path cached = cache_folder() / (folder.filename().string() + name);
  if (fs::exists(cached)) {
    Result<Database> db = load_database(cached);
    if (db) {
      std::printf("mm-viewer: loaded the cached database %s\n", cached.c_str());
      return std::make_shared<const Database>(std::move(*db));
    }
    std::fprintf(stderr, "mm-viewer: rebuilding (%s)\n", db.message().c_str());
  }
  std::printf("mm-viewer: building the database from %zu files in %s\n", files->size(),
              folder.c_str());
  std::fflush(stdout);
  cli::ProgressBar progress("mm-viewer: build", true);
  BuildOptions options;
  options.bvh.scale = 0.0f;  // units from each skeleton's size, as `mm build` without --scale
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  Result<Database> db = build_database(*files, options);
  if (!db) return db.error();
  std::error_code ec;
  fs::create_directories(cached.parent_path(), ec);
  if (Status s = save_database(*db, cached); !s) {
    std::fprintf(stderr, "mm-viewer: not cached: %s\n", s.message().c_str());
  } else {
    std::printf("mm-viewer: cached as %s\n", cached.c_str());
  }
  return std::make_shared<const Database>(std::move(*db));
}

}  // namespace

std::string default_data_folder() {
  if (const char* data = std::getenv("MM_DATA"); data && *data) return data;
  return MM_SHARED_DIR "/mocap/bandai-normal";
}

Result<std::shared_ptr<const Database>> open_database(const std::string& db_path,
                                                      const std::string& data_path) {
  if (!db_path.empty()) {
    Result<Database> db = load_database(db_path);
    if (!db) return db.error();
    return std::make_shared<const Database>(std::move(*db));
  }
  return build_folder(data_path.empty() ? default_data_folder() : data_path);
}

}  // namespace mm::viewer
