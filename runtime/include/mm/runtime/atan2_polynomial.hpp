#pragma once
// atan2 without the library call: the per-update yaws (quat_yaw, pair_yaw) and the logarithm
// of large rotations take dozens of atan2 an update, and the library's atan2f costs several
// times a polynomial. The octant is reduced to a ratio t in [0, 1], atan(t) = t p(t^2) with p
// a degree-8 fit of atan(t) / t on [0, 1] (minimax, refined in long double, rounded to float),
// then mapped back. Its error is within about 1e-7 rad of the exact value, two units in the last
// place of pi / 4, plus the final rounding: far below any angle the controller or its metrics
// resolve. Zeros, infinities and NaN take the library's atan2, so its conventions
// (atan2(+-0, -0) = +-pi, atan2(inf, inf) = pi / 4, NaN in -> NaN out) hold unchanged.

#include <cfloat>
#include <cmath>

namespace mm {

// The fit p of atan(t) / t, highest degree first (Horner's order), and the octant's constants as
// floats: the scalar function and the dead blend's lanes (dead_blending.cpp) share them.
inline constexpr float kAtanFit[9] = {2.456725342e-03f,  -1.440136135e-02f, 3.978123143e-02f,
                                      -7.234857976e-02f, 1.049894616e-01f,  -1.416122913e-01f,
                                      1.998590678e-01f,  -3.333259821e-01f, 9.999998808e-01f};
inline constexpr float kAtanHalfPi = 1.57079637f;
inline constexpr float kAtanPi = 3.14159274f;

inline float atan2_polynomial(float y, float x) {
  const float ax = std::abs(x);
  const float ay = std::abs(y);
  const float largest = ax > ay ? ax : ay;
  // Also false for NaN.
  if (!(largest > 0.0f && largest <= FLT_MAX)) return std::atan2(y, x);
  const float t = (ax > ay ? ay : ax) / largest;
  const float s = t * t;
  float p = kAtanFit[0];
  for (int k = 1; k < 9; ++k) p = p * s + kAtanFit[k];
  float angle = t * p;
  if (ay > ax) angle = kAtanHalfPi - angle;
  if (x < 0.0f) angle = kAtanPi - angle;
  return std::copysign(angle, y);
}

}  // namespace mm
