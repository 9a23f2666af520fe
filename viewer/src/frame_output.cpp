// The end of a frame: the ImGui panel and the numbered screenshot (frame_output.hpp).

#include "frame_output.hpp"

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cstdio>

#include "mm/controller/script.hpp"

namespace mm::viewer {

bool start_imgui(const GlContext& context) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui::GetStyle().Alpha = 0.92f;
  if (context.window()) ImGui_ImplGlfw_InitForOpenGL(context.window(), true);
  if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
    if (context.window()) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    return false;
  }
  return true;
}

void stop_imgui(const GlContext& context) {
  ImGui_ImplOpenGL3_Shutdown();
  if (context.window()) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void draw_imgui_frame(const GlContext& context, bool& laid_out,
                      const std::function<void()>& panel) {
  const int passes = !context.window() && !laid_out ? 2 : 1;
  laid_out = true;
  for (int pass = 0; pass < passes; ++pass) {
    ImGui_ImplOpenGL3_NewFrame();
    if (context.window()) {
      ImGui_ImplGlfw_NewFrame();
    } else {
      int width = 0, height = 0;
      context.framebuffer_size(width, height);
      ImGui::GetIO().DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
      ImGui::GetIO().DeltaTime = kDefaultRunDt;
    }
    ImGui::NewFrame();
    panel();
    ImGui::Render();
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

std::filesystem::path numbered(const std::string& path, int frame) {
  std::filesystem::path p(path);
  char suffix[16];
  std::snprintf(suffix, sizeof suffix, "-%06d", frame);
  return p.parent_path() / (p.stem().string() + suffix + p.extension().string());
}

}  // namespace mm::viewer
