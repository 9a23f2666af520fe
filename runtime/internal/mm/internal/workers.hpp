#pragma once
// A minimal parallel loop for build-time work (database building, search structure building).
// Internal (runtime/internal/, never installed): shared by the search structures built at load,
// the file loader and the builder.

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace mm::detail {

// Runs `work(worker, item)` for every item on up to `threads` threads (the caller's included)
// that pull item indices from a shared counter. Returns the number of threads used. `work` must
// not throw.
template <class Work>
int run_workers(size_t items, int threads, const Work& work) {
  std::atomic<size_t> next{0};
  auto loop = [&](int worker) {
    for (size_t i = next.fetch_add(1); i < items; i = next.fetch_add(1)) work(worker, i);
  };
  std::vector<std::thread> pool;
  const int wanted =
      static_cast<int>(std::min<size_t>(static_cast<size_t>(std::max(threads, 1)), items));
  for (int t = 1; t < wanted; ++t) {
    try {
      pool.emplace_back(loop, t);
    } catch (const std::exception&) {
      break;  // no more threads available: the ones running (and this one) do the work
    }
  }
  loop(0);
  for (std::thread& t : pool) t.join();
  return static_cast<int>(pool.size()) + 1;
}

// Threads for build-time work: `wanted` when positive, else every core.
inline int worker_threads(int wanted) {
  return wanted > 0 ? wanted : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

}  // namespace mm::detail
