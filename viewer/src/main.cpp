// mm-viewer: the motion-matching demo (`mm-viewer --help`; options in viewer_options.cpp).

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "body_source.hpp"
#include "database_source.hpp"
#include "run_loops.hpp"
#include "viewer_options.hpp"

namespace {

bool has_display() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x11 && *x11) || (wayland && *wayland);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mm::viewer;
  ViewerOptions options;
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const int code = parse_viewer_options(args, options); code >= 0) return code;
  if (!options.headless && !has_display()) {
    std::fprintf(stderr,
                 "mm-viewer: no display (DISPLAY is not set): run with --headless --script FILE, "
                 "or under xvfb-run\n");
    return 1;
  }

  mm::Result<std::shared_ptr<const mm::Database>> database =
      open_database(options.db_path, options.data_path);
  if (!database) {
    std::fprintf(stderr, "mm-viewer: %s\n", database.message().c_str());
    return 1;
  }
  mm::Result<BodySource> body = make_body(**database, options);
  if (!body) {
    std::fprintf(stderr, "mm-viewer: %s\n", body.message().c_str());
    return 1;
  }
  std::printf("mm-viewer: %s\n", body->description.c_str());
  mm::Result<std::unique_ptr<Scene>> scene =
      Scene::create(*database, options.settings, std::move(body->mesh), options.weights,
                    std::move(body->reweigh));
  if (!scene) {
    std::fprintf(stderr, "mm-viewer: %s\n", scene.message().c_str());
    return 1;
  }
  return options.headless ? run_headless(options, **scene) : run_windowed(options, **scene);
}
