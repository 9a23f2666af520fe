#pragma once
// BVH (Biovision Hierarchy) importer: text in, Clip out, in one pass over the buffer; and the
// exporter that writes a Clip back as BVH text the importer reads (see format_bvh).
//
// What it produces:
// - Joints in file (depth-first) order, names kept. End Sites are not joints (they carry no
//   channels and nothing animates them); the first End Site offset of each joint is kept in
//   Clip::end_sites, where retargeting finds the direction of a bone that has no child joint.
// - Rest transform of a joint = its OFFSET (scaled to metres), identity rotation.
// - Per-frame local transform: the translation is the OFFSET, with every position channel the
//   joint has replacing the matching component (the convention of the BVH files we read: their
//   non-root position channels repeat the offset). The rotation is the product of the rotation
//   channels' Euler angles (degrees) in the order the channels are listed, column vectors:
//   "Zrotation Xrotation Yrotation" gives R = Rz * Rx * Ry.
// - Any channel order per joint, 0 to 6 channels (each channel name at most once), position and
//   rotation channels interleaved freely; tabs or spaces; LF or CRLF line ends.
//
// The MOTION section holds one frame per line (blank lines are skipped). Fewer frame lines than
// "Frames:" declares is an error. More is accepted, as Blender and assimp accept it (assimp's
// own Boxing_Toes.bvh declares 3069 frames and holds 3070): the declared frames are read, the
// non-blank lines after them are counted but not parsed (whatever they hold), and the clip gets
// one warning in Clip::warnings: "<file>:<line>: ignored N frame line(s) beyond 'Frames: M' on
// line L", <line> being the first ignored line. Malformed input is refused with
// "<file>:<line>: expected ..., found ..." rather than repaired. The parser is iterative (no
// recursion, whatever the hierarchy depth), never hangs, and never allocates more frame storage
// than the remaining bytes could fill.

#include <filesystem>
#include <string>
#include <string_view>

#include "mm/offline/clip.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// Settings of the BVH importer.
struct BvhOptions {
  // Multiplies every OFFSET and position channel: source units to metres. The Bandai files are
  // in centimetres, hence 0.01. 0 picks the units from the skeleton's size (see
  // bvh_units_to_metres). Must be finite and >= 0.
  float scale = 0.01f;
};

// The scale from file units to metres of a skeleton whose joints and End Sites reach at most
// `extent` file units from its root in the rest pose (a person's reaches 0.7-1.1 m): metres
// below 5, inches below 50, centimetres below 500, millimetres above.
float bvh_units_to_metres(float extent);

// Parses the whole text of a BVH file. path_for_messages names the file in error messages and
// warnings and becomes the clip's source_path; its stem becomes the clip's name. What was
// accepted but ignored is in the clip's warnings (see above).
Result<Clip> parse_bvh(std::string_view text, std::string_view path_for_messages,
                       const BvhOptions& options = {});

// Reads the whole file into memory at once, then parses it with parse_bvh.
Result<Clip> load_bvh(const std::filesystem::path& path, const BvhOptions& options = {});

// Writes a clip as BVH text that parse_bvh reads back as the same clip (positions and rotations
// to float precision; options.scale = 1 / units_per_metre):
// - HIERARCHY: the joints depth-first (ROOT for each joint without a parent, several allowed),
//   children in index order, which is the skeleton's own order when it is depth-first as every
//   importer makes it. OFFSET = the joint's rest translation in file units. Every joint has the
//   six channels "Xposition Yposition Zposition Zrotation Xrotation Yrotation", so per-frame
//   translations that leave the offset survive. A leaf gets an End Site whose OFFSET is its
//   Clip::end_sites entry (zero when there is none); a joint with children gets one only when
//   its entry is non-zero.
// - MOTION: "Frames: N", "Frame Time: <seconds>", one line per frame: each joint's local
//   translation in file units, then Euler angles in degrees with R = Rz * Rx * Ry.
// - Numbers are the shortest decimals that read back as the same float, never in exponent
//   form, so other BVH readers parse them too.
// - BVH has no rest rotation and no scale: rest rotations and every scale are not written.
// Requires a clip that passes Clip::validate() and units_per_metre finite and > 0; save_bvh
// checks both (and more) before calling it.
std::string format_bvh(const Clip& clip, float units_per_metre);

// Writes format_bvh(clip, units_per_metre) to `out` (units_per_metre 100: centimetres, as the
// Bandai files). Refused, with `out` and the reason in the message: a clip that fails
// Clip::validate(), units_per_metre not finite or <= 0, a joint name BVH cannot hold (with
// whitespace, or "{" or "}"), a value that overflows a float in file units, a file that cannot
// be written.
Status save_bvh(const Clip& clip, const std::filesystem::path& out, float units_per_metre = 100.0f);

}  // namespace mm
