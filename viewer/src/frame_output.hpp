#pragma once
// What both run loops (run_loops.hpp: one character; crowd_run.hpp: the crowd) do at the end of
// a frame: start and stop ImGui, draw the panel, and name the frame's own screenshot.

#include <filesystem>
#include <functional>
#include <string>

#include "gl_context.hpp"

namespace mm::viewer {

// ImGui on `context` (its GLFW window's input when it has one), dark, no imgui.ini left in the
// working folder; false, with nothing left started, when its OpenGL backend cannot start.
bool start_imgui(const GlContext& context);
// Undoes start_imgui(), before the context goes.
void stop_imgui(const GlContext& context);

// One ImGui frame around `panel` (which makes the ImGui calls), drawn into the current
// framebuffer. Headless runs may draw one frame only, and ImGui measures an auto-sized window on
// its first frame and hides it, so a headless context's first call lays the panel out twice
// (`laid_out` remembers that it has).
void draw_imgui_frame(const GlContext& context, bool& laid_out, const std::function<void()>& panel);

// OUT.png -> OUT-000120.png for frame 120's own screenshot.
std::filesystem::path numbered(const std::string& path, int frame);

}  // namespace mm::viewer
