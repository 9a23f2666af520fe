#include "mm/database/search_input.hpp"

namespace mm {

DatabaseSearchInput::DatabaseSearchInput(const Database& database) {
  clips.reserve(database.clips().size());
  for (const ClipRange& clip : database.clips()) clips.push_back({clip.start, clip.end, clip.tags});
  input.features = database.features();
  input.dims = database.feature_dims();
  input.searchable = database.searchable();
  input.frame_clip = database.frame_clip();
  input.clips = clips;
}

}  // namespace mm
