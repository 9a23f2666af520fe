#pragma once
// Shared helpers for the test suites: where the real data is and a scratch folder.

#include <filesystem>
#include <string>

namespace mm::test {

// The folder of real BVH clips the tests assert facts about: ../shared/mocap/bandai-normal.
std::filesystem::path data_dir();
// ../shared/mocap (the archive and licence live here).
std::filesystem::path mocap_dir();
// A fresh, empty folder under the build tree, unique to the calling test.
std::filesystem::path scratch_dir();
// Path of one named clip in data_dir(), e.g. clip_path("dataset-2_walk_normal_001").
std::filesystem::path clip_path(const std::string& stem);

}  // namespace mm::test
