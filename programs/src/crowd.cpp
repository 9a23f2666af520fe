// The crowd benchmark: controllers in contiguous slices per thread, a barrier per frame as in a
// game loop, every update timed.

#include "mm/programs/crowd.hpp"
#include "mm/runtime/float_to_integer.hpp"

#include <algorithm>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <thread>

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

// What the frames of a run measured, frame-major: update_us[f * characters + i].
struct CrowdTimes {
  std::vector<float> update_us;
  std::vector<double> frame_seconds;   // barrier to barrier
  std::vector<double> search_seconds;  // per character, over the frames before the replay
  std::vector<double> replay_seconds;  // per character, the replay's updates
};

// The mean update time (microseconds) over frames [first, last).
double mean_update_us(const CrowdTimes& times, size_t characters, size_t first, size_t last) {
  double sum = 0.0;
  for (size_t k = first * characters; k < last * characters; ++k) sum += times.update_us[k];
  return sum / static_cast<double>(characters * (last - first));
}

// The figures of a run whose frames [replay_start, end) also updated the replay (none when
// replay_start is the end): the steady figures come from the frames before the replay, and
// the first window from the replay, when there is one.
CrowdResult summarize(CrowdTimes& times, size_t n, size_t window, size_t replay_start) {
  const size_t frames = times.frame_seconds.size();
  const size_t steady = replay_start;
  CrowdResult result;
  result.update_us_mean = mean_update_us(times, n, 0, steady);
  double search = 0.0, replay = 0.0;
  for (size_t i = 0; i < n; ++i) {
    search += times.search_seconds[i];
    replay += times.replay_seconds[i];
  }
  const double update = result.update_us_mean * 1e-6 * static_cast<double>(n * steady);
  result.search_share = update > 0.0 ? std::min(1.0, search / update) : 0.0;
  result.update_us_last_window = mean_update_us(times, n, frames - window, frames);
  result.update_us_first_window = steady == frames ? mean_update_us(times, n, 0, window)
                                                   : replay * 1e6 / static_cast<double>(n * window);
  double frame_seconds = 0.0;
  for (size_t f = 0; f < steady; ++f) frame_seconds += times.frame_seconds[f];
  const double frame_mean = frame_seconds / static_cast<double>(steady);
  result.frame_ms_mean = frame_mean * 1e3;
  result.max_characters_60hz =
      clamped_integer<int>(std::floor(static_cast<double>(n) * (1.0 / 60.0) / frame_mean));
  // The p99 of the steady frames, which come first in the frame-major times.
  const auto begin = times.update_us.begin();
  const auto end = begin + static_cast<std::ptrdiff_t>(steady * n);
  const size_t count = steady * n;
  const size_t rank = std::min(
      count - 1, clamped_integer<size_t>(std::ceil(0.99 * static_cast<double>(count))) - 1);
  std::nth_element(begin, begin + static_cast<std::ptrdiff_t>(rank), end);
  result.update_us_p99 = times.update_us[rank];
  return result;
}

}  // namespace

Result<CrowdResult> run_crowd(std::shared_ptr<const ControllerDatabase> database,
                              const CrowdOptions& options) {
  if (options.characters < 1) return Error{"crowd: at least one character"};
  if (options.threads < 1 || options.threads > 256) return Error{"crowd: threads in [1, 256]"};
  if (!(options.seconds > 0.0f) || !std::isfinite(options.seconds)) {
    return Error{"crowd: seconds must be positive"};
  }
  if (!(options.dt > 0.0f) || !(options.dt <= 1.0f)) return Error{"crowd: dt in (0, 1] s"};
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
  CrowdTimes times{std::vector<float>(frames * n), std::vector<double>(frames, 0.0),
                   std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)};
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

  CrowdResult result = summarize(times, n, window, replay_start);
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
  return result;
}

}  // namespace mm
