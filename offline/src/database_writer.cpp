// The database file's writer: a Database, or the DatabaseContents of one, to the bytes of
// database_file.hpp's layout, read back by load_database().

#include "mm/offline/database_writer.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <type_traits>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "mm/database/files.hpp"
#include "mm/internal/database_format.hpp"
#include "mm/internal/workers.hpp"

namespace mm {

namespace {

using namespace detail;

class ByteWriter {
 public:
  explicit ByteWriter(size_t expected_size) {
    bytes_.reserve(expected_size);
    advise_huge_pages(bytes_.data(), expected_size);
  }

  void raw(const void* data, size_t size) {
    const auto* p = static_cast<const std::byte*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  template <class T>
  void pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&value, sizeof value);
  }
  void string(std::string_view s) {
    pod(static_cast<uint32_t>(s.size()));
    raw(s.data(), s.size());
  }
  template <class T>
  void array(const std::vector<T>& values) {
    array(std::span<const T>(values));
  }
  template <class T>
  void array(std::span<const T> values) {
    if (values.empty()) return;
    if constexpr (std::is_trivially_copyable_v<T>) {
      raw(values.data(), values.size() * sizeof(T));
    } else {
      // GLM types: standard-layout runs of floats, written from their float members.
      static_assert(std::is_standard_layout_v<T> && sizeof(T) % sizeof(float) == 0);
      raw(glm::value_ptr(values[0]), values.size() * sizeof(T));
    }
  }
  void zeros(size_t count) { bytes_.insert(bytes_.end(), count, std::byte{0}); }
  // Appends `count` bytes for the caller to fill; returns their offset.
  size_t extend(size_t count) {
    const size_t offset = bytes_.size();
    bytes_.resize(offset + count);
    return offset;
  }
  void align16() { zeros((16 - bytes_.size() % 16) % 16); }

  size_t size() const { return bytes_.size(); }
  template <class T>
  void patch(size_t offset, const T& value) {
    std::memcpy(bytes_.data() + offset, &value, sizeof value);
  }
  std::vector<std::byte>& bytes() { return bytes_; }

