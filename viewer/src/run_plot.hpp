#pragma once
// The run plot: a top-down picture of a whole scripted run (`mm-viewer --plot OUT.png`), so a
// run can be judged at a glance: where the simulation went, where the character followed,
// where it transitioned, stood still and planted its feet.
//
// Conventions, shared by everything here:
// - Input is world space: metres, Y up, right-handed. Y is ignored.
// - The plot looks down -Y with +X to the right and +Z down the image, which is the true view
//   from above of a right-handed Y-up world (nothing is mirrored).
// - Both axes have the same scale. The view frames every finite position of the run (both
//   paths and the toes) with a margin and shows at least RunPlotOptions::min_span metres, so a
//   run that barely moves is centred at a readable scale rather than blown up.
// - Pixel coordinates are continuous: pixel (i, j) covers [i, i+1) x [j, j+1), row j = 0 on top.
// - Non-finite values are skipped field by field (a NaN toe drops that toe's mark, not the
//   sample's path point); paths join the finite points on either side.
// - An empty run, or one with no finite position, is not an error: it renders a valid image
//   (background, grid, scale bar, legend) with the words "no finite samples" instead of paths.
// - A level's outline (level_outline), when given, is drawn under the run in grey and named in
//   the legend; the view still frames the run, and the outline is cut at the plot's edges.

#include <filesystem>
#include <span>
#include <vector>

#include <glm/ext/vector_uint3_sized.hpp>
#include <glm/glm.hpp>

#include "mm/runtime/result.hpp"

namespace mm::viewer {

// One frame of a run, recorded by the viewer after each controller update.
struct RunSample {
  float time = 0;                    // seconds since the run started
  glm::vec3 simulation{0};           // simulation object position
  glm::vec3 character{0};            // character root position
  glm::vec2 character_facing{0, 1};  // XZ direction the character faces (any length)
  glm::vec3 toes[2]{};               // left, right toe positions
  bool contact[2]{};                 // toe in contact (locked) this frame: left, right
  bool transition = false;           // a transition to another clip started this frame
  bool standing = false;             // the controller is in a stand phase (stick released)
};

using Rgb = glm::u8vec3;

// How the picture looks. Sizes are in pixels and suit the default 1200 x 1200 image.
struct RunPlotOptions {
  int width = 1200;                   // image size, each clamped to
  int height = 1200;                  //   [kMinRunPlotSize, kMaxRunPlotSize]
  int margin = 40;                    // image border to framed run; at most a quarter of the size
  float min_span = 2.0f;              // metres the view shows at least, across either axis
  int text_scale = 2;                 // font pixel size multiplier in [1, 8]
  float facing_tick_interval = 0.5f;  // seconds between facing marks; <= 0 draws none
  float simulation_width = 2.0f;      // line widths
  float character_width = 5.0f;
  Rgb background{250, 250, 247};
  Rgb grid{226, 226, 221};
  Rgb text{40, 40, 40};
  Rgb simulation{240, 130, 20};               // the simulation path
  Rgb character{40, 90, 200};                 // the character path while moving
  Rgb standing{150, 60, 180};                 // the character path in a stand phase, and its ring
  Rgb facing{70, 70, 70};                     // facing marks (chevrons)
  Rgb transition{215, 30, 30};                // transition dots
  Rgb toe[2]{{0, 165, 190}, {225, 60, 170}};  // left, right toe contact marks
  Rgb start{20, 150, 60};                     // the first position
  Rgb end{20, 20, 20};                        // the last position
  Rgb outline{135, 135, 135};                 // the level's outline
  float outline_width = 1.5f;
};

// A segment of a level's outline, world space (Y ignored).
struct OutlineSegment {
  glm::vec3 a{0.0f};
  glm::vec3 b{0.0f};
};

// A level's outline seen from above: every triangle edge that borders no other triangle, or
// where the surface folds by more than `crease_degrees` (a step's nosing and foot, a ramp's foot
// and top, a wall's and a box's footprint), so that the flat ground and gentle bumps stay blank.
// Triangles meet where their edges' end points agree to 1 mm (levels often repeat a vertex per
// face). Edges seen end-on from above are left out; so are triangles with an index out of range
// or a position that is not finite, and degenerate ones. World positions, three indices a
// triangle.
std::vector<OutlineSegment> level_outline(std::span<const glm::vec3> positions,
                                          std::span<const uint32_t> indices,
                                          float crease_degrees = 8.0f);

inline constexpr int kMinRunPlotSize = 200;
inline constexpr int kMaxRunPlotSize = 8192;

// RGB8 pixels, row-major, top row first, 3 bytes a pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

// How world positions map to pixels: pixel = pixel_center + (xz - world_center) * scale.
struct RunPlotView {
  glm::dvec2 world_center{0.0};  // metres, (x, z)
  glm::dvec2 pixel_center{0.0};  // continuous pixel coordinates
  double pixels_per_metre = 1.0;
  int plot_top = 0, plot_bottom = 0;  // the rows of the plot area; the legend lies below it
  int legend_top = 0;                 // the first row of the legend band
  glm::dvec2 to_pixel(const glm::vec3& world) const;
};

// The view render_run_plot uses for these samples and options.
RunPlotView run_plot_view(std::span<const RunSample> samples, const RunPlotOptions& options = {},
                          std::span<const OutlineSegment> outline = {});

// Renders the run into an image of options.width x options.height (after clamping), over the
// level's outline when one is given.
Image render_run_plot(std::span<const RunSample> samples, const RunPlotOptions& options = {},
                      std::span<const OutlineSegment> outline = {});

// Writes the image as an 8-bit RGB PNG. Fails with a message naming the path when the image is
// malformed or the file cannot be written.
Status write_png(const Image& image, const std::filesystem::path& path);

}  // namespace mm::viewer
