// BVH import throughput on the real clips, file contents cached in memory.
//
//   build/<dir>/bench/bvh_bench [--benchmark_min_time=0.2]
//
// Compares, on the same bytes in the same run:
// - parse_bvh: the importer (target: 600+ MB/s on one core);
// - load_bvh: the importer plus reading each file (from the OS page cache);
// - iostream baseline: a naive tokenizer (std::istringstream >> std::string, strtod per
//   value) building the same transforms, i.e. what a straightforward importer does;
// - from_chars scan: only splitting the text at whitespace and running std::from_chars on
//   every token, no structure or transforms: roughly the ceiling for a from_chars parser.
// Then prints parse_bvh's speed as a ratio against each of them. Rates use CPU time (the target
// is per core, and the machine may be shared); with --benchmark_repetitions=N the summary takes
// each benchmark's best repetition. The data folder is $MM_DATA, else
// MM_SHARED_DIR/mocap/bandai-normal.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "mm/database/files.hpp"
#include "mm/offline/bvh.hpp"

namespace {

struct BvhFile {
  std::filesystem::path path;
  std::string text;
};

std::filesystem::path data_dir() {
  if (const char* env = std::getenv("MM_DATA"); env && *env) return env;
  return std::filesystem::path(MM_SHARED_DIR) / "mocap" / "bandai-normal";
}

const std::vector<BvhFile>& files() {
  static const std::vector<BvhFile> loaded = [] {
    std::vector<BvhFile> out;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(data_dir(), error)) {
      if (!mm::has_extension(entry.path(), {".bvh"})) continue;
      if (auto contents = mm::read_whole_file(entry.path())) {
        out.push_back({entry.path(), std::string(contents->text())});
      }
    }
    std::sort(out.begin(), out.end(),
              [](const BvhFile& a, const BvhFile& b) { return a.path < b.path; });
    return out;
  }();
  return loaded;
}

int64_t total_bytes() {
  int64_t bytes = 0;
  for (const BvhFile& f : files()) bytes += static_cast<int64_t>(f.text.size());
  return bytes;
}

void BM_ParseBvh(benchmark::State& state) {
  if (files().empty()) {
    state.SkipWithError("no .bvh files in the data folder (set MM_DATA)");
    return;
  }
  for (auto _ : state) {
    for (const BvhFile& f : files()) {
      mm::Result<mm::Clip> clip = mm::parse_bvh(f.text, f.path.native());
      if (!clip) {
        state.SkipWithError(clip.message().c_str());
        return;
      }
      benchmark::DoNotOptimize(clip->local.data());
    }
  }
  state.SetBytesProcessed(state.iterations() * total_bytes());
  state.counters["files"] = static_cast<double>(files().size());
}
BENCHMARK(BM_ParseBvh)->Unit(benchmark::kMillisecond);

void BM_LoadBvh(benchmark::State& state) {
  for (auto _ : state) {
    for (const BvhFile& f : files()) {
      mm::Result<mm::Clip> clip = mm::load_bvh(f.path);
      if (!clip) {
        state.SkipWithError(clip.message().c_str());
        return;
      }
      benchmark::DoNotOptimize(clip->local.data());
    }
  }
  state.SetBytesProcessed(state.iterations() * total_bytes());
}
BENCHMARK(BM_LoadBvh)->Unit(benchmark::kMillisecond);

