// mm-crowd-example: the smallest complete program built on the mm motion-matching runtime.
//
// It does what a game does with mm, without the rendering:
//   1. load a motion database (a .mmdb file, built offline from motion capture by `mm build`);
//   2. wrap it once in a ControllerDatabase, the read-only part all characters share;
//   3. create one Controller per character and place it in the world;
//   4. every frame, give each controller the frame's time step and that character's input
//      (a gamepad's sticks and buttons in a game; scripted input here), then read its pose;
//   5. print where every character ended up.
//
// Usage: mm-crowd-example DATABASE.mmdb [characters=100] [seconds=3]
//
// Make a database and run (see README.md, "Embedding", for building this against an install):
//   mm build ../shared/mocap/bandai-normal -o walk.mmdb
//   mm-crowd-example walk.mmdb 100 3
//
// Units throughout are metres, seconds and radians; Y is up and the ground is y = 0.

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/controller/controller.hpp"   // ControllerDatabase, Controller, ControllerInput
#include "mm/controller/script.hpp"       // varied_input_script: made-up input for the demo
#include "mm/database/database_file.hpp"  // load_database

namespace {

const char* const kUsage =
    "usage: mm-crowd-example DATABASE.mmdb [characters=100] [seconds=3]\n"
    "Runs that many characters for that many seconds of game time at 60 Hz, each with its own\n"
    "varied input, and prints where each one ended up.\n";

// Reads a whole command-line argument as a number; false on anything else ("12abc", "").
template <class T>
bool parse_number(std::string_view text, T& value) {
  const char* end = text.data() + text.size();
  const auto [last, error] = std::from_chars(text.data(), end, value);
  return error == std::errc() && last == end;
}

// The yaw of a character's facing in degrees: 0 faces world +Z, 90 faces +X (a rotation about
// +Y, as teleport() and the camera yaw use).
float yaw_degrees(const glm::quat& rotation) {
  const glm::vec3 forward = rotation * glm::vec3(0.0f, 0.0f, 1.0f);
  return glm::degrees(std::atan2(forward.x, forward.z));
}

struct Options {
  const char* database_path = nullptr;
  int characters = 100;
  float seconds = 3.0f;
};

// The command line: returns -1 to go on, else the exit code (0 after --help, 2 after a misuse).
int parse_arguments(int argc, char** argv, Options& options) {
  if (argc == 2 && (std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (argc < 2 || argc > 4) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  options.database_path = argv[1];
  if (argc > 2 && (!parse_number(argv[2], options.characters) || options.characters < 1 ||
                   options.characters > 100000)) {
    std::fprintf(
        stderr,
        "mm-crowd-example: characters must be a whole number in [1, 100000], not '%s'\n\n%s",
        argv[2], kUsage);
    return 2;
  }
  if (argc > 3 && (!parse_number(argv[3], options.seconds) || !(options.seconds > 0.0f) ||
                   !(options.seconds <= 3600.0f))) {
    std::fprintf(stderr, "mm-crowd-example: seconds must be a number in (0, 3600], not '%s'\n\n%s",
                 argv[3], kUsage);
    return 2;
  }
  return -1;
}

// ---- Loading (once, at level load; nothing here belongs in a frame).
// Everything that can fail in mm (files, settings) returns a Result: test it, and on failure
// its message says what went wrong and where (the file, the section). Nothing throws.
mm::Result<std::shared_ptr<const mm::ControllerDatabase>> load_shared_database(
    const char* path, const mm::ControllerSettings& settings) {
  mm::Result<mm::Database> loaded = mm::load_database(path);
  if (!loaded) return loaded.error();
  // The ControllerDatabase holds what every character reads and nobody writes: the animation
  // data, the search structures and the speeds measured on the data. Make one and share it, so
  // a hundred characters cost one copy of the animation, not a hundred.
  mm::Result<std::shared_ptr<const mm::ControllerDatabase>> shared = mm::ControllerDatabase::create(
      std::make_shared<const mm::Database>(std::move(loaded).value()));
  if (!shared) return shared.error();
  // The search structure is built on first use. Build it now, during loading, so that the
  // first game frame does not pay for it.
  if (mm::Result<const mm::Searcher*> searcher = (*shared)->searcher(settings.search_method);
      !searcher) {
    return searcher.error();
  }
  return shared;
}

// ---- Spawning. One Controller per character: it owns that character's state (where it is,
// which clip it plays, its transition) and every buffer update() needs, allocated here.
// Characters stand on a square grid 3 m apart so that none starts inside another.
struct Crowd {
  std::vector<mm::Controller> controllers;
  std::vector<glm::vec3> start_positions;
  std::vector<mm::InputScript> inputs;
};

mm::Result<Crowd> spawn_crowd(const std::shared_ptr<const mm::ControllerDatabase>& shared,
                              const mm::ControllerSettings& settings, int characters,
                              float seconds) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<float>(characters))));
  constexpr float kSpacing = 3.0f;  // metres
  Crowd crowd;
  crowd.controllers.reserve(static_cast<size_t>(characters));
  crowd.start_positions.reserve(static_cast<size_t>(characters));
  crowd.inputs.reserve(static_cast<size_t>(characters));
  for (int i = 0; i < characters; ++i) {
    mm::Result<mm::Controller> controller = mm::Controller::create(shared, settings);
    if (!controller) return controller.error();
    const glm::vec3 spot(static_cast<float>(i % columns) * kSpacing, 0.0f,
                         static_cast<float>(i / columns) * kSpacing);
    controller->teleport(spot, 0.0f);  // facing +Z (yaw 0)
    crowd.controllers.push_back(std::move(controller).value());
    crowd.start_positions.push_back(spot);
    // Stand-in for players or AI: a reproducible script per character that changes direction
    // every 0.5 to 3 s, sometimes stops, runs or strafes. In a game you fill the
    // mm::ControllerInput yourself each frame instead, for example:
    //   mm::ControllerInput input;
    //   input.left_stick = {pad.left_x, pad.left_y};  // x right, y away from the camera
    //   input.camera_yaw = camera.yaw;                 // sticks are read relative to the camera
    //   input.run = pad.held(Button::A);
    crowd.inputs.push_back(mm::varied_input_script(static_cast<uint32_t>(i), seconds));
  }
  return crowd;
}

