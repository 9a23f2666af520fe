#pragma once
// The database file: one relocatable binary blob written and read by one call each (the writer,
// save_database(), is on the build side: mm/offline/database_writer.hpp). Loading
// trusts nothing: the magic, version, endianness, sizes, every section's place, every count and
// string length, a 64-bit checksum over the whole file and finally Database::validate() are all
// checked, and any failure comes back as a message naming the file, the section and the index.
//
// Layout of format version 4 (all integers and floats in the writer's native byte order, which
// the endianness marker pins down; offsets in bytes from the start of the file). docs/
// database-file.md explains the choices and the measurements behind them.
//
//   0    magic            8 bytes  8A 'M' 'M' 'D' '\r' '\n' 1A '\n' (catches text-mode and
//                                  7-bit transfers, which rewrite or strip these bytes)
//   8    format_version   uint32   kDatabaseFormatVersion
//   12   endian_marker    uint32   0x01020304
//   16   file_size        uint64   the total size of the file, checksum included
//   24   header_size      uint32   kDatabaseHeaderSize (where the first section may start)
//   28   section_count    uint32   kDatabaseSectionCount
//   32   joint_count, frame_count, clip_count, tag_count, feature_dims, channel_count: uint32 each
//   56   frame_time       float32  seconds
//   60   reserved         28 bytes of zeros
//   88   section table    kDatabaseSectionCount x {uint64 offset, uint64 length}, in
//                                  DatabaseSection order
//   ...  sections         each at a 16-byte aligned offset, in table order, zero padding between
//   file_size - 8         checksum uint64   database_checksum() of every byte before it
//
// Only what cannot be derived is stored, and losslessly: after loading, local positions,
// rotations, contacts, features and everything else are bit for bit what was saved.
//   - Positions: a joint whose local position is the same (bit for bit) on every frame of a clip
//     (every joint but the roots and the hips in BVH data) is stored once for that clip.
//     position_columns holds one uint8 per clip and joint (clip-major): 1 = constant in the
//     clip, its value next in constant_positions; 0 = varies, its values in varying_positions
//     (clip by clip, frame by frame, the varying joints in joint order).
//   - Rotations: "smallest three" without loss. Per sample (frame-major, like the arrays),
//     rotation_components holds the three components other than the largest one, in x, y, z, w
//     order, and rotation_codes one byte: bits 0-1 the index (x, y, z, w) of the left-out
//     component, bit 2 its sign, bits 3-7 (0..30) 16 + the distance in units in the last place
//     between its magnitude and float(sqrt(1 - a*a - b*b - c*c)) computed in double from the
//     three stored ones. Code 31 in bits 3-7 marks a value too far off (or not finite): the
//     exact float is in rotation_exceptions, records {uint64 sample, float32 value, uint32 0}
//     in increasing sample order, one per such code.
//   - Velocities and angular velocities are not stored: load recomputes them clip by clip with
//     compute_local_velocities() (preprocess.hpp), the builder's own function, so they equal
//     the built ones bit for bit and never look across a clip boundary.
//   - Features are stored (recomputing them from the poses costs more than reading them).
// Fixed-size sections are plain arrays: vec3 as x, y, z; a rest transform as rotation (x, y, z,
// w), translation (x, y, z), scale (x, y, z). Variable sections are records packed back to back
// with no padding:
//   string list (skeleton names, tag names): uint32 length, then the bytes (no terminator);
//   style_names: uint32 count (at most kMaxStyles), then that many strings;
//   schema channel: uint8 kind, 3 zero bytes, string name, string bone, uint32 time count, that
//     many float32 times, float32 axis x, y, z, float32 weight;
//   clip: int32 start, int32 end, uint64 tags, uint8 mirrored (0 or 1), 3 zero bytes, int32 style
//     (an index into style_names, or -1 for none), string name.
// frame_clip is not stored: it is derived from the clips on load.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// The format version this program writes and the only one it reads. Older versions are refused
// with a message to rebuild: version 1 stored every array per frame and joint, velocities
// included; version 2 held six joint roles in the header instead of the humanoid map's section;
// version 3 had no styles (no style in the clip records, no style_names section).
inline constexpr uint32_t kDatabaseFormatVersion = 4;
// The value written in the endianness field; read back byte-swapped on a machine of the other
// byte order.
inline constexpr uint32_t kDatabaseEndianMarker = 0x01020304u;
// The 8 magic bytes at the start of every database file.
inline constexpr std::array<unsigned char, 8> kDatabaseMagic = {0x8A, 'M',  'M',  'D',
                                                                '\r', '\n', 0x1A, '\n'};

