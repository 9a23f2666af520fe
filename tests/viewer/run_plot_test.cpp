#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <stb_image.h>
#include <glm/gtc/constants.hpp>

#include "run_plot.hpp"
#include "test_support.hpp"

namespace mm::viewer {
namespace {

constexpr float nan = std::numeric_limits<float>::quiet_NaN();
constexpr float inf = std::numeric_limits<float>::infinity();
constexpr float kFrameTime = 1.0f / 60.0f;

// ---------------------------------------------------------------------------------------------
// A synthetic run: walk straight along +X, stop, then walk a half circle to the left. The
// simulation leads the character a little, the toes alternate contacts, and the character
// transitions at a steady rate and whenever it stops or starts.

struct Leg {
  float seconds;
  float speed;      // m/s
  float turn_rate;  // rad/s, positive turns from +X toward -Z (to the left seen from above)
};

std::vector<RunSample> synthetic_run(const std::vector<Leg>& legs, glm::vec3 start = {0, 0, 0}) {
  std::vector<RunSample> run;
  glm::vec3 position = start;
  float heading = 0.0f, time = 0.0f;  // heading 0 faces +X
  int frame = 0;
  for (const Leg& leg : legs) {
    const int frames = static_cast<int>(std::lround(leg.seconds / kFrameTime));
    for (int i = 0; i < frames; ++i, ++frame, time += kFrameTime) {
      heading += leg.turn_rate * kFrameTime;
      const glm::vec3 forward(std::cos(heading), 0.0f, -std::sin(heading));
      const glm::vec3 left(forward.z, 0.0f, -forward.x);  // forward turned toward the left
      position += forward * leg.speed * kFrameTime;
      RunSample s;
      s.time = time;
      s.character = position;
      s.simulation = position + forward * (0.25f * leg.speed) + left * 0.03f;
      s.character_facing = {forward.x, forward.z};
      s.standing = leg.speed == 0.0f;
      const float phase = std::fmod(time / 1.0f, 1.0f);  // one stride a second
      s.contact[0] = s.standing || phase < 0.6f;
      s.contact[1] = s.standing || phase >= 0.5f || phase < 0.1f;
      s.toes[0] = position + left * 0.1f + forward * 0.12f;
      s.toes[1] = position - left * 0.1f + forward * 0.12f;
      s.transition = frame % 37 == 0 || (i == 0 && frame > 0);
      run.push_back(s);
    }
  }
  return run;
}

std::vector<RunSample> walk_stop_turn() {
  return synthetic_run(
      {{4.0f, 1.4f, 0.0f}, {2.0f, 0.0f, 0.0f}, {4.0f, 1.2f, glm::pi<float>() / 4.0f}});
}

// ---------------------------------------------------------------------------------------------
// Pixel helpers.

Rgb at(const Image& image, int x, int y) {
  const unsigned char* p = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
  return {p[0], p[1], p[2]};
}

// Pixels of exactly this colour in rows [top, bottom), as pixel centres.
std::vector<glm::dvec2> pixels_of(const Image& image, Rgb colour, int top, int bottom) {
  std::vector<glm::dvec2> found;
  for (int y = std::max(top, 0); y < std::min(bottom, image.height); ++y)
    for (int x = 0; x < image.width; ++x)
      if (at(image, x, y) == colour) found.push_back({x + 0.5, y + 0.5});
  return found;
}

// Pixels that are neither background nor grid ("ink") in rows [top, bottom).
int ink_count(const Image& image, int top, int bottom, glm::dvec2* lo = nullptr,
              glm::dvec2* hi = nullptr) {
  const RunPlotOptions o;
  int count = 0;
  for (int y = std::max(top, 0); y < std::min(bottom, image.height); ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgb c = at(image, x, y);
      if (c == o.background || c == o.grid) continue;
      ++count;
      if (lo) *lo = glm::min(*lo, glm::dvec2(x, y)), *hi = glm::max(*hi, glm::dvec2(x + 1, y + 1));
    }
  }
  return count;
}

double distance_to_segment(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 ab = b - a;
  const double l2 = glm::dot(ab, ab);
  const double t = l2 > 0 ? std::clamp(glm::dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// Distance from p to the projected character path, over segments of moving samples.
double distance_to_path(glm::dvec2 p, const std::vector<glm::dvec2>& path) {
  double best = HUGE_VAL;
  for (size_t i = 1; i < path.size(); ++i)
    best = std::min(best, distance_to_segment(p, path[i - 1], path[i]));
  return best;
}

std::vector<glm::dvec2> projected_character(const RunPlotView& view,
                                            const std::vector<RunSample>& run) {
  std::vector<glm::dvec2> path;
  for (const RunSample& s : run) path.push_back(view.to_pixel(s.character));
  return path;
}

bool near_colour(const Image& image, glm::dvec2 p, Rgb colour, int radius) {
  for (int y = static_cast<int>(p.y) - radius; y <= static_cast<int>(p.y) + radius; ++y)
    for (int x = static_cast<int>(p.x) - radius; x <= static_cast<int>(p.x) + radius; ++x)
      if (x >= 0 && y >= 0 && x < image.width && y < image.height && at(image, x, y) == colour)
        return true;
  return false;
}

// ---------------------------------------------------------------------------------------------
// The picture.

TEST(RunPlot, CharacterPathIsDrawnAlongTheProjectedPathAndNowhereElse) {
  const std::vector<RunSample> run = walk_stop_turn();
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  ASSERT_EQ(image.width, o.width);
  ASSERT_EQ(image.height, o.height);
  ASSERT_EQ(image.rgb.size(), size_t{1200} * 1200 * 3);
  const RunPlotView view = run_plot_view(run, o);
  const std::vector<glm::dvec2> path = projected_character(view, run);

  // Every pixel of the character's colour in the plot area lies on the thick line.
  const std::vector<glm::dvec2> ink = pixels_of(image, o.character, 0, view.legend_top);
  ASSERT_GT(ink.size(), 1000u);
  double worst = 0;
  for (const glm::dvec2& p : ink) worst = std::max(worst, distance_to_path(p, path));
  EXPECT_LE(worst, 0.5 * o.character_width + 1.0);

  // And the line is there along the whole walk (markers may hide a few points of it).
  int walked = 0, found = 0;
  for (size_t i = 0; i < run.size(); i += 10) {
    if (run[i].standing) continue;
    ++walked;
    found += near_colour(image, path[i], o.character, 2) ? 1 : 0;
  }
  EXPECT_GE(found, walked * 9 / 10) << found << " of " << walked;
}

TEST(RunPlot, StandPhaseTransitionsAndContactsAreMarked) {
  const std::vector<RunSample> run = walk_stop_turn();
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o);
  // The stand phase begins at 4 s: its ring surrounds that position.
  const size_t stand = 240;
  ASSERT_TRUE(run[stand].standing && !run[stand - 1].standing);
  EXPECT_TRUE(near_colour(image, view.to_pixel(run[stand].character), o.standing, 13));
  EXPECT_FALSE(near_colour(image, view.to_pixel(run[100].character), o.standing, 13));
  // A transition dot where one started, and toe marks where contacts began.
  EXPECT_TRUE(near_colour(image, view.to_pixel(run[37].character), o.transition, 2));
  EXPECT_TRUE(
      near_colour(image, view.to_pixel(run[60].toes[0]), o.toe[0], 1));  // left lands at 1 s
  EXPECT_TRUE(near_colour(image, view.to_pixel(run[30].toes[1]), o.toe[1], 1));  // right at 0.5 s
  // Facing chevrons every half second (a chevron's strokes pass a few pixels from its
  // sample), and none when they are turned off.
  EXPECT_TRUE(near_colour(image, view.to_pixel(run[30].character), o.facing, 8));
  EXPECT_TRUE(near_colour(image, view.to_pixel(run[60].character), o.facing, 8));
  RunPlotOptions no_facing = o;
  no_facing.facing_tick_interval = 0;
  const Image plain = render_run_plot(run, no_facing);
  EXPECT_TRUE(pixels_of(plain, o.facing, 0, image.height).empty());
  // The start and end markers.
  EXPECT_TRUE(near_colour(image, view.to_pixel(run.front().character), o.start, 1));
  EXPECT_TRUE(near_colour(image, view.to_pixel(run.back().character), o.end, 1));
}

// The longest horizontal run of text-coloured pixels in the legend band is the scale bar.
TEST(RunPlot, ScaleBarHasARoundLengthNearAFifthOfThePlot) {
  const std::vector<RunSample> run = walk_stop_turn();
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o);
  int longest = 0;
  for (int y = view.legend_top; y < image.height; ++y) {
    int length = 0;
    for (int x = 0; x < image.width; ++x) {
      length = at(image, x, y) == o.text ? length + 1 : 0;
      longest = std::max(longest, length);
    }
  }
  const double plot_width = o.width - 2.0 * o.margin;
  EXPECT_GE(longest, plot_width / 10);
  EXPECT_LE(longest, plot_width / 2.5);
  const double metres = longest / view.pixels_per_metre;
  const double mantissa = metres / std::pow(10.0, std::floor(std::log10(metres) + 1e-9));
  const double nearest =
      std::min({std::abs(mantissa - 1), std::abs(mantissa - 2), std::abs(mantissa - 5)});
  EXPECT_LT(nearest * std::pow(10.0, std::floor(std::log10(metres) + 1e-9)) * view.pixels_per_metre,
            2.0)
      << longest << " pixels are " << metres << " m";
}

TEST(RunPlot, LegendIsWrittenBelowThePlot) {
  const RunPlotOptions o;
  const std::vector<RunSample> run = walk_stop_turn();
  const Image image = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o);
  ASSERT_GT(view.legend_top, view.plot_bottom);
  ASSERT_LT(view.legend_top, image.height);
  // Text and every legend mark's colour are in the band.
  EXPECT_GT(pixels_of(image, o.text, view.legend_top, image.height).size(), 2000u);
  for (Rgb c :
       {o.simulation, o.character, o.standing, o.transition, o.toe[0], o.toe[1], o.start, o.end}) {
    EXPECT_FALSE(pixels_of(image, c, view.legend_top, image.height).empty())
        << int(c.r) << "," << int(c.g) << "," << int(c.b);
  }
}

