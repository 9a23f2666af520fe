#pragma once
// Database::validate in two parts, for the file loader: it checks each clip's per-frame joint
// values as it decodes them (positions as it copies them, velocities as it computes them,
// rotations with rotations_unit while they are in cache), and then validates the rest without
// scanning those arrays a second time.

#include <bit>
#include <cstddef>
#include <cstdint>

#include "mm/database/database.hpp"

namespace mm::detail {

// True when every one of `count` rotations is what validate() accepts: a finite unit quaternion.
bool rotations_unit(const glm::quat* rotations, size_t count);

// True when every float is finite, tested as validate() tests it.
inline bool finite_bits(float v) {
  return (std::bit_cast<uint32_t>(v) & 0x7f800000u) != 0x7f800000u;
}

inline bool finite3(const glm::vec3& v) {
  return finite_bits(v.x) && finite_bits(v.y) && finite_bits(v.z);
}

// Everything validate() checks but the per-frame joint arrays; validate() is this and then
// those arrays.
Status validate_except_joint_values(const DatabaseView& db);

}  // namespace mm::detail
