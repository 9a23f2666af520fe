// The `mm` command line as scripts use it: exit codes, messages, and files that round-trip.
// Runs the real binary (MM_TOOL_PATH) in a shell and reads its output.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mm/database/database_file.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/gltf.hpp"
#include "run_tool.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

using test::CommandRun;
using test::quoted;
using test::run_mm;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A copy of a few real clips in a scratch folder, plus whatever the test adds.
fs::path folder_with_real_clips(const fs::path& dir) {
  const fs::path in = dir / "in";
  fs::create_directories(in);
  for (const char* stem : {"dataset-2_walk_normal_001", "dataset-2_walk-turn-left_normal_001",
                           "dataset-2_run_normal_001"}) {
    fs::copy_file(test::clip_path(stem), in / (std::string(stem) + ".bvh"));
  }
  return in;
}

TEST(Cli, HelpListsEveryCommandAndEachCommandHasHelp) {
  const CommandRun help = run_mm("--help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* command : {"build", "info", "export", "retarget", "search-bench"}) {
    EXPECT_NE(help.output.find(command), std::string::npos) << command;
    const CommandRun sub = run_mm(std::string(command) + " --help");
    EXPECT_EQ(sub.exit_code, 0) << command;
    EXPECT_NE(sub.output.find(std::string("usage: mm ") + command), std::string::npos)
        << sub.output;
  }
  EXPECT_EQ(run_mm("no-such-command").exit_code, 2);
  EXPECT_EQ(run_mm("build --no-such-option").exit_code, 2);
}

TEST(Cli, BuildWritesALoadableDatabaseAndPrintsItsSummary) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  const fs::path out = dir / "db.mmdb";
  const CommandRun build = run_mm("build " + quoted(in) + " -o " + quoted(out));
  ASSERT_EQ(build.exit_code, 0) << build.output;
  for (const char* field : {"clips:", "frames:", "joints:", "tags:", "features:", "file size:"}) {
    EXPECT_NE(build.output.find(field), std::string::npos) << field << "\n" << build.output;
  }
  // The idle clip (3 s by default) and the frame it holds.
  const size_t idle_line =
      build.output.find("idle:        90 frames (3.0 s), clip 3, holding frame ");
  ASSERT_NE(idle_line, std::string::npos) << build.output;
  EXPECT_NE(build.output.find(" of dataset-2_", idle_line), std::string::npos) << build.output;
  Result<Database> db = load_database(out);
  ASSERT_TRUE(db.ok()) << db.message();
  ASSERT_EQ(db->clips().size(), 4u);
  EXPECT_EQ(db->clips()[3].name, "idle");
  // The frames of the three sources, counted by the importer independently of the builder,
  // and the idle clip's.
  int frames = 0;
  for (const auto& entry : fs::directory_iterator(in))
    frames += load_bvh(entry.path())->frame_count;
  EXPECT_EQ(db->frame_count(), frames + 90);

  const CommandRun info = run_mm("info " + quoted(out));
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("left_foot_position"), std::string::npos) << info.output;
}

TEST(Cli, BuildRefusesABadFileNamingItAndSkipBadBuildsFromTheRest) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  // The file ends inside line 4, in the middle of an OFFSET.
  write_text(in / "broken.bvh", "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0");
  const fs::path out = dir / "db.mmdb";

  const CommandRun strict = run_mm("build " + quoted(in) + " -o " + quoted(out) + " --quiet");
  EXPECT_EQ(strict.exit_code, 1);
  EXPECT_NE(strict.output.find("broken.bvh:4: expected"), std::string::npos) << strict.output;
  EXPECT_FALSE(fs::exists(out));

  const CommandRun skip =
      run_mm("build " + quoted(in) + " -o " + quoted(out) + " --skip-bad --idle 0");
  EXPECT_EQ(skip.exit_code, 0) << skip.output;
  EXPECT_NE(skip.output.find("refused 1"), std::string::npos) << skip.output;
  EXPECT_NE(skip.output.find("broken.bvh"), std::string::npos) << skip.output;
  Result<Database> db = load_database(out);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->clips().size(), 3u);
}

