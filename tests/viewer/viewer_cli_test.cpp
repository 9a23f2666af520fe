// mm-viewer run as a program: headless (EGL) and windowed under Xvfb, on a short script of the
// real data, and its images checked: sky, a ground grid and the character where the viewer
// says it drew it.

#include <gtest/gtest.h>
#include <stb_image.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <sys/wait.h>

#include "mm/controller/script.hpp"
#include "mm/database/database_file.hpp"
#include "mm/offline/database_writer.hpp"
#include "normal_database.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

namespace fs = std::filesystem;

struct ProgramRun {
  int exit_code = -1;
  std::string output;
};

// Runs a shell command line; Mesa leaks a little at exit, which is not ours to report.
ProgramRun run(const std::string& command_line) {
  static const std::string asan_options = [] {
    const char* given = std::getenv("ASAN_OPTIONS");
    return std::string(given && *given ? given : "") + (given && *given ? ":" : "") +
           "detect_leaks=0";
  }();
  setenv("ASAN_OPTIONS", asan_options.c_str(), 1);
  ProgramRun r;
  FILE* pipe = popen((command_line + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string viewer() {
  return std::string("'") + MM_VIEWER_PATH + "'";
}

std::string script(const std::string& name) {
  return std::string(MM_SOURCE_DIR) + "/scripts/input/" + name;
}

// The Bandai normal database: the file of ctest's setup test, or built once per test program
// into the build tree when the program runs by hand.
const fs::path& database_file() {
  static const fs::path path = [] {
    if (const fs::path file = test::normal_database_file(); !file.empty()) return file;
    const fs::path out = test::scratch_dir() / "normal.mmdb";
    Result<Database> db = test::build_normal_database();
    EXPECT_TRUE(db.ok()) << (db.ok() ? "" : db.message());
    if (db.ok()) {
      EXPECT_TRUE(save_database(*db, out).ok());
    }
    return out;
  }();
  return path;
}

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  glm::ivec3 at(int x, int y) const {
    const unsigned char* p = rgb.data() + (static_cast<size_t>(y) * width + x) * 3;
    return {p[0], p[1], p[2]};
  }
};

Image load_png(const fs::path& path) {
  Image image;
  int channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  if (!data) return image;
  image.rgb.assign(data, data + static_cast<size_t>(image.width) * image.height * 3);
  stbi_image_free(data);
  return image;
}

struct Box {
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};

// The viewer prints where it drew the character: "pixels x A..B, y C..D". (Read with sscanf:
// std::regex trips GCC 12's -Wmaybe-uninitialized in the sanitizer build.)
bool parse_box(const std::string& output, Box& box) {
  const size_t at = output.find("pixels x ");
  if (at == std::string::npos) return false;
  return std::sscanf(output.c_str() + at, "pixels x %d..%d, y %d..%d", &box.x0, &box.x1, &box.y0,
                     &box.y1) == 4;
}

bool near(const glm::ivec3& a, const glm::ivec3& b, int tolerance) {
  return std::abs(a.x - b.x) <= tolerance && std::abs(a.y - b.y) <= tolerance &&
         std::abs(a.z - b.z) <= tolerance;
}

// The checks of an image of the scene: the top rows are sky, the bottom rows ground crossed
// by grid lines (two clearly different greys), and the character's box is mostly neither.
void expect_scene(const Image& image, const Box& box) {
  ASSERT_GT(image.width, 0) << "no image";
  const glm::ivec3 sky = image.at(image.width - 1, 0);
  EXPECT_GT(sky.z, sky.x) << "the sky is bluish";
  int sky_pixels = 0;
  for (int x = 0; x < image.width; ++x) sky_pixels += near(image.at(x, 2), sky, 6);
  EXPECT_GT(sky_pixels, image.width * 9 / 10) << "the top row is sky";

  // Ground: the bottom row away from the character holds the plane's grey and darker lines.
  const int y = image.height - 2;
  int light = 0, dark = 0;
  for (int x = 0; x < image.width; ++x) {
    const glm::ivec3 c = image.at(x, y);
    const int grey = (c.x + c.y + c.z) / 3;
    if (!near(c, glm::ivec3(grey), 8) || grey <= 100) continue;
    (grey > 145 ? light : dark) += 1;
  }
  EXPECT_GT(light, image.width / 2) << "ground plane";
  EXPECT_GT(dark, 3) << "grid lines";

  ASSERT_GE(box.x0, 0);
  ASSERT_LT(box.x1, image.width);
  ASSERT_GE(box.y0, 0);
  ASSERT_LT(box.y1, image.height);
  EXPECT_GT((box.x1 - box.x0) * (box.y1 - box.y0), 500) << "the character is not a speck";
  // Pixels of the character's box that are neither sky nor grey ground: the body's colour.
  int body = 0, total = 0;
  for (int py = box.y0; py <= box.y1; ++py) {
    for (int px = box.x0; px <= box.x1; ++px) {
      const glm::ivec3 c = image.at(px, py);
      ++total;
      // Warm (red over green over blue), unlike the bluish sky, the grey ground and its pure
      // red and blue axis lines.
      body += c.x > c.z + 10 && c.x >= c.y && c.y >= c.z && c.x - c.y < 40;
    }
  }
  EXPECT_GT(body, total / 6) << body << " body pixels of " << total;
}

// A run that succeeded and wrote a screenshot of the given size showing the scene, with the
// character inside the box the viewer printed.
void expect_screenshot_of_the_scene(const ProgramRun& r, const fs::path& png, int width,
                                    int height) {
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Box box;
  ASSERT_TRUE(parse_box(r.output, box)) << r.output;
  const Image image = load_png(png);
  EXPECT_EQ(image.width, width);
  EXPECT_EQ(image.height, height);
  expect_scene(image, box);
}

TEST(ViewerCli, HeadlessScreenshotShowsSkyGroundGridAndTheCharacter) {
  const fs::path dir = test::scratch_dir();
  const ProgramRun r =
      run(viewer() + " --db '" + database_file().string() + "' --headless --script '" +
          script("circle.txt") + "' --frames 120 --size 640x360 --no-panel --debug none" +
          " --screenshot '" + (dir / "shot.png").string() + "'");
  expect_screenshot_of_the_scene(r, dir / "shot.png", 640, 360);
}

TEST(ViewerCli, WindowedUnderXvfbShowsTheSameScene) {
  const fs::path dir = test::scratch_dir();
  const ProgramRun r = run("xvfb-run -a -s '-screen 0 1024x768x24' " + viewer() + " --db '" +
                           database_file().string() + "' --script '" + script("zigzag.txt") +
                           "' --frames 90 --dt 0.0166667 --size 800x450 --no-panel --debug none" +
                           " --screenshot '" + (dir / "window.png").string() + "'");
  expect_screenshot_of_the_scene(r, dir / "window.png", 800, 450);
}

TEST(ViewerCli, EveryWritesNumberedScreenshotsAndThePlot) {
  const fs::path dir = test::scratch_dir();
  const ProgramRun r = run(
      viewer() + " --db '" + database_file().string() + "' --headless --script '" +
      script("stop-and-go.txt") + "' --frames 60 --every 25 --size 320x180" + " --screenshot '" +
      (dir / "s.png").string() + "' --plot '" + (dir / "plot.png").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "s-000025.png"));
  EXPECT_TRUE(fs::exists(dir / "s-000050.png"));
  EXPECT_TRUE(fs::exists(dir / "s.png"));
  EXPECT_FALSE(fs::exists(dir / "s-000060.png")) << "the last frame is s.png itself";
  EXPECT_EQ(load_png(dir / "s-000025.png").width, 320);
  EXPECT_GT(load_png(dir / "plot.png").width, 0);
}

// The crowd headless: numbered screenshots without --script, every tier the budget plans, and
// the tiers' colours on the screen when asked for.
TEST(ViewerCli, HeadlessCrowdDrawsEveryCharacterInItsTiersColour) {
  const fs::path dir = test::scratch_dir();
  const ProgramRun r =
      run(viewer() + " --db '" + database_file().string() +
          "' --headless --crowd 60 --budget-ms 0.2 --tier-colours --frames 40 --every 20" +
          " --size 480x270 --no-panel --screenshot '" + (dir / "crowd.png").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "crowd-000020.png"));
  EXPECT_FALSE(fs::exists(dir / "crowd-000040.png")) << "the last frame is crowd.png itself";
  int full = -1, half = -1, quarter = -1, move_only = -1;
  const size_t at = r.output.find("tiers:");
  ASSERT_NE(at, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at, "tiers: full %d, half %d, quarter %d, move_only %d",
                        &full, &half, &quarter, &move_only),
            4)
      << r.output;
  EXPECT_EQ(full + half + quarter + move_only, 60) << r.output;
  // 0.2 ms holds neither every character at full rate nor at half: some at full, the rest lower.
  EXPECT_GT(full, 0) << r.output;
  EXPECT_GT(quarter + move_only, 0) << r.output;
  const Image image = load_png(dir / "crowd.png");
  ASSERT_EQ(image.width, 480);
  int green = 0, warm = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const glm::ivec3 c = image.at(x, y);
      green += c.y > c.x + 40 && c.y > c.z + 40;  // full rate
      warm += c.x > c.z + 60 && c.y > c.z + 20;   // quarter rate (yellow)
    }
  }
  EXPECT_GT(green, 50) << "characters at full rate drawn green";
  if (quarter > 0) {
    EXPECT_GT(warm, 50) << "characters at quarter rate drawn yellow";
  }
}

