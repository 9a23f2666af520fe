#include "run_plot.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

// Debian's libstb compiles the stb implementations into libstb.so, which PkgConfig::STB links:
// the headers are included for declarations only, so no copy of stb's code is compiled here
// (and none has to pass this project's warnings).
#include <stb_easy_font.h>
#include <stb_image_write.h>
#include "mm/runtime/finite.hpp"
#include "mm/runtime/float_to_integer.hpp"

namespace mm::viewer {
namespace {

// Options a caller can set to anything, brought into ranges the drawing relies on.
RunPlotOptions sanitized(RunPlotOptions o) {
  o.width = std::clamp(o.width, kMinRunPlotSize, kMaxRunPlotSize);
  o.height = std::clamp(o.height, kMinRunPlotSize, kMaxRunPlotSize);
  o.margin = std::clamp(o.margin, 0, std::min(o.width, o.height) / 4);
  o.text_scale = std::clamp(o.text_scale, 1, 8);
  if (!(o.min_span > 1e-3f) || !finite(o.min_span)) o.min_span = 2.0f;
  if (!(o.facing_tick_interval > 0.0f) || !finite(o.facing_tick_interval))
    o.facing_tick_interval = 0;
  if (!finite(o.simulation_width)) o.simulation_width = 2.0f;
  if (!finite(o.character_width)) o.character_width = 5.0f;
  o.simulation_width = std::clamp(o.simulation_width, 0.5f, 50.0f);
  o.character_width = std::clamp(o.character_width, 0.5f, 50.0f);
  if (!finite(o.outline_width)) o.outline_width = 1.5f;
  o.outline_width = std::clamp(o.outline_width, 0.5f, 50.0f);
  return o;
}

// ---------------------------------------------------------------------------------------------
// A small software rasterizer: shapes are signed distance functions in pixels, and a pixel's
// coverage is how far its centre lies inside the edge, which anti-aliases every shape alike.

void blend(Image& image, int x, int y, Rgb colour, float coverage) {
  unsigned char* p = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
  for (int k = 0; k < 3; ++k) {
    const float mixed = p[k] + (static_cast<float>(colour[k]) - p[k]) * coverage;
    p[k] = clamped_integer<unsigned char>(std::round(mixed));
  }
}

// Pixel index range [0, size] of a continuous coordinate; the caller has checked it is finite.
int clamp_to_pixels(float v, int size) {
  return static_cast<int>(std::clamp(v, 0.0f, static_cast<float>(size)));
}

// Fills the shape whose signed distance (pixels, negative inside) is `distance`, within the
// bounding box [lo, hi].
template <class Distance>
void fill_shape(Image& image, glm::vec2 lo, glm::vec2 hi, Rgb colour, Distance distance) {
  if (!finite(lo) || !finite(hi)) return;
  const int x0 = clamp_to_pixels(std::floor(lo.x), image.width);
  const int x1 = clamp_to_pixels(std::ceil(hi.x), image.width);
  const int y0 = clamp_to_pixels(std::floor(lo.y), image.height);
  const int y1 = clamp_to_pixels(std::ceil(hi.y), image.height);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const float d =
          distance(glm::vec2(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f));
      const float coverage = std::clamp(0.5f - d, 0.0f, 1.0f);
      if (coverage > 0.0f) blend(image, x, y, colour, coverage);
    }
  }
}

// A line of this width with round caps (a capsule).
void draw_segment(Image& image, glm::vec2 a, glm::vec2 b, float width, Rgb colour) {
  const float half = 0.5f * width;
  const glm::vec2 ab = b - a;
  const float length2 = glm::dot(ab, ab);
  fill_shape(image, glm::min(a, b) - half - 1.0f, glm::max(a, b) + half + 1.0f, colour,
             [&](glm::vec2 p) {
               const float t =
                   length2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / length2, 0.0f, 1.0f) : 0.0f;
               return glm::length(p - (a + t * ab)) - half;
             });
}

