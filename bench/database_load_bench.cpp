// How long loading a database file takes, against reading the same file into memory.
//
// A synthetic database the size of the full Bandai set (167k frames x 23 joints x 27 features)
// shaped like it (the simulation root, the BVH root and the hips move; every other joint keeps
// its offset through a clip, as BVH joints do) is generated in memory, saved next to this
// executable (~76 MB in format version 2), then loaded repeatedly. With MM_LOAD_BENCH_FILE set
// to a database file (e.g. one `mm build` made of the all-styles set), that file is loaded
// instead. The baseline is one fread of the whole file into a fresh buffer: the ratio
// load / read shows what the checksum, decoding, recomputed velocities and validation cost on
// top of the IO.
//
//   build/<dir>/bench/database_load_bench [--benchmark_min_time=0.2]
//   MM_LOAD_BENCH_FILE=all.mmdb build/<dir>/bench/database_load_bench

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"
#include "mm/offline/database_writer.hpp"

namespace {

constexpr int kFrames = 167423;
constexpr int kJoints = 23;
constexpr int kFramesPerClip = 160;

// Plausible but random: unit rotations, positions within a couple of metres, speeds of a few
// m/s, normalized features around zero.
mm::Database make_synthetic_database() {
  std::mt19937 rng(1234);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  mm::DatabaseContents db;
  std::vector<std::string> names;
  std::vector<int> parents;
  for (int j = 0; j < kJoints; ++j) {
    names.push_back(j == 0 ? "Simulation" : "joint_" + std::to_string(j));
    parents.push_back(j - 1 - (j > 5 ? j % 3 : 0));  // a few branches, always parent-first
  }
  std::vector<mm::Transform> rest(kJoints);
  for (mm::Transform& t : rest) t.translation = {0.1f * normal(rng), 0.1f, 0.0f};
  db.skeleton = mm::Skeleton::create(names, parents, rest).value();
  db.roles.hips = 1;
  db.roles.left_foot = 18;
  db.roles.right_foot = 22;
  db.frame_time = 1.0f / 30.0f;
  db.frame_count = kFrames;
  const size_t samples = size_t{kFrames} * kJoints;
  db.local_positions.resize(samples);
  db.local_rotations.resize(samples);
  db.local_velocities.resize(samples);
  db.local_angular_velocities.resize(samples);
  for (size_t i = 0; i < samples; ++i) {
    const size_t joint = i % kJoints;
    const size_t clip_start = i / kJoints / kFramesPerClip * kFramesPerClip * kJoints;
    db.local_positions[i] = joint < 3 || i < clip_start + kJoints
                                ? glm::vec3(normal(rng), normal(rng), normal(rng))
                                : db.local_positions[clip_start + joint];
    db.local_rotations[i] =
        glm::normalize(glm::quat(normal(rng), normal(rng), normal(rng), normal(rng)));
  }
  // Velocities are not stored in the file (load recomputes them); zeros keep the sizes valid.
  db.contacts.resize(size_t{kFrames} * 2);
  for (uint8_t& c : db.contacts) c = unit(rng) < 0.5f ? 1 : 0;
  db.tag_names = {"walk", "run", "turn", "mirror"};
  for (int start = 0, c = 0; start < kFrames; start += kFramesPerClip, ++c) {
    const int end = std::min(kFrames, start + kFramesPerClip);
    db.clips.push_back({"dataset-2_walk_normal_" + std::to_string(c), start, end,
                        uint64_t{1} << (c % 4), c % 2 == 1});
  }
  db.schema = mm::FeatureSchema::default_schema();
  const int dims = db.schema.dims();
  db.features.resize(size_t{kFrames} * dims);
  for (float& f : db.features) f = normal(rng);
  for (int c = 0; c < dims; ++c) {
    db.feature_offset.push_back(0.1f * normal(rng));
    db.feature_scale.push_back(0.5f + unit(rng));
  }
  db.searchable.resize(kFrames);
  for (uint8_t& s : db.searchable) s = unit(rng) < 0.95f ? 1 : 0;
  return mm::Database::create(db).value();
}

std::filesystem::path g_path;
size_t g_file_size = 0;

std::vector<std::byte> read_whole_file(const std::filesystem::path& path) {
  std::vector<std::byte> bytes(std::filesystem::file_size(path));
  FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return {};
  const size_t n = std::fread(bytes.data(), 1, bytes.size(), file);
  std::fclose(file);
  bytes.resize(n);
  return bytes;
}

// Baseline: the file into memory with one fread, nothing checked.
void BM_ReadFile(benchmark::State& state) {
  for (auto _ : state) {
    std::vector<std::byte> bytes = read_whole_file(g_path);
    benchmark::DoNotOptimize(bytes.data());
    // Freeing is not part of reading (nor of loading, below).
    state.PauseTiming();
    bytes = {};
    state.ResumeTiming();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * g_file_size));
}
BENCHMARK(BM_ReadFile)->Unit(benchmark::kMillisecond)->UseRealTime();