TEST(ViewerCli, RecordsLiveInputAsAScriptThatParses) {
  const fs::path dir = test::scratch_dir();
  const fs::path recorded = dir / "recorded.txt";
  const ProgramRun r =
      run("xvfb-run -a " + viewer() + " --db '" + database_file().string() +
          "' --frames 20 --dt 0.0166667 --size 320x180 --record '" + recorded.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Result<InputScript> parsed = load_input_script(recorded);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  // Nobody touches the keyboard under Xvfb: one line, at time 0, of a neutral input.
  ASSERT_EQ(parsed->events().size(), 1u);
  EXPECT_EQ(parsed->events()[0].time, 0.0f);
  EXPECT_EQ(parsed->events()[0].input.left_stick, glm::vec2(0.0f));
}

TEST(ViewerCli, RefusesBadUsageAndBadFiles) {
  ProgramRun r = run(viewer() + " --headless --db x.mmdb");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--headless needs --script"), std::string::npos) << r.output;
  r = run(viewer() + " --db a.mmdb --data b");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("give --db or --data, not both"), std::string::npos) << r.output;
  r = run(viewer() + " --frames 1.5 --headless --script x");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--frames: '1.5' is not an integer"), std::string::npos) << r.output;
  r = run(viewer() + " --weights blobs");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--weights: blobs not in {distance,envelope,heat,geodesic}"),
            std::string::npos)
      << r.output;

  const fs::path dir = test::scratch_dir();
  r = run(viewer() + " --db '" + (dir / "missing.mmdb").string() + "' --headless --script '" +
          script("circle.txt") + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("missing.mmdb"), std::string::npos) << r.output;
  r = run(viewer() + " --db '" + database_file().string() + "' --headless --script '" +
          (dir / "none.txt").string() + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("none.txt"), std::string::npos) << r.output;
  r = run("env -u DISPLAY -u WAYLAND_DISPLAY " + viewer() + " --db '" + database_file().string() +
          "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no display"), std::string::npos) << r.output;
}

