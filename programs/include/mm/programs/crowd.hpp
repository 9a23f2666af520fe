#pragma once
// The crowd benchmark (`mm crowd-bench`): many controllers over one shared database, each with
// its own varied scripted input, updated at a fixed rate on one or more threads. Characters are
// independent, so the result (every character's final pose) does not depend on the thread count.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/controller.hpp"
#include "mm/controller/crowd_scheduler.hpp"
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
  // Level of detail under a frame budget (crowd_scheduler.hpp); none: every character updated
  // every frame, as a plain loop of Controller::update. With it, every character is stepped by
  // the scheduler, threads take characters in chunks off a shared counter (the tiers are not
  // spread evenly over the index), and there is no replay: the windows are the run's own first
  // and last. The significance of a character is minus its distance to a camera point that
  // circles through the crowd's start area (crowd_camera), so tiers change during the run.
  // What such a crowd shows is the scheduler's poses, so its controllers compute no skinning
  // matrices (settings.compute_skinning is off for them): skinning is the renderer's work.
  std::optional<CrowdSchedulerSettings> lod;
};

// The camera point of a budgeted run at game time t (s): on an ellipse through the middle of
// the characters' start area (half its extent across), once round every 60 s.
glm::vec3 crowd_camera(const CrowdOptions& options, float t);

// One frame of a budgeted run: its times, and the steps by kind that made its work.
struct CrowdFrameRecord {
  float frame_ms = 0.0f;  // barrier to barrier
  float plan_ms = 0.0f;
  float work_ms = 0.0f;  // the threads' CPU time stepping, all threads
  // Controller updates by the tier of the character (a half- or quarter-rate character's
  // update frames only), and Controller::update_move_only steps.
  std::array<int, kCrowdTierCount> steps{};
  int searches = 0;         // updates that searched
  int transitions = 0;      // updates that jumped to a new frame
  float planned_us = 0.0f;  // the plan's work by the cost model, averaged over periods
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
  double frame_ms_mean = 0.0;  // wall time per frame for the whole crowd (planning included)
  double frame_ms_p99 = 0.0;   // nearest rank
  // Characters one frame of 1/60 s could update at this run's rate per character and thread
  // count: characters * (1/60 s) / frame time.
  int max_characters_60hz = 0;
  std::vector<glm::vec3> final_positions;         // root of each character after the run
  std::vector<glm::vec3> replay_final_positions;  // after the replay; empty without one
  // The displayed pose of every character after the run (character-major, global transforms):
  // the scheduler's with a budget, else the controllers' own.
  std::vector<Transform> final_poses;
  // Characters per tier on the last steady frame (all at full rate without a budget), the
  // fewest at full rate on any steady frame, and the cost model's mean planned work per frame
  // (us, all threads; 0 without a budget).
  std::array<int, kCrowdTierCount> tier_counts{};
  int full_min = 0;
  double planned_cost_us_mean = 0.0;
  // Budgeted runs: where the steady frames' wall time went (mean ms per frame): the plan
  // (significances and CrowdScheduler::plan, one thread), the longest thread's steps, and the
  // rest (the threads' hand-off at the frame's barriers, waits for a core); and every steady
  // frame's wall time (ms). Zero and empty without a budget.
  double plan_ms_mean = 0.0;
  double steps_ms_mean = 0.0;
  double sync_ms_mean = 0.0;
  // Budgeted runs: the threads' CPU time stepping characters per steady frame (ms, all threads
  // together): the work the plan asked for, whose p99 against its mean is how unevenly the
  // frames' work falls, whatever else runs on the machine.
  double work_ms_mean = 0.0;
  double work_ms_p99 = 0.0;
  std::vector<double> frame_ms;
  // Budgeted runs: what each steady frame did, for finding what makes a frame dear.
  std::vector<CrowdFrameRecord> frame_records;
};

// Runs the crowd. Fails on invalid options or settings.
Result<CrowdResult> run_crowd(std::shared_ptr<const ControllerDatabase> database,
                              const CrowdOptions& options);

// The scheduler's cost model measured on this machine: `characters` of the options' crowd, every
// one at a tier for two seconds, stepped on the threads the budget is planned for (options.lod);
// the tier's cost is the CPU time the threads spent stepping, per character and frame (us;
// clock_gettime(CLOCK_THREAD_CPUTIME_ID) around each thread's share of a frame), the median of
// five samples over the last second (one noisy sample does not move it).
// Measured at the crowd's size, it holds the cache misses of a large crowd; measured as CPU time
// rather than wall time times threads, it leaves out the time a thread waited for a core that
// other processes held, or at the frame's barrier for the other thread.
Result<std::array<float, kCrowdTierCount>> calibrate_crowd_tiers(
    std::shared_ptr<const ControllerDatabase> database, const CrowdOptions& options,
    int characters);

// The ground metrics (ground_metrics.hpp) of the displayed poses of a crowd all at one tier,
// averaged over its characters.
struct CrowdTierQuality {
  double foot_skate_geom_cm_s_mean = 0.0;
  double foot_penetration_cm_mean = 0.0;
  double foot_penetration_cm_max = 0.0;  // the deepest of any character
  double toe_clearance_cm_min = 0.0;     // the lowest of any character
  double hips_vertical_accel_p99_m_s2 = 0.0;
};
Result<std::array<CrowdTierQuality, kCrowdTierCount>> crowd_tier_quality(
    std::shared_ptr<const ControllerDatabase> database, const CrowdOptions& options, int characters,
    float seconds);

}  // namespace mm
