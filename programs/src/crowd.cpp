// The crowd benchmark: controllers in contiguous slices per thread, a barrier per frame as in a
// game loop, every update timed.

#include "mm/programs/crowd.hpp"
#include "mm/programs/ground_metrics.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "statistics.hpp"

#include <algorithm>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <span>
#include <thread>

#include <time.h>

namespace mm {

namespace {

// Where character i starts: on a grid, so a viewer of the run sees the characters apart;
// wrapped into `area` (x0, z0, x1, z1) when it has one.
glm::vec3 start_position(size_t i, const glm::vec4& area) {
  glm::vec3 p(static_cast<float>(i % 32) * 3.0f, 0.0f, static_cast<float>(i / 32) * 3.0f);
  const float width = area.z - area.x, depth = area.w - area.y;
  if (width > 0.0f && depth > 0.0f) {
    p.x = area.x + std::fmod(p.x, width);
    p.z = area.y + std::fmod(p.z + 1.5f * static_cast<float>(i / (32 * 32)), depth);
  }
  return p;
}

// A world that times its own queries, for the share of the update spent in them: the wall time
// of every call, summed over all threads.
class TimedWorld final : public WorldQueries {
 public:
  explicit TimedWorld(const WorldQueries& world) : world_(world) {}
  void probe_ground(const glm::dvec3& origin, std::span<const GroundProbe> probes,
                    std::span<GroundHit> hits) const override {
    const auto start = std::chrono::steady_clock::now();
    world_.probe_ground(origin, probes, hits);
    add(start);
  }
  void sweep(const glm::dvec3& origin, std::span<const ShapeSweep> sweeps,
             std::span<SweepHit> hits) const override {
    const auto start = std::chrono::steady_clock::now();
    world_.sweep(origin, sweeps, hits);
    add(start);
  }
  double seconds() const { return static_cast<double>(nanoseconds_.load()) * 1e-9; }

 private:
  void add(std::chrono::steady_clock::time_point start) const {
    const auto elapsed = std::chrono::steady_clock::now() - start;
    nanoseconds_.fetch_add(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count(),
                           std::memory_order_relaxed);
  }
  const WorldQueries& world_;
  mutable std::atomic<int64_t> nanoseconds_{0};
};

// The frames a run's steady state leaves out at its start (the first searches, every character
// at once): one second of game time, when the steady frames are at least twice that.
size_t warm_up_frames(size_t steady, float dt) {
  const size_t second = clamped_integer<size_t>(std::ceil(1.0f / dt));
  return steady >= 2 * second ? second : 0;
}

// The nearest-rank p99 of `values` (reordered).
template <typename T>
T p99(std::span<T> values) {
  const size_t count = values.size();
  const size_t rank = std::min(
      count - 1, clamped_integer<size_t>(std::ceil(0.99 * static_cast<double>(count))) - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank),
                   values.end());
  return values[rank];
}

// Controllers for `n` characters, each at its start position.
Result<std::vector<Controller>> make_characters(
    const std::shared_ptr<const ControllerDatabase>& database, const CrowdOptions& options,
    const WorldQueries* world, size_t n) {
  std::vector<Controller> characters;
  characters.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Result<Controller> c = Controller::create(database, options.settings);
    if (!c) return Error{c.message()};
    c->set_world(world);
    c->teleport(start_position(i, options.start_area), 0.0f);
    characters.push_back(std::move(c).value());
  }
  return characters;
}

// What the frames of a run measured, frame-major: update_us[f * characters + i] (runs at full
// rate; a budgeted run keeps its sampled steps' times in fixed memory, below).
struct CrowdTimes {
  std::vector<float> update_us;
  std::vector<double> frame_seconds;   // barrier to barrier
  std::vector<double> search_seconds;  // per character, over the frames before the replay
  std::vector<double> replay_seconds;  // per character, the replay's updates
  // Budgeted runs: the CPU time each thread spent stepping characters, per frame (frame-major,
  // threads per frame), which a thread descheduled by other processes is not charged for.
  std::vector<double> step_cpu_seconds;
  // Budgeted runs: the plan's wall time (significances and CrowdScheduler::plan, on one thread)
  // per frame, and each thread's wall time stepping characters (frame-major).
  std::vector<double> plan_seconds;
  std::vector<double> step_wall_seconds;
  // Budgeted runs: each thread's steps by kind, per frame (frame-major, threads per frame).
  std::vector<CrowdFrameRecord> step_records;
  // Budgeted runs: the timed steps (one in kTimedEvery), per frame and thread their summed time
  // (us) and count (frame-major), and per thread the histogram of their times for the p99: memory
  // by frames and threads, not by frames and characters (a 120 s run of 10,000 characters kept
  // 288 MB of per-step times).
  std::vector<double> timed_us_sum;
  std::vector<uint32_t> timed_count;
  std::vector<detail::PercentileHistogram> timed_us;
};