 private:
  std::vector<std::byte> bytes_;
};

void write_rest(ByteWriter& w, const Transform& t) {
  const float values[10] = {t.rotation.x,    t.rotation.y,    t.rotation.z,    t.rotation.w,
                            t.translation.x, t.translation.y, t.translation.z, t.scale.x,
                            t.scale.y,       t.scale.z};
  w.raw(values, sizeof values);
}

// ---- Rotations ---------------------------------------------------------------------------------

struct EncodedRotation {
  float components[3];
  uint8_t code;
  float exact;  // the left-out component, needed when the code is an escape
};

EncodedRotation encode_rotation(const glm::quat& q) {
  const float c[4] = {q.x, q.y, q.z, q.w};
  // The first of the largest magnitudes, without branches (the index is data, not a pattern).
  int largest = 0;
  float best = std::abs(c[0]);
  for (int k = 1; k < 4; ++k) {
    const float magnitude = std::abs(c[k]);
    const bool larger = magnitude > best;
    largest = larger ? k : largest;
    best = larger ? magnitude : best;
  }
  constexpr int kOthers[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  EncodedRotation out{};
  for (int n = 0; n < 3; ++n) out.components[n] = c[kOthers[largest][n]];
  const uint32_t bits = std::bit_cast<uint32_t>(c[largest]);
  const uint32_t sign = bits >> 31;
  const uint32_t magnitude = bits & 0x7FFFFFFFu;
  const uint32_t predicted = std::bit_cast<uint32_t>(
      unit_complement(out.components[0], out.components[1], out.components[2]));
  const int64_t ulps = static_cast<int64_t>(magnitude) - static_cast<int64_t>(predicted);
  const bool fits = ulps >= kMinUlp && ulps <= kMaxUlp;
  const uint32_t field = fits ? static_cast<uint32_t>(ulps + kUlpBias) : kEscape;
  out.code = static_cast<uint8_t>(static_cast<uint32_t>(largest) | sign << 2 | field << 3);
  out.exact = c[largest];
  return out;
}

// ---- Positions ---------------------------------------------------------------------------------

// flags[j] = 1 when joint j's local position has the same bits on every frame of the clip
// (read frame by frame, in memory order).
void find_constant_columns(const JointValues<glm::vec3>& positions, size_t joints,
                           const ClipRange& clip, uint8_t* flags) {
  std::fill(flags, flags + joints, uint8_t{1});
  const size_t first = static_cast<size_t>(clip.start) * joints;
  for (int f = clip.start + 1; f < clip.end; ++f) {
    const size_t frame = static_cast<size_t>(f) * joints;
    for (size_t j = 0; j < joints; ++j) {
      const glm::vec3 value = positions[frame + j], first_value = positions[first + j];
      flags[j] &= static_cast<uint8_t>(std::memcmp(&value, &first_value, sizeof(glm::vec3)) == 0);
    }
  }
}

PositionLayout position_layout_of(const DatabaseView& db) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  PositionLayout layout;
  layout.constant.resize(db.clips.size() * joints);
  for (size_t c = 0; c < db.clips.size(); ++c) {
    find_constant_columns(db.local_positions, joints, db.clips[c],
                          layout.constant.data() + c * joints);
  }
  lay_out_positions(db.clips, joints, layout);
  return layout;
}

// ---- The file
// ------------------------------------------------------------------------------------

// The header and the small sections of a version-3 file, written in place.
void write_header(ByteWriter& w, const DatabaseView& db) {
  w.raw(kDatabaseMagic.data(), kDatabaseMagic.size());
  w.pod(kDatabaseFormatVersion);
  w.pod(kDatabaseEndianMarker);
  w.zeros(kDatabaseHeaderSize - w.size());  // patched below once the sizes are known
  const uint32_t counts[6] = {static_cast<uint32_t>(db.skeleton.joint_count()),
                              static_cast<uint32_t>(db.frame_count),
                              static_cast<uint32_t>(db.clips.size()),
                              static_cast<uint32_t>(db.tag_names.size()),
                              static_cast<uint32_t>(db.schema.dims()),
                              static_cast<uint32_t>(db.schema.channels.size())};
  w.patch(kOffHeaderSize, kDatabaseHeaderSize);
  w.patch(kOffSectionCount, static_cast<uint32_t>(kDatabaseSectionCount));
  w.patch(kOffCounts, counts);
  w.patch(kOffFrameTime, db.frame_time);
}

void write_schema(ByteWriter& w, const FeatureSchema& schema) {
  for (const FeatureChannel& c : schema.channels) {
    w.pod(static_cast<uint8_t>(c.kind));
    w.zeros(3);
    w.string(c.name);
    w.string(c.bone);
    w.pod(static_cast<uint32_t>(c.times.size()));
    w.array(c.times);
    const float tail[4] = {c.axis.x, c.axis.y, c.axis.z, c.weight};
    w.raw(tail, sizeof tail);
  }
}

void write_clips(ByteWriter& w, std::span<const ClipRange> clips) {
  for (const ClipRange& c : clips) {
    w.pod(static_cast<int32_t>(c.start));
    w.pod(static_cast<int32_t>(c.end));
    w.pod(c.tags);
    w.pod(static_cast<uint8_t>(c.mirrored ? 1 : 0));
    w.zeros(3);
    w.pod(static_cast<int32_t>(c.style));
    w.string(c.name);
  }
}

void write_positions(ByteWriter& w, const DatabaseView& db, const PositionLayout& layout,
                     bool constant) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  const size_t offset = w.extend(12 * (constant ? layout.constant_count : layout.varying_count));
  std::byte* out = w.bytes().data() + offset;
  for (size_t c = 0; c < db.clips.size(); ++c) {
    const ClipRange& clip = db.clips[c];
    const uint8_t* flags = layout.constant.data() + c * joints;
    const int last = constant ? clip.start + 1 : clip.end;  // a constant column once
    for (int f = clip.start; f < last; ++f) {
      const size_t frame = static_cast<size_t>(f) * joints;
      for (size_t j = 0; j < joints; ++j) {
        if (flags[j] != (constant ? 1 : 0)) continue;
        const glm::vec3 value = db.local_positions[frame + j];
        std::memcpy(out, glm::value_ptr(value), 12);
        out += 12;
      }
    }
  }
}

