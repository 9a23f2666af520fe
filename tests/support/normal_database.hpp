#pragma once
// The Bandai normal database: every clip of data_dir() built with the default options, the
// database the controller, real-data search and viewer suites run on.
//
// ctest runs every GoogleTest case as its own process, and building this database from BVH takes
// seconds (far longer under the sanitizers), so ctest builds it once per run: the setup test
// normal_database_setup (tests/CMakeLists.txt) writes it to the build tree and the suites that
// require that fixture find its path in MM_NORMAL_DATABASE. A test program started by hand, with
// no MM_NORMAL_DATABASE, builds the same database from BVH instead.
// Header-only: the support library itself does not link the database.

#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include "mm/database/database_file.hpp"
#include "mm/offline/builder.hpp"
#include "test_support.hpp"

namespace mm::test {

// The variable ctest sets on the suites that load the setup test's file.
inline constexpr const char* kNormalDatabaseVariable = "MM_NORMAL_DATABASE";

// The setup test's file, or an empty path when MM_NORMAL_DATABASE is not set.
inline std::filesystem::path normal_database_file() {
  const char* file = std::getenv(kNormalDatabaseVariable);
  return file ? std::filesystem::path(file) : std::filesystem::path();
}

// The normal database built from BVH (the setup test writes exactly this).
inline Result<Database> build_normal_database() {
  const std::filesystem::path inputs[] = {data_dir()};
  return build_database(inputs, BuildOptions{});
}

// The setup test's file when ctest runs the program, else built from BVH.
inline Result<Database> normal_database() {
  const std::filesystem::path file = normal_database_file();
  if (file.empty()) return build_normal_database();
  Result<Database> loaded = load_database(file);
  if (!loaded) {
    // Appended in place: gcc 12 warns (-Warray-bounds) on a chain of operator+ temporaries.
    std::string message(kNormalDatabaseVariable);
    message.append(" (written by the ctest setup test normal_database_setup): ")
        .append(loaded.message());
    return Error{std::move(message)};
  }
  return loaded;
}

}  // namespace mm::test
