// mm-viewer: the motion-matching demo (`mm-viewer --help`; options in viewer_options.cpp).

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "body_source.hpp"
#include "crowd_run.hpp"
#include "database_source.hpp"
#include "mm/programs/number_parsing.hpp"
#include "mm/world/bullet_world.hpp"
#include "mm/world/level.hpp"
#include "run_loops.hpp"
#include "viewer_options.hpp"

namespace {

bool has_display() {
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x11 && *x11) || (wayland && *wayland);
}

// The level at `path` as a Bullet world, given to the scene with its triangles to draw.
mm::Result<std::unique_ptr<mm::BulletWorld>> open_world(const std::string& path,
                                                        mm::viewer::Scene& scene) {
  mm::Result<mm::Level> level = mm::load_level(path);
  if (!level) return level.error();
  mm::Result<mm::BulletWorld> made = mm::BulletWorld::create(*level);
  if (!made) return made.error();
  auto world = std::make_unique<mm::BulletWorld>(std::move(made).value());
  // Drawn in float world coordinates: the level's own origin added in double, rounded once.
  std::vector<glm::vec3> positions;
  positions.reserve(level->positions.size());
  for (const glm::vec3& p : level->positions) {
    positions.emplace_back(level->origin + glm::dvec3(p));
  }
  std::printf("mm-viewer: level %s, %zu triangles\n", path.c_str(), level->triangle_count());
  scene.set_level(world.get(), std::move(positions), std::move(level->indices));
  return world;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mm::viewer;
  ViewerOptions options;
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const int code = parse_viewer_options(args, options); code >= 0) return code;
  if (!options.headless && !has_display()) {
    std::fprintf(
        stderr,
        "mm-viewer: no display (DISPLAY is not set): run with --headless (--script FILE or "
        "--crowd N), "
        "or under xvfb-run\n");
    return 1;
  }

  mm::Result<std::shared_ptr<const mm::Database>> database =
      open_database(options.db_path, options.data_path);
  if (!database) {
    std::fprintf(stderr, "mm-viewer: %s\n", database.message().c_str());
    return 1;
  }
  if (options.crowd > 0) return run_crowd(options, *database);
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
  // The level's world lives as long as the scene that queries it.
  std::unique_ptr<mm::BulletWorld> world;
  if (!options.world_path.empty()) {
    mm::Result<std::unique_ptr<mm::BulletWorld>> made = open_world(options.world_path, **scene);
    if (!made) {
      std::fprintf(stderr, "mm-viewer: %s\n", made.message().c_str());
      return 1;
    }
    world = std::move(*made);
  }
  if (const auto start = mm::cli::parse_number_pair(options.start)) {
    (*scene)->controller().teleport_world(glm::dvec3(start->first, 0.0, start->second), 0.0f);
  }
  return options.headless ? run_headless(options, **scene) : run_windowed(options, **scene);
}
