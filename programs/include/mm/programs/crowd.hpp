#pragma once
// The crowd benchmark (`mm crowd-bench`): many controllers over one shared database, each with
// its own varied scripted input, updated at a fixed rate on one or more threads. Characters are
// independent, so the result (every character's final pose) does not depend on the thread count.

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/controller/world.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// The length (s of game time) of the windows at the start and at the end of a run whose update
// costs CrowdResult compares: a controller's cost must not creep up over a long run (its
// decaying state shrinking into slow subnormal floats did once, and kept growing for a minute).
// The machine's own speed drifts over seconds (clock boost, other tenants of a virtual machine)
// by as much as the creep this comparison is there to see, so the first window is not timed at
// the start of the run: over the run's last window, a second, fresh controller per character
// replays that character's first window, updated right beside the aged one in the same frames,
// so both windows are timed on the machine as it is then. A run of one window or less has one
// window, the whole run, and no replay.
inline constexpr float kCrowdWindowSeconds = 20.0f;

struct CrowdOptions {
  int characters = 100;
  float seconds = 10.0f;  // of game time
  float dt = kDefaultRunDt;
  int threads = 1;  // >= 1; characters are split into contiguous slices
  ControllerSettings settings;
  // The world every character runs in (world.hpp; not owned); null: the flat plane.
  const WorldQueries* world = nullptr;
  // Where the characters start: their 3 m grid wrapped into this rectangle (x0, z0, x1, z1,
  // world metres) when it has an area, else the grid from the origin on.
  glm::vec4 start_area{0.0f};
};

// The steady figures (mean, p99, search share, frame time, max characters) are over the frames
// before the last window when the run has a replay (its frames carry twice the work), else over
// the whole run.
struct CrowdResult {
  int threads = 0;
  int frames = 0;
  double wall_seconds = 0.0;    // the whole run, replay included
  double update_us_mean = 0.0;  // per character per frame (each update timed)
  double update_us_p99 = 0.0;
  double update_us_first_window = 0.0;  // replayed beside the last window: kCrowdWindowSeconds
  double update_us_last_window = 0.0;
  double search_share = 0.0;   // time in search / time in update
  double world_share = 0.0;    // time in the world's queries / time in update (0 without one)
  double frame_ms_mean = 0.0;  // wall time per frame for the whole crowd
  // Characters one frame of 1/60 s could update at this run's rate per character and thread
  // count: characters * (1/60 s) / frame time.
  int max_characters_60hz = 0;
  std::vector<glm::vec3> final_positions;         // root of each character after the run
  std::vector<glm::vec3> replay_final_positions;  // after the replay; empty without one
};

// Runs the crowd. Fails on invalid options or settings.
Result<CrowdResult> run_crowd(std::shared_ptr<const ControllerDatabase> database,
                              const CrowdOptions& options);

}  // namespace mm
