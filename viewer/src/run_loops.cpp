#include "run_loops.hpp"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "frame_output.hpp"
#include "gl_context.hpp"
#include "input_recorder.hpp"
#include "live_input.hpp"
#include "mm/controller/script.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "panel.hpp"
#include "style_selector.hpp"

namespace mm::viewer {
namespace {

// What both loops draw with: the context, the renderer, the camera and the panel's state.
struct Stage {
  std::unique_ptr<GlContext> context;
  std::optional<Renderer> renderer;
  OrbitCamera camera;
  PanelState panel;
  bool imgui = false;
  bool imgui_laid_out = false;

  ~Stage() {
    if (imgui) stop_imgui(*context);
    renderer.reset();  // its GL objects go before the context
  }
};

Status prepare(Stage& stage, const ViewerOptions& options, Scene& scene) {
  Result<Renderer> renderer = Renderer::create();
  if (!renderer) return Error{renderer.message()};
  stage.renderer.emplace(std::move(*renderer));
  stage.renderer->set_body_triangles(scene.body().mesh().mesh.indices);
  stage.camera.snap(scene.controller().root_transform().translation);
  if (!std::isnan(options.view_pitch_deg))
    stage.camera.pitch = glm::radians(options.view_pitch_deg);
  if (!std::isnan(options.view_distance)) stage.camera.distance = options.view_distance;
  stage.panel.skinning = options.skinning;
  scene.toggles = options.toggles;
  return Status::success();
}

// Dear ImGui on the context: with GLFW's input in a window; headless it only draws.
bool start_imgui(Stage& stage) {
  stage.imgui = start_imgui(*stage.context);
  return stage.imgui;
}

void draw_frame(Stage& stage, Scene& scene, bool show_panel) {
  scene.draw(*stage.renderer, *stage.context, stage.camera, stage.panel.show_body);
  if (!stage.imgui) return;
  draw_imgui_frame(*stage.context, stage.imgui_laid_out, [&] {
    if (show_panel) draw_panel(scene, stage.panel);
  });
}

Status save_screenshot(const GlContext& context, const std::filesystem::path& path) {
  return write_png(context.read_pixels(), path);
}

void print_summary(const Scene& scene, double wall_seconds) {
  const std::vector<RunSample>& run = scene.run();
  double walked = 0.0;
  int transitions = 0, standing = 0;
  for (size_t i = 0; i < run.size(); ++i) {
    if (i > 0) walked += glm::length(run[i].character - run[i - 1].character);
    transitions += run[i].transition;
    standing += run[i].standing;
  }
  const ControllerDebug& d = scene.controller().debug();
  std::printf("run:         %zu frames, %.2f s of game time in %.2f s of wall time\n", run.size(),
              scene.time(), wall_seconds);
  std::printf(
      "character:   walked %.2f m, %d transitions (%.2f per s), %d of %zu frames standing\n",
      walked, transitions, scene.time() > 0 ? transitions / scene.time() : 0.0, standing,
      run.size());
  std::printf("controller:  %d searches, update %.1f us and search %.1f us (running means)\n",
              d.searches, scene.times().update * 1e6, scene.times().search * 1e6);
}

// Where the character is in the last screenshot, for whoever checks the image (tests).
void print_character_box(const Stage& stage, const Scene& scene) {
  int width = 0, height = 0;
  stage.context->framebuffer_size(width, height);
  const glm::vec4 box = scene.screen_box(stage.camera, width, height);
  std::printf("character in the last screenshot: pixels x %.0f..%.0f, y %.0f..%.0f\n", box.x, box.z,
              box.y, box.w);
}

Status write_plot(const ViewerOptions& options, const Scene& scene) {
  if (options.plot_path.empty()) return Status::success();
  // In a level, its outline under the run: the steps, ramps and walls the run met.
  const std::vector<OutlineSegment> outline =
      level_outline(scene.level_positions(), scene.level_indices());
  if (Status s = write_png(render_run_plot(scene.run(), {}, outline), options.plot_path); !s) {
    return s;
  }
  std::printf("wrote the run plot %s\n", options.plot_path.c_str());
  return Status::success();
}

// A script with its style=NAME columns resolved against the scene's database.
Result<InputScript> load_scene_script(const std::string& path, const Scene& scene) {
  Result<InputScript> script = load_input_script(path);
  if (!script) return script;
  if (Status s = script->resolve_styles(scene.controller().controller_database(), path); !s) {
    return Error{s.message()};
  }
  return script;
}

// ---- Headless.

}  // namespace

int run_headless(const ViewerOptions& options, Scene& scene) {
  Result<InputScript> script = load_scene_script(options.script_path, scene);
  if (!script) {
    std::fprintf(stderr, "mm-viewer: %s\n", script.message().c_str());
    return 1;
  }
  const float dt = options.dt > 0.0f ? options.dt : kDefaultRunDt;
  // The same bounds as mm eval (script.hpp): a run too long is refused before anything is
  // built for it.
  const Result<int> script_frames = scripted_run_frames(script->duration() + 2.0f, dt);
  if (!script_frames) {
    std::fprintf(stderr, "mm-viewer: %s: %s\n", options.script_path.c_str(),
                 script_frames.message().c_str());
    return 1;
  }
  const int frames = options.frames > 0 ? options.frames : *script_frames;
  Stage stage;
  Result<std::unique_ptr<GlContext>> context =
      GlContext::create_headless(options.width, options.height);
  if (!context) {
    std::fprintf(stderr, "mm-viewer: %s\n", context.message().c_str());
    return 1;
  }
  stage.context = std::move(*context);
  if (Status s = prepare(stage, options, scene); !s) {
    std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
    return 1;
  }
  if (options.panel && !start_imgui(stage)) {
    std::fprintf(stderr, "mm-viewer: the panel cannot start headless; drawing without it\n");
  }
  stage.panel.input_source = "script: " + options.script_path;

  const auto start = std::chrono::steady_clock::now();
  int written = 0;
  for (int frame = 1; frame <= frames; ++frame) {
    const ControllerInput input = script->at(scene.time());
    scene.step(dt, input, stage.panel.skinning);
    stage.camera.yaw = input.camera_yaw + glm::radians(options.view_turn_deg);
    stage.camera.follow(scene.controller().root_transform().translation, dt);
    const bool last = frame == frames;
    const bool every = options.every > 0 && frame % options.every == 0;
    if (options.screenshot_path.empty() || (!last && !every)) continue;
    draw_frame(stage, scene, options.panel);
    stage.context->present();
    const std::filesystem::path out = last ? std::filesystem::path(options.screenshot_path)
                                           : numbered(options.screenshot_path, frame);
    if (Status s = save_screenshot(*stage.context, out); !s) {
      std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
      return 1;
    }
    ++written;
  }
  print_summary(scene,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (written > 0) {
    std::printf("wrote %d screenshot%s, the last as %s\n", written, written > 1 ? "s" : "",
                options.screenshot_path.c_str());
    print_character_box(stage, scene);
  }
  if (Status s = write_plot(options, scene); !s) {
    std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}

// ---- Windowed.

namespace {

struct WindowKeys {
  bool panel = true;
  bool screenshot = false;
};

void on_key(GLFWwindow* window, int key, WindowKeys& keys) {
  if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(window, GLFW_TRUE);
  if (key == GLFW_KEY_F1) keys.panel = !keys.panel;
  if (key == GLFW_KEY_F12) keys.screenshot = true;
}

// Keys are read as edges (one press, one action); the held keys of the controls are polled.
void poll_keys(GLFWwindow* window, WindowKeys& keys, bool (&was_down)[3]) {
  const int watched[3] = {GLFW_KEY_ESCAPE, GLFW_KEY_F1, GLFW_KEY_F12};
  for (int i = 0; i < 3; ++i) {
    const bool down = glfwGetKey(window, watched[i]) == GLFW_PRESS;
    if (down && !was_down[i]) on_key(window, watched[i], keys);
    was_down[i] = down;
  }
}

}  // namespace

int run_windowed(const ViewerOptions& options, Scene& scene) {
  std::optional<InputScript> script;
  if (!options.script_path.empty()) {
    Result<InputScript> loaded = load_scene_script(options.script_path, scene);
    if (!loaded) {
      std::fprintf(stderr, "mm-viewer: %s\n", loaded.message().c_str());
      return 1;
    }
    script = std::move(*loaded);
  }
  Stage stage;
  Result<std::unique_ptr<GlContext>> context =
      GlContext::create_window(options.width, options.height, "mm-viewer");
  if (!context) {
    std::fprintf(stderr, "mm-viewer: %s (without a display, use --headless)\n",
                 context.message().c_str());
    return 1;
  }
  stage.context = std::move(*context);
  if (Status s = prepare(stage, options, scene); !s) {
    std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
    return 1;
  }
  GLFWwindow* window = stage.context->window();
  LiveInput live(window);  // before ImGui, which chains the callbacks it finds
  if (!start_imgui(stage)) std::fprintf(stderr, "mm-viewer: the panel cannot start\n");
  InputRecorder recorder;
  StyleSelector styles;
  if (!script) {
    stage.panel.recorder = &recorder;
    stage.panel.styles = &styles;
    stage.panel.record_path =
        options.record_path.empty() ? "mm-viewer-input.txt" : options.record_path;
    if (!options.record_path.empty()) recorder.start(0.0f);
  }

  WindowKeys keys;
  keys.panel = options.panel;
  bool was_down[3] = {false, false, false};
  double last = glfwGetTime();
  int frame = 0;
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    const double now = glfwGetTime();
    const float wall_dt = static_cast<float>(now - last);
    last = now;
    scene.note_frame_time(wall_dt);
    const bool ui_mouse = stage.imgui && ImGui::GetIO().WantCaptureMouse;
    const bool ui_keyboard = stage.imgui && ImGui::GetIO().WantCaptureKeyboard;
    if (!ui_keyboard) poll_keys(window, keys, was_down);
    ControllerInput input = live.read(stage.camera, wall_dt, ui_mouse, ui_keyboard);
    stage.panel.input_source = script ? "script: " + options.script_path : live.device();
    const ControllerDatabase& db = scene.controller().controller_database();
    if (script) {
      input = script->at(scene.time());
      stage.camera.yaw = input.camera_yaw + glm::radians(options.view_turn_deg);
    } else {
      styles.poll(window, db, !ui_keyboard);
      styles.apply(input);
      input.tag_bits = db.tag_bits(input.tag);  // resolved here, not in the update
    }
    const float dt = stage.panel.paused
                         ? 0.0f
                         : (options.dt > 0.0f ? options.dt : wall_dt) * stage.panel.time_scale;
    if (dt > 0.0f) {
      // Stamped with the time it takes effect, as a script's line is read (script.hpp).
      recorder.record(scene.time(), input,
                      input.style >= 0 ? StyleSelector::name(db, input.style) : "");
      scene.step(dt, input, stage.panel.skinning);
    }
    stage.camera.follow(scene.controller().root_transform().translation, dt);
    draw_frame(stage, scene, keys.panel);
    ++frame;
    const bool done = options.frames > 0 && frame >= options.frames;
    if (keys.screenshot || (done && !options.screenshot_path.empty())) {
      const std::string path =
          done && !options.screenshot_path.empty()
              ? options.screenshot_path
              : "mm-viewer-" + std::to_string(clamped_integer<long>(now * 1000)) + ".png";
      const Status s = save_screenshot(*stage.context, path);
      stage.panel.message = s ? "saved " + path : s.message();
      std::printf("mm-viewer: %s\n", stage.panel.message.c_str());
      if (done) print_character_box(stage, scene);
      keys.screenshot = false;
    }
    stage.context->present();
    if (done) break;
  }
  int code = 0;
  if (recorder.active()) {
    const Status s = recorder.save(stage.panel.record_path);
    std::printf(
        "mm-viewer: %s\n",
        s ? ("recorded the input into " + stage.panel.record_path).c_str() : s.message().c_str());
    if (!s) code = 1;
  }
  if (Status s = write_plot(options, scene); !s) {
    std::fprintf(stderr, "mm-viewer: %s\n", s.message().c_str());
    code = 1;
  }
  return code;
}

}  // namespace mm::viewer
