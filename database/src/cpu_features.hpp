#pragma once
// Whether to use AVX, decided once: the per-sample kernels of the loader and the builder have an
// AVX version next to the SSE2 one every x86-64 CPU runs. MM_DISABLE_AVX=1 in the environment
// forces the SSE2 ones (the tests run that way too, so both give the same bits).

#include <cstdlib>
#include <cstring>

namespace mm::detail {

inline bool cpu_has_avx() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  static const bool has = [] {
    const char* disabled = std::getenv("MM_DISABLE_AVX");
    if (disabled != nullptr && *disabled != '\0' && std::strcmp(disabled, "0") != 0) return false;
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx") != 0;
  }();
  return has;
#else
  return false;
#endif
}

}  // namespace mm::detail
