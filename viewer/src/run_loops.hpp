#pragma once
// The two ways mm-viewer runs a scene: in a window with live (or replayed) input and the panel,
// or headless on a script at a fixed dt, writing screenshots, the run plot and a summary.
// Both return a process exit code.

#include "scene.hpp"
#include "viewer_options.hpp"

namespace mm::viewer {

int run_windowed(const ViewerOptions& options, Scene& scene);
int run_headless(const ViewerOptions& options, Scene& scene);

}  // namespace mm::viewer
