#include "mm/runtime/assert.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace mm {

namespace {

void print_failure(const char* expression, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: precondition failed: %s\n", file, line, expression);
}

std::atomic<AssertHandler> g_handler{&print_failure};

}  // namespace

AssertHandler set_assert_handler(AssertHandler handler) {
  return g_handler.exchange(handler != nullptr ? handler : &print_failure);
}

void assert_failed(const char* expression, const char* file, int line) {
  g_handler.load()(expression, file, line);
  std::abort();
}

}  // namespace mm