void draw_disc(Image& image, glm::vec2 centre, float radius, Rgb colour) {
  fill_shape(image, centre - radius - 1.0f, centre + radius + 1.0f, colour,
             [&](glm::vec2 p) { return glm::length(p - centre) - radius; });
}

void draw_ring(Image& image, glm::vec2 centre, float radius, float width, Rgb colour) {
  const float outer = radius + 0.5f * width;
  fill_shape(image, centre - outer - 1.0f, centre + outer + 1.0f, colour, [&](glm::vec2 p) {
    return std::abs(glm::length(p - centre) - radius) - 0.5f * width;
  });
}

void draw_square(Image& image, glm::vec2 centre, float half, Rgb colour) {
  fill_shape(image, centre - half - 1.0f, centre + half + 1.0f, colour, [&](glm::vec2 p) {
    const glm::vec2 d = glm::abs(p - centre);
    return std::max(d.x, d.y) - half;
  });
}

// Plain pixel rectangle [x0, x1) x [y0, y1), clipped.
void fill_rect(Image& image, int x0, int y0, int x1, int y1, Rgb colour) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, image.width), y1 = std::min(y1, image.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) blend(image, x, y, colour, 1.0f);
}

// ---------------------------------------------------------------------------------------------
// Text: stb_easy_font builds each glyph from axis-aligned quads, drawn here as rectangles
// scaled by a whole number so their edges stay on pixel boundaries.

int text_width(const std::string& text, int scale) {
  std::string copy = text;  // the font's API takes a mutable string
  return stb_easy_font_width(copy.data()) * scale;
}

void draw_text(Image& image, int x, int y, const std::string& text, int scale, Rgb colour) {
  std::string copy = text;
  std::vector<char> quads(copy.size() * 400 + 64);  // the font needs about 270 bytes a glyph
  const int count = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, quads.data(),
                                        static_cast<int>(quads.size()));
  for (int q = 0; q < count; ++q) {
    float corner[4][4];  // x, y, z, colour bytes of the quad's four vertices
    std::memcpy(corner, quads.data() + static_cast<size_t>(q) * sizeof corner, sizeof corner);
    const float qx0 = std::min(corner[0][0], corner[2][0]),
                qx1 = std::max(corner[0][0], corner[2][0]);
    const float qy0 = std::min(corner[0][1], corner[2][1]),
                qy1 = std::max(corner[0][1], corner[2][1]);
    fill_rect(image, x + clamped_integer<int>(std::round(qx0 * scale)),
              y + clamped_integer<int>(std::round(qy0 * scale)),
              x + clamped_integer<int>(std::round(qx1 * scale)),
              y + clamped_integer<int>(std::round(qy1 * scale)), colour);
  }
}

// ---------------------------------------------------------------------------------------------
// Marks, shared by the plot and its legend so that the legend shows exactly what is drawn.

const Rgb kWhite{255, 255, 255};

void mark_transition(Image& image, glm::vec2 at, const RunPlotOptions& o) {
  draw_disc(image, at, 6.5f, kWhite);  // an outline keeps the dot visible on either path
  draw_disc(image, at, 5.0f, o.transition);
}

void mark_contact(Image& image, glm::vec2 at, int foot, const RunPlotOptions& o) {
  draw_disc(image, at, 3.5f, o.toe[foot]);
}

void mark_stand(Image& image, glm::vec2 at, const RunPlotOptions& o) {
  draw_ring(image, at, 11.0f, 2.5f, o.standing);
}

// A chevron around `at` pointing along the unit `direction`.
void draw_chevron(Image& image, glm::vec2 at, glm::vec2 direction, float size, Rgb colour) {
  const glm::vec2 side(-direction.y, direction.x);
  const glm::vec2 tip = at + direction * size;
  draw_segment(image, tip, at - direction * (0.2f * size) + side * size, 2.0f, colour);
  draw_segment(image, tip, at - direction * (0.2f * size) - side * size, 2.0f, colour);
}