TEST(RunPlot, LongRunIsFramedWithinTheMargins) {
  // 100 m east, a turn, and back: much larger than the image at one pixel a metre.
  const std::vector<RunSample> run = synthetic_run(
      {{70.0f, 1.5f, 0.0f}, {3.0f, 1.5f, glm::pi<float>() / 3.0f}, {30.0f, 1.5f, 0.0f}});
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o);
  glm::dvec2 lo(HUGE_VAL), hi(-HUGE_VAL);
  ASSERT_GT(ink_count(image, 0, view.plot_bottom + o.margin / 2, &lo, &hi), 1000);
  const double marker = 13;  // the largest mark's radius may reach past the framed positions
  EXPECT_GE(lo.x, o.margin - marker);
  EXPECT_LE(hi.x, o.width - o.margin + marker);
  EXPECT_GE(lo.y, o.margin - marker);
  EXPECT_LE(hi.y, view.plot_bottom + marker);
  // It fills the plot's width: the run is longer east-west than north-south.
  EXPECT_GE(hi.x - lo.x, 0.95 * (o.width - 2 * o.margin));
}

TEST(RunPlot, TinyRunIsCentredAtAReadableScale) {
  // A character shuffling on the spot: a few centimetres in all.
  std::vector<RunSample> run = synthetic_run({{2.0f, 0.02f, 0.0f}}, {5, 0, -3});
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o);
  // The view shows min_span metres, not the few centimetres moved.
  EXPECT_NEAR(view.pixels_per_metre, (view.plot_bottom - view.plot_top) / o.min_span, 1e-6);
  glm::dvec2 lo(HUGE_VAL), hi(-HUGE_VAL);
  ASSERT_GT(ink_count(image, 0, view.plot_bottom + o.margin / 2, &lo, &hi), 100);
  const glm::dvec2 centre = view.pixel_center;
  EXPECT_GE(lo.x, centre.x - 100);
  EXPECT_LE(hi.x, centre.x + 100);
  EXPECT_GE(lo.y, centre.y - 100);
  EXPECT_LE(hi.y, centre.y + 100);
}

