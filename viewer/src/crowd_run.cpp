#include "crowd_run.hpp"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <vector>

#include "crowd_renderer.hpp"
#include "crowd_view.hpp"
#include "frame_output.hpp"
#include "gl.hpp"
#include "gl_context.hpp"
#include "live_input.hpp"
#include "mm/controller/script.hpp"
#include "orbit_camera.hpp"
#include "renderer.hpp"

namespace mm::viewer {
namespace {

// Headless, the camera goes round the crowd at this rate (rad/s), so a run's screenshots show
// the tiers following it.
constexpr float kHeadlessOrbitRate = 0.1f;
// Headless without --frames: this many seconds of game time.
constexpr float kHeadlessSeconds = 5.0f;
constexpr float kMaxBudgetMs = 30.0f;

// What a crowd run draws with and shows.
struct CrowdStage {
  std::unique_ptr<GlContext> context;
  std::optional<Renderer> ground;
  std::optional<CrowdRenderer> bodies;
  std::unique_ptr<CrowdView> view;
  OrbitCamera camera;
  std::vector<BoneInstance> bones;
  bool tier_colours = false;
  bool panel = true;
  bool imgui = false;
  bool imgui_laid_out = false;
  float draw_ms = 0.0f;  // smoothed: packing, upload, drawing to the end (glFinish)
  std::string message;

