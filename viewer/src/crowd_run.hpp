#pragma once
// `mm-viewer --crowd N`: the crowd of crowd_view.hpp in a window (mouse orbits and zooms, T
// shows the tiers' colours, F1 the panel, F12 a screenshot) or headless into screenshots, the
// camera going slowly round the crowd. Returns a process exit code.

#include <memory>

#include "mm/database/database.hpp"
#include "viewer_options.hpp"

namespace mm::viewer {

int run_crowd(const ViewerOptions& options, std::shared_ptr<const Database> database);

}  // namespace mm::viewer