TEST(RunPlot, DegenerateRunsGiveValidImages) {
  const RunPlotOptions o;
  // Empty: the background, the legend and a note, no path.
  const Image empty = render_run_plot({}, o);
  ASSERT_EQ(empty.rgb.size(), size_t{1200} * 1200 * 3);
  const RunPlotView view = run_plot_view({}, o);
  EXPECT_TRUE(pixels_of(empty, o.character, 0, view.legend_top).empty());
  EXPECT_GT(pixels_of(empty, o.text, 0, view.plot_bottom).size(), 100u);  // "no finite samples"
  // One sample, and many at one point: the start and end marks at the centre.
  for (size_t count : {size_t{1}, size_t{50}}) {
    std::vector<RunSample> run(count);
    for (RunSample& s : run) s.character = s.simulation = s.toes[0] = s.toes[1] = {3, 0, 4};
    const Image image = render_run_plot(run, o);
    const RunPlotView v = run_plot_view(run, o);
    EXPECT_NEAR(v.to_pixel(run[0].character).x, 0.5 * o.width, 1e-9);
    EXPECT_TRUE(near_colour(image, v.to_pixel(run[0].character), o.start, 1)) << count;
  }
  // Out-of-range options are clamped to a usable image.
  RunPlotOptions tiny;
  tiny.width = 3, tiny.height = -5, tiny.margin = 1000, tiny.text_scale = 0, tiny.min_span = nan;
  const Image clamped = render_run_plot(walk_stop_turn(), tiny);
  EXPECT_EQ(clamped.width, kMinRunPlotSize);
  EXPECT_EQ(clamped.height, kMinRunPlotSize);
  EXPECT_EQ(clamped.rgb.size(), size_t{kMinRunPlotSize} * kMinRunPlotSize * 3);
}