// The baseline: the obvious iostream importer. Returns the number of transforms built.
size_t baseline_iostream_parse(const std::string& text, std::vector<mm::Transform>& local) {
  struct Joint {
    glm::vec3 offset{0.0f};
    std::vector<std::string> channels;
  };
  std::istringstream in(text);
  std::vector<Joint> joints;
  std::string token;
  int depth = 0;
  bool in_end_site = false;
  while (in >> token && token != "MOTION") {
    if (token == "ROOT" || token == "JOINT") {
      in >> token;
      joints.emplace_back();
    } else if (token == "End") {
      in >> token;
      in_end_site = true;
    } else if (token == "{") {
      ++depth;
    } else if (token == "}") {
      --depth;
      in_end_site = false;
    } else if (token == "OFFSET") {
      glm::vec3 offset;
      for (int a = 0; a < 3; ++a) {
        in >> token;
        offset[a] = static_cast<float>(std::strtod(token.c_str(), nullptr)) * 0.01f;
      }
      if (!in_end_site) joints.back().offset = offset;
    } else if (token == "CHANNELS") {
      int count = 0;
      in >> count;
      for (int c = 0; c < count; ++c) {
        in >> token;
        joints.back().channels.push_back(token);
      }
    }
  }
  int frames = 0;
  in >> token >> frames >> token >> token >> token;  // Frames: N Frame Time: T
  local.clear();
  for (int f = 0; f < frames; ++f) {
    for (const Joint& joint : joints) {
      mm::Transform t;
      t.translation = joint.offset;
      for (const std::string& channel : joint.channels) {
        in >> token;
        const float value = static_cast<float>(std::strtod(token.c_str(), nullptr));
        const int axis = channel[0] - 'X';
        if (channel.find("position") != std::string::npos) {
          t.translation[axis] = value * 0.01f;
        } else {
          glm::vec3 unit(0.0f);
          unit[axis] = 1.0f;
          t.rotation = t.rotation * glm::angleAxis(glm::radians(value), unit);
        }
      }
      local.push_back(t);
    }
  }
  return local.size();
}

void BM_BaselineIostream(benchmark::State& state) {
  std::vector<mm::Transform> local;
  for (auto _ : state) {
    for (const BvhFile& f : files()) {
      benchmark::DoNotOptimize(baseline_iostream_parse(f.text, local));
    }
  }
  state.SetBytesProcessed(state.iterations() * total_bytes());
}
BENCHMARK(BM_BaselineIostream)->Unit(benchmark::kMillisecond)->Iterations(1);

// Whitespace split plus from_chars on every token: no structure, no transforms.
void BM_FromCharsScan(benchmark::State& state) {
  for (auto _ : state) {
    double sum = 0.0;
    for (const BvhFile& f : files()) {
      const char* p = f.text.data();
      const char* end = p + f.text.size();
      while (p < end) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
        const char* start = p;
        while (p < end && !(*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
        float value = 0.0f;
        if (std::from_chars(start, p, value).ec == std::errc()) sum += value;
      }
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * total_bytes());
}
BENCHMARK(BM_FromCharsScan)->Unit(benchmark::kMillisecond);

// Keeps each benchmark's best bytes per second (over repetitions, ignoring the mean/median/cv
// rows) so main() can print ratios after the run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.error_occurred || run.run_type == Run::RT_Aggregate) continue;
      auto it = run.counters.find("bytes_per_second");
      if (it == run.counters.end()) continue;
      double& best = bytes_per_second[run.run_name.function_name];
      best = std::max(best, it->second.value);
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> bytes_per_second;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::printf("data: %s (%zu files, %.1f MB)\n", data_dir().c_str(), files().size(),
              static_cast<double>(total_bytes()) / 1e6);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto& rates = reporter.bytes_per_second;
  const auto find = [&](const char* name) {
    auto it = rates.find(name);
    return it == rates.end() ? 0.0 : it->second;
  };
  const double parse = find("BM_ParseBvh");
  if (parse > 0.0) {
    std::printf("\nparse_bvh: %.0f MB/s per core, CPU time (target 600 MB/s)\n", parse / 1e6);
    const char* baselines[] = {"BM_LoadBvh", "BM_BaselineIostream", "BM_FromCharsScan"};
    for (const char* name : baselines) {
      const double other = find(name);
      if (other > 0.0) {
        std::printf("parse_bvh vs %-20s %.0f MB/s  ratio %.2fx\n", name, other / 1e6,
                    parse / other);
      }
    }
  }
  benchmark::Shutdown();
  return 0;
}
