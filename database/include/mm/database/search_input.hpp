#pragma once
// The bridge from a Database to the search library (mm/search/search.hpp), which knows nothing
// of the Database type and takes views of the arrays it searches.

#include <vector>

#include "mm/database/database.hpp"
#include "mm/search/search.hpp"

namespace mm {

// A database's search arrays as a SearchInput. The features, searchable flags and clip indices
// are views of the database, which must outlive this object; the clips' ranges and tags are
// copied (SearchClip), so `input` also points into this object, which therefore cannot be
// copied or moved. Change `input`'s views (e.g. a narrower searchable mask) before building.
struct DatabaseSearchInput {
  explicit DatabaseSearchInput(const Database& database);
  DatabaseSearchInput(const DatabaseSearchInput&) = delete;
  DatabaseSearchInput& operator=(const DatabaseSearchInput&) = delete;

  std::vector<SearchClip> clips;  // one per database clip: range and tag mask
  SearchInput input;              // views of the database and of `clips`
};

}  // namespace mm
