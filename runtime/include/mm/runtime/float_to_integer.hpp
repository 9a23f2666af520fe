#pragma once
// Float-to-integer conversion defined for every input. A static_cast of a floating-point value
// that is NaN, infinite or outside the integer type's range is undefined behaviour (UBSan's
// float-cast-overflow), and values derived from files, command lines or long runs (times,
// rates, frame counts from durations) can be anything. Every such conversion in the tree goes
// through one of these two instead of a bare static_cast:
// - checked_integer: the caller reports a value that does not fit (an error to the user);
// - clamped_integer: the caller has validated the inputs and only needs the conversion to stay
//   defined; an out-of-range value saturates, NaN gives 0.
// Both truncate toward zero like static_cast; round first (std::floor, std::ceil, std::round)
// for another rounding. std::round gives what std::lround gives, without lround's unspecified
// result for a value outside long. Nothing here allocates.

#include <cmath>
#include <concepts>
#include <limits>
#include <optional>

namespace mm {

// True when `value`, truncated toward zero, is a value of I. The bounds are powers of two, so
// they are exact in double even for 64-bit integers.
template <std::integral I>
constexpr bool fits_integer(double value) {
  constexpr double upper = static_cast<double>(std::numeric_limits<I>::max() / 2 + 1) * 2.0;
  constexpr double lower = std::numeric_limits<I>::is_signed ? -upper : 0.0;
  // Truncation toward zero: lower - 1 < value < lower still gives lower (0 for unsigned types).
  // For 64-bit types lower - 1 rounds to lower in double, hence the first test.
  return value < upper && (value >= lower || value > lower - 1.0);
}

// `value` truncated toward zero, or nullopt when it is NaN, infinite or does not fit I.
template <std::integral I>
std::optional<I> checked_integer(double value) {
  if (!fits_integer<I>(value)) return std::nullopt;  // NaN fails both comparisons
  return static_cast<I>(value);
}

// `value` truncated toward zero and saturated to I's range; NaN gives 0.
template <std::integral I>
I clamped_integer(double value) {
  if (std::isnan(value)) return 0;
  if (fits_integer<I>(value)) return static_cast<I>(value);
  return value > 0.0 ? std::numeric_limits<I>::max() : std::numeric_limits<I>::min();
}

}  // namespace mm
