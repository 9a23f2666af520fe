#pragma once
// Allocating the database's large arrays (the builder's and the file loader's): fresh memory
// costs more to fault in than to fill, so the arrays get huge pages and are sized in parallel.

#include <cstddef>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/files.hpp"
#include "mm/runtime/workers.hpp"

namespace mm::detail {

// Grows a vector to n value-initialized elements (dropping what it held), its block first
// marked for huge pages: reserve allocates without touching the memory, so the advice applies.
template <class T>
void resize_large(std::vector<T>& v, size_t n) {
  v.clear();
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
  v.resize(n);
}

// The same for a per-frame array, whose new elements are left for the caller to write (every
// one of them): the first write then also faults the fresh memory in, while it is in cache.
template <class T>
void resize_large(FrameArray<T>& v, size_t n) {
  v.clear();
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
  struct Skip {
    Skip() { skip_value_initialization = true; }
    ~Skip() { skip_value_initialization = false; }
  } skip;
  v.resize(n);
}

// On up to `threads` threads: `job(k)` for k in [0, jobs) (started first), and the four
// per-frame joint arrays of `db` sized to `samples` values each.
template <class Job>
void size_joint_arrays(Database& db, size_t samples, int threads, size_t jobs, const Job& job) {
  run_workers(jobs + 4, threads, [&](int, size_t k) {
    if (k < jobs) {
      job(k);
      return;
    }
    switch (k - jobs) {
      case 0:
        resize_large(db.local_rotations, samples);
        break;
      case 1:
        resize_large(db.local_positions, samples);
        break;
      case 2:
        resize_large(db.local_velocities, samples);
        break;
      default:
        resize_large(db.local_angular_velocities, samples);
        break;
    }
  });
}

}  // namespace mm::detail