  ~CrowdStage() {
    if (imgui) stop_imgui(*context);
    bodies.reset();  // GL objects go before the context
    ground.reset();
  }
};

Status prepare(CrowdStage& stage, const ViewerOptions& options,
               std::shared_ptr<const Database> database) {
  Result<Renderer> ground = Renderer::create();
  if (!ground) return Error{ground.message()};
  stage.ground.emplace(std::move(*ground));
  Result<CrowdRenderer> bodies = CrowdRenderer::create();
  if (!bodies) return Error{bodies.message()};
  stage.bodies.emplace(std::move(*bodies));
  Result<std::shared_ptr<const ControllerDatabase>> shared =
      ControllerDatabase::create(std::move(database));
  if (!shared) return Error{shared.message()};
  CrowdViewSettings crowd;
  crowd.characters = options.crowd;
  crowd.budget_ms = options.budget_ms;
  Result<std::unique_ptr<CrowdView>> view = CrowdView::create(*shared, options.settings, crowd);
  if (!view) return Error{view.message()};
  stage.view = std::move(*view);
  // Above the middle of the crowd, far enough out to see most of it.
  stage.camera.target = glm::vec3(0.0f, 0.9f, 0.0f);
  stage.camera.distance = std::clamp(1.2f * stage.view->radius() + 4.0f, OrbitCamera::kMinDistance,
                                     OrbitCamera::kMaxDistance);
  stage.camera.pitch = 0.5f;
  stage.tier_colours = options.tier_colours;
  stage.panel = options.panel;
  return Status::success();
}

bool start_imgui(CrowdStage& stage) {
  stage.imgui = start_imgui(*stage.context);
  return stage.imgui;
}

void tier_legend(const CrowdScheduler& scheduler) {
  for (int t = 0; t < kCrowdTierCount; ++t) {
    const CrowdTier tier = static_cast<CrowdTier>(t);
    const glm::vec3 c = crowd_tier_colour(tier);
    ImGui::ColorButton(("##tier" + std::to_string(t)).c_str(), ImVec4(c.r, c.g, c.b, 1.0f),
                       ImGuiColorEditFlags_NoTooltip, ImVec2(14, 14));
    ImGui::SameLine();
    ImGui::Text("%-9s %6d", std::string(crowd_tier_name(tier)).c_str(),
                scheduler.tier_counts()[static_cast<size_t>(t)]);
  }
}

void crowd_panel(CrowdStage& stage) {
  CrowdView& view = *stage.view;
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::Begin("crowd", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("%zu characters   time %.2f s", view.characters(), view.time());
  ImGui::Text("update %.2f ms   draw %.2f ms", view.update_ms(), stage.draw_ms);
  ImGui::Text("planned work %.2f ms (cost model)", view.scheduler().planned_cost_us() * 1e-3);
  float budget = view.budget_ms();
  if (ImGui::SliderFloat("budget ms", &budget, 0.0f, kMaxBudgetMs, "%.1f")) {
    if (Status s = view.set_budget_ms(budget); !s) stage.message = s.message();
  }
  ImGui::TextDisabled("0: no budget, every character at full rate");
  ImGui::Checkbox("tier colours (T)", &stage.tier_colours);
  tier_legend(view.scheduler());
  if (!stage.message.empty()) ImGui::TextWrapped("%s", stage.message.c_str());
  ImGui::End();
}

void draw_panel_frame(CrowdStage& stage) {
  draw_imgui_frame(*stage.context, stage.imgui_laid_out, [&] { crowd_panel(stage); });
}

void draw_frame(CrowdStage& stage) {
  int width = 0, height = 0;
  stage.context->framebuffer_size(width, height);
  const CameraMatrices matrices = stage.camera.matrices(width, height);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  stage.ground->begin(stage.context->framebuffer(), width, height);
  stage.ground->draw_ground(matrices, stage.camera.target);
  stage.view->pack(stage.tier_colours, stage.bones);
  stage.bodies->draw(matrices, stage.bones);
  glFinish();
  const float ms = std::chrono::duration<float, std::milli>(Clock::now() - start).count();
  stage.draw_ms = stage.draw_ms == 0.0f ? ms : stage.draw_ms + (ms - stage.draw_ms) / 30.0f;
  if (stage.imgui && stage.panel) draw_panel_frame(stage);
}

void print_summary(const CrowdStage& stage, int frames, double wall_seconds) {
  const CrowdView& view = *stage.view;
  const auto& counts = view.scheduler().tier_counts();
  std::printf(
      "crowd:       %zu characters, %d frames, %.2f s of game time in %.2f s of wall time\n",
      view.characters(), frames, view.time(), wall_seconds);
  std::printf("tiers:       full %d, half %d, quarter %d, move_only %d (budget %.1f ms)\n",
              counts[0], counts[1], counts[2], counts[3], view.budget_ms());
  std::printf("frame:       update %.2f ms, draw %.2f ms (running means)\n", view.update_ms(),
              stage.draw_ms);
}

int run_headless(const ViewerOptions& options, CrowdStage& stage) {
  const float dt = options.dt > 0.0f ? options.dt : kDefaultRunDt;
  const int frames =
      options.frames > 0 ? options.frames : static_cast<int>(std::ceil(kHeadlessSeconds / dt));
  const std::string screenshot =
      options.screenshot_path.empty() ? "mm-viewer-crowd.png" : options.screenshot_path;
  const auto start = std::chrono::steady_clock::now();
  int written = 0;
  for (int frame = 1; frame <= frames; ++frame) {
    stage.camera.yaw = kHeadlessOrbitRate * stage.view->time();
    stage.view->step(dt, stage.camera.eye());
    const bool last = frame == frames;
    const bool every = options.every > 0 && frame % options.every == 0;
    if (!last && !every) continue;
    draw_frame(stage);
    stage.context->present();
    const std::filesystem::path out =
        last ? std::filesystem::path(screenshot) : numbered(screenshot, frame);
    if (Status s = write_png(stage.context->read_pixels(), out); !s) {
      std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
      return 1;
    }
    ++written;
  }
  print_summary(stage, frames,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::printf("wrote %d screenshot%s, the last as %s\n", written, written > 1 ? "s" : "",
              screenshot.c_str());
  return 0;
}

// Keys read as edges: T the tier colours, F1 the panel, F12 a screenshot, Esc quits.
struct CrowdKeys {
  static constexpr int kWatched[4] = {GLFW_KEY_T, GLFW_KEY_F1, GLFW_KEY_F12, GLFW_KEY_ESCAPE};
  bool down[4] = {false, false, false, false};
  bool pressed[4] = {false, false, false, false};
  void poll(GLFWwindow* window) {
    for (int k = 0; k < 4; ++k) {
      const bool now = glfwGetKey(window, kWatched[k]) == GLFW_PRESS;
      pressed[k] = now && !down[k];
      down[k] = now;
    }
  }
};

int run_windowed(const ViewerOptions& options, CrowdStage& stage) {
  GLFWwindow* window = stage.context->window();
  LiveInput live(window);  // the mouse and Q/E orbit the camera; before ImGui chains callbacks
  if (!start_imgui(stage)) std::fprintf(stderr, "mm-viewer: the panel cannot start\n");
  CrowdKeys keys;
  double last = glfwGetTime();
  int frame = 0;
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    const double now = glfwGetTime();
    const float wall_dt = static_cast<float>(now - last);
    last = now;
    const bool ui_mouse = stage.imgui && ImGui::GetIO().WantCaptureMouse;
    const bool ui_keyboard = stage.imgui && ImGui::GetIO().WantCaptureKeyboard;
    live.read(stage.camera, wall_dt, ui_mouse, ui_keyboard);  // the camera only
    if (!ui_keyboard) keys.poll(window);
    if (keys.pressed[0]) stage.tier_colours = !stage.tier_colours;
    if (keys.pressed[1]) stage.panel = !stage.panel;
    if (keys.pressed[3]) glfwSetWindowShouldClose(window, GLFW_TRUE);
    const float dt = options.dt > 0.0f ? options.dt : std::min(wall_dt, 0.1f);
    if (dt > 0.0f) stage.view->step(dt, stage.camera.eye());
    draw_frame(stage);
    ++frame;
    const bool done = options.frames > 0 && frame >= options.frames;
    if (keys.pressed[2] || (done && !options.screenshot_path.empty())) {
      const std::string path = done && !options.screenshot_path.empty()
                                   ? options.screenshot_path
                                   : "mm-viewer-crowd-" + std::to_string(frame) + ".png";
      const Status s = write_png(stage.context->read_pixels(), path);
      stage.message = s ? "saved " + path : s.message();
      std::printf("mm-viewer: %s\n", stage.message.c_str());
    }
    stage.context->present();
    if (done) break;
  }
  return 0;
}

}  // namespace

int run_crowd(const ViewerOptions& options, std::shared_ptr<const Database> database) {
  CrowdStage stage;
  Result<std::unique_ptr<GlContext>> context =
      options.headless ? GlContext::create_headless(options.width, options.height)
                       : GlContext::create_window(options.width, options.height, "mm-viewer crowd");
  if (!context) {
    std::fprintf(stderr, "mm-viewer: %s\n", context.message().c_str());
    return 1;
  }
  stage.context = std::move(*context);
  if (Status s = prepare(stage, options, std::move(database)); !s) {
    std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("mm-viewer: a crowd of %d characters, budget %.1f ms\n", options.crowd,
              options.budget_ms);
  if (!options.headless) return run_windowed(options, stage);
  if (options.panel && !start_imgui(stage)) {
    std::fprintf(stderr, "mm-viewer: the panel cannot start headless; drawing without it\n");
  }
  return run_headless(options, stage);
}

}  // namespace mm::viewer
