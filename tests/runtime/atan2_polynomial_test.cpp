#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mm/runtime/atan2_polynomial.hpp"

namespace mm {
namespace {

// Over every direction of the plane (a million angles) and magnitudes from 1e-30 to 1e30, the
// polynomial stays within 4e-7 rad of the exact angle (computed in double): the fit's 1e-7 plus
// the rounding of pi - angle (half a unit in the last place of pi).
TEST(Atan2Polynomial, WithinFourTenthsOfAMicroradianEverywhere) {
  double worst = 0.0;
  for (double magnitude : {1e-30, 1e-6, 1.0, 3.7, 1e6, 1e30}) {
    for (int i = 0; i <= 1000000; ++i) {
      const double a = -M_PI + 2.0 * M_PI * i / 1000000.0;
      const float y = static_cast<float>(magnitude * std::sin(a));
      const float x = static_cast<float>(magnitude * std::cos(a));
      const double exact = std::atan2(static_cast<double>(y), static_cast<double>(x));
      worst = std::max(worst, std::abs(atan2_polynomial(y, x) - exact));
    }
  }
  EXPECT_LT(worst, 4e-7);
  EXPECT_GT(worst, 0.0);  // an approximation: it is not the library's function
}

// Near the axes a tiny ratio keeps its relative precision (the yaw of a nearly straight forward).
TEST(Atan2Polynomial, SmallAnglesKeepRelativePrecision) {
  for (float t : {1e-30f, 1e-12f, 1e-6f, 1e-3f}) {
    const double exact = std::atan(static_cast<double>(t));
    EXPECT_NEAR(atan2_polynomial(t, 1.0f), exact, 2e-7 * t) << t;
    EXPECT_NEAR(atan2_polynomial(-t, 1.0f), -exact, 2e-7 * t) << t;
  }
}

// Zeros, infinities and NaN follow the library's conventions exactly.
TEST(Atan2Polynomial, SpecialValuesAsTheLibrary) {
  const float inf = std::numeric_limits<float>::infinity();
  const float values[] = {0.0f, -0.0f, 1.0f, -2.0f, inf, -inf};
  for (float y : values) {
    for (float x : values) {
      const bool special = y == 0.0f || x == 0.0f || std::isinf(y) || std::isinf(x);
      if (!special) continue;
      const float expected = std::atan2(y, x);
      const float got = atan2_polynomial(y, x);
      EXPECT_EQ(got, expected) << y << ", " << x;
      EXPECT_EQ(std::signbit(got), std::signbit(expected)) << y << ", " << x;
    }
  }
  EXPECT_TRUE(std::isnan(atan2_polynomial(std::nanf(""), 1.0f)));
  EXPECT_TRUE(std::isnan(atan2_polynomial(1.0f, std::nanf(""))));
}

}  // namespace
}  // namespace mm
