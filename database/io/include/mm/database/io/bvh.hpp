#pragma once
// BVH (Biovision Hierarchy) importer: text in, Clip out, in one pass over the buffer.
//
// What it produces:
// - Joints in file (depth-first) order, names kept. End Sites are not joints: their offsets
//   are read and validated, then dropped, because they carry no channels and nothing animates
//   them.
// - Rest transform of a joint = its OFFSET (scaled to metres), identity rotation.
// - Per-frame local transform: the translation is the OFFSET, with every position channel the
//   joint has replacing the matching component (the convention of the BVH files we read: their
//   non-root position channels repeat the offset). The rotation is the product of the rotation
//   channels' Euler angles (degrees) in the order the channels are listed, column vectors:
//   "Zrotation Xrotation Yrotation" gives R = Rz * Rx * Ry.
// - Any channel order per joint, 0 to 6 channels (each channel name at most once), position and
//   rotation channels interleaved freely; tabs or spaces; LF or CRLF line ends.
//
// The MOTION section holds exactly one frame per line (blank lines are skipped). Malformed
// input is refused with "<file>:<line>: expected ..., found ..." rather than repaired. The
// parser is iterative (no recursion, whatever the hierarchy depth), never hangs, and never
// allocates more frame storage than the remaining bytes could fill.

#include <filesystem>
#include <string_view>

#include "mm/database/clip.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// Settings of the BVH importer.
struct BvhOptions {
  // Multiplies every OFFSET and position channel: source units to metres. The BVH files of
  // this project are in centimetres, hence 0.01. Must be finite and > 0.
  float scale = 0.01f;
};

// Parses the whole text of a BVH file. path_for_messages names the file in error messages and
// becomes the clip's source_path; its stem becomes the clip's name.
Result<Clip> parse_bvh(std::string_view text, std::string_view path_for_messages,
                       const BvhOptions& options = {});

// Reads the whole file into memory at once, then parses it with parse_bvh.
Result<Clip> load_bvh(const std::filesystem::path& path, const BvhOptions& options = {});

}  // namespace mm
