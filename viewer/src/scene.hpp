#pragma once
// Everything a frame of the viewer shows, shared by the window and the headless run: one
// controller over the database, the character's body, the camera, the debug drawing, timing
// statistics, and one sample per frame for the run plot.

#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "debug_drawing.hpp"
#include "gl_context.hpp"
#include "mm/controller/controller.hpp"
#include "mm/offline/bone_weights.hpp"
#include "orbit_camera.hpp"
#include "renderer.hpp"
#include "run_plot.hpp"
#include "skinned_body.hpp"

namespace mm::viewer {

// Recomputes the body's weights with another method (empty: the body's weights are fixed, e.g.
// a loaded glTF character's).
using ReweighFunction = std::function<Result<std::vector<VertexInfluences>>(WeightMethod)>;

// Running means of the frame's costs (seconds), smoothed over about a second.
struct FrameTimes {
  float frame = 0.0f;  // wall time between frames; 0 until measured (headless: never)
  float update = 0.0f;
  float search = 0.0f;  // of the frames that searched
};

class Scene {
 public:
  static Result<std::unique_ptr<Scene>> create(std::shared_ptr<const Database> database,
                                               const ControllerSettings& settings, SkinnedMesh body,
                                               WeightMethod body_weights, ReweighFunction reweigh);

  // One controller update (timed), the body's skinning and the run's sample.
  void step(float dt, const ControllerInput& input, SkinningMethod skinning);
  // Draws the ground, the body and the debug lines into the context's framebuffer.
  void draw(Renderer& renderer, const GlContext& context, const OrbitCamera& camera,
            bool show_body);

  // The character's bounding box on the screen, in pixels from the top left (x0, y0, x1, y1):
  // the body's vertices, or the joints when there is no body, through the camera.
  glm::vec4 screen_box(const OrbitCamera& camera, int width, int height) const;

  Controller& controller() { return *controller_; }
  const Controller& controller() const { return *controller_; }
  const Database& database() const { return *database_; }
  const SkinnedBody& body() const { return body_; }
  bool can_reweigh() const { return static_cast<bool>(reweigh_); }
  WeightMethod weight_method() const { return weight_method_; }
  const FrameTimes& times() const { return times_; }
  const std::vector<RunSample>& run() const { return run_; }
  float time() const { return time_; }
  void note_frame_time(float seconds);

  DebugToggles toggles;

  // Live tuning: new settings for the controller (fails, changing nothing, when invalid).
  Status apply_settings(const ControllerSettings& settings);
  // A feature channel's weight: the normalized features are rebuilt with it, the search
  // structures too, and the controller starts again where the character stands.
  Status set_channel_weight(int channel, float weight);
  // The body's weights by another method (fails when the body's weights are fixed).
  Status set_weight_method(WeightMethod method);
  // A level: the world the controller moves through (not owned: it must outlive the scene) and
  // its triangles to draw instead of the ground grid (world positions, three indices a
  // triangle). The character is placed on its ground where it stands.
  void set_level(const WorldQueries* world, std::vector<glm::vec3> positions,
                 std::vector<uint32_t> indices);
  // The level's triangles (empty without one): world positions, three indices a triangle.
  std::span<const glm::vec3> level_positions() const { return level_positions_; }
  std::span<const uint32_t> level_indices() const { return level_indices_; }

 private:
  explicit Scene(SkinnedMesh body) : body_(std::move(body)) {}
  void record_sample();

  std::shared_ptr<const Database> database_;
  std::shared_ptr<const ControllerDatabase> shared_;
  std::unique_ptr<Controller> controller_;
  SkinnedBody body_;
  ReweighFunction reweigh_;
  WeightMethod weight_method_ = WeightMethod::HeatDiffusion;
  FrameTimes times_;
  std::vector<RunSample> run_;
  float time_ = 0.0f;
  int last_transitions_ = 0;
  DebugLines lines_;
  // The level (set_level), uploaded to the renderer on the first draw after it is set.
  const WorldQueries* world_ = nullptr;
  std::vector<glm::vec3> level_positions_;
  std::vector<uint32_t> level_indices_;
  bool level_uploaded_ = false;
};

}  // namespace mm::viewer
