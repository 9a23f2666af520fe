#pragma once
// Counts every allocation of a test program that links tests/support/allocation_counter.cpp
// (which replaces the global operator new and delete): the no-allocation tests read the count
// before and after the code that must not allocate. Link it into those programs only.

#include <atomic>

namespace mm::test {
// Every operator new of the program so far.
extern std::atomic<long> g_allocations;
}  // namespace mm::test