// Rotations [begin, end) into their 12 bytes of components and their code byte, the escapes'
// exact values appended to `exceptions` in sample order.
void encode_rotations(const JointValues<glm::quat>& rotations, size_t begin, size_t end,
                      std::byte* components, std::byte* codes,
                      std::vector<RotationException>& exceptions) {
  for (size_t i = begin; i < end; ++i) {
    const EncodedRotation e = encode_rotation(rotations[i]);
    std::memcpy(components + 12 * i, e.components, sizeof e.components);
    codes[i] = std::byte{e.code};
    if (is_escape(e.code)) exceptions.push_back({i, e.exact});
  }
}

// The three rotation sections: components and codes sample by sample, then the exceptions.
void write_rotations(ByteWriter& w, const DatabaseView& db,
                     std::array<DatabaseFileSection, kDatabaseSectionCount>& table) {
  const size_t samples = db.local_rotations.size();
  w.align16();
  const size_t components = w.extend(12 * samples);
  w.align16();
  const size_t codes = w.extend(samples);
  table[static_cast<size_t>(DatabaseSection::RotationComponents)] = {components, 12 * samples};
  table[static_cast<size_t>(DatabaseSection::RotationCodes)] = {codes, samples};
  // In chunks on two threads for a large database, each chunk's exceptions kept apart and then
  // joined in chunk order, so they stay in sample order.
  const size_t chunks = samples * 16 >= kParallelBytes ? 8 : 1;
  std::vector<std::vector<RotationException>> exceptions(chunks);
  std::byte* bytes = w.bytes().data();
  detail::run_workers(chunks, chunks > 1 ? 2 : 1, [&](int, size_t chunk) {
    encode_rotations(db.local_rotations, samples * chunk / chunks, samples * (chunk + 1) / chunks,
                     bytes + components, bytes + codes, exceptions[chunk]);
  });
  w.align16();
  size_t count = 0;
  for (const auto& list : exceptions) count += list.size();
  table[static_cast<size_t>(DatabaseSection::RotationExceptions)] = {
      w.size(), count * kRotationExceptionBytes};
  for (const auto& list : exceptions) {
    for (const RotationException& e : list) {
      w.pod(e.sample);
      w.pod(e.value);
      w.zeros(4);
    }
  }
}

// The bytes serialize_database() will write, to allocate them once.
size_t expected_file_size(const DatabaseView& db, const PositionLayout& layout) {
  size_t bytes = kDatabaseHeaderSize + 16 * kDatabaseSectionCount + kChecksumSize;
  for (const std::string& s : db.skeleton.names()) bytes += s.size() + 4;
  for (const std::string& s : db.tag_names) bytes += s.size() + 4;
  bytes += 4;
  for (const std::string& s : db.style_names) bytes += s.size() + 4;
  for (const ClipRange& c : db.clips) bytes += c.name.size() + kMinClipBytes;
  for (const FeatureChannel& c : db.schema.channels) {
    bytes += c.name.size() + c.bone.size() + c.times.size() * 4 + kMinChannelBytes;
  }
  bytes += db.skeleton.rest().size() * (kRestTransformBytes + 4);
  bytes += layout.constant.size() + 12 * (layout.constant_count + layout.varying_count);
  bytes += 13 * db.local_rotations.size();
  bytes += db.contacts.size() +
           4 * (db.features.size() + db.feature_offset.size() + db.feature_scale.size()) +
           db.searchable.size();
  return bytes;
}

// True when the clips and the position array agree well enough to lay the positions out by
// clip (Database::validate() checks far more).
bool positions_fit_clips(const DatabaseView& db) {
  const size_t samples =
      static_cast<size_t>(std::max(db.frame_count, 0)) * static_cast<size_t>(db.joint_count());
  return db.local_positions.size() == samples && db.local_rotations.size() == samples &&
         validate_clip_ranges(db.clips, db.frame_count, 64).ok();
}

}  // namespace