TEST(Cli, IdleLengthIsAnOptionAndInfoShowsTheIdleClip) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  const fs::path out = dir / "db.mmdb";
  EXPECT_NE(run_mm("build --help").output.find("--idle SECONDS"), std::string::npos);

  const CommandRun none = run_mm("build " + quoted(in) + " -o " + quoted(out) + " --idle 0");
  ASSERT_EQ(none.exit_code, 0) << none.output;
  EXPECT_NE(none.output.find("idle:        none"), std::string::npos) << none.output;
  Result<Database> db = load_database(out);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->clips().size(), 3u);

  const CommandRun two = run_mm("build " + quoted(in) + " -o " + quoted(out) + " --idle 2");
  ASSERT_EQ(two.exit_code, 0) << two.output;
  EXPECT_NE(two.output.find("idle:        60 frames (2.0 s), clip 3, holding frame "),
            std::string::npos)
      << two.output;
  const CommandRun info = run_mm("info " + quoted(out) + " --clips");
  EXPECT_EQ(info.exit_code, 0) << info.output;
  // The summary line (without the source frame, which the file does not record), the tag with
  // its counts, and the clip in the list with its tag.
  EXPECT_NE(info.output.find("idle:        60 frames (2.0 s), clip 3\n"), std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("  idle                         1 clips       60 frames"),
            std::string::npos)
      << info.output;
  EXPECT_NE(info.output.find("     3      60 frames  idle"), std::string::npos) << info.output;

  for (const char* bad : {"-1", "61", "nan", "abc"}) {
    const CommandRun run =
        run_mm("build " + quoted(in) + " -o " + quoted(dir / "bad.mmdb") + " --idle " + bad);
    EXPECT_EQ(run.exit_code, 2) << bad << "\n" << run.output;
    const std::string number = bad;
    const std::string message = number == "-1" || number == "61"
                                    ? "--idle: " + number + " is outside [0, 60]"
                                    : "--idle: '" + number + "' is not a finite number";
    EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
  }
  // In range but too short for a searchable frame: the builder's message.
  const CommandRun short_idle =
      run_mm("build " + quoted(in) + " -o " + quoted(dir / "short.mmdb") + " --idle 0.5");
  EXPECT_EQ(short_idle.exit_code, 1) << short_idle.output;
  EXPECT_NE(short_idle.output.find("at least 31 frames"), std::string::npos) << short_idle.output;
  EXPECT_FALSE(fs::exists(dir / "short.mmdb"));
}

TEST(Cli, ContactThresholdsAreConfigurable) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  auto contact_frames = [](const fs::path& file) {
    Result<Database> db = load_database(file);
    EXPECT_TRUE(db.ok()) << db.message();
    int n = 0;
    for (uint8_t c : db->contacts()) n += c;
    return n;
  };
  ASSERT_EQ(run_mm("build " + quoted(in) + " -o " + quoted(dir / "a.mmdb") + " --quiet").exit_code,
            0);
  // No joint is ever below the ground, so zero heights leave no contact at all.
  ASSERT_EQ(run_mm("build " + quoted(in) + " -o " + quoted(dir / "b.mmdb") +
                   " --quiet --contact-height 0 --contact-toe-height 0")
                .exit_code,
            0);
  EXPECT_GT(contact_frames(dir / "a.mmdb"), 0);
  EXPECT_EQ(contact_frames(dir / "b.mmdb"), 0);
  EXPECT_EQ(run_mm("build " + quoted(in) + " -o x.mmdb --contact-speed -1").exit_code, 2);
}

TEST(Cli, InfoRefusesATruncatedDatabase) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  const fs::path out = dir / "db.mmdb";
  ASSERT_EQ(run_mm("build " + quoted(in) + " -o " + quoted(out) + " --quiet").exit_code, 0);
  fs::resize_file(out, fs::file_size(out) / 2);
  const CommandRun info = run_mm("info " + quoted(out));
  EXPECT_EQ(info.exit_code, 1);
  EXPECT_NE(info.output.find("truncated"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("db.mmdb"), std::string::npos) << info.output;
}

