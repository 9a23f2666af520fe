// Database build speed on the real data: the whole bandai-normal folder (472 clips, 71 MB) and
// the all-styles archive (1,067 clips, 214 MB), built into a Database in memory on one thread
// and on every hardware thread, in the same run; the multi-threaded builds are then also saved
// (save_database into build/<dir>/build_bench.mmdb), so the build + save row is what `mm build`
// does end to end.
//
//   build/<dir>/bench/build_bench [--repeat N] [--normal-only] [--threads N]
//
// Prints, per data set and thread count, the best and median wall time of N builds (after one
// untimed warm-up that also fills the OS file cache), the BVH megabytes per second and the
// database frames per second of the best build, the time of each build phase, the speed-up of
// the multi-threaded build over the single-threaded one, and the end-to-end targets of issue 11
// (0.3 s and 1.0 s for build + save on two cores). As a second baseline it times a plain sequential
// load_bvh of every file (parsing only, no preprocessing). The archive is unpacked with `tar -xJf`
// into the build folder (build/<dir>/bandai-all-styles, next to this program's folder) when it is
// not there yet.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/database_writer.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct DataSet {
  std::string name;
  fs::path folder;
  double target_seconds;  // on two cores
};

struct Timing {
  double best = 0.0;
  double median = 0.0;
  mm::BuildReport best_report;
  double with_save_best = 0.0;  // build + save_database, when the builds were saved
  double with_save_median = 0.0;
  uint64_t file_bytes = 0;
};

fs::path build_folder() {
  // This program lives in build/<dir>/bench/; the data goes to build/<dir>/.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return fs::current_path();
  return exe.parent_path().parent_path();
}

bool ensure_all_styles(const fs::path& folder) {
  if (fs::exists(folder / "dataset-2_walk_normal_001.bvh")) return true;
  const fs::path archive = fs::path(MM_SHARED_DIR) / "mocap" / "bandai-all-styles.tar.xz";
  if (!fs::exists(archive)) {
    std::fprintf(stderr, "build_bench: %s not found; skipping the all-styles set\n",
                 archive.c_str());
    return false;
  }
  std::fprintf(stderr, "build_bench: unpacking %s into %s (once) ...\n", archive.c_str(),
               folder.parent_path().c_str());
  const std::string command =
      "tar -xJf '" + archive.string() + "' -C '" + folder.parent_path().string() + "'";
  if (std::system(command.c_str()) != 0 || !fs::exists(folder)) {
    std::fprintf(stderr, "build_bench: unpacking failed; skipping the all-styles set\n");
    return false;
  }
  return true;
}

// `save_to` empty: build only; otherwise every build is also saved there and timed with it.
Timing time_builds(const fs::path& folder, int threads, int repeat, const fs::path& save_to = {}) {
  std::vector<double> seconds, with_save;
  Timing timing;
  for (int r = 0; r < repeat; ++r) {
    mm::BuildOptions options;
    options.threads = threads;
    mm::BuildReport report;
    const fs::path inputs[] = {folder};
    const Clock::time_point start = Clock::now();
    mm::Result<mm::Database> db = mm::build_database(inputs, options, &report);
    const double s = std::chrono::duration<double>(Clock::now() - start).count();
    if (!db) {
      std::fprintf(stderr, "build_bench: %s\n", db.message().c_str());
      std::exit(1);
    }
    if (seconds.empty() || s < *std::min_element(seconds.begin(), seconds.end())) {
      timing.best_report = report;
    }
    seconds.push_back(s);
    if (!save_to.empty()) {
      if (mm::Status saved = mm::save_database(*db, save_to); !saved) {
        std::fprintf(stderr, "build_bench: %s\n", saved.message().c_str());
        std::exit(1);
      }
      with_save.push_back(std::chrono::duration<double>(Clock::now() - start).count());
      timing.file_bytes = fs::file_size(save_to);
    }
  }
  std::sort(seconds.begin(), seconds.end());
  timing.best = seconds.front();
  timing.median = seconds[seconds.size() / 2];
  if (!with_save.empty()) {
    std::sort(with_save.begin(), with_save.end());
    timing.with_save_best = with_save.front();
    timing.with_save_median = with_save[with_save.size() / 2];
  }
  return timing;
}

