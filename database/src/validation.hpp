#pragma once
// Database::validate in two parts, for the file loader: it checks each clip's per-frame joint
// values as it decodes them, while they are still in cache, and then validates the rest
// without scanning those arrays a second time.

#include <cstddef>

#include "mm/database/database.hpp"

namespace mm::detail {

// True when the joint values of samples [first, first + count) (frame * joints + joint) are
// what validate() accepts: finite unit rotations, finite positions and velocities.
bool joint_values_valid(const Database& db, size_t first, size_t count);

// Everything validate() checks but the per-frame joint arrays; validate() is this and then
// those arrays.
Status validate_except_joint_values(const Database& db);

}  // namespace mm::detail
