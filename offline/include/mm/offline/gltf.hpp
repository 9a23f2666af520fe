#pragma once
// glTF 2.0 import and export of skeletal animation (through tinygltf).
//
// Import (load_gltf) reads one skin of a .gltf (JSON, buffers embedded or in files next to it)
// or .glb file and turns it into a Skeleton, its inverse bind matrices, and one Clip per
// animation, sampled at a fixed rate:
// - Joints: the skin's joints plus any non-joint node lying between two joints (so the
//   hierarchy stays expressible), stored depth-first, parent before child, roots in the order
//   their first joint appears in the skin, children in the nodes' child order. The ancestors
//   of a skeleton root are not joints: their transforms (rest and animated) are folded into the
//   root's local transform, so globals come out in scene space. Joint names are the node
//   names; an empty or repeated name becomes "<name>_<node index>" ("node_<index>" if empty).
// - Rest transforms come from the nodes' TRS (a "matrix" is decomposed into TRS).
// - inverse_bind_matrices: the skin's, per skeleton joint (identity if the skin has none);
//   for the inserted non-joint nodes, the inverse of their rest global transform.
// - Animations: translation, rotation and scale channels with STEP, LINEAR (rotations: slerp
//   along the shortest path) or CUBICSPLINE (Hermite with the in/out tangents scaled by the
//   keyframe interval; rotations renormalized) samplers, sampled every 1 / sample_rate
//   seconds from the earliest to the latest keyframe time of the channels that reach the
//   skeleton (a tail shorter than one frame is dropped; a sample within a few float ulps of a
//   key takes that key exactly, as float key times are rounded). Joints without a channel keep
//   their node's rest TRS. Channels on nodes outside the skeleton and its roots' ancestors, and
//   "weights" (morph target) channels, are ignored; an animation none of whose channels
//   reaches the skeleton produces no clip. A clip is named after its animation; an unnamed
//   one takes the file stem (plus "_<animation index>" when the file has several).
// - Folding ancestors uses mm::compose, exact for rotations, translations and uniform scale; a
//   non-uniform scale above a rotated root is approximated (glTF would need a sheared matrix).
//   The skin's optional "skeleton" property is not needed and not read.
// - Everything is validated (indices, accessor types and bounds, counts, finite values,
//   increasing key times, the GLB container); an error names the file and what is wrong.
//   Sparse accessors and images are not read (images are skipped, never decoded; an image
//   naming a file is never opened).
// - External files: a glTF file is untrusted input, so its buffers come only from data: URIs,
//   the GLB binary chunk, or a relative path (percent-decoded) to a file inside the glTF
//   file's own folder or below it: no absolute path, no ".." out of the folder, no symbolic
//   link resolving outside it (paths are made canonical before the check). The file must be
//   a regular file (not a FIFO, folder or device) whose size equals the buffer's byteLength,
//   at most kGltfMaxExternalBufferBytes, the external buffers together at most that too. All
//   of this is checked for every buffer before any file is opened, and each file is checked
//   again on its open descriptor; a refusal names the buffer, its uri and the reason:
//   "<file>: buffer 0 (uri '../x.bin') leaves the glTF file's folder through '..'". With
//   GltfImportOptions::allow_external_files false (bytes from anywhere but a file) every
//   buffer naming a file is refused.
// - Skinned mesh (only with GltfImportOptions::read_skinned_mesh): the first primitive of the
//   mesh of the first node (in node order) skinned with the chosen skin. Triangles only
//   (mode 4), indexed (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT) or not; POSITION
//   (FLOAT VEC3), JOINTS_0 (UNSIGNED_BYTE or UNSIGNED_SHORT VEC4) and WEIGHTS_0 (FLOAT or
//   normalized UNSIGNED_BYTE/UNSIGNED_SHORT VEC4) are required, NORMAL (FLOAT VEC3) is read
//   when present; more than four influences (JOINTS_1) are refused. JOINTS_0 values index the
//   skin's joints and are mapped to skeleton joint indices; weights must be >= 0 with a
//   positive sum and are normalized to sum 1; a slot with weight 0 is stored as joint 0. The
//   bind pose of every skeleton joint is the inverse of its inverse bind matrix. The node's
//   own transform is ignored, as glTF specifies for skinned meshes.
//
// Export (save_gltf) writes a pose sequence and its skeleton as a file Blender and other
// importers open as an animated armature: one node per joint with its rest TRS, a skin over
// all joints whose inverse bind matrices are the inverses of the rest globals, a one-triangle
// mesh (1 cm, at the first joint's rest position, fully weighted to joint 0) so every
// importer sees the skin, and one animation with a LINEAR translation and rotation channel per
// joint (and a scale channel for joints whose scale leaves the rest scale), one key per frame.
// ".glb" writes a binary file; ".gltf" writes one JSON file with the buffer embedded as base64.
// save_skinned_gltf writes the same with a real body instead of the anchor triangle: the
// joint nodes' rest TRS are the body's bind pose (so importers show the armature in it), the
// inverse bind matrices are the inverses of the body's bind_global, and one mesh primitive
// holds POSITION, NORMAL (when the mesh has normals), JOINTS_0 (UNSIGNED_SHORT), WEIGHTS_0
// (FLOAT, normalized to sum 1) and UNSIGNED_INT indices, on a node bound to the skin.
//
// Units as everywhere in the project: metres, seconds, Y up, right-handed.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "mm/offline/clip.hpp"
#include "mm/runtime/mesh.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// The largest external buffer file the importer reads, and the most all of one glTF file's
// external buffers may add up to (1 GiB: hours of animation of a detailed skeleton; the
// bytes are held in memory while the file is parsed).
inline constexpr uint64_t kGltfMaxExternalBufferBytes = uint64_t{1} << 30;

