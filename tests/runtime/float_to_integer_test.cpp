// The float-to-integer conversions at and past the integer types' ends, and on NaN and
// infinity, where a static_cast is undefined behaviour (the sanitizer build would abort).

#include "mm/runtime/float_to_integer.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

namespace mm {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(FloatToInteger, CheckedTruncatesTowardZeroInsideTheRange) {
  EXPECT_EQ(checked_integer<int>(0.0), 0);
  EXPECT_EQ(checked_integer<int>(2.9), 2);
  EXPECT_EQ(checked_integer<int>(-2.9), -2);
  EXPECT_EQ(checked_integer<int>(2147483647.9), 2147483647);
  EXPECT_EQ(checked_integer<int>(-2147483648.9), -2147483648);
  // -1 < x < 0 truncates to 0, which an unsigned type holds.
  EXPECT_EQ(checked_integer<uint32_t>(-0.5), 0u);
  EXPECT_EQ(checked_integer<uint32_t>(4294967295.5), 4294967295u);
  EXPECT_EQ(checked_integer<int64_t>(-9223372036854775808.0), std::numeric_limits<int64_t>::min());
}

TEST(FloatToInteger, CheckedRefusesWhatDoesNotFit) {
  EXPECT_FALSE(checked_integer<int>(2147483648.0));
  EXPECT_FALSE(checked_integer<int>(-2147483649.0));
  EXPECT_FALSE(checked_integer<int>(1e30));
  EXPECT_FALSE(checked_integer<int>(kInf));
  EXPECT_FALSE(checked_integer<int>(-kInf));
  EXPECT_FALSE(checked_integer<int>(kNaN));
  EXPECT_FALSE(checked_integer<uint32_t>(-1.0));
  EXPECT_FALSE(checked_integer<uint32_t>(4294967296.0));
  EXPECT_FALSE(checked_integer<uint64_t>(18446744073709551616.0));  // 2^64
  EXPECT_FALSE(checked_integer<int64_t>(9223372036854775808.0));    // 2^63
}

TEST(FloatToInteger, ClampedSaturatesAndMapsNanToZero) {
  EXPECT_EQ(clamped_integer<int>(-2.9), -2);
  EXPECT_EQ(clamped_integer<int>(1e30), std::numeric_limits<int>::max());
  EXPECT_EQ(clamped_integer<int>(-1e30), std::numeric_limits<int>::min());
  EXPECT_EQ(clamped_integer<int>(kInf), std::numeric_limits<int>::max());
  EXPECT_EQ(clamped_integer<int>(-kInf), std::numeric_limits<int>::min());
  EXPECT_EQ(clamped_integer<int>(kNaN), 0);
  EXPECT_EQ(clamped_integer<uint32_t>(-7.0), 0u);
  EXPECT_EQ(clamped_integer<uint32_t>(4294967296.0), 4294967295u);
  EXPECT_EQ(clamped_integer<unsigned char>(300.0), 255);
  EXPECT_EQ(clamped_integer<uint64_t>(1e30), std::numeric_limits<uint64_t>::max());
}

}  // namespace
}  // namespace mm