// Wider than the character path, so that it shows on the path, which it mostly follows.
void mark_facing(Image& image, glm::vec2 at, glm::vec2 direction, const RunPlotOptions& o) {
  draw_chevron(image, at, direction, std::max(6.0f, 1.4f * o.character_width), o.facing);
}

void mark_start(Image& image, glm::vec2 at, const RunPlotOptions& o) {
  draw_disc(image, at, 9.5f, kWhite);
  draw_disc(image, at, 8.0f, o.start);
}

void mark_end(Image& image, glm::vec2 at, const RunPlotOptions& o) {
  draw_square(image, at, 8.5f, kWhite);
  draw_square(image, at, 7.0f, o.end);
}

// ---------------------------------------------------------------------------------------------
// Layout: the plot area on top, a legend band at the bottom. The band's first row holds the
// scale bar and a summary line; the legend's items flow over the rows below it.

enum class Mark {
  Outline,
  Axes,
  Simulation,
  Character,
  Standing,
  Facing,
  Transition,
  LeftToe,
  RightToe,
  Start,
  End
};

struct LegendItem {
  Mark mark;
  std::string label;
};

std::vector<LegendItem> legend_items(const RunPlotOptions& o, bool outline) {
  char facing[64];
  std::snprintf(facing, sizeof facing, "facing (every %g s)",
                static_cast<double>(o.facing_tick_interval));
  std::vector<LegendItem> items = {{Mark::Simulation, "simulation"},
                                   {Mark::Character, "character"},
                                   {Mark::Standing, "stand phase"},
                                   {Mark::Facing, facing},
                                   {Mark::Transition, "transition"},
                                   {Mark::LeftToe, "left toe contact"},
                                   {Mark::RightToe, "right toe contact"},
                                   {Mark::Start, "start"},
                                   {Mark::End, "end"},
                                   {Mark::Axes, "+X, +Z (seen from above)"}};
  if (o.facing_tick_interval == 0.0f) items.erase(items.begin() + 3);  // no facing marks drawn
  if (outline) items.insert(items.begin(), {Mark::Outline, "level outline"});
  return items;
}

struct Layout {
  int left = 0;  // the legend's left edge
  int row_height = 0;
  int glyph_width = 0;  // the sample of each mark, left of its label
  int legend_top = 0;
  std::vector<glm::ivec2> items;  // top-left corner of each legend item (glyph, then label)
};