// Settings of the glTF importer.
struct GltfImportOptions {
  // Animations are resampled to this fixed rate (Hz); must be finite and > 0.
  float sample_rate = 30.0f;
  // Index of the skin (in the file's "skins" array) that defines the skeleton.
  int skin = 0;
  // Also read the mesh skinned with that skin into GltfAsset::skinned_mesh; a file without
  // one, or whose mesh is malformed, is then refused. Off, meshes are not looked at.
  bool read_skinned_mesh = false;
  // Whether buffers may name files beside the glTF file (see "External files" above). Off, as
  // for bytes that did not come from a file (fuzzing, the network), only data: URIs and the
  // GLB binary chunk are read.
  bool allow_external_files = true;
};

// What a glTF file holds for us: one skeleton and its animations.
struct GltfAsset {
  // The skin's joint hierarchy (see the header comment for which nodes become joints).
  Skeleton skeleton;
  // One matrix per skeleton joint (same order), mapping scene space to the joint's bind space.
  std::vector<glm::mat4> inverse_bind_matrices;
  // One clip per animation that moves the skeleton, in file order, sharing `skeleton`.
  std::vector<Clip> clips;
  // With GltfImportOptions::read_skinned_mesh: the skinned mesh, its influences as skeleton
  // joint indices, and bind_global per skeleton joint (the inverse of inverse_bind_matrices).
  std::optional<SkinnedMesh> skinned_mesh;
};

// Reads a .gltf or .glb file (recognized by its content: binary files start with "glTF").
Result<GltfAsset> load_gltf(const std::filesystem::path& path,
                            const GltfImportOptions& options = {});

// Parses a glTF file already in memory; path_for_messages names it in errors, becomes each
// clip's source_path, and its folder is where external buffers are looked up (unless
// options.allow_external_files is false).
Result<GltfAsset> parse_gltf(std::span<const unsigned char> bytes,
                             const std::filesystem::path& path_for_messages,
                             const GltfImportOptions& options = {});

// Writes a clip (skeleton, frames, frame time) as glTF; the format follows the extension of
// `out` (".glb" binary, ".gltf" single JSON file). The animation is named after the clip.
Status save_gltf(const Clip& clip, const std::filesystem::path& out);

// Writes any pose sequence: frame_count poses of skeleton.joint_count() local transforms each,
// frame-major (frames[f * joint_count + j]), frame_time seconds apart, as an animation named
// `name`. The format follows the extension of `out` as above.
Status save_gltf(const Skeleton& skeleton, std::span<const Transform> frames, int frame_count,
                 float frame_time, std::string_view name, const std::filesystem::path& out);

// Writes a pose sequence (as the save_gltf above) together with a skinned body: `body` has one
// bind_global per skeleton joint and one influence per vertex with joints in range. The body
// is checked (sizes, indices, finite values, weights >= 0 with a positive sum) before anything
// is written.
Status save_skinned_gltf(const Skeleton& skeleton, const SkinnedMesh& body,
                         std::span<const Transform> frames, int frame_count, float frame_time,
                         std::string_view name, const std::filesystem::path& out);

}  // namespace mm