std::vector<std::byte> serialize_database(const DatabaseView& db) {
  // An inconsistent database keeps its positions and rotations out of the file (load refuses it
  // then), rather than reading past its arrays.
  const bool fits = positions_fit_clips(db);
  PositionLayout layout;
  if (fits) layout = position_layout_of(db);
  ByteWriter w(expected_file_size(db, layout));
  write_header(w, db);

  std::array<DatabaseFileSection, kDatabaseSectionCount> table{};
  auto section = [&](DatabaseSection s, auto&& write) {
    w.align16();
    const size_t start = w.size();
    write();
    table[static_cast<size_t>(s)] = {start, w.size() - start};
  };
  section(DatabaseSection::Schema, [&] { write_schema(w, db.schema); });
  section(DatabaseSection::SkeletonNames, [&] {
    for (const std::string& n : db.skeleton.names()) w.string(n);
  });
  section(DatabaseSection::SkeletonParents, [&] {
    for (int p : db.skeleton.parents()) w.pod(static_cast<int32_t>(p));
  });
  section(DatabaseSection::SkeletonRest, [&] {
    for (const Transform& t : db.skeleton.rest()) write_rest(w, t);
  });
  section(DatabaseSection::SkeletonRoles, [&] {
    for (const JointRoleInfo& role : kJointRoles) w.pod(static_cast<int32_t>(db.roles.*role.index));
  });
  section(DatabaseSection::Clips, [&] { write_clips(w, db.clips); });
  section(DatabaseSection::TagNames, [&] {
    for (const std::string& n : db.tag_names) w.string(n);
  });
  section(DatabaseSection::PositionColumns, [&] { w.array(layout.constant); });
  section(DatabaseSection::ConstantPositions, [&] {
    if (fits) write_positions(w, db, layout, true);
  });
  section(DatabaseSection::VaryingPositions, [&] {
    if (fits) write_positions(w, db, layout, false);
  });
  if (fits) {
    write_rotations(w, db, table);
  } else {
    for (DatabaseSection s : {DatabaseSection::RotationComponents, DatabaseSection::RotationCodes,
                              DatabaseSection::RotationExceptions}) {
      section(s, [] {});
    }
  }
  section(DatabaseSection::Contacts, [&] { w.array(db.contacts); });
  section(DatabaseSection::Features, [&] { w.array(db.features); });
  section(DatabaseSection::FeatureOffset, [&] { w.array(db.feature_offset); });
  section(DatabaseSection::FeatureScale, [&] { w.array(db.feature_scale); });
  section(DatabaseSection::Searchable, [&] { w.array(db.searchable); });
  section(DatabaseSection::StyleNames, [&] {
    w.pod(static_cast<uint32_t>(db.style_names.size()));
    for (const std::string& n : db.style_names) w.string(n);
  });

  for (size_t i = 0; i < kDatabaseSectionCount; ++i) {
    w.patch(kOffSectionTable + 16 * i, table[i].offset);
    w.patch(kOffSectionTable + 16 * i + 8, table[i].length);
  }
  const uint64_t file_size = w.size() + kChecksumSize;
  w.patch(kOffFileSize, file_size);
  const uint64_t checksum = database_checksum(w.bytes());
  w.pod(checksum);
  return std::move(w.bytes());
}

Status save_database(const DatabaseView& db, const std::filesystem::path& path) {
  if (Status s = validate_database(db); !s) {
    return Error{"not saving '" + path.string() + "': " + s.message()};
  }
  const std::vector<std::byte> bytes = serialize_database(db);
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    return Error{"cannot write '" + temporary.string() + "': " + errno_text(errno)};
  }
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), file);
  const int write_error = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != bytes.size() || !closed) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return Error{"cannot write '" + temporary.string() + "': " + errno_text(write_error) +
                 " (wrote " + std::to_string(written) + " of " + std::to_string(bytes.size()) +
                 " bytes)"};
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    return Error{"cannot move '" + temporary.string() + "' to '" + path.string() +
                 "': " + error.message()};
  }
  return Status::success();
}

}  // namespace mm