// The sections of a version-4 file, in the order they appear in the table and in the file.
enum class DatabaseSection : uint32_t {
  Schema = 0,          // feature channels (variable records)
  SkeletonNames,       // joint names (string list)
  SkeletonParents,     // int32 per joint
  SkeletonRest,        // rest transform per joint (10 floats)
  SkeletonRoles,       // int32 joint (or -1) per row of kJointRoles, in its order
  Clips,               // clip records
  TagNames,            // string list
  PositionColumns,     // uint8 per clip and joint: 1 constant in the clip, 0 varying
  ConstantPositions,   // vec3 per constant column
  VaryingPositions,    // vec3 per frame and varying column, clip by clip
  RotationComponents,  // 3 float32 per frame and joint
  RotationCodes,       // uint8 per frame and joint
  RotationExceptions,  // {uint64 sample, float32 value, uint32 0} per escape code
  Contacts,            // uint8 x 2 per frame
  Features,            // float32 x feature_dims per frame
  FeatureOffset,       // float32 x feature_dims
  FeatureScale,        // float32 x feature_dims
  Searchable,          // uint8 per frame
  StyleNames,          // uint32 count, then a string list
  Count,               // not a section: the number of sections
};
// Number of sections in a version-4 file.
inline constexpr size_t kDatabaseSectionCount = static_cast<size_t>(DatabaseSection::Count);
// Size of the fixed header including the section table (88 + 16 per section), rounded up to 16
// bytes.
inline constexpr uint32_t kDatabaseHeaderSize = (88 + 16 * kDatabaseSectionCount + 15) / 16 * 16;

// Largest counts a file may declare; anything larger is refused as corrupt before allocating.
inline constexpr uint32_t kMaxDatabaseJoints = 4096;
inline constexpr uint32_t kMaxDatabaseFrames = 1u << 27;
inline constexpr uint32_t kMaxDatabaseFeatureDims = 4096;
inline constexpr uint32_t kMaxDatabaseChannels = 1024;

// Human-readable name of a section for messages, e.g. "local_rotations".
const char* database_section_name(DatabaseSection section);

// Where one section lies in the file.
struct DatabaseFileSection {
  uint64_t offset = 0;  // bytes from the start of the file, a multiple of 16
  uint64_t length = 0;  // bytes
};

// What the header of a database file says, after its magic, version, endianness, sizes and
// section table were checked against the file size (the checksum and contents are not).
struct DatabaseFileInfo {
  uint32_t format_version = 0;  // always kDatabaseFormatVersion once parsed
  uint64_t file_size = 0;       // bytes, checksum included
  uint32_t joint_count = 0;     // skeleton joints (the simulation root included)
  uint32_t frame_count = 0;     // database frames
  uint32_t clip_count = 0;      // clip ranges
  uint32_t tag_count = 0;       // tag names
  uint32_t feature_dims = 0;    // columns of the feature matrix
  uint32_t channel_count = 0;   // feature schema channels
  float frame_time = 0.0f;      // seconds between frames
  std::array<DatabaseFileSection, kDatabaseSectionCount> sections{};  // in DatabaseSection order
  uint64_t stored_checksum = 0;  // the last 8 bytes of the file (0 when not read)

  const DatabaseFileSection& section(DatabaseSection s) const {
    return sections[static_cast<size_t>(s)];
  }
};

// The file's 64-bit checksum of a byte range: four independent multiply-rotate lanes over
// 32-byte blocks (several GB/s), a word and byte tail, and an avalanche finalizer. Every lane
// step is a bijection of both the state and the input word, so any change confined to one
// 8-byte word is always detected.
uint64_t database_checksum(std::span<const std::byte> bytes);

// Parses and checks the header of a file image (magic, endianness, version, header and total
// sizes, section table against the counts). `name_for_messages` prefixes every message. Does not
// verify the checksum; `stored_checksum` is filled when the image is complete.
Result<DatabaseFileInfo> parse_database_header(std::span<const std::byte> bytes,
                                               std::string_view name_for_messages);

// Rebuilds a database from a file image, validating everything (see the top of this file),
// recomputes the velocities and derives frame_clip. Never trusts a count or offset before
// checking it against the bytes.
Result<Database> deserialize_database(std::span<const std::byte> bytes,
                                      std::string_view name_for_messages);

// Reads the whole file (memory-mapped when possible) and deserializes it. Messages name the path.
Result<Database> load_database(const std::filesystem::path& path);

// Reads and checks only the header of a database file (cheap, for `mm info`): the full load
// still has to verify the checksum and contents.
Result<DatabaseFileInfo> read_database_header(const std::filesystem::path& path);

}  // namespace mm