// What a program calls: map, checksum, copy, validate.
void BM_LoadDatabase(benchmark::State& state) {
  for (auto _ : state) {
    mm::Result<mm::Database> db = mm::load_database(g_path);
    if (!db) {
      state.SkipWithError(db.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(db->features().data());
    state.PauseTiming();
    db = mm::Error{"freed"};
    state.ResumeTiming();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * g_file_size));
}
BENCHMARK(BM_LoadDatabase)->Unit(benchmark::kMillisecond)->UseRealTime();

// The parts on their own, from a buffer already in memory.
void BM_Checksum(benchmark::State& state) {
  const std::vector<std::byte> bytes = read_whole_file(g_path);
  for (auto _ : state) benchmark::DoNotOptimize(mm::database_checksum(bytes));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes.size()));
}
BENCHMARK(BM_Checksum)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Validate(benchmark::State& state) {
  const mm::Database db = mm::load_database(g_path).value();
  for (auto _ : state) {
    const mm::Status s = db.validate();
    benchmark::DoNotOptimize(s.ok());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * g_file_size));
}
BENCHMARK(BM_Validate)->Unit(benchmark::kMillisecond)->UseRealTime();

// Prints as usual and keeps each benchmark's time per iteration for the ratio at the end.
class RecordingReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type == Run::RT_Iteration && run.iterations > 0) {
        milliseconds[run.run_name.function_name] =
            run.real_accumulated_time * 1e3 / static_cast<double>(run.iterations);
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> milliseconds;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const char* given = std::getenv("MM_LOAD_BENCH_FILE");
  g_path = given != nullptr && given[0] != '\0'
               ? std::filesystem::path(given)
               : std::filesystem::absolute(argv[0]).parent_path() / "database_load_bench.mmdb";
  if (given == nullptr || given[0] == '\0') {
    const mm::Database db = make_synthetic_database();
    if (mm::Status s = mm::save_database(db, g_path); !s) {
      std::fprintf(stderr, "database_load_bench: %s\n", s.message().c_str());
      return 1;
    }
  }
  g_file_size = std::filesystem::file_size(g_path);
  if (mm::Result<mm::DatabaseFileInfo> info = mm::read_database_header(g_path); info) {
    std::printf("database: %u frames x %u joints x %u features, file %.1f MB (%s)\n",
                info->frame_count, info->joint_count, info->feature_dims, g_file_size / 1e6,
                g_path.c_str());
  }

  RecordingReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto read = reporter.milliseconds.find("BM_ReadFile");
  const auto load = reporter.milliseconds.find("BM_LoadDatabase");
  if (read != reporter.milliseconds.end() && load != reporter.milliseconds.end()) {
    std::printf(
        "load_database: %.1f ms (%.0f MB/s); one fread of the file: %.1f ms (%.0f MB/s); "
        "load / read = %.2fx\n",
        load->second, g_file_size / 1e3 / load->second, read->second,
        g_file_size / 1e3 / read->second, load->second / read->second);
  }
  if (given == nullptr || given[0] == '\0') std::filesystem::remove(g_path);
  benchmark::Shutdown();
  return 0;
}
