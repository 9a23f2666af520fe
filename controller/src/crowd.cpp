// The crowd benchmark: controllers in contiguous slices per thread, a barrier per frame as in a
// game loop, every update timed.

#include "mm/controller/crowd.hpp"
#include "mm/runtime/float_to_integer.hpp"

#include <algorithm>
#include <barrier>
#include <chrono>
#include <cmath>
#include <random>
#include <thread>

namespace mm {

namespace {

// A float in [0, 1) from the generator's raw bits (std::uniform_real_distribution differs
// between standard libraries; this does not).
float unit(std::mt19937& rng) {
  return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f);
}

// The mean of every character's update times (microseconds) over frames [first, last).
double mean_update_us(const std::vector<float>& update_us, size_t characters, size_t frames,
                      size_t first, size_t last) {
  double sum = 0.0;
  for (size_t i = 0; i < characters; ++i) {
    for (size_t f = first; f < last; ++f) sum += update_us[i * frames + f];
  }
  return sum / static_cast<double>(characters * (last - first));
}

}  // namespace

InputScript varied_input_script(uint32_t seed, float seconds) {
  std::mt19937 rng(seed * 2654435761u + 12345u);
  std::vector<ScriptEvent> events;
  float t = 0.0f;
  int line = 1;
  while (t < seconds) {
    ScriptEvent e;
    e.time = t;
    e.line = line++;
    const float kind = unit(rng);
    const float angle = unit(rng) * glm::two_pi<float>();
    if (kind < 0.15f) {
      e.input.left_stick = glm::vec2(0.0f);  // stand
    } else {
      e.input.left_stick = glm::vec2(std::sin(angle), std::cos(angle));
    }
    e.input.run = unit(rng) < 0.3f;
    e.input.strafe = unit(rng) < 0.1f;
    if (e.input.strafe) {
      const float facing = unit(rng) * glm::two_pi<float>();
      e.input.right_stick = glm::vec2(std::sin(facing), std::cos(facing));
    }
    e.input.camera_yaw = unit(rng) < 0.2f ? (unit(rng) - 0.5f) * glm::pi<float>() : 0.0f;
    events.push_back(e);
    t += 0.5f + 2.5f * unit(rng);
  }
  return InputScript(std::move(events));
}

Result<CrowdResult> run_crowd(std::shared_ptr<const ControllerDatabase> database,
                              const CrowdOptions& options) {
  if (options.characters < 1) return Error{"crowd: at least one character"};
  if (options.threads < 1 || options.threads > 256) return Error{"crowd: threads in [1, 256]"};
  if (!(options.seconds > 0.0f) || !std::isfinite(options.seconds)) {
    return Error{"crowd: seconds must be positive"};
  }
  if (!(options.dt > 0.0f) || !(options.dt <= 1.0f)) return Error{"crowd: dt in (0, 1] s"};
  const size_t n = static_cast<size_t>(options.characters);
  std::vector<Controller> controllers;
  std::vector<InputScript> scripts;
  controllers.reserve(n);
  scripts.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Result<Controller> c = Controller::create(database, options.settings);
    if (!c) return Error{c.message()};
    // Spread the characters on a grid so a viewer of the run sees them apart.
    const float x = static_cast<float>(i % 32) * 3.0f;
    const float z = static_cast<float>(i / 32) * 3.0f;
    c->teleport(glm::vec3(x, 0.0f, z), 0.0f);
    controllers.push_back(std::move(c).value());
    scripts.push_back(varied_input_script(static_cast<uint32_t>(i), options.seconds));
  }

  const int frames = clamped_integer<int>(std::ceil(options.seconds / options.dt));
  const int threads = std::min<int>(options.threads, options.characters);
  // Per character: every update's time, and the summed search time.
  std::vector<float> update_us(n * static_cast<size_t>(frames));
  std::vector<double> search_seconds(n, 0.0), update_seconds(n, 0.0);
  std::barrier sync(threads);
  using Clock = std::chrono::steady_clock;

  auto worker = [&](int index) {
    const size_t first = n * static_cast<size_t>(index) / static_cast<size_t>(threads);
    const size_t last = n * static_cast<size_t>(index + 1) / static_cast<size_t>(threads);
    for (int f = 0; f < frames; ++f) {
      const float t = static_cast<float>(f + 1) * options.dt;
      for (size_t i = first; i < last; ++i) {
        const ControllerInput input = scripts[i].at(t);
        const Clock::time_point start = Clock::now();
        controllers[i].update(options.dt, input);
        const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
        update_us[i * static_cast<size_t>(frames) + static_cast<size_t>(f)] =
            static_cast<float>(elapsed * 1e6);
        update_seconds[i] += elapsed;
        search_seconds[i] += controllers[i].debug().search_seconds;
      }
      sync.arrive_and_wait();
    }
  };
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker, k);
  worker(0);
  for (std::thread& t : pool) t.join();
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  CrowdResult result;
  result.threads = threads;
  result.frames = frames;
  result.wall_seconds = wall;
  double total_update = 0.0, total_search = 0.0;
  for (size_t i = 0; i < n; ++i) {
    total_update += update_seconds[i];
    total_search += search_seconds[i];
  }
  result.update_us_mean = total_update * 1e6 / static_cast<double>(update_us.size());
  result.search_share = total_update > 0.0 ? total_search / total_update : 0.0;
  const size_t all_frames = static_cast<size_t>(frames);
  const size_t window = std::clamp<size_t>(
      clamped_integer<size_t>(std::round(kCrowdWindowSeconds / options.dt)), 1, all_frames);
  result.update_us_first_window = mean_update_us(update_us, n, all_frames, 0, window);
  result.update_us_last_window =
      mean_update_us(update_us, n, all_frames, all_frames - window, all_frames);
  const size_t rank = std::min(update_us.size() - 1,
                               clamped_integer<size_t>(std::ceil(0.99 * update_us.size())) - 1);
  std::nth_element(update_us.begin(), update_us.begin() + static_cast<std::ptrdiff_t>(rank),
                   update_us.end());
  result.update_us_p99 = update_us[rank];
  result.frame_ms_mean = wall * 1e3 / frames;
  result.max_characters_60hz =
      clamped_integer<int>(std::floor(static_cast<double>(n) * (1.0 / 60.0) / (wall / frames)));
  for (const Controller& c : controllers)
    result.final_positions.push_back(c.root_transform().translation);
  return result;
}

}  // namespace mm