double time_parse_only(const fs::path& folder, uint64_t& bytes) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  bytes = 0;
  const Clock::time_point start = Clock::now();
  for (const fs::path& f : files) {
    mm::Result<mm::Clip> clip = mm::load_bvh(f);
    if (!clip) {
      std::fprintf(stderr, "build_bench: %s\n", clip.message().c_str());
      std::exit(1);
    }
    bytes += fs::file_size(f);
  }
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void print_row(const char* label, int threads, const Timing& t, double baseline_best) {
  const mm::BuildReport& r = t.best_report;
  const double mb = r.bytes_read / 1e6;
  std::printf("  %-22s %2d  %7.3f  %7.3f  %7.1f  %9.0f  %5.2fx   %.3f / %.3f / %.3f / %.3f\n",
              label, threads, t.best, t.median, mb / t.best, r.frames / t.best,
              baseline_best / t.best, r.load_seconds, r.layout_seconds, r.process_seconds,
              r.finish_seconds);
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 5;
  bool normal_only = false;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--threads" && i + 1 < argc) {
      threads = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--normal-only") {
      normal_only = true;
    } else {
      std::fprintf(stderr, "usage: build_bench [--repeat N] [--threads N] [--normal-only]\n");
      return a == "--help" || a == "-h" ? 0 : 2;
    }
  }

  std::vector<DataSet> sets = {
      {"bandai-normal", fs::path(MM_SHARED_DIR) / "mocap" / "bandai-normal", 0.3}};
  if (!normal_only) {
    const fs::path all = build_folder() / "bandai-all-styles";
    if (ensure_all_styles(all)) sets.push_back({"bandai-all-styles", all, 1.0});
  }

  std::printf(
      "database build benchmark: %d builds per row (best and median), %u hardware "
      "threads, load average now:",
      repeat, std::thread::hardware_concurrency());
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) == 3) std::printf(" %.2f %.2f %.2f", load[0], load[1], load[2]);
  std::printf("\n\n");
  for (const DataSet& set : sets) {
    // Warm-up: fills the file cache and the allocator.
    (void)time_builds(set.folder, threads, 1);
    uint64_t parse_bytes = 0;
    const double parse_seconds = time_parse_only(set.folder, parse_bytes);
    const Timing single = time_builds(set.folder, 1, repeat);
    const fs::path saved = build_folder() / "build_bench.mmdb";
    const Timing multi = time_builds(set.folder, threads, repeat, saved);
    fs::remove(saved);
    const mm::BuildReport& r = multi.best_report;
    std::printf("%s: %d clips, %d frames, %.1f MB of BVH\n", set.name.c_str(), r.clips, r.frames,
                r.bytes_read / 1e6);
    std::printf("  %-22s %2s  %7s  %7s  %7s  %9s  %6s   %s\n", "", "th", "best s", "median", "MB/s",
                "frames/s", "ratio",
                "phases of the best (s): read / layout / process / "
                "normalize");
    std::printf("  %-22s %2d  %7.3f  %7s  %7.1f  %9.0f  %5.2fx\n", "load_bvh only (parse)", 1,
                parse_seconds, "-", parse_bytes / 1e6 / parse_seconds, r.frames / parse_seconds,
                single.best / parse_seconds);
    print_row("build, 1 thread", 1, single, single.best);
    print_row("build, all threads", threads, multi, single.best);
    std::printf("  speed-up of %d threads over 1: %.2fx (best), %.2fx (median)\n", threads,
                single.best / multi.best, single.median / multi.median);
    std::printf(
        "  build + save (what mm build does), %d threads: best %.3f s, median %.3f s, file "
        "%.1f MB; target: at most %.1f s on two cores: %s\n\n",
        threads, multi.with_save_best, multi.with_save_median, multi.file_bytes / 1e6,
        set.target_seconds, multi.with_save_best <= set.target_seconds ? "met" : "NOT met");
  }
  std::printf(
      "ratio column: build speed relative to the single-threaded build (for the parse "
      "row: how much longer a whole single-threaded build takes than parsing alone)\n");
  return 0;
}
