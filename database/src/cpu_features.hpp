#pragma once
// Whether this CPU has AVX, checked once: the per-sample kernels of the loader and the builder
// have an AVX version next to the SSE2 one every x86-64 CPU runs.

namespace mm::detail {

inline bool cpu_has_avx() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx") != 0;
  }();
  return has;
#else
  return false;
#endif
}

}  // namespace mm::detail
