// The translation unit that tests/CMakeLists.txt's mm_test_pch compiles its precompiled header
// for; the test programs reuse that header. Nothing of its own.
