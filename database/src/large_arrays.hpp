#pragma once
// Sizing the database's large arrays (the builder's and the file loader's): they get huge pages,
// and the per-frame ones are not value-initialized, since the caller writes every value.

#include <cstddef>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/files.hpp"

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

}  // namespace mm::detail