// Bounded runs (script.hpp), as mm eval: an absurd time step is a usage error, a script time
// past the longest script is refused by file and line. `--frames 2` keeps a run that is wrongly
// accepted short, so that the test fails rather than runs for hours.
TEST(ViewerCli, HeadlessRefusesRunsPastTheLimits) {
  const fs::path dir = test::scratch_dir();  // first: it empties the folder the database goes to
  const std::string headless = viewer() + " --db '" + database_file().string() +
                               "' --headless --frames 2 --size 320x180 --no-panel --script ";
  ProgramRun r = run(headless + "'" + script("showcase.txt") + "' --dt 0.000001");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--dt: 0.000001 is outside [0.0001, 1]"), std::string::npos) << r.output;

  const fs::path far = dir / "far.txt";
  std::ofstream(far) << "0 0 1 0 0\n1e30 0 0 0 0\n";
  r = run(headless + "'" + far.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("far.txt:2: expected the time in seconds (a number in [0, 28800], the "
                          "longest script), found '1e30'"),
            std::string::npos)
      << r.output;
}

// The generated help lists every option; typed options refuse bad values naming the option,
// and the options that go together stay usage errors.
TEST(ViewerCli, HelpListsEveryOptionAndTypedOptionsRefuseBadValues) {
  ProgramRun r = run(viewer() + " --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output.rfind("usage: mm-viewer", 0), 0u) << r.output;
  for (const char* option :
       {"--db",        "--data",       "--body",         "--weights",   "--skinning",
        "--script",    "--record",     "--set",          "--debug",     "--no-panel",
        "--headless",  "--frames",     "--screenshot",   "--every",     "--plot",
        "--size",      "--dt",         "--crowd",        "--budget-ms", "--tier-colours",
        "--view-turn", "--view-pitch", "--view-distance"}) {
    EXPECT_NE(r.output.find(std::string("  ") + option + " "), std::string::npos) << option << "\n"
                                                                                  << r.output;
  }
  EXPECT_NE(r.output.find("--skinning {lbs,dqs}"), std::string::npos) << r.output;

  const std::pair<std::string, std::string> cases[] = {
      {" --frames 1.5", "--frames: '1.5' is not an integer"},
      {" --every 2.5 --screenshot s.png", "--every: '2.5' is not an integer"},
      {" --frames 0", "--frames: 0 is outside [1, 4194304]"},
      {" --frames 4194305", "--frames: 4194305 is outside [1, 4194304]"},
      {" --dt nan", "--dt: 'nan' is not a finite number"},
      {" --dt 0", "--dt: 0 is outside [0.0001, 1]"},
      {" --dt 0.000001", "--dt: 0.000001 is outside [0.0001, 1]"},
      {" --view-turn 200", "--view-turn: 200 is outside [-180, 180]"},
      {" --view-pitch 90", "--view-pitch: 90 is outside [-5, 80]"},
      {" --view-distance 0.5", "--view-distance: 0.5 is outside [1, 30]"},
      {" --size 640x10", "--size: '640x10' is not WxH"},
      {" --skinning fancy", "--skinning: fancy not in {lbs,dqs}"},
      {" --debug roots,sparkles", "--debug: 'roots,sparkles' is not a list of"},
      {" --set nonsense=1", "--set: unknown setting 'nonsense'"},
      {" --every 10", "--every needs --screenshot"},
      {" --script a.txt --record b.txt", "--record records live input"},
      {" --crowd 10 --script a.txt", "--crowd runs its own input"},
      {" --crowd 0", "--crowd: 0 is outside [1, 1000000]"},
      {" --budget-ms 3", "--budget-ms and --tier-colours need --crowd"},
      {" stray", "not expected: stray"},
  };
  for (const auto& [arguments, message] : cases) {
    r = run(viewer() + arguments);
    EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << arguments << "\n" << r.output;
  }
}

}  // namespace
}  // namespace mm
