#include "body_source.hpp"

#include <cstdio>
#include <memory>

#include "mm/offline/character_body.hpp"

namespace mm::viewer {
namespace {

std::string describe(const SkinnedMesh& mesh, const std::string& origin) {
  char text[160];
  std::snprintf(text, sizeof text, "%zu vertices, %zu triangles", mesh.mesh.vertex_count(),
                mesh.mesh.triangle_count());
  return origin + " (" + text + ")";
}

}  // namespace

Result<BodySource> make_body(const Database& database, const ViewerOptions& options) {
  BodySource source;
  if (!options.body_path.empty()) {
    Result<SkinnedMesh> loaded = load_body_gltf(options.body_path, database.skeleton());
    if (!loaded) return loaded.error();
    source.mesh = std::move(*loaded);
    source.description = describe(source.mesh, "body loaded from " + options.body_path);
    return source;
  }
  CharacterBodyOptions body_options;
  body_options.weights.method = options.weights;
  Result<CharacterBody> body = build_character_body(database, body_options);
  if (!body) return body.error();
  char timing[120];
  std::snprintf(timing, sizeof timing, ", surface %.2f s, %s weights %.2f s", body->mesh_seconds,
                std::string(weight_method_name(options.weights)).c_str(), body->weight_seconds);
  source.description = describe(body->skinned, "body generated from the skeleton") + timing;
  // Other weight methods are recomputed on the same surface and capsules.
  auto kept = std::make_shared<const CharacterBody>(*body);
  source.reweigh = [kept](WeightMethod method) {
    BoneWeightOptions weights;
    weights.method = method;
    return compute_bone_weights(kept->skinned.mesh, kept->segments, weights);
  };
  source.mesh = std::move(body->skinned);
  return source;
}

}  // namespace mm::viewer