TEST(Cli, ExportWritesAGlbThatImportsWithTheClipsFramesAndJoints) {
  const fs::path dir = test::scratch_dir();
  const fs::path source = test::clip_path("dataset-2_walk_normal_001");
  const fs::path out = dir / "walk.glb";
  const CommandRun run = run_mm("export " + quoted(source) + " -o " + quoted(out));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  Result<Clip> original = load_bvh(source);
  Result<GltfAsset> asset = load_gltf(out);
  ASSERT_TRUE(original.ok() && asset.ok()) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  EXPECT_EQ(asset->clips[0].frame_count, original->frame_count);
  EXPECT_TRUE(asset->skeleton.same_topology(original->skeleton));

  EXPECT_EQ(run_mm("export " + quoted(source)).exit_code, 2);  // no -o
  EXPECT_EQ(run_mm("export " + quoted(dir / "missing.bvh") + " -o " + quoted(out)).exit_code, 1);
}

// A file with more frame lines than it declares (Debian's assimp-testmodels, installed by
// scripts/setup.sh): `mm build` and `mm export` read its declared frames and say so once.
TEST(Cli, BuildAndExportPrintAFilesImportWarningOnce) {
  const fs::path source = "/usr/share/assimp/models/BVH/Boxing_Toes.bvh";
  ASSERT_TRUE(fs::is_regular_file(source))
      << source << " is missing: install Debian's assimp-testmodels (scripts/setup.sh)";
  const std::string warning =
      source.string() + ":3199: ignored 1 frame line beyond 'Frames: 3069' on line 128\n";
  const auto count = [](const std::string& text, const std::string& part) {
    size_t n = 0;
    for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
    return n;
  };
  const fs::path dir = test::scratch_dir();
  const CommandRun build =
      run_mm("build " + quoted(source) + " --quiet -o " + quoted(dir / "boxing.mmdb"));
  ASSERT_EQ(build.exit_code, 0) << build.output;
  EXPECT_EQ(count(build.output, "mm build: warning: " + warning), 1u) << build.output;
  EXPECT_EQ(count(build.output, "ignored"), 1u) << build.output;

  const CommandRun run = run_mm("export " + quoted(source) + " -o " + quoted(dir / "boxing.glb"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(count(run.output, "mm export: warning: " + warning), 1u) << run.output;
  EXPECT_EQ(count(run.output, "ignored"), 1u) << run.output;
  GltfImportOptions at_100_hz;  // the file's own rate
  at_100_hz.sample_rate = 100.0f;
  Result<GltfAsset> asset = load_gltf(dir / "boxing.glb", at_100_hz);
  ASSERT_TRUE(asset) << asset.message();
  ASSERT_EQ(asset->clips.size(), 1u);
  EXPECT_EQ(asset->clips[0].frame_count, 3069);
}

// `mm export --body`: the database clip with the generated body, reloadable as a skinned mesh
// over every joint; the weight method is chosen by name; a BVH input or an unknown method is
// a usage error.
TEST(Cli, ExportBodyWritesASkinnedCharacterWithTheClip) {
  const fs::path dir = test::scratch_dir();
  const fs::path db = dir / "db.mmdb";
  const CommandRun build =
      run_mm("build " + quoted(folder_with_real_clips(dir)) + " -o " + quoted(db));
  ASSERT_EQ(build.exit_code, 0) << build.output;
  const fs::path out = dir / "walk_body.glb";
  const CommandRun run =
      run_mm("export " + quoted(db) + " --clip dataset-2_walk_normal_001 --body " +
             "--weights distance -o " + quoted(out));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("distance weights"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("with the body"), std::string::npos) << run.output;
  GltfImportOptions options;
  options.read_skinned_mesh = true;
  Result<GltfAsset> asset = load_gltf(out, options);
  ASSERT_TRUE(asset.ok()) << asset.message();
  ASSERT_TRUE(asset->skinned_mesh.has_value());
  EXPECT_GT(asset->skinned_mesh->mesh.vertex_count(), 5000u);
  EXPECT_EQ(asset->skinned_mesh->bind_global.size(),
            static_cast<size_t>(asset->skeleton.joint_count()));
  ASSERT_EQ(asset->clips.size(), 1u);
  EXPECT_EQ(asset->clips[0].name, "dataset-2_walk_normal_001");

  const CommandRun help = run_mm("export --help");
  EXPECT_NE(help.output.find("--body"), std::string::npos);
  EXPECT_NE(help.output.find("--weights METHOD"), std::string::npos);
  const CommandRun bad_method =
      run_mm("export " + quoted(db) + " --body --weights magic -o " + quoted(out));
  EXPECT_EQ(bad_method.exit_code, 2);
  EXPECT_NE(bad_method.output.find("--weights: magic not in {distance,envelope,heat,geodesic}"),
            std::string::npos)
      << bad_method.output;
  const CommandRun bvh = run_mm("export " + quoted(test::clip_path("dataset-2_walk_normal_001")) +
                                " --body -o " + quoted(out));
  EXPECT_EQ(bvh.exit_code, 2);
  EXPECT_NE(bvh.output.find("--body needs a database (.mmdb)"), std::string::npos) << bvh.output;
}

// search-bench on generated data: every method and the FLANN reference in the JSON with the
// documented fields; the exact methods match brute on every query; the reference row only
// when nothing plays (it cannot apply the rules).
TEST(Cli, SearchBenchJsonHoldsEveryMethodWithItsFields) {
  const fs::path dir = test::scratch_dir();
  for (bool playing : {false, true}) {
    const fs::path json_path = dir / (playing ? "playing.json" : "plain.json");
    // A tenth of the default synthetic data: every method's structure is built for it.
    const CommandRun run =
        run_mm(std::string("search-bench --synthetic --synthetic-clips 60 --queries 300 --quiet ") +
               (playing ? "--playing " : "") + "--json " + quoted(json_path));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::ifstream file(json_path);
    const nlohmann::json json = nlohmann::json::parse(file, nullptr, /*allow_exceptions=*/false);
    ASSERT_FALSE(json.is_discarded()) << json_path;
    EXPECT_EQ(json["run"]["database"], "synthetic (60 clips)");
    for (const char* method :
         {"brute", "brute-simd", "aabb", "kdtree", "boxtree", "approx", "kdtree-eps"}) {
      ASSERT_TRUE(json.contains(method)) << method;
      const nlohmann::json& m = json[method];
      for (const char* field :
           {"build_ms", "memory_bytes", "median_us", "p99_us", "exact_match_rate", "cost_ratio"}) {
        ASSERT_TRUE(m.contains(field) && m[field].is_number()) << method << " " << field;
      }
      EXPECT_GT(m["memory_bytes"].get<double>(), 0) << method;
      EXPECT_GT(m["median_us"].get<double>(), 0) << method;
      EXPECT_LE(m["median_us"].get<double>(), m["p99_us"].get<double>()) << method;
      EXPECT_GE(m["cost_ratio"].get<double>(), 1.0 - 1e-6) << method;
      const std::string name = method;
      if (name != "approx" && name != "kdtree-eps") {
        EXPECT_EQ(m["exact_match_rate"].get<double>(), 1.0) << method;
      }
    }
    EXPECT_EQ(json.contains("flann-plain"), !playing);
    if (!playing) {
      EXPECT_EQ(json["flann-plain"]["exact_match_rate"].get<double>(), 1.0);
    }
    // The neighbourhood shares: percentiles in order, the wider factor holding at least as many
    // rows, and never less than the nearest row itself.
    const double candidates = json["run"]["candidates"].get<double>();
    const nlohmann::json& near = json["run"]["share_within_1.2x_nearest"];
    const nlohmann::json& wide = json["run"]["share_within_1.5x_nearest"];
    for (const char* stat : {"median", "p90", "p99"}) {
      ASSERT_TRUE(near.contains(stat) && wide.contains(stat)) << stat;
      EXPECT_GE(near[stat].get<double>(), 1.0 / candidates - 1e-12) << stat;
      EXPECT_GE(wide[stat].get<double>(), near[stat].get<double>()) << stat;
      EXPECT_LE(wide[stat].get<double>(), 1.0) << stat;
    }
    EXPECT_LE(near["median"].get<double>(), near["p90"].get<double>());
    EXPECT_LE(near["p90"].get<double>(), near["p99"].get<double>());
  }
}

// Without noise every query is a searchable row, which is its own nearest row at distance 0; on
// the synthetic data no other row coincides with it, so exactly one candidate is within any
// factor of the nearest distance.
TEST(Cli, SearchBenchNeighbourhoodOfExactRowsIsTheRowItself) {
  const fs::path json_path = test::scratch_dir() / "noiseless.json";
  const CommandRun run = run_mm(
      "search-bench --synthetic --synthetic-clips 60 --queries 100 --noise 0 --quiet "
      "--methods brute,brute-simd --no-flann-reference --json " +
      quoted(json_path));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream file(json_path);
  const nlohmann::json json = nlohmann::json::parse(file, nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(json.is_discarded()) << json_path;
  const double one_row = 1.0 / json["run"]["candidates"].get<double>();
  EXPECT_DOUBLE_EQ(json["run"]["share_within_1.5x_nearest"]["p99"].get<double>(), one_row);
  EXPECT_DOUBLE_EQ(json["run"]["share_within_1.2x_nearest"]["median"].get<double>(), one_row);
}

// search-bench parses integers as integers: a fractional query count is a usage error that
// names the option and the value; a count out of range is refused the same way.
TEST(Cli, SearchBenchRefusesAFractionalQueryCount) {
  const CommandRun run = run_mm("search-bench --synthetic --queries 1.5");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--queries"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("'1.5' is not an integer"), std::string::npos) << run.output;
  const CommandRun none = run_mm("search-bench --synthetic --synthetic-clips 0");
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_NE(none.output.find("--synthetic-clips"), std::string::npos) << none.output;
}

// Every command's --help exits 0, starts with its usage line and lists the options it declares
// (search-bench's own list is its converter's to check; here only its main options).
TEST(Cli, EveryCommandsHelpListsItsOptions) {
  const std::pair<const char*, std::vector<const char*>> commands[] = {
      {"build",
       {"-o,--output", "--rate", "--mirror", "--idle", "--tags", "--skip-bad", "--threads",
        "--scale", "--role", "--mirror-pair", "--forward-axis", "--contact-height",
        "--contact-toe-height", "--contact-speed", "--quiet", "--target", "--target-map"}},
      {"info", {"--clips"}},
      {"export", {"-o,--output", "--clip", "--scale", "--body", "--weights", "--voxel"}},
      {"retarget",
       {"--to", "-o,--output", "--map", "--target-map", "--rest-frame", "--rate", "--clip"}},
      {"eval", {"--db", "--script", "--dt", "--ik", "--set", "--json", "--dump"}},
      {"crowd-bench",
       {"--db", "--characters", "--seconds", "--threads", "--set", "--budget-ms", "--tier-costs-us",
        "--json"}},
      {"search-bench", {"--db", "--queries"}},
  };
  for (const auto& [command, options] : commands) {
    const CommandRun help = run_mm(std::string(command) + " --help");
    EXPECT_EQ(help.exit_code, 0) << command;
    EXPECT_EQ(help.output.rfind(std::string("usage: mm ") + command, 0), 0u) << help.output;
    for (const char* option : options) {
      EXPECT_NE(help.output.find(std::string("  ") + option + " "), std::string::npos)
          << command << " " << option << "\n"
          << help.output;
    }
  }
  // The choices and ranges show in the help.
  EXPECT_NE(run_mm("eval --help").output.find("--ik {on,off}"), std::string::npos);
  EXPECT_NE(run_mm("build --help").output.find("--threads N in [0, 256]"), std::string::npos);
  // `mm` alone and an unknown command are usage errors; `mm --help` lists every command with
  // its summary.
  EXPECT_EQ(run_mm("").exit_code, 2);
  EXPECT_EQ(run_mm("no-such-command").exit_code, 2);
  const CommandRun help = run_mm("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("crowd-bench    many controllers at 60 Hz"), std::string::npos)
      << help.output;
}

// An integer option given a fraction is a usage error naming the option, before any file is
// read (the database path does not exist).
TEST(Cli, IntegerOptionsRefuseFractions) {
  for (const std::string& arguments :
       {std::string("build in -o out.mmdb --threads 1.5"),
        std::string("crowd-bench --db none.mmdb --seconds 1 --characters 1.5"),
        std::string("crowd-bench --db none.mmdb --seconds 1 --characters 4 --threads 1.5")}) {
    const CommandRun run = run_mm(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    const std::string option =
        arguments.find("--threads") != std::string::npos ? "--threads" : "--characters";
    EXPECT_NE(run.output.find(option + ": '1.5' is not an integer"), std::string::npos)
        << run.output;
  }
  const CommandRun range = run_mm("crowd-bench --db none.mmdb --seconds 1 --characters 0");
  EXPECT_EQ(range.exit_code, 2);
  EXPECT_NE(range.output.find("--characters: 0 is outside [1, 100000]"), std::string::npos)
      << range.output;
}

// A real-valued option given NaN, infinity or a value outside its range is a usage error
// naming the option.
TEST(Cli, NumberOptionsRefuseNanInfinityAndOutOfRange) {
  const std::pair<std::string, std::string> cases[] = {
      {"build in -o out.mmdb --rate nan", "--rate: 'nan' is not a finite number"},
      {"build in -o out.mmdb --scale 0", "--scale: 0 is outside (0, 1000]"},
      {"export in.bvh -o out.glb --voxel inf", "--voxel: 'inf' is not a finite number"},
      {"eval --db none.mmdb --script none.txt --dt nan", "--dt: 'nan' is not a finite number"},
      {"crowd-bench --db none.mmdb --characters 2 --seconds nan",
       "--seconds: 'nan' is not a finite number"},
      {"crowd-bench --db none.mmdb --characters 2 --seconds 1 --budget-ms 0",
       "--budget-ms: 0 is outside (0, 1000]"},
  };
  for (const auto& [arguments, message] : cases) {
    const CommandRun run = run_mm(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
  }
}

// A missing required option or argument is a usage error naming it; so are a bad choice and a
// second positional argument.
TEST(Cli, MissingRequiredOptionsAndBadChoicesAreUsageErrors) {
  const std::pair<std::string, std::string> cases[] = {
      {"build in", "--output is required"},
      {"build -o out.mmdb", "inputs is required"},
      {"info", "file is required"},
      {"info a.mmdb b.mmdb", "not expected: b.mmdb"},
      {"export in.bvh", "--output is required"},
      {"eval --script none.txt", "--db is required"},
      {"eval --db none.mmdb", "--script is required"},
      {"eval --db none.mmdb --script none.txt --ik maybe", "--ik: maybe not in {on,off}"},
      {"eval --db none.mmdb --script none.txt --set halflife", "--set: 'halflife' is not "},
      {"crowd-bench --db none.mmdb --characters 2", "--seconds is required"},
      {"build in -o out.mmdb --role knee=Knee", "unknown role 'knee'"},
  };
  for (const auto& [arguments, message] : cases) {
    const CommandRun run = run_mm(arguments);
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << arguments << "\n" << run.output;
  }
  // Repeatable options take one value each time: two scripts, then a run-time failure (the
  // database does not exist), not a usage error.
  const CommandRun two_scripts =
      run_mm("eval --db none.mmdb --script a.txt --script b.txt --set sync_mode=none");
  EXPECT_EQ(two_scripts.exit_code, 1) << two_scripts.output;
  EXPECT_NE(two_scripts.output.find("none.mmdb"), std::string::npos) << two_scripts.output;
}

// An option given twice keeps its last value (scripts append overrides), as before CLI11.
TEST(Cli, AnOptionGivenTwiceKeepsItsLastValue) {
  const fs::path dir = test::scratch_dir();
  const fs::path in = folder_with_real_clips(dir);
  const CommandRun run =
      run_mm("build " + quoted(in) + " -o " + quoted(dir / "db.mmdb") + " --idle 2 --idle 0");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("idle:        none"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace mm