TEST(RunPlot, NonFiniteSamplesAreSkipped) {
  const std::vector<RunSample> run = walk_stop_turn();
  // Every 7th sample repeated with every number non-finite and no new event: skipping them
  // must give exactly the picture without them.
  std::vector<RunSample> damaged;
  for (size_t i = 0; i < run.size(); ++i) {
    damaged.push_back(run[i]);
    if (i % 7 != 3) continue;
    RunSample bad = run[i];
    bad.time = nan;
    bad.simulation = {inf, 0, 0};
    bad.character = {0, nan, 0};
    bad.character_facing = {nan, 1};
    bad.toes[0] = {-inf, 0, 0};
    bad.toes[1] = {0, 0, nan};
    bad.transition = false;
    damaged.push_back(bad);
  }
  const Image clean = render_run_plot(run);
  const Image image = render_run_plot(damaged);
  EXPECT_EQ(image.rgb, clean.rgb);
  // A run of nothing but non-finite samples is drawn like an empty one.
  std::vector<RunSample> all_bad(10);
  for (RunSample& s : all_bad)
    s.time = nan, s.character = s.simulation = s.toes[0] = s.toes[1] = {nan, nan, nan};
  EXPECT_EQ(render_run_plot(all_bad).rgb, render_run_plot({}).rgb);
}

