#pragma once
// The character's body: generated from the database's skeleton and skinned with the chosen
// weight method, or a skinned glTF character (--body) whose joints are matched to the
// database's by name.

#include <string>

#include "mm/database/database.hpp"
#include "scene.hpp"
#include "viewer_options.hpp"

namespace mm::viewer {

struct BodySource {
  SkinnedMesh mesh;
  ReweighFunction reweigh;  // empty for a loaded body (its weights are its own)
  std::string description;  // for the log: where the body came from, its size
};

Result<BodySource> make_body(const Database& database, const ViewerOptions& options);

}  // namespace mm::viewer
