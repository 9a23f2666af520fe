#include "test_support.hpp"

#include <cstdlib>

#include <gtest/gtest.h>

namespace mm::test {

std::filesystem::path mocap_dir() {
  return std::filesystem::path(MM_SHARED_DIR) / "mocap";
}

// Tests assert facts about the Bandai files (counts, names), so they always read that folder;
// MM_DATA only redirects the run command.
std::filesystem::path data_dir() {
  return mocap_dir() / "bandai-normal";
}

std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "scratch";
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  // The same tests also run without AVX (tests/CMakeLists.txt), maybe at the same time.
  if (std::getenv("MM_DISABLE_AVX") != nullptr) name += "-without-avx";
  auto dir = std::filesystem::path(MM_BINARY_DIR) / "test-scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path clip_path(const std::string& stem) {
  return data_dir() / (stem + ".bvh");
}

}  // namespace mm::test