TEST(RunPlot, ExtremeFiniteValuesDoNotBreakTheDrawing) {
  std::vector<RunSample> run = walk_stop_turn();
  run[10].simulation = {std::numeric_limits<float>::max(), 0, -std::numeric_limits<float>::max()};
  run[20].toes[0] = {-std::numeric_limits<float>::max(), 0, std::numeric_limits<float>::max()};
  run[30].character_facing = {1e-30f, 0};
  const RunPlotOptions o;
  const Image image = render_run_plot(run, o);
  ASSERT_EQ(image.rgb.size(), size_t{1200} * 1200 * 3);
  const RunPlotView view = run_plot_view(run, o);
  EXPECT_TRUE(std::isfinite(view.pixels_per_metre));
  EXPECT_GT(view.pixels_per_metre, 0.0);
  EXPECT_GT(pixels_of(image, o.text, view.legend_top, image.height).size(), 1000u);
}

// ---------------------------------------------------------------------------------------------
// PNG.

TEST(RunPlotPng, WritesAReadablePngWithTheSamePixels) {
  RunPlotOptions o;
  o.width = 640, o.height = 480;
  const Image image = render_run_plot(walk_stop_turn(), o);
  const auto path = test::scratch_dir() / "run.png";
  const Status written = write_png(image, path);
  ASSERT_TRUE(written.ok()) << written.message();
  int w = 0, h = 0, channels = 0;
  unsigned char* pixels = stbi_load(path.string().c_str(), &w, &h, &channels, 3);
  ASSERT_NE(pixels, nullptr) << stbi_failure_reason();
  const std::vector<unsigned char> read(pixels, pixels + static_cast<size_t>(w) * h * 3);
  stbi_image_free(pixels);
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 480);
  EXPECT_EQ(channels, 3);
  EXPECT_TRUE(read == image.rgb);
}

// The picture a person looks at: a longer run with several stops and turns, at the default
// size, left in the test's scratch folder (build/.../run_plot_example.png).
TEST(RunPlotPng, WritesAnExampleOfARealisticRun) {
  const float quarter = glm::pi<float>() / 2.0f;
  const std::vector<RunSample> run = synthetic_run({{3.0f, 1.4f, 0.0f},
                                                    {1.5f, 1.4f, quarter},
                                                    {2.0f, 3.5f, 0.0f},
                                                    {2.0f, 0.0f, 0.0f},
                                                    {3.0f, 1.2f, -quarter},
                                                    {4.0f, 1.4f, 0.2f},
                                                    {1.5f, 0.0f, 0.0f}});
  const auto path = test::scratch_dir() / "run_plot_example.png";
  const Status written = write_png(render_run_plot(run), path);
  ASSERT_TRUE(written.ok()) << written.message();
  EXPECT_GT(std::filesystem::file_size(path), 1000u);
}

TEST(RunPlotPng, UnwritablePathIsAnErrorNamingIt) {
  const Image image = render_run_plot(walk_stop_turn());
  const auto missing = test::scratch_dir() / "no_such_folder" / "run.png";
  const Status status = write_png(image, missing);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(missing.string()), std::string::npos) << status.message();
  EXPECT_FALSE(std::filesystem::exists(missing));
  // A folder is not a file either.
  const Status folder = write_png(image, test::scratch_dir());
  EXPECT_FALSE(folder.ok());
  // A malformed image is refused before any file is made.
  Image broken = image;
  broken.rgb.pop_back();
  const auto path = test::scratch_dir() / "broken.png";
  const Status refused = write_png(broken, path);
  EXPECT_FALSE(refused.ok());
  EXPECT_NE(refused.message().find("malformed"), std::string::npos) << refused.message();
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace mm::viewer

namespace mm::viewer {
namespace {

// A 4 m floor (two triangles) and on it a 1 m box 0.2 m high, x and z in [0, 1], each face with
// its own vertices, as exporters write them.
struct OutlineLevel {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const uint32_t first = static_cast<uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c, d});
    indices.insert(indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
  }
  OutlineLevel() {
    quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2});
    const float h = 0.2f;
    quad({0, h, 0}, {0, h, 1}, {1, h, 1}, {1, h, 0});  // top
    quad({0, 0, 0}, {0, h, 0}, {1, h, 0}, {1, 0, 0});  // the four sides
    quad({1, 0, 0}, {1, h, 0}, {1, h, 1}, {1, 0, 1});
    quad({1, 0, 1}, {1, h, 1}, {0, h, 1}, {0, 0, 1});
    quad({0, 0, 1}, {0, h, 1}, {0, h, 0}, {0, 0, 0});
  }
};

