#pragma once
// Writing the database file (database_file.hpp describes its layout; load_database() reads it):
// the builder's last step and `mm build`'s output. Both take a view, so a Database and a
// DatabaseContents write alike.

#include <cstddef>
#include <filesystem>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// The exact bytes of the file save_database() writes. Writes whatever the arrays hold (an
// inconsistent database gives a file that load refuses); does not validate. The velocities and
// angular velocities are not written: load recomputes them from the poses.
std::vector<std::byte> serialize_database(const DatabaseView& db);

// Validates the database, then writes it to `path` through a temporary file in the same folder
// renamed into place, so a failed write never leaves a half-written database behind.
Status save_database(const DatabaseView& db, const std::filesystem::path& path);

}  // namespace mm
