#include <gtest/gtest.h>

#include <cmath>

#include "mm/offline/clip.hpp"

namespace mm {
namespace {

Clip two_joint_clip() {
  Clip clip;
  clip.name = "fixture";
  clip.skeleton = Skeleton::create({"root", "child"}, {-1, 0}, {Transform{}, Transform{}}).value();
  clip.frame_count = 2;
  clip.local.resize(4);
  return clip;
}

TEST(Clip, ValidatesSizesTimesAndValues) {
  Clip clip = two_joint_clip();
  EXPECT_TRUE(clip.validate().ok());

  Clip bad_time = clip;
  bad_time.frame_time = 0.0f;
  EXPECT_NE(bad_time.validate().message().find("frame time"), std::string::npos);

  Clip bad_size = clip;
  bad_size.local.pop_back();
  EXPECT_NE(bad_size.validate().message().find("expected 4"), std::string::npos);

  Clip bad_value = clip;
  bad_value.local[3].translation.y = std::nanf("");
  EXPECT_NE(bad_value.validate().message().find("joint 'child'"), std::string::npos);
}

}  // namespace
}  // namespace mm