// The mean time (us) of a budgeted run's timed steps over frames [first, last).
double mean_timed_us(const CrowdTimes& times, size_t first, size_t last) {
  const size_t threads = times.timed_us.size();
  double sum = 0.0;
  size_t count = 0;
  for (size_t k = first * threads; k < last * threads; ++k) {
    sum += times.timed_us_sum[k];
    count += times.timed_count[k];
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

// The mean update time (microseconds) over frames [first, last), of the updates that were
// timed (a budgeted run times a sample of them; the others are NaN).
double mean_update_us(const CrowdTimes& times, size_t characters, size_t first, size_t last) {
  double sum = 0.0;
  size_t timed = 0;
  for (size_t k = first * characters; k < last * characters; ++k) {
    if (std::isnan(times.update_us[k])) continue;
    sum += times.update_us[k];
    ++timed;
  }
  return timed > 0 ? sum / static_cast<double>(timed) : 0.0;
}

// The figures of a run whose frames [replay_start, end) also updated the replay (none when
// replay_start is the end): the steady figures come from the frames before the replay, and
// the first window from the replay, when there is one.
CrowdResult summarize(CrowdTimes& times, size_t n, size_t window, size_t replay_start, float dt) {
  const size_t frames = times.frame_seconds.size();
  const size_t steady = replay_start;
  CrowdResult result;
  const bool sampled = times.update_us.empty();  // a budgeted run's fixed-memory timings
  result.update_us_mean =
      sampled ? mean_timed_us(times, 0, steady) : mean_update_us(times, n, 0, steady);
  double search = 0.0, replay = 0.0;
  for (size_t i = 0; i < n; ++i) {
    search += times.search_seconds[i];
    replay += times.replay_seconds[i];
  }
  const double update = result.update_us_mean * 1e-6 * static_cast<double>(n * steady);
  result.search_share = update > 0.0 ? std::min(1.0, search / update) : 0.0;
  result.update_us_last_window = sampled ? mean_timed_us(times, frames - window, frames)
                                         : mean_update_us(times, n, frames - window, frames);
  result.update_us_first_window = steady != frames ? replay * 1e6 / static_cast<double>(n * window)
                                  : sampled        ? mean_timed_us(times, 0, window)
                                                   : mean_update_us(times, n, 0, window);
  // The frames' figures leave the start out (warm_up_frames).
  const size_t warm = warm_up_frames(steady, dt);
  double frame_seconds = 0.0;
  for (size_t f = warm; f < steady; ++f) frame_seconds += times.frame_seconds[f];
  const double frame_mean = frame_seconds / static_cast<double>(steady - warm);
  result.frame_ms_mean = frame_mean * 1e3;
  // p99 reorders what it is given: the frames' own order is kept for frame_ms and the records.
  std::vector<double> frames_seconds(
      times.frame_seconds.begin() + static_cast<std::ptrdiff_t>(warm),
      times.frame_seconds.begin() + static_cast<std::ptrdiff_t>(steady));
  result.frame_ms_p99 = p99(std::span<double>(frames_seconds)) * 1e3;
  result.max_characters_60hz =
      clamped_integer<int>(std::floor(static_cast<double>(n) * (1.0 / 60.0) / frame_mean));
  if (sampled) {
    detail::PercentileHistogram all;
    for (const detail::PercentileHistogram& thread : times.timed_us) all.merge(thread);
    result.update_us_p99 = all.percentile(99.0);
    return result;
  }
  // The p99 of the steady frames' timed updates, which come first in the frame-major times.
  const auto untimed = std::partition(
      times.update_us.begin(), times.update_us.begin() + static_cast<std::ptrdiff_t>(steady * n),
      [](float us) { return !std::isnan(us); });
  const size_t timed = static_cast<size_t>(untimed - times.update_us.begin());
  result.update_us_p99 = timed > 0 ? p99(std::span<float>(times.update_us.data(), timed)) : 0.0;
  return result;
}

Status check_options(const CrowdOptions& options) {
  if (options.characters < 1) return Error{"crowd: at least one character"};
  if (options.threads < 1 || options.threads > 256) return Error{"crowd: threads in [1, 256]"};
  if (!(options.seconds > 0.0f) || !std::isfinite(options.seconds)) {
    return Error{"crowd: seconds must be positive"};
  }
  if (!(options.dt > 0.0f) || !(options.dt <= 1.0f)) return Error{"crowd: dt in (0, 1] s"};
  if (options.lod) {
    if (Status valid = options.lod->validate(); !valid) return Error{"crowd: " + valid.message()};
  }
  return Status::success();
}

// ---- Budgeted runs (crowd_scheduler.hpp) ----------------------------------------------------

// The CPU time the calling thread has run (s): what a calibration charges, since on a machine
// other processes share the wall clock of a thread's work overstates its cost.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// The characters a worker takes off the shared counter at a time: few enough that the threads
// end a frame together, many enough that the counter is not contended.
constexpr size_t kChunk = 32;

// A budgeted run times one step in this many (every character in turn, (i + frame) % this ==
// 0): two clock reads around every step are the bench's bookkeeping, which a game's frame
// does not pay, and a sample of every character in turn estimates the same mean and p99.
constexpr size_t kTimedEvery = 8;

// What a character that does not update this frame is handed (and does not read).
const ControllerInput kNoInput{};

// A crowd under its scheduler: the controllers, their scripts and what the run measures.
// What a game keeps of its characters outside the animation is kept here the way a game
// keeps it: each character's current input (its AI's output) and its position (for the
// significance), in arrays walked in order, not looked up in each controller and script.
struct ScheduledCrowd {
  std::vector<Controller> controllers;
  std::vector<InputScript> scripts;
  CrowdScheduler scheduler;
  std::vector<float> significance;
  std::vector<glm::vec3> positions;     // each root after its last step
  std::vector<ControllerInput> inputs;  // the script's line in effect
  std::vector<uint32_t> next_line;      // the script's next line
  std::vector<float> next_line_time;    // its time (infinite: none)
};

// Character i's input at game time t, which only grows from call to call: the line in effect
// is kept and replaced when the next line's time comes (the same input as InputScript::at,
// without its binary search over lines that lie far apart in memory).
const ControllerInput& scripted_input(ScheduledCrowd& crowd, size_t i, float t) {
  if (t >= crowd.next_line_time[i]) {
    const std::vector<ScriptEvent>& lines = crowd.scripts[i].events();
    size_t k = crowd.next_line[i];
    while (k < lines.size() && lines[k].time <= t) ++k;
    crowd.inputs[i] = lines[k - 1].input;
    crowd.next_line[i] = static_cast<uint32_t>(k);
    crowd.next_line_time[i] =
        k < lines.size() ? lines[k].time : std::numeric_limits<float>::infinity();
  }
  return crowd.inputs[i];
}

Result<ScheduledCrowd> make_scheduled_crowd(
    const std::shared_ptr<const ControllerDatabase>& database, const CrowdOptions& options,
    size_t n, const CrowdSchedulerSettings& settings) {
  // What a scheduled character shows is the scheduler's pose, not its controller's: skinning
  // matrices are the renderer's, from that pose.
  CrowdOptions scheduled = options;
  scheduled.settings.compute_skinning = false;
  Result<std::vector<Controller>> controllers =
      make_characters(database, scheduled, options.world, n);
  if (!controllers) return Error{controllers.message()};
  Result<CrowdScheduler> scheduler =
      CrowdScheduler::create(n, database->database().skeleton().joint_count(), settings);
  if (!scheduler) return Error{"crowd: " + scheduler.message()};
  std::vector<InputScript> scripts;
  scripts.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    scripts.push_back(varied_input_script(static_cast<uint32_t>(i), options.seconds));
  }
  ScheduledCrowd crowd{std::move(controllers).value(),
                       std::move(scripts),
                       std::move(scheduler).value(),
                       std::vector<float>(n, 0.0f),
                       std::vector<glm::vec3>(n),
                       std::vector<ControllerInput>(n),
                       std::vector<uint32_t>(n, 0),
                       std::vector<float>(n, std::numeric_limits<float>::infinity())};
  for (size_t i = 0; i < n; ++i) {
    crowd.positions[i] = crowd.controllers[i].root_transform().translation;
    const std::vector<ScriptEvent>& lines = crowd.scripts[i].events();
    if (!lines.empty()) crowd.next_line_time[i] = lines.front().time;
  }
  return crowd;
}

// Steps character i at game time t and keeps its position; returns the step's wall time (s)
// when `timed`, else NaN, adds what its update spent searching to `search`, and counts the
// step by kind into `record` when there is one.
float step_character(ScheduledCrowd& crowd, size_t i, float t, float dt, double& search,
                     bool timed = false, CrowdFrameRecord* record = nullptr) {
  const bool updates = crowd.scheduler.updates(i);
  const ControllerInput& input = updates ? scripted_input(crowd, i, t) : kNoInput;
  Controller& controller = crowd.controllers[i];
  float elapsed = std::numeric_limits<float>::quiet_NaN();
  if (timed) {
    const auto start = std::chrono::steady_clock::now();
    crowd.scheduler.step(i, controller, dt, input);
    elapsed = std::chrono::duration<float>(std::chrono::steady_clock::now() - start).count();
  } else {
    crowd.scheduler.step(i, controller, dt, input);
  }
  crowd.positions[i] = controller.root_transform().translation;
  if (updates) search += controller.debug().search_seconds;
  if (record != nullptr && updates) {
    ++record->steps[static_cast<size_t>(crowd.scheduler.tier(i))];
    record->searches += controller.debug().searched ? 1 : 0;
    record->transitions += controller.debug().transitioned ? 1 : 0;
  }
  return elapsed;
}

// This frame's plan: every character's significance from the camera at game time t.
void plan_frame(ScheduledCrowd& crowd, const CrowdOptions& options, float t) {
  const glm::vec3 camera = crowd_camera(options, t);
  for (size_t i = 0; i < crowd.positions.size(); ++i) {
    const glm::vec3& p = crowd.positions[i];
    crowd.significance[i] = -glm::distance(glm::vec2(p.x, p.z), glm::vec2(camera.x, camera.z));
  }
  crowd.scheduler.plan(crowd.significance);
}

// What a budgeted run keeps of each frame besides CrowdTimes: the tiers and the planned work.
struct PlanRecord {
  std::vector<std::array<int, kCrowdTierCount>> counts;
  std::vector<double> planned_us;
};

// The frames of a budgeted run on `threads` threads: planned on thread 0 (every character at
// `all` when given), stepped by all.
void run_scheduled_frames(ScheduledCrowd& crowd, const CrowdOptions& options, int threads,
                          CrowdTimes& times, PlanRecord& plans,
                          std::optional<CrowdTier> all = std::nullopt) {
  const size_t n = crowd.controllers.size();
  const size_t frames = times.frame_seconds.size();
  std::atomic<size_t> next{0};
  std::barrier sync(threads);
  using Clock = std::chrono::steady_clock;
  times.step_cpu_seconds.assign(frames * static_cast<size_t>(threads), 0.0);
  times.step_wall_seconds.assign(frames * static_cast<size_t>(threads), 0.0);
  times.plan_seconds.assign(frames, 0.0);
  times.step_records.assign(frames * static_cast<size_t>(threads), CrowdFrameRecord{});
  times.timed_us_sum.assign(frames * static_cast<size_t>(threads), 0.0);
  times.timed_count.assign(frames * static_cast<size_t>(threads), 0);
  times.timed_us.assign(static_cast<size_t>(threads), detail::PercentileHistogram{});
  // The histograms' bins are allocated by their first value: before the frames.
  for (detail::PercentileHistogram& histogram : times.timed_us) histogram.reserve();
  auto worker = [&](int index) {
    Clock::time_point frame_start = Clock::now();
    for (size_t f = 0; f < frames; ++f) {
      const float t = static_cast<float>(f + 1) * options.dt;
      if (index == 0) {
        if (all) {
          crowd.scheduler.plan_all(*all);
        } else {
          plan_frame(crowd, options, t);
        }
        times.plan_seconds[f] = std::chrono::duration<double>(Clock::now() - frame_start).count();
        plans.counts[f] = crowd.scheduler.tier_counts();
        plans.planned_us[f] = crowd.scheduler.planned_cost_us();
        next.store(0, std::memory_order_relaxed);
      }
      sync.arrive_and_wait();
      const Clock::time_point steps_start = Clock::now();
      const double cpu_start = thread_cpu_seconds();
      const size_t slot = f * static_cast<size_t>(threads) + static_cast<size_t>(index);
      CrowdFrameRecord& record = times.step_records[slot];
      for (size_t first = next.fetch_add(kChunk); first < n; first = next.fetch_add(kChunk)) {
        for (size_t i = first; i < std::min(n, first + kChunk); ++i) {
          if (i + 2 < n) crowd.scheduler.prefetch_ahead(i + 2, crowd.controllers[i + 2]);
          if (i + 1 < n) crowd.scheduler.prefetch(i + 1, crowd.controllers[i + 1]);
          const bool timed = (i + f) % kTimedEvery == 0;
          const float us =
              step_character(crowd, i, t, options.dt, times.search_seconds[i], timed, &record) *
              1e6f;
          if (timed) {
            times.timed_us[static_cast<size_t>(index)].add(us);
            times.timed_us_sum[slot] += us;
            ++times.timed_count[slot];
          }
        }
      }
      times.step_cpu_seconds[slot] = thread_cpu_seconds() - cpu_start;
      times.step_wall_seconds[slot] =
          std::chrono::duration<double>(Clock::now() - steps_start).count();
      sync.arrive_and_wait();
      if (index == 0) {
        const Clock::time_point now = Clock::now();
        times.frame_seconds[f] = std::chrono::duration<double>(now - frame_start).count();
        frame_start = now;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker, k);
  worker(0);
  for (std::thread& t : pool) t.join();
}

Result<CrowdResult> run_budgeted(const std::shared_ptr<const ControllerDatabase>& database,
                                 const CrowdOptions& options) {
  const size_t n = static_cast<size_t>(options.characters);
  const size_t frames = clamped_integer<size_t>(std::ceil(options.seconds / options.dt));
  const size_t window = std::clamp<size_t>(
      clamped_integer<size_t>(std::round(kCrowdWindowSeconds / options.dt)), 1, frames);
  Result<ScheduledCrowd> crowd = make_scheduled_crowd(database, options, n, *options.lod);
  if (!crowd) return Error{crowd.message()};
  const int threads = std::min<int>(options.threads, options.characters);
  CrowdTimes times;
  times.frame_seconds.assign(frames, 0.0);
  times.search_seconds.assign(n, 0.0);
  times.replay_seconds.assign(n, 0.0);
  PlanRecord plans{std::vector<std::array<int, kCrowdTierCount>>(frames),
                   std::vector<double>(frames, 0.0)};
  const auto start = std::chrono::steady_clock::now();
  run_scheduled_frames(*crowd, options, threads, times, plans);
  // No replay: every frame is steady, the first window is the run's own.
  CrowdResult result = summarize(times, n, window, frames, options.dt);
  result.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.threads = threads;
  result.frames = clamped_integer<int>(frames);
  const size_t warm = warm_up_frames(frames, options.dt);
  result.tier_counts = plans.counts.back();
  result.full_min = options.characters;
  double planned = 0.0;
  for (size_t f = warm; f < frames; ++f) {
    result.full_min = std::min(result.full_min, plans.counts[f][0]);
    planned += plans.planned_us[f];
  }
  result.planned_cost_us_mean = planned / static_cast<double>(frames - warm);
  // Where the frame's wall time went: the plan, the longest thread's steps, and the rest (the
  // hand-off between the threads at the frame's two barriers, and a thread's wait for a core).
  double plan = 0.0, steps = 0.0;
  for (size_t f = warm; f < frames; ++f) {
    plan += times.plan_seconds[f];
    const auto first = times.step_wall_seconds.begin() +
                       static_cast<std::ptrdiff_t>(f * static_cast<size_t>(threads));
    steps += *std::max_element(first, first + threads);
  }
  const double steady = static_cast<double>(frames - warm);
  result.plan_ms_mean = plan * 1e3 / steady;
  result.steps_ms_mean = steps * 1e3 / steady;
  result.sync_ms_mean = result.frame_ms_mean - result.plan_ms_mean - result.steps_ms_mean;
  // The work itself, as the threads' CPU time stepping (all threads): its spread does not
  // count the time a thread waited for a core.
  std::vector<double> work(frames - warm, 0.0);
  for (size_t f = warm; f < frames; ++f) {
    for (size_t k = 0; k < static_cast<size_t>(threads); ++k) {
      work[f - warm] += times.step_cpu_seconds[f * static_cast<size_t>(threads) + k] * 1e3;
    }
  }
  double work_sum = 0.0;
  for (const double ms : work) work_sum += ms;
  result.work_ms_mean = work_sum / steady;
  result.work_ms_p99 = p99(std::span<double>(work));
  result.frame_ms.assign(times.frame_seconds.begin() + static_cast<std::ptrdiff_t>(warm),
                         times.frame_seconds.end());
  for (double& ms : result.frame_ms) ms *= 1e3;
  result.frame_records.resize(frames - warm);
  for (size_t f = warm; f < frames; ++f) {
    CrowdFrameRecord& record = result.frame_records[f - warm];
    record.frame_ms = static_cast<float>(times.frame_seconds[f] * 1e3);
    record.plan_ms = static_cast<float>(times.plan_seconds[f] * 1e3);
    record.planned_us = static_cast<float>(plans.planned_us[f]);
    for (size_t k = 0; k < static_cast<size_t>(threads); ++k) {
      const size_t slot = f * static_cast<size_t>(threads) + k;
      record.work_ms += static_cast<float>(times.step_cpu_seconds[slot] * 1e3);
      const CrowdFrameRecord& part = times.step_records[slot];
      for (size_t t = 0; t < record.steps.size(); ++t) record.steps[t] += part.steps[t];
      record.searches += part.searches;
      record.transitions += part.transitions;
    }
  }
  const size_t joints = crowd->scheduler.joints();
  result.final_poses.resize(n * joints);
  for (size_t i = 0; i < n; ++i) {
    result.final_positions.push_back(crowd->controllers[i].root_transform().translation);
    crowd->scheduler.displayed_pose(
        i, std::span<Transform>(result.final_poses.data() + i * joints, joints));
  }
  return result;
}
}  // namespace

Result<CrowdResult> run_crowd(std::shared_ptr<const ControllerDatabase> database,
                              const CrowdOptions& options) {
  if (Status valid = check_options(options); !valid) return Error{valid.message()};
  if (options.lod) return run_budgeted(database, options);
  const size_t n = static_cast<size_t>(options.characters);
  const size_t frames = clamped_integer<size_t>(std::ceil(options.seconds / options.dt));
  const size_t window = std::clamp<size_t>(
      clamped_integer<size_t>(std::round(kCrowdWindowSeconds / options.dt)), 1, frames);
  // A run of one window has nothing to replay: its first window is its last.
  const bool replayed = frames > window;
  const size_t replay_start = replayed ? frames - window : frames;

  std::optional<TimedWorld> world;
  if (options.world) world.emplace(*options.world);
  const WorldQueries* queries = world ? &*world : nullptr;
  Result<std::vector<Controller>> controllers = make_characters(database, options, queries, n);
  if (!controllers) return Error{controllers.message()};
  Result<std::vector<Controller>> replay =
      make_characters(database, options, queries, replayed ? n : 0);
  if (!replay) return Error{replay.message()};
  std::vector<InputScript> scripts;
  scripts.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    scripts.push_back(varied_input_script(static_cast<uint32_t>(i), options.seconds));
  }

  const int threads = std::min<int>(options.threads, options.characters);
  CrowdTimes times;
  times.update_us.assign(frames * n, 0.0f);
  times.frame_seconds.assign(frames, 0.0);
  times.search_seconds.assign(n, 0.0);
  times.replay_seconds.assign(n, 0.0);
  std::barrier sync(threads);
  using Clock = std::chrono::steady_clock;
  // Every update's time, replays included, summed per thread: what the world's share is of.
  std::vector<double> thread_update_seconds(static_cast<size_t>(threads), 0.0);
  const double world_before = world ? world->seconds() : 0.0;
  auto timed_update = [&](Controller& controller, float t, const InputScript& script) {
    const ControllerInput input = script.at(t);
    const Clock::time_point start = Clock::now();
    controller.update(options.dt, input);
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  auto worker = [&](int index) {
    const size_t first = n * static_cast<size_t>(index) / static_cast<size_t>(threads);
    const size_t last = n * static_cast<size_t>(index + 1) / static_cast<size_t>(threads);
    Clock::time_point frame_start = Clock::now();
    for (size_t f = 0; f < frames; ++f) {
      const float t = static_cast<float>(f + 1) * options.dt;
      const bool replaying = f >= replay_start;
      const float replay_t = static_cast<float>(f - replay_start + 1) * options.dt;
      // Which of a character's two updates goes first alternates, so that neither always runs
      // in the cache the other left.
      const bool replay_first = f % 2 == 0;
      double& spent = thread_update_seconds[static_cast<size_t>(index)];
      for (size_t i = first; i < last; ++i) {
        if (replaying && replay_first) {
          const double replayed_seconds = timed_update((*replay)[i], replay_t, scripts[i]);
          times.replay_seconds[i] += replayed_seconds;
          spent += replayed_seconds;
        }
        const double elapsed = timed_update((*controllers)[i], t, scripts[i]);
        times.update_us[f * n + i] = static_cast<float>(elapsed * 1e6);
        spent += elapsed;
        if (!replaying) times.search_seconds[i] += (*controllers)[i].debug().search_seconds;
        if (replaying && !replay_first) {
          const double replayed_seconds = timed_update((*replay)[i], replay_t, scripts[i]);
          times.replay_seconds[i] += replayed_seconds;
          spent += replayed_seconds;
        }
      }
      sync.arrive_and_wait();
      if (index == 0) {
        const Clock::time_point now = Clock::now();
        times.frame_seconds[f] = std::chrono::duration<double>(now - frame_start).count();
        frame_start = now;
      }
    }
  };
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker, k);
  worker(0);
  for (std::thread& t : pool) t.join();

  CrowdResult result = summarize(times, n, window, replay_start, options.dt);
  if (world) {
    double spent = 0.0;
    for (const double seconds : thread_update_seconds) spent += seconds;
    result.world_share =
        spent > 0.0 ? std::min(1.0, (world->seconds() - world_before) / spent) : 0.0;
  }
  result.threads = threads;
  result.frames = clamped_integer<int>(frames);
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  for (const Controller& c : *controllers)
    result.final_positions.push_back(c.root_transform().translation);
  for (const Controller& c : *replay)
    result.replay_final_positions.push_back(c.root_transform().translation);
  for (const Controller& c : *controllers) {
    result.final_poses.insert(result.final_poses.end(), c.global_transforms().begin(),
                              c.global_transforms().end());
  }
  result.tier_counts[0] = result.full_min = clamped_integer<int>(n);
  return result;
}

glm::vec3 crowd_camera(const CrowdOptions& options, float t) {
  glm::vec4 area = options.start_area;
  if (!(area.z > area.x && area.w > area.y)) {
    const int n = std::max(options.characters, 1);
    area = glm::vec4(0.0f, 0.0f, static_cast<float>(std::min(n, 32) - 1) * 3.0f,
                     static_cast<float>((n - 1) / 32) * 3.0f);
  }
  const glm::vec2 centre(0.5f * (area.x + area.z), 0.5f * (area.y + area.w));
  const glm::vec2 half(0.5f * (area.z - area.x), 0.5f * (area.w - area.y));
  const float angle = 2.0f * glm::pi<float>() * t / 60.0f;
  return glm::vec3(centre.x + 0.5f * half.x * std::sin(angle), 0.0f,
                   centre.y + 0.5f * half.y * std::cos(angle));
}

namespace {

// The samples a tier's calibration takes over its second second.
constexpr size_t kCalibrationSamples = 5;

// A tier's cost (us per character and frame) from a calibration run's CPU time per frame and
// thread: the second half's frames cut into kCalibrationSamples samples, the median sample's
// CPU time per character and frame. Not the frame's wall time times the threads: on a shared
// machine a thread waits for a core (and the other waits at the barrier), which is not work
// the budget can plan away. The median, not the mean: a burst of another process's work (its
// cache traffic, a descheduled thread's lost cache) in one sample does not move it.
float calibrated_cost_us(const std::vector<double>& step_cpu_seconds, size_t threads,
                         size_t characters) {
  const size_t frames = step_cpu_seconds.size() / threads;
  const size_t first = frames / 2;
  const size_t per_sample = std::max<size_t>(1, (frames - first) / kCalibrationSamples);
  std::array<double, kCalibrationSamples> samples{};
  size_t count = 0;
  for (; count < kCalibrationSamples && first + (count + 1) * per_sample <= frames; ++count) {
    const auto begin = step_cpu_seconds.begin() +
                       static_cast<std::ptrdiff_t>((first + count * per_sample) * threads);
    const double seconds =
        std::accumulate(begin, begin + static_cast<std::ptrdiff_t>(per_sample * threads), 0.0);
    samples[count] = seconds * 1e6 / static_cast<double>(characters * per_sample);
  }
  std::sort(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(count));
  return static_cast<float>(samples[count / 2]);
}

}  // namespace

Result<std::array<float, kCrowdTierCount>> calibrate_crowd_tiers(
    std::shared_ptr<const ControllerDatabase> database, const CrowdOptions& options,
    int characters) {
  CrowdOptions calibration = options;
  calibration.characters = std::max(1, characters);
  calibration.seconds = 2.0f;
  if (Status valid = check_options(calibration); !valid) return Error{valid.message()};
  const CrowdSchedulerSettings settings = options.lod ? *options.lod : CrowdSchedulerSettings{};
  const int threads = std::min(settings.threads, calibration.characters);
  const size_t n = static_cast<size_t>(calibration.characters);
  const size_t frames = clamped_integer<size_t>(std::ceil(calibration.seconds / options.dt));
  std::array<float, kCrowdTierCount> costs{};
  for (int tier = 0; tier < kCrowdTierCount; ++tier) {
    Result<ScheduledCrowd> crowd = make_scheduled_crowd(database, calibration, n, settings);
    if (!crowd) return Error{crowd.message()};
    CrowdTimes times;
    times.frame_seconds.assign(frames, 0.0);
    times.search_seconds.assign(n, 0.0);
    times.replay_seconds.assign(n, 0.0);
    PlanRecord plans{std::vector<std::array<int, kCrowdTierCount>>(frames),
                     std::vector<double>(frames, 0.0)};
    run_scheduled_frames(*crowd, calibration, threads, times, plans, static_cast<CrowdTier>(tier));
    costs[static_cast<size_t>(tier)] =
        calibrated_cost_us(times.step_cpu_seconds, static_cast<size_t>(threads), n);
  }
  // Timing noise must not make a slower tier look dearer than a faster one.
  for (size_t t = 1; t < costs.size(); ++t) costs[t] = std::min(costs[t], costs[t - 1]);
  return costs;
}

namespace {

// One character's ground metrics, fed its displayed pose every frame.
struct QualityProbe {
  QualityProbe(const JointRoleIndices& roles, float dt, size_t joints)
      : ground(roles, dt), pose(joints), positions(joints) {}
  GroundAccumulator ground;
  std::vector<Transform> pose;
  std::vector<glm::vec3> positions;
};

}  // namespace

Result<std::array<CrowdTierQuality, kCrowdTierCount>> crowd_tier_quality(
    std::shared_ptr<const ControllerDatabase> database, const CrowdOptions& options, int characters,
    float seconds) {
  CrowdOptions run = options;
  run.characters = std::max(1, characters);
  run.seconds = seconds;
  if (Status valid = check_options(run); !valid) return Error{valid.message()};
  const size_t n = static_cast<size_t>(run.characters);
  const size_t frames = clamped_integer<size_t>(std::ceil(seconds / options.dt));
  const Database& db = database->database();
  std::array<CrowdTierQuality, kCrowdTierCount> quality{};
  for (int tier = 0; tier < kCrowdTierCount; ++tier) {
    Result<ScheduledCrowd> crowd = make_scheduled_crowd(
        database, run, n, options.lod ? *options.lod : CrowdSchedulerSettings{});
    if (!crowd) return Error{crowd.message()};
    std::vector<std::unique_ptr<QualityProbe>> probes;
    for (size_t i = 0; i < n; ++i) {
      probes.push_back(
          std::make_unique<QualityProbe>(db.roles(), options.dt, crowd->scheduler.joints()));
    }
    double search = 0.0;
    for (size_t f = 0; f < frames; ++f) {
      const float t = static_cast<float>(f + 1) * options.dt;
      crowd->scheduler.plan_all(static_cast<CrowdTier>(tier));
      for (size_t i = 0; i < n; ++i) {
        step_character(*crowd, i, t, options.dt, search);
        QualityProbe& probe = *probes[i];
        crowd->scheduler.displayed_pose(i, probe.pose);
        for (size_t j = 0; j < probe.pose.size(); ++j) {
          probe.positions[j] = probe.pose[j].translation;
        }
        GroundFrame frame;
        frame.joints = probes[i]->positions;
        probes[i]->ground.add(frame);
      }
    }
    CrowdTierQuality& q = quality[static_cast<size_t>(tier)];
    q.toe_clearance_cm_min = 1e30;
    for (const auto& probe : probes) {
      const GroundMetrics m = probe->ground.metrics();
      q.foot_skate_geom_cm_s_mean += m.foot_skate_geom_cm_s_mean / static_cast<double>(n);
      q.foot_penetration_cm_mean += m.foot_penetration_cm_mean / static_cast<double>(n);
      q.hips_vertical_accel_p99_m_s2 += m.hips_vertical_accel_p99_m_s2 / static_cast<double>(n);
      q.foot_penetration_cm_max = std::max(q.foot_penetration_cm_max, m.foot_penetration_cm_max);
      q.toe_clearance_cm_min = std::min(q.toe_clearance_cm_min, m.toe_clearance_cm_min);
    }
  }
  return quality;
}

}  // namespace mm