// ---- The game loop: a fixed step of dt. Each update() advances one character by dt of game
// time: it reads the input, searches the database for the frame that best continues the
// motion when needed, blends into it, moves the character and plants its feet. update() never
// allocates, locks or touches files, and characters do not share mutable state, so a game can
// split the controllers over its worker threads; this example keeps to one thread.
// Returns the wall-clock seconds the frames took.
double run_game_loop(Crowd& crowd, int frames, float dt) {
  const auto wall_start = std::chrono::steady_clock::now();
  for (int frame = 0; frame < frames; ++frame) {
    const float game_time = static_cast<float>(frame) * dt;
    for (size_t i = 0; i < crowd.controllers.size(); ++i) {
      const mm::ControllerInput input = crowd.inputs[i].at(game_time);
      crowd.controllers[i].update(dt, input);
      // This is where a game reads the pose back for rendering: global_transforms() (one
      // world transform per joint of the database's skeleton) or skinning_matrices(). Far
      // from the world origin: origin() (double) plus origin_transforms() relative to it.
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
}

// ---- Results. root_transform() is joint 0, the "simulation root": the character's ground
// position (y = 0) and facing, the thing gameplay code cares about.
void print_results(const Crowd& crowd, int frames, float dt, double wall_seconds) {
  int moved = 0;
  double total_distance = 0.0;
  for (size_t i = 0; i < crowd.controllers.size(); ++i) {
    const mm::Transform& root = crowd.controllers[i].root_transform();
    const glm::vec3& start = crowd.start_positions[i];
    const float distance =
        glm::length(glm::vec2(root.translation.x - start.x, root.translation.z - start.z));
    total_distance += distance;
    if (distance > 0.1f) ++moved;
    std::printf("character %zu: x=%.3f z=%.3f yaw_deg=%.1f (started at x=%.3f z=%.3f)\n", i,
                root.translation.x, root.translation.z, yaw_degrees(root.rotation), start.x,
                start.z);
  }
  const double characters = static_cast<double>(crowd.controllers.size());
  std::printf(
      "summary: %zu characters, %d frames at 60 Hz (%.2f s of game time); %d moved more than "
      "0.1 m, %.2f m from the start on average; %.1f us per character update\n",
      crowd.controllers.size(), frames, static_cast<double>(frames) * dt, moved,
      total_distance / characters,
      frames > 0 ? wall_seconds * 1e6 / (static_cast<double>(frames) * characters) : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const int code = parse_arguments(argc, argv, options); code >= 0) return code;
  // Every tunable (speeds, blend times, foot locking...) with its unit and default is a field
  // of ControllerSettings (controller.hpp). This example keeps the defaults.
  const mm::ControllerSettings settings;
  auto shared = load_shared_database(options.database_path, settings);
  if (!shared) {
    std::fprintf(stderr, "mm-crowd-example: %s\n", shared.message().c_str());
    return 1;
  }
  auto crowd = spawn_crowd(*shared, settings, options.characters, options.seconds);
  if (!crowd) {
    std::fprintf(stderr, "mm-crowd-example: %s\n", crowd.message().c_str());
    return 1;
  }
  constexpr float kDt = 1.0f / 60.0f;
  const int frames = static_cast<int>(std::lround(options.seconds / kDt));
  const double wall_seconds = run_game_loop(*crowd, frames, kDt);
  print_results(*crowd, frames, kDt, wall_seconds);
  return 0;
}