bool on_line(const OutlineSegment& s, int axis, float value) {
  return std::abs(s.a[axis] - value) < 1e-6f && std::abs(s.b[axis] - value) < 1e-6f;
}

TEST(RunPlot, TheLevelOutlineIsTheBordersAndFoldsSeenFromAbove) {
  const OutlineLevel level;
  const std::vector<OutlineSegment> outline = level_outline(level.positions, level.indices);
  int floor_border = 0, box_top = 0, box_foot = 0;
  for (const OutlineSegment& s : outline) {
    // Nothing seen end-on (the box's vertical edges), nothing across a flat face (the
    // diagonals of the floor and the box's top and sides).
    ASSERT_TRUE(s.a.x != s.b.x || s.a.z != s.b.z);
    ASSERT_TRUE(s.a.x == s.b.x || s.a.z == s.b.z) << "a diagonal";
    const bool box_line =
        on_line(s, 0, 0.0f) || on_line(s, 0, 1.0f) || on_line(s, 2, 0.0f) || on_line(s, 2, 1.0f);
    if (on_line(s, 0, -2.0f) || on_line(s, 0, 2.0f) || on_line(s, 2, -2.0f) ||
        on_line(s, 2, 2.0f)) {
      ++floor_border;
    } else if (box_line && s.a.y == 0.2f) {
      ++box_top;  // the top's edges, where it folds down into the sides
    } else if (box_line && s.a.y == 0.0f) {
      ++box_foot;  // the sides' open bottom edges
    } else {
      ADD_FAILURE() << "unexpected segment (" << s.a.x << ", " << s.a.z << ") - (" << s.b.x << ", "
                    << s.b.z << ")";
    }
  }
  EXPECT_EQ(floor_border, 4);
  EXPECT_EQ(box_top, 4);
  EXPECT_EQ(box_foot, 4);
  // A crease wider than the box's fold leaves only the borders (the floor's and the box's foot).
  EXPECT_EQ(level_outline(level.positions, level.indices, 95.0f).size(), 8u);
  // Bad triangles are skipped, not read.
  const std::vector<uint32_t> out_of_range = {0, 1, 99};
  EXPECT_TRUE(level_outline(level.positions, out_of_range).empty());
}

TEST(RunPlot, TheLevelOutlineIsDrawnUnderTheRunAndNamedInTheLegend) {
  const std::vector<RunSample> run = synthetic_run({{2.0f, 1.0f, 0.0f}}, {-1, 0, 0.5f});
  const OutlineLevel level;
  const std::vector<OutlineSegment> outline = level_outline(level.positions, level.indices);
  const RunPlotOptions o;
  const Image with = render_run_plot(run, o, outline);
  const Image without = render_run_plot(run, o);
  const RunPlotView view = run_plot_view(run, o, outline);
  // The box's side at z = 0 (x from 0 to 1), beside the run along z = 0.5, is drawn where the
  // view puts it.
  for (float x : {0.25f, 0.5f, 0.75f}) {
    EXPECT_TRUE(near_colour(with, view.to_pixel({x, 0.0f, 0.0f}), o.outline, 1)) << x;
  }
  EXPECT_TRUE(pixels_of(without, o.outline, 0, without.height).empty());
  // In the legend: an item more (its anti-aliased glyph never takes the exact colour).
  const size_t band = static_cast<size_t>(view.legend_top) * with.width * 3;
  EXPECT_FALSE(std::equal(with.rgb.begin() + band, with.rgb.end(), without.rgb.begin() + band));
}

}  // namespace
}  // namespace mm::viewer
