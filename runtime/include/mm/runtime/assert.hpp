#pragma once
// MM_ASSERT: the preconditions of the library's functions that a caller can break (span sizes
// that must match, indices in range, a Result read for a value it does not hold).
//
// A failed check calls the assert handler with the expression, file and line. The default
// handler prints them to stderr. A game may install its own (log it, break into a debugger, or
// throw, as the tests do to observe the checks); when the handler returns, the program aborts:
// a broken precondition is never run past. Checks are compiled in unless MM_ASSERTS_ENABLED is
// defined to 0 (the CMake option MM_ASSERTS=OFF): they are integer comparisons, a fraction of a
// percent of an update's instructions.

#ifndef MM_ASSERTS_ENABLED
#define MM_ASSERTS_ENABLED 1
#endif

namespace mm {

using AssertHandler = void (*)(const char* expression, const char* file, int line);

// Installs `handler` (nullptr: the default) for every thread and returns the previous one.
AssertHandler set_assert_handler(AssertHandler handler);

// Calls the handler, then aborts if it returns. What MM_ASSERT calls on a failed check.
[[noreturn]] void assert_failed(const char* expression, const char* file, int line);

}  // namespace mm

#if MM_ASSERTS_ENABLED
#define MM_ASSERT(condition) \
  (static_cast<bool>(condition) ? void(0) : ::mm::assert_failed(#condition, __FILE__, __LINE__))
#else
#define MM_ASSERT(condition) void(0)
#endif
