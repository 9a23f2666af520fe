// The ctest setup test of the fixture normal_database (tests/CMakeLists.txt): builds the Bandai
// normal database from BVH once per ctest run and writes it where MM_NORMAL_DATABASE says, for
// the suites that load it (normal_database.hpp). Reading the file back and comparing every field
// makes sure those suites run on exactly the database they would have built themselves.

#include <gtest/gtest.h>

#include "database_helpers.hpp"
#include "mm/offline/database_writer.hpp"
#include "normal_database.hpp"

namespace mm {
namespace {

TEST(NormalDatabaseSetup, WritesTheNormalSetBuiltFromBvhLosslessly) {
  const std::filesystem::path file = test::normal_database_file();
  ASSERT_FALSE(file.empty()) << test::kNormalDatabaseVariable
                             << " is not set: ctest sets it to the file to write";
  Result<Database> built = test::build_normal_database();
  ASSERT_TRUE(built.ok()) << built.message();
  std::filesystem::create_directories(file.parent_path());
  const Status saved = save_database(*built, file);
  ASSERT_TRUE(saved.ok()) << saved.message();
  Result<Database> loaded = load_database(file);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  test::expect_same_database(*built, *loaded);
}

}  // namespace
}  // namespace mm