Layout layout(const RunPlotOptions& o, const std::vector<LegendItem>& items) {
  Layout l;
  l.left = std::max(o.margin, 8);
  l.row_height = 12 * o.text_scale + 8;
  l.glyph_width = 34;
  const int gap = 8 * o.text_scale;
  const int right = o.width - l.left;
  int x = l.left, row = 1;
  for (const LegendItem& item : items) {
    const int w = l.glyph_width + gap / 2 + text_width(item.label, o.text_scale);
    if (x > l.left && x + w > right) x = l.left, ++row;
    l.items.push_back({x, row * l.row_height});
    x += w + gap;
  }
  const int band = (row + 1) * l.row_height;
  l.legend_top = o.height - band - std::max(o.margin / 2, 4);
  for (glm::ivec2& p : l.items) p.y += l.legend_top;
  return l;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The view.

glm::dvec2 RunPlotView::to_pixel(const glm::vec3& world) const {
  return pixel_center + (glm::dvec2(world.x, world.z) - world_center) * pixels_per_metre;
}

namespace {

// The XZ bounds of every finite position; false when there is none.
bool run_bounds(std::span<const RunSample> samples, glm::dvec2& lo, glm::dvec2& hi) {
  lo = glm::dvec2(HUGE_VAL), hi = glm::dvec2(-HUGE_VAL);
  bool any = false;
  const auto add = [&](const glm::vec3& p) {
    if (!finite(p)) return;
    lo = glm::min(lo, glm::dvec2(p.x, p.z)), hi = glm::max(hi, glm::dvec2(p.x, p.z));
    any = true;
  };
  for (const RunSample& s : samples) {
    add(s.simulation), add(s.character), add(s.toes[0]), add(s.toes[1]);
  }
  return any;
}

RunPlotView make_view(std::span<const RunSample> samples, const RunPlotOptions& o,
                      const Layout& l) {
  RunPlotView view;
  view.plot_top = o.margin;
  view.legend_top = l.legend_top;
  view.plot_bottom = std::max(view.plot_top + 1, l.legend_top - o.margin);
  const double plot_width = std::max(1, o.width - 2 * o.margin);
  const double plot_height = view.plot_bottom - view.plot_top;
  glm::dvec2 lo(0.0), hi(0.0);
  if (!run_bounds(samples, lo, hi)) lo = hi = glm::dvec2(0.0);
  const glm::dvec2 span = glm::max(hi - lo, glm::dvec2(o.min_span));
  view.pixels_per_metre = std::min(plot_width / span.x, plot_height / span.y);
  view.world_center = 0.5 * (lo + hi);
  view.pixel_center = glm::dvec2(0.5 * o.width, view.plot_top + 0.5 * plot_height);
  return view;
}

}  // namespace

RunPlotView run_plot_view(std::span<const RunSample> samples, const RunPlotOptions& options,
                          std::span<const OutlineSegment> outline) {
  const RunPlotOptions o = sanitized(options);
  return make_view(samples, o, layout(o, legend_items(o, !outline.empty())));
}

namespace {

// ---------------------------------------------------------------------------------------------
// The plot.

// The 1, 2 or 5 x 10^k length nearest to `target` metres, by ratio.
double round_length(double target) {
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  double best = decade;
  for (double m : {2.0, 5.0, 10.0}) {
    if (std::abs(std::log(m * decade / target)) < std::abs(std::log(best / target)))
      best = m * decade;
  }
  return best;
}

// "2 m", "50 cm", "5 mm": the length as a person would write it.
std::string length_label(double metres) {
  char text[64];
  if (metres >= 1.0)
    std::snprintf(text, sizeof text, "%g m", metres);
  else if (metres >= 0.01)
    std::snprintf(text, sizeof text, "%g cm", std::round(metres * 1e4) / 100.0);
  else
    std::snprintf(text, sizeof text, "%g mm", metres * 1e3);
  return text;
}

// One line a metre, or every 2, 5, 10... metres when metre lines would crowd into a grey wash.
double grid_step(double pixels_per_metre) {
  constexpr double kMinGridSpacing = 12.0;  // pixels
  double step = 1.0;
  for (int i = 0; i < 400 && step * pixels_per_metre < kMinGridSpacing; ++i) {
    step = round_length(step * 2.1);  // the next of 1, 2, 5, 10, 20, ...
  }
  return step;
}

// The lines of one axis: world = center + (pixel - pixel_center) / scale over [0, size).
template <class DrawLine>
void grid_lines(double world_center, double pixel_center, double scale, int size, double step,
                DrawLine draw_line) {
  const double first = std::ceil((world_center - pixel_center / scale) / step);
  for (int k = 0; k < 100000; ++k) {
    const double pixel = pixel_center + ((first + k) * step - world_center) * scale;
    if (!(pixel < size)) break;
    draw_line(clamped_integer<int>(std::floor(pixel)));
  }
}

void draw_grid(Image& image, const RunPlotView& view, const RunPlotOptions& o, int bottom) {
  const double step = grid_step(view.pixels_per_metre);
  const double scale = view.pixels_per_metre;
  grid_lines(view.world_center.x, view.pixel_center.x, scale, image.width, step,
             [&](int x) { fill_rect(image, x, 0, x + 1, bottom, o.grid); });
  grid_lines(view.world_center.y, view.pixel_center.y, scale, bottom, step,
             [&](int y) { fill_rect(image, 0, y, image.width, y + 1, o.grid); });
}

glm::vec2 pixel(const RunPlotView& view, const glm::vec3& world) {
  return glm::vec2(view.to_pixel(world));
}

// The character path (moving and standing) under the thinner simulation path.
void draw_paths(Image& image, const RunPlotView& view, std::span<const RunSample> samples,
                const RunPlotOptions& o) {
  const RunSample* previous = nullptr;
  for (const RunSample& s : samples) {
    if (!finite(s.character)) continue;
    if (previous) {
      draw_segment(image, pixel(view, previous->character), pixel(view, s.character),
                   o.character_width, s.standing ? o.standing : o.character);
    }
    previous = &s;
  }
  previous = nullptr;
  for (const RunSample& s : samples) {
    if (!finite(s.simulation)) continue;
    if (previous) {
      draw_segment(image, pixel(view, previous->simulation), pixel(view, s.simulation),
                   o.simulation_width, o.simulation);
    }
    previous = &s;
  }
}

void draw_facing_ticks(Image& image, const RunPlotView& view, std::span<const RunSample> samples,
                       const RunPlotOptions& o) {
  if (o.facing_tick_interval == 0.0f) return;  // sanitized: none wanted
  float next = -HUGE_VALF;
  for (const RunSample& s : samples) {
    if (!finite(s.time) || !finite(s.character) || !finite(s.character_facing)) continue;
    if (s.time < next - o.facing_tick_interval) next = -HUGE_VALF;  // time restarted
    const float length = glm::length(s.character_facing);
    if (s.time < next || !(length > 1e-6f) || !finite(length)) continue;
    mark_facing(image, pixel(view, s.character), s.character_facing / length, o);
    next = s.time + o.facing_tick_interval;
  }
}

// Stand rings where a stand phase begins, a mark where each toe's contact begins, and the
// transition dots on top.
void draw_events(Image& image, const RunPlotView& view, std::span<const RunSample> samples,
                 const RunPlotOptions& o) {
  bool was_standing = false, had_contact[2] = {false, false};
  for (const RunSample& s : samples) {
    if (s.standing && !was_standing && finite(s.character))
      mark_stand(image, pixel(view, s.character), o);
    was_standing = s.standing;
    for (int foot = 0; foot < 2; ++foot) {
      if (s.contact[foot] && !had_contact[foot] && finite(s.toes[foot])) {
        mark_contact(image, pixel(view, s.toes[foot]), foot, o);
      }
      had_contact[foot] = s.contact[foot];
    }
  }
  for (const RunSample& s : samples) {
    if (s.transition && finite(s.character)) mark_transition(image, pixel(view, s.character), o);
  }
}

// The level's outline, cut to the image (a segment across a level far larger than the run would
// otherwise cost a pass over its whole bounding box for nothing).
void draw_outline(Image& image, const RunPlotView& view, std::span<const OutlineSegment> outline,
                  const RunPlotOptions& o) {
  const glm::dvec2 lo(-o.outline_width - 2.0),
      hi(image.width + o.outline_width + 2.0, image.height + o.outline_width + 2.0);
  for (const OutlineSegment& segment : outline) {
    if (!finite(segment.a) || !finite(segment.b)) continue;
    glm::dvec2 a = view.to_pixel(segment.a), b = view.to_pixel(segment.b);
    // Liang-Barsky: the part of a-b inside [lo, hi].
    double t0 = 0.0, t1 = 1.0;
    const glm::dvec2 d = b - a;
    bool inside = true;
    for (int axis = 0; axis < 2 && inside; ++axis) {
      const double p[2] = {-d[axis], d[axis]};
      const double q[2] = {a[axis] - lo[axis], hi[axis] - a[axis]};
      for (int k = 0; k < 2; ++k) {
        if (p[k] == 0.0) {
          if (q[k] < 0.0) inside = false;
        } else if (const double t = q[k] / p[k]; p[k] < 0.0) {
          t0 = std::max(t0, t);
        } else {
          t1 = std::min(t1, t);
        }
      }
    }
    if (!inside || t0 > t1) continue;
    b = a + t1 * d;
    a = a + t0 * d;
    draw_segment(image, glm::vec2(a), glm::vec2(b), o.outline_width, o.outline);
  }
}

void draw_start_end(Image& image, const RunPlotView& view, std::span<const RunSample> samples,
                    const RunPlotOptions& o) {
  const auto has_position = [](const RunSample& s) { return finite(s.character); };
  const auto first = std::find_if(samples.begin(), samples.end(), has_position);
  const auto last = std::find_if(samples.rbegin(), samples.rend(), has_position);
  if (first == samples.end()) return;
  // The start goes on top, so that a run ending where it began still shows both.
  mark_end(image, pixel(view, last->character), o);
  mark_start(image, pixel(view, first->character), o);
}

// ---------------------------------------------------------------------------------------------
// The legend band.

// "31.2 s, 14 transitions, character path 25.3 m": the numbers a run is first judged by.
std::string summary(std::span<const RunSample> samples) {
  float first = HUGE_VALF, last = -HUGE_VALF, walked = 0.0f;
  int transitions = 0;
  const glm::vec3* previous = nullptr;
  for (const RunSample& s : samples) {
    if (finite(s.time)) first = std::min(first, s.time), last = std::max(last, s.time);
    transitions += s.transition ? 1 : 0;
    if (!finite(s.character)) continue;
    if (previous)
      walked += glm::length(glm::vec2(s.character.x - previous->x, s.character.z - previous->z));
    previous = &s.character;
  }
  const double duration = last >= first ? static_cast<double>(last - first) : 0.0;
  char text[160];
  std::snprintf(text, sizeof text, "%.1f s, %d transition%s, character path %.1f m", duration,
                transitions, transitions == 1 ? "" : "s", static_cast<double>(walked));
  return text;
}

// The sample of a mark, centred in a glyph box of this width.
void draw_legend_glyph(Image& image, Mark mark, glm::vec2 left, float width,
                       const RunPlotOptions& o) {
  const glm::vec2 centre = left + glm::vec2(0.5f * width, 0.0f);
  const glm::vec2 right = left + glm::vec2(width, 0.0f);
  switch (mark) {
    case Mark::Outline:
      draw_segment(image, left, right, o.outline_width, o.outline);
      break;
    case Mark::Simulation:
      draw_segment(image, left, right, o.simulation_width, o.simulation);
      break;
    case Mark::Character:
      draw_segment(image, left, right, o.character_width, o.character);
      break;
    case Mark::Standing:
      draw_segment(image, left, right, o.character_width, o.standing);
      mark_stand(image, centre, o);
      break;
    case Mark::Facing:
      draw_segment(image, left, right, o.character_width, o.character);
      mark_facing(image, centre, glm::vec2(1.0f, 0.0f), o);
      break;
    case Mark::Axes: {  // +X to the right, +Z down, from one corner
      const glm::vec2 corner = left + glm::vec2(0.0f, -7.0f);
      draw_segment(image, corner, corner + glm::vec2(width, 0.0f), 1.5f, o.text);
      draw_chevron(image, corner + glm::vec2(width - 4.0f, 0.0f), {1.0f, 0.0f}, 4.0f, o.text);
      draw_segment(image, corner, corner + glm::vec2(0.0f, 15.0f), 1.5f, o.text);
      draw_chevron(image, corner + glm::vec2(0.0f, 11.0f), {0.0f, 1.0f}, 4.0f, o.text);
      break;
    }
    case Mark::Transition:
      mark_transition(image, centre, o);
      break;
    case Mark::LeftToe:
      mark_contact(image, centre, 0, o);
      break;
    case Mark::RightToe:
      mark_contact(image, centre, 1, o);
      break;
    case Mark::Start:
      mark_start(image, centre, o);
      break;
    case Mark::End:
      mark_end(image, centre, o);
      break;
  }
}

// A bar of a round length near a fifth of the plot's width, with end ticks and its length.
int draw_scale_bar(Image& image, const RunPlotView& view, const RunPlotOptions& o, glm::ivec2 at) {
  const double plot_metres = (o.width - 2.0 * o.margin) / view.pixels_per_metre;
  const double metres = round_length(plot_metres / 5.0);
  const int length =
      clamped_integer<int>(std::round(std::min(metres * view.pixels_per_metre, 4.0 * o.width)));
  const int y = at.y + 4 * o.text_scale;
  fill_rect(image, at.x, y - 1, at.x + length, y + 2, o.text);
  fill_rect(image, at.x, y - 6, at.x + 2, y + 7, o.text);
  fill_rect(image, at.x + length - 2, y - 6, at.x + length, y + 7, o.text);
  const std::string label = length_label(metres);
  draw_text(image, at.x + length + 4 * o.text_scale, at.y, label, o.text_scale, o.text);
  return at.x + length + 4 * o.text_scale + text_width(label, o.text_scale);
}

void draw_legend(Image& image, const RunPlotView& view, std::span<const RunSample> samples,
                 const RunPlotOptions& o, const Layout& l, const std::vector<LegendItem>& items) {
  const int text_offset = (l.row_height - 8 * o.text_scale) / 2;  // centres a line of text in a row
  const int x = draw_scale_bar(image, view, o, {l.left, l.legend_top + text_offset});
  draw_text(image, x + 12 * o.text_scale, l.legend_top + text_offset, summary(samples),
            o.text_scale, o.text);
  for (size_t i = 0; i < items.size(); ++i) {
    const glm::ivec2 at = l.items[i];
    const float mid = static_cast<float>(at.y + text_offset + 4 * o.text_scale);
    draw_legend_glyph(image, items[i].mark, glm::vec2(at.x + 6, mid),
                      static_cast<float>(l.glyph_width - 12), o);
    draw_text(image, at.x + l.glyph_width + 4 * o.text_scale, at.y + text_offset, items[i].label,
              o.text_scale, o.text);
  }
}

}  // namespace

Image render_run_plot(std::span<const RunSample> samples, const RunPlotOptions& options,
                      std::span<const OutlineSegment> outline) {
  const RunPlotOptions o = sanitized(options);
  const std::vector<LegendItem> items = legend_items(o, !outline.empty());
  const Layout l = layout(o, items);
  const RunPlotView view = make_view(samples, o, l);
  Image image{o.width, o.height, {}};
  image.rgb.resize(static_cast<size_t>(o.width) * o.height * 3);
  fill_rect(image, 0, 0, o.width, o.height, o.background);
  const int grid_bottom = l.legend_top - 2 * o.text_scale;
  draw_grid(image, view, o, grid_bottom);
  if (!outline.empty()) {
    draw_outline(image, view, outline, o);
    // What of it reached below the plot is cleared for the legend.
    fill_rect(image, 0, grid_bottom, o.width, o.height, o.background);
  }
  fill_rect(image, 0, grid_bottom, o.width, grid_bottom + 1, o.text);  // separates the legend
  glm::dvec2 lo, hi;
  if (run_bounds(samples, lo, hi)) {
    draw_paths(image, view, samples, o);
    draw_facing_ticks(image, view, samples, o);
    draw_events(image, view, samples, o);
    draw_start_end(image, view, samples, o);
  } else {
    const std::string text = "no finite samples";
    draw_text(image, (o.width - text_width(text, 2 * o.text_scale)) / 2,
              static_cast<int>(view.pixel_center.y), text, 2 * o.text_scale, o.text);
  }
  draw_legend(image, view, samples, o, l, items);
  return image;
}

// ---------------------------------------------------------------------------------------------
// The level's outline.

namespace {

// A position rounded to whole millimetres: where two triangles' edges meet.
using Key = std::array<int64_t, 3>;

Key key_of(const glm::vec3& p) {
  return {static_cast<int64_t>(std::llround(static_cast<double>(p.x) * 1000.0)),
          static_cast<int64_t>(std::llround(static_cast<double>(p.y) * 1000.0)),
          static_cast<int64_t>(std::llround(static_cast<double>(p.z) * 1000.0))};
}

struct Edge {
  glm::vec3 a{0.0f}, b{0.0f};
  glm::vec3 first_normal{0.0f};
  int triangles = 0;
  bool folds = false;  // a triangle after the first meets the first at more than the crease
};

}  // namespace

std::vector<OutlineSegment> level_outline(std::span<const glm::vec3> positions,
                                          std::span<const uint32_t> indices, float crease_degrees) {
  const float min_cos = std::cos(glm::radians(std::clamp(crease_degrees, 0.0f, 180.0f)));
  std::map<std::pair<Key, Key>, Edge> edges;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    if (indices[t] >= positions.size() || indices[t + 1] >= positions.size() ||
        indices[t + 2] >= positions.size()) {
      continue;
    }
    const glm::vec3 v[3] = {positions[indices[t]], positions[indices[t + 1]],
                            positions[indices[t + 2]]};
    if (!finite(v[0]) || !finite(v[1]) || !finite(v[2])) continue;
    const glm::vec3 cross = glm::cross(v[1] - v[0], v[2] - v[0]);
    if (!(glm::length(cross) > 0.0f)) continue;
    const glm::vec3 normal = glm::normalize(cross);
    for (int e = 0; e < 3; ++e) {
      glm::vec3 a = v[e], b = v[(e + 1) % 3];
      Key ka = key_of(a), kb = key_of(b);
      if (kb < ka) std::swap(ka, kb), std::swap(a, b);
      if (ka == kb) continue;
      Edge& edge = edges[{ka, kb}];
      if (edge.triangles == 0) {
        edge.a = a, edge.b = b, edge.first_normal = normal;
      } else if (std::abs(glm::dot(edge.first_normal, normal)) < min_cos) {
        // Either winding: a level's faces need not agree on it.
        edge.folds = true;
      }
      ++edge.triangles;
    }
  }
  std::vector<OutlineSegment> outline;
  for (const auto& [key, edge] : edges) {
    if (edge.triangles != 1 && !edge.folds) continue;
    if (key.first[0] == key.second[0] && key.first[2] == key.second[2]) continue;  // end-on
    outline.push_back({edge.a, edge.b});
  }
  return outline;
}

// ---------------------------------------------------------------------------------------------
// PNG.

Status write_png(const Image& image, const std::filesystem::path& path) {
  // Built by appending: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string name = "'";
  name += path.string();
  name += "'";
  if (image.width <= 0 || image.height <= 0 || image.width > kMaxRunPlotSize ||
      image.height > kMaxRunPlotSize ||
      image.rgb.size() != static_cast<size_t>(image.width) * image.height * 3) {
    return Error{"cannot write " + name +
                 ": the image is malformed (its size and pixels disagree)"};
  }
  std::vector<unsigned char> png;
  const auto append = [](void* context, void* data, int size) {
    auto* bytes = static_cast<std::vector<unsigned char>*>(context);
    const auto* begin = static_cast<const unsigned char*>(data);
    bytes->insert(bytes->end(), begin, begin + size);
  };
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(),
                              image.width * 3)) {
    return Error{"cannot write " + name + ": PNG encoding failed"};
  }
  errno = 0;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    return Error{"cannot write " + name + ": " +
                 (errno ? std::strerror(errno) : "cannot open the file")};
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.close();
  if (!out) return Error{"cannot write " + name + ": writing failed (disk full?)"};
  return Status::success();
}

}  // namespace mm::viewer
