#pragma once
// Where the viewer's database comes from: a file (--db), or a folder of motion capture built
// on start (--data, $MM_DATA, or the shared Bandai folder) with a progress bar. A built
// database is cached next to the program (viewer-cache/<folder>-<fingerprint>.mmdb); the
// fingerprint covers every input file's path, size and modification time, so changed data
// is rebuilt and unchanged data loads at once.

#include <memory>
#include <string>

#include "mm/database/database.hpp"
#include "mm/runtime/result.hpp"

namespace mm::viewer {

// The folder used when neither --db nor --data is given.
std::string default_data_folder();

// Loads `db_path` when given, else builds (or loads the cached build of) `data_path` or the
// default folder. Says what it does on stdout.
Result<std::shared_ptr<const Database>> open_database(const std::string& db_path,
                                                      const std::string& data_path);

}  // namespace mm::viewer
