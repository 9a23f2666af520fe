#include "mm/database/database_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <system_error>
#include <thread>
#include <type_traits>

#include <glm/gtc/type_ptr.hpp>

#include "mm/database/files.hpp"

namespace mm {

namespace {

// ---------------------------------------------------------------------------------------------
// Checksum. Four lanes each consume one 8-byte word of every 32-byte block, so the four
// multiply chains run in parallel; the lanes are only combined at the end.

constexpr uint64_t kLaneSeed[4] = {0x243F6A8885A308D3ull, 0x13198A2E03707344ull,
                                   0xA4093822299F31D1ull, 0x082EFA98EC4E6C89ull};
constexpr uint64_t kWordMul = 0x9E3779B97F4A7C15ull;  // odd: multiplying by it is a bijection
constexpr uint64_t kStateMul = 0xC2B2AE3D27D4EB4Full;
constexpr uint64_t kTailMul = 0x165667B19E3779F9ull;
constexpr uint64_t kMixMul1 = 0xFF51AFD7ED558CCDull;
constexpr uint64_t kMixMul2 = 0xC4CEB9FE1A85EC53ull;

uint64_t load_u64(const std::byte* p) {
  uint64_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// One lane step; for a fixed state it is a bijection of the word and vice versa, so changing
// one word always changes the lane's final state.
inline uint64_t lane_step(uint64_t state, uint64_t word) {
  return std::rotl(state ^ (word * kWordMul), 29) * kStateMul;
}

// Spreads every input bit over the whole output (bijective).
inline uint64_t avalanche(uint64_t h) {
  h ^= h >> 33;
  h *= kMixMul1;
  h ^= h >> 29;
  h *= kMixMul2;
  h ^= h >> 32;
  return h;
}

// ---------------------------------------------------------------------------------------------
// Writing.

class ByteWriter {
 public:
  explicit ByteWriter(size_t expected_size) { bytes_.reserve(expected_size); }

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

// Header field offsets (see the layout in database_file.hpp).
constexpr size_t kOffVersion = 8;
constexpr size_t kOffEndian = 12;
constexpr size_t kOffFileSize = 16;
constexpr size_t kOffHeaderSize = 24;
constexpr size_t kOffSectionCount = 28;
constexpr size_t kOffCounts = 32;
constexpr size_t kOffFrameTime = 56;
constexpr size_t kOffRoles = 60;
constexpr size_t kOffReserved = 84;
constexpr size_t kOffSectionTable = 88;
constexpr size_t kChecksumSize = 8;
static_assert(kOffSectionTable + kDatabaseSectionCount * 16 <= kDatabaseHeaderSize);
static_assert(kDatabaseHeaderSize % 16 == 0);
static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::quat) == 16);

// Smallest encoded size of one record of each variable section (with empty strings and lists).
constexpr uint64_t kMinStringBytes = 4;
constexpr uint64_t kMinChannelBytes = 4 + 4 + 4 + 4 + 12 + 4;
constexpr uint64_t kMinClipBytes = 4 + 4 + 8 + 4 + 4;
constexpr uint64_t kRestTransformBytes = 10 * 4;

void write_rest(ByteWriter& w, const Transform& t) {
  const float values[10] = {t.rotation.x,    t.rotation.y,    t.rotation.z,    t.rotation.w,
                            t.translation.x, t.translation.y, t.translation.z, t.scale.x,
                            t.scale.y,       t.scale.z};
  w.raw(values, sizeof values);
}

// ---------------------------------------------------------------------------------------------
// Reading: a cursor over one section that refuses to read past its end.

class SectionReader {
 public:
  SectionReader(std::span<const std::byte> bytes, DatabaseSection section, std::string_view file)
      : bytes_(bytes), section_(section), file_(file) {}

  size_t remaining() const { return bytes_.size() - pos_; }

  template <class T>
  Status pod(T& out, std::string_view what) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (remaining() < sizeof(T)) return truncated(what, sizeof(T));
    std::memcpy(&out, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return Status::success();
  }
  Status string(std::string& out, std::string_view what) {
    uint32_t length = 0;
    if (Status s = pod(length, what); !s) return s;
    // Checked against the bytes that are actually there before allocating anything.
    if (length > remaining()) {
      return fail(std::string(what) + " claims " + std::to_string(length) + " bytes but only " +
                  std::to_string(remaining()) + " remain in the section");
    }
    out.assign(reinterpret_cast<const char*>(bytes_.data() + pos_), length);
    pos_ += length;
    return Status::success();
  }
  Status floats(float* out, size_t count, std::string_view what) {
    if (count == 0) return Status::success();  // `out` may be null (an empty vector's data)
    if (remaining() / sizeof(float) < count) return truncated(what, count * sizeof(float));
    std::memcpy(out, bytes_.data() + pos_, count * sizeof(float));
    pos_ += count * sizeof(float);
    return Status::success();
  }
  Status zero_padding(size_t count, std::string_view what) {
    if (remaining() < count) return truncated(what, count);
    for (size_t i = 0; i < count; ++i) {
      if (bytes_[pos_ + i] != std::byte{0}) return fail(std::string(what) + ": non-zero padding");
    }
    pos_ += count;
    return Status::success();
  }
  Status finish() const {
    if (remaining() == 0) return Status::success();
    return fail(std::to_string(remaining()) + " unused bytes at the end of the section");
  }
  Error fail(const std::string& message) const {
    return Error{std::string(file_) + ": section '" + database_section_name(section_) +
                 "': " + message};
  }

 private:
  Error truncated(std::string_view what, size_t need) const {
    return fail(std::string(what) + " needs " + std::to_string(need) + " bytes at section offset " +
                std::to_string(pos_) + " but the section has " + std::to_string(remaining()) +
                " left");
  }

  std::span<const std::byte> bytes_;
  size_t pos_ = 0;
  DatabaseSection section_;
  std::string_view file_;
};

template <class T>
T read_at(std::span<const std::byte> bytes, size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

std::string hex(uint64_t v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "0x%016llx", static_cast<unsigned long long>(v));
  return buffer;
}

// The checks that must pass before the checksum can even be computed: what kind of file this is
// (magic, endianness, version) and whether it is complete. `prefix` holds the first bytes (at
// least the whole header, or the whole file when it is shorter).
Status check_identity(std::span<const std::byte> prefix, uint64_t actual_size,
                      std::string_view name) {
  const std::string where(name);
  if (actual_size == 0) return Error{where + ": empty file (0 bytes); expected a motion database"};
  const size_t magic_bytes = std::min<size_t>(prefix.size(), kDatabaseMagic.size());
  for (size_t i = 0; i < magic_bytes; ++i) {
    if (prefix[i] != std::byte{kDatabaseMagic[i]}) {
      return Error{where +
                   ": not a motion database file (wrong magic bytes at the start; a different "
                   "kind of file, or a database damaged by a text-mode copy)"};
    }
  }
  if (prefix.size() < kDatabaseHeaderSize) {
    return Error{where + ": truncated: expected at least " + std::to_string(kDatabaseHeaderSize) +
                 " bytes of header, file has " + std::to_string(actual_size)};
  }
  const uint32_t endian = read_at<uint32_t>(prefix, kOffEndian);
  if (endian != kDatabaseEndianMarker) {
    if (endian == __builtin_bswap32(kDatabaseEndianMarker)) {
      return Error{where +
                   ": written on a machine of the other endianness (byte order); rebuild the "
                   "database on this machine"};
    }
    return Error{where + ": corrupt endianness marker " + hex(endian) + ", expected " +
                 hex(kDatabaseEndianMarker)};
  }
  const uint32_t version = read_at<uint32_t>(prefix, kOffVersion);
  if (version != kDatabaseFormatVersion) {
    const bool newer = version > kDatabaseFormatVersion;
    return Error{where + ": database format version " + std::to_string(version) + " is " +
                 (newer ? "newer" : "older") + " than the version this program reads (" +
                 std::to_string(kDatabaseFormatVersion) + "); " +
                 (newer ? "update the program or rebuild the database with this one"
                        : "rebuild the database with `mm build`")};
  }
  const uint64_t declared_size = read_at<uint64_t>(prefix, kOffFileSize);
  if (declared_size > actual_size) {
    return Error{where + ": truncated: expected " + std::to_string(declared_size) +
                 " bytes, file has " + std::to_string(actual_size)};
  }
  if (declared_size < actual_size) {
    return Error{where + ": file has " + std::to_string(actual_size) +
                 " bytes but its header says " + std::to_string(declared_size) +
                 " (trailing data or a corrupt header)"};
  }
  return Status::success();
}

// Checks the whole header: check_identity(), then the sizes, counts and section table.
Result<DatabaseFileInfo> parse_header(std::span<const std::byte> prefix, uint64_t actual_size,
                                      std::string_view name) {
  if (Status s = check_identity(prefix, actual_size, name); !s) return Error{s.message()};
  const std::string where(name);
  const uint32_t version = read_at<uint32_t>(prefix, kOffVersion);
  const uint64_t declared_size = read_at<uint64_t>(prefix, kOffFileSize);
  const uint32_t header_size = read_at<uint32_t>(prefix, kOffHeaderSize);
  const uint32_t section_count = read_at<uint32_t>(prefix, kOffSectionCount);
  if (header_size != kDatabaseHeaderSize || section_count != kDatabaseSectionCount ||
      read_at<uint32_t>(prefix, kOffReserved) != 0) {
    return Error{where + ": corrupt header: header size " + std::to_string(header_size) +
                 " and section count " + std::to_string(section_count) + ", expected " +
                 std::to_string(kDatabaseHeaderSize) + " and " +
                 std::to_string(kDatabaseSectionCount) + " with a zero reserved field"};
  }
  if (actual_size < uint64_t{kDatabaseHeaderSize} + kChecksumSize) {
    return Error{where + ": truncated: expected at least " +
                 std::to_string(kDatabaseHeaderSize + kChecksumSize) + " bytes, file has " +
                 std::to_string(actual_size)};
  }

  DatabaseFileInfo info;
  info.format_version = version;
  info.file_size = declared_size;
  uint32_t counts[6];
  std::memcpy(counts, prefix.data() + kOffCounts, sizeof counts);
  info.joint_count = counts[0];
  info.frame_count = counts[1];
  info.clip_count = counts[2];
  info.tag_count = counts[3];
  info.feature_dims = counts[4];
  info.channel_count = counts[5];
  info.frame_time = read_at<float>(prefix, kOffFrameTime);
  int32_t roles[6];
  std::memcpy(roles, prefix.data() + kOffRoles, sizeof roles);
  info.roles = {roles[0], roles[1], roles[2], roles[3], roles[4], roles[5]};

  // Sane limits, so that nothing later allocates from a corrupt count.
  struct Limit {
    const char* what;
    uint32_t value, min, max;
  };
  const Limit limits[] = {
      {"joint_count", info.joint_count, 1, kMaxDatabaseJoints},
      {"frame_count", info.frame_count, 1, kMaxDatabaseFrames},
      {"clip_count", info.clip_count, 1, std::min(info.frame_count, kMaxDatabaseFrames)},
      {"tag_count", info.tag_count, 0, 64},
      {"feature_dims", info.feature_dims, 1, kMaxDatabaseFeatureDims},
      {"channel_count", info.channel_count, 1, kMaxDatabaseChannels},
  };
  for (const Limit& l : limits) {
    if (l.value < l.min || l.value > l.max) {
      return Error{where + ": header: " + l.what + " " + std::to_string(l.value) +
                   " is outside the valid range [" + std::to_string(l.min) + ", " +
                   std::to_string(l.max) + "]"};
    }
  }

  // The section table: ordered, aligned, inside the file, sized as the counts say.
  const uint64_t data_end = declared_size - kChecksumSize;
  const uint64_t frames = info.frame_count;
  const uint64_t samples = frames * info.joint_count;
  const uint64_t dims = info.feature_dims;
  uint64_t previous_end = kDatabaseHeaderSize;
  for (size_t i = 0; i < kDatabaseSectionCount; ++i) {
    const auto section = static_cast<DatabaseSection>(i);
    DatabaseFileSection& s = info.sections[i];
    s.offset = read_at<uint64_t>(prefix, kOffSectionTable + 16 * i);
    s.length = read_at<uint64_t>(prefix, kOffSectionTable + 16 * i + 8);
    const std::string sec = where + ": section '" + database_section_name(section) + "'";
    if (s.offset % 16 != 0 || s.offset < previous_end || s.offset > data_end ||
        s.length > data_end - s.offset) {
      return Error{sec + ": offset " + std::to_string(s.offset) + " and length " +
                   std::to_string(s.length) + " do not lie in order, 16-byte aligned, within [" +
                   std::to_string(previous_end) + ", " + std::to_string(data_end) + ")"};
    }
    previous_end = s.offset + s.length;

    uint64_t exact = 0;    // expected length of a fixed-size section (0: variable)
    uint64_t minimum = 0;  // smallest possible length of a variable section
    std::string how;
    switch (section) {
      case DatabaseSection::Schema:
        minimum = kMinChannelBytes * info.channel_count;
        how = "channel_count " + std::to_string(info.channel_count) + " records";
        break;
      case DatabaseSection::SkeletonNames:
        minimum = kMinStringBytes * info.joint_count;
        how = "joint_count " + std::to_string(info.joint_count) + " names";
        break;
      case DatabaseSection::SkeletonParents:
        exact = 4 * uint64_t{info.joint_count};
        how = "joint_count x 4";
        break;
      case DatabaseSection::SkeletonRest:
        exact = kRestTransformBytes * info.joint_count;
        how = "joint_count x 40";
        break;
      case DatabaseSection::LocalPositions:
      case DatabaseSection::LocalVelocities:
      case DatabaseSection::LocalAngularVelocities:
        exact = samples * 12;
        how = "frame_count x joint_count x 12";
        break;
      case DatabaseSection::LocalRotations:
        exact = samples * 16;
        how = "frame_count x joint_count x 16";
        break;
      case DatabaseSection::Contacts:
        exact = frames * 2;
        how = "frame_count x 2";
        break;
      case DatabaseSection::Features:
        exact = frames * dims * 4;
        how = "frame_count x feature_dims x 4";
        break;
      case DatabaseSection::FeatureOffset:
      case DatabaseSection::FeatureScale:
        exact = dims * 4;
        how = "feature_dims x 4";
        break;
      case DatabaseSection::Searchable:
        exact = frames;
        how = "frame_count";
        break;
      case DatabaseSection::Clips:
        minimum = kMinClipBytes * info.clip_count;
        how = "clip_count " + std::to_string(info.clip_count) + " records";
        break;
      case DatabaseSection::TagNames:
        minimum = kMinStringBytes * info.tag_count;
        how = "tag_count " + std::to_string(info.tag_count) + " names";
        break;
      case DatabaseSection::Count:
        break;
    }
    if (exact != 0 && s.length != exact) {
      return Error{sec + ": " + std::to_string(s.length) + " bytes, expected " +
                   std::to_string(exact) + " (" + how + ")"};
    }
    if (exact == 0 && s.length < minimum) {
      return Error{sec + ": " + std::to_string(s.length) + " bytes cannot hold " + how +
                   " (at least " + std::to_string(minimum) + " bytes)"};
    }
  }
  if (prefix.size() >= declared_size) {
    info.stored_checksum = read_at<uint64_t>(prefix, static_cast<size_t>(data_end));
  }
  return info;
}

std::span<const std::byte> section_bytes(std::span<const std::byte> file,
                                         const DatabaseFileInfo& info, DatabaseSection s) {
  const DatabaseFileSection& sec = info.section(s);
  return file.subspan(static_cast<size_t>(sec.offset), static_cast<size_t>(sec.length));
}

// Copies a fixed-size section whose length parse_header() already matched to the counts.
template <class T>
void copy_array(std::span<const std::byte> file, const DatabaseFileInfo& info, DatabaseSection s,
                std::vector<T>& out) {
  const std::span<const std::byte> bytes = section_bytes(file, info, s);
  const size_t count = bytes.size() / sizeof(T);
  out.clear();
  out.reserve(count);  // allocates without touching the memory, so the advice applies
  advise_huge_pages(out.data(), count * sizeof(T));
  out.resize(count);
  if (bytes.empty()) return;
  if constexpr (std::is_trivially_copyable_v<T>) {
    std::memcpy(out.data(), bytes.data(), bytes.size());
  } else {
    // GLM vectors and quaternions (not trivially copyable under GLM_FORCE_CTOR_INIT) are
    // standard-layout runs of floats: the bytes are copied into those float members.
    static_assert(std::is_standard_layout_v<T> && sizeof(T) % sizeof(float) == 0);
    std::memcpy(glm::value_ptr(out[0]), bytes.data(), bytes.size());
  }
}

Status read_string_list(std::span<const std::byte> file, const DatabaseFileInfo& info,
                        DatabaseSection s, uint32_t count, std::string_view name,
                        std::vector<std::string>& out) {
  SectionReader r(section_bytes(file, info, s), s, name);
  out.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    if (Status st = r.string(out[i], "string " + std::to_string(i)); !st) return st;
  }
  return r.finish();
}

Status read_schema(std::span<const std::byte> file, const DatabaseFileInfo& info,
                   std::string_view name, FeatureSchema& schema) {
  SectionReader r(section_bytes(file, info, DatabaseSection::Schema), DatabaseSection::Schema,
                  name);
  schema.channels.resize(info.channel_count);
  for (uint32_t i = 0; i < info.channel_count; ++i) {
    FeatureChannel& c = schema.channels[i];
    const std::string where = "channel " + std::to_string(i);
    uint8_t kind = 0;
    if (Status s = r.pod(kind, where + " kind"); !s) return s;
    if (kind > static_cast<uint8_t>(FeatureKind::BoneDirection)) {
      return r.fail(where + ": unknown feature kind " + std::to_string(kind));
    }
    c.kind = static_cast<FeatureKind>(kind);
    if (Status s = r.zero_padding(3, where + " padding"); !s) return s;
    if (Status s = r.string(c.name, where + " name"); !s) return s;
    if (Status s = r.string(c.bone, where + " bone"); !s) return s;
    uint32_t time_count = 0;
    if (Status s = r.pod(time_count, where + " time count"); !s) return s;
    if (time_count > r.remaining() / sizeof(float)) {
      return r.fail(where + " claims " + std::to_string(time_count) + " times but only " +
                    std::to_string(r.remaining()) + " bytes remain");
    }
    c.times.resize(time_count);
    if (Status s = r.floats(c.times.data(), time_count, where + " times"); !s) return s;
    float tail[4];  // axis x, y, z and weight
    if (Status s = r.floats(tail, 4, where + " axis and weight"); !s) return s;
    c.axis = {tail[0], tail[1], tail[2]};
    c.weight = tail[3];
    if (!std::isfinite(c.axis.x) || !std::isfinite(c.axis.y) || !std::isfinite(c.axis.z)) {
      return r.fail(where + " '" + c.name + "': axis is not finite");
    }
  }
  return r.finish();
}

Status read_clips(std::span<const std::byte> file, const DatabaseFileInfo& info,
                  std::string_view name, std::vector<ClipRange>& clips) {
  SectionReader r(section_bytes(file, info, DatabaseSection::Clips), DatabaseSection::Clips, name);
  clips.resize(info.clip_count);
  for (uint32_t i = 0; i < info.clip_count; ++i) {
    ClipRange& c = clips[i];
    const std::string where = "clip " + std::to_string(i);
    int32_t start = 0, end = 0;
    uint8_t mirrored = 0;
    if (Status s = r.pod(start, where + " start"); !s) return s;
    if (Status s = r.pod(end, where + " end"); !s) return s;
    if (Status s = r.pod(c.tags, where + " tags"); !s) return s;
    if (Status s = r.pod(mirrored, where + " mirrored flag"); !s) return s;
    if (mirrored > 1) {
      return r.fail(where + ": mirrored flag is " + std::to_string(mirrored) + ", expected 0 or 1");
    }
    if (Status s = r.zero_padding(3, where + " padding"); !s) return s;
    if (Status s = r.string(c.name, where + " name"); !s) return s;
    c.start = start;
    c.end = end;
    c.mirrored = mirrored != 0;
  }
  return r.finish();
}

Status read_skeleton(std::span<const std::byte> file, const DatabaseFileInfo& info,
                     std::string_view name, Skeleton& skeleton) {
  std::vector<std::string> names;
  if (Status s = read_string_list(file, info, DatabaseSection::SkeletonNames, info.joint_count,
                                  name, names);
      !s) {
    return s;
  }
  std::vector<int32_t> parents;
  copy_array(file, info, DatabaseSection::SkeletonParents, parents);
  const std::span<const std::byte> rest_bytes =
      section_bytes(file, info, DatabaseSection::SkeletonRest);
  std::vector<Transform> rest(info.joint_count);
  for (size_t j = 0; j < rest.size(); ++j) {
    float v[10];
    std::memcpy(v, rest_bytes.data() + j * kRestTransformBytes, sizeof v);
    rest[j].rotation = glm::quat(v[3], v[0], v[1], v[2]);
    rest[j].translation = {v[4], v[5], v[6]};
    rest[j].scale = {v[7], v[8], v[9]};
  }
  Result<Skeleton> created = Skeleton::create(
      std::move(names), std::vector<int>(parents.begin(), parents.end()), std::move(rest));
  if (!created) {
    return Error{std::string(name) +
                 ": sections 'skeleton_names'/'skeleton_parents': " + created.message()};
  }
  skeleton = std::move(created).value();
  return Status::success();
}

// The large arrays in two groups for the two threads: the hashing thread takes rotations,
// velocities and features (115 MB of 219 MB at 167k frames x 23 joints), the parsing thread
// positions and angular velocities (92 MB), which balances them once the hash is counted.
void copy_arrays_a(std::span<const std::byte> file, const DatabaseFileInfo& info, Database& db) {
  copy_array(file, info, DatabaseSection::LocalRotations, db.local_rotations);
  copy_array(file, info, DatabaseSection::LocalVelocities, db.local_velocities);
  copy_array(file, info, DatabaseSection::Features, db.features);
}

void copy_arrays_b(std::span<const std::byte> file, const DatabaseFileInfo& info, Database& db) {
  copy_array(file, info, DatabaseSection::LocalPositions, db.local_positions);
  copy_array(file, info, DatabaseSection::LocalAngularVelocities, db.local_angular_velocities);
}

// Everything but the checksum and copy_arrays_a(): the variable sections record by record, the
// other arrays by memcpy.
Status read_contents(std::span<const std::byte> file, const DatabaseFileInfo& info,
                     std::string_view name, Database& db) {
  if (Status s = read_schema(file, info, name, db.schema); !s) return s;
  if (db.schema.dims() != static_cast<int>(info.feature_dims)) {
    return Error{std::string(name) + ": section 'schema': its channels have " +
                 std::to_string(db.schema.dims()) + " feature columns but the header says " +
                 std::to_string(info.feature_dims)};
  }
  if (Status s = read_skeleton(file, info, name, db.skeleton); !s) return s;
  db.roles = info.roles;
  db.frame_time = info.frame_time;
  db.frame_count = static_cast<int>(info.frame_count);
  copy_arrays_b(file, info, db);
  copy_array(file, info, DatabaseSection::Contacts, db.contacts);
  copy_array(file, info, DatabaseSection::FeatureOffset, db.feature_offset);
  copy_array(file, info, DatabaseSection::FeatureScale, db.feature_scale);
  copy_array(file, info, DatabaseSection::Searchable, db.searchable);
  if (Status s = read_clips(file, info, name, db.clips); !s) return s;
  if (Status s = read_string_list(file, info, DatabaseSection::TagNames, info.tag_count, name,
                                  db.tag_names);
      !s) {
    return s;
  }
  // frame_clip is derived, not stored; clips that do not tile the frames leave -1 entries,
  // and validate() reports the clip itself.
  db.frame_clip.assign(info.frame_count, -1);
  for (size_t c = 0; c < db.clips.size(); ++c) {
    const int start = std::max(db.clips[c].start, 0);
    const int end = std::min(db.clips[c].end, db.frame_count);
    for (int f = start; f < end; ++f) db.frame_clip[static_cast<size_t>(f)] = static_cast<int>(c);
  }
  return Status::success();
}

// Files at least this large hash on a second thread while the first copies the arrays.
constexpr size_t kParallelHashBytes = size_t{8} << 20;

std::string errno_text(int error) {
  return std::generic_category().message(error);
}

}  // namespace

const char* database_section_name(DatabaseSection section) {
  switch (section) {
    case DatabaseSection::Schema:
      return "schema";
    case DatabaseSection::SkeletonNames:
      return "skeleton_names";
    case DatabaseSection::SkeletonParents:
      return "skeleton_parents";
    case DatabaseSection::SkeletonRest:
      return "skeleton_rest";
    case DatabaseSection::LocalPositions:
      return "local_positions";
    case DatabaseSection::LocalRotations:
      return "local_rotations";
    case DatabaseSection::LocalVelocities:
      return "local_velocities";
    case DatabaseSection::LocalAngularVelocities:
      return "local_angular_velocities";
    case DatabaseSection::Contacts:
      return "contacts";
    case DatabaseSection::Features:
      return "features";
    case DatabaseSection::FeatureOffset:
      return "feature_offset";
    case DatabaseSection::FeatureScale:
      return "feature_scale";
    case DatabaseSection::Searchable:
      return "searchable";
    case DatabaseSection::Clips:
      return "clips";
    case DatabaseSection::TagNames:
      return "tag_names";
    case DatabaseSection::Count:
      break;
  }
  return "unknown";
}

uint64_t database_checksum(std::span<const std::byte> bytes) {
  const std::byte* p = bytes.data();
  const size_t size = bytes.size();
  uint64_t lane0 = kLaneSeed[0], lane1 = kLaneSeed[1], lane2 = kLaneSeed[2], lane3 = kLaneSeed[3];
  size_t i = 0;
  for (; i + 32 <= size; i += 32) {
    lane0 = lane_step(lane0, load_u64(p + i));
    lane1 = lane_step(lane1, load_u64(p + i + 8));
    lane2 = lane_step(lane2, load_u64(p + i + 16));
    lane3 = lane_step(lane3, load_u64(p + i + 24));
  }
  // Up to three whole words left: lanes 0, 1, 2 take one each.
  uint64_t* lanes[3] = {&lane0, &lane1, &lane2};
  for (size_t k = 0; i + 8 <= size; i += 8, ++k) *lanes[k] = lane_step(*lanes[k], load_u64(p + i));
  // Up to seven bytes left: packed little-end-first into one word for lane 3. Zero padding is
  // unambiguous because the length is mixed in below.
  if (i < size) {
    uint64_t word = 0;
    for (size_t k = 0; i + k < size; ++k) {
      word |= static_cast<uint64_t>(std::to_integer<uint8_t>(p[i + k])) << (8 * k);
    }
    lane3 = lane_step(lane3, word ^ kTailMul);
  }
  uint64_t h =
      std::rotl(lane0, 1) + std::rotl(lane1, 7) + std::rotl(lane2, 12) + std::rotl(lane3, 18);
  h += static_cast<uint64_t>(size) * kTailMul;
  return avalanche(h);
}

std::vector<std::byte> serialize_database(const Database& db) {
  auto bytes_of = [](const auto& v) { return v.size() * sizeof(v[0]); };
  size_t strings = 0;
  for (const std::string& s : db.skeleton.names()) strings += s.size() + 4;
  for (const std::string& s : db.tag_names) strings += s.size() + 4;
  for (const ClipRange& c : db.clips) strings += c.name.size() + kMinClipBytes;
  for (const FeatureChannel& c : db.schema.channels) {
    strings += c.name.size() + c.bone.size() + c.times.size() * 4 + kMinChannelBytes;
  }
  const size_t expected = kDatabaseHeaderSize + strings + bytes_of(db.local_positions) +
                          bytes_of(db.local_rotations) + bytes_of(db.local_velocities) +
                          bytes_of(db.local_angular_velocities) + bytes_of(db.contacts) +
                          bytes_of(db.features) + bytes_of(db.feature_offset) +
                          bytes_of(db.feature_scale) + bytes_of(db.searchable) +
                          db.skeleton.rest().size() * (kRestTransformBytes + 4) +
                          16 * kDatabaseSectionCount + kChecksumSize;
  ByteWriter w(expected);

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
  const int32_t roles[6] = {db.roles.hips,     db.roles.left_foot, db.roles.right_foot,
                            db.roles.left_toe, db.roles.right_toe, db.roles.head};
  w.patch(kOffRoles, roles);

  std::array<DatabaseFileSection, kDatabaseSectionCount> table{};
  auto section = [&](DatabaseSection s, auto&& write) {
    w.align16();
    const size_t start = w.size();
    write();
    table[static_cast<size_t>(s)] = {start, w.size() - start};
  };
  section(DatabaseSection::Schema, [&] {
    for (const FeatureChannel& c : db.schema.channels) {
      w.pod(static_cast<uint8_t>(c.kind));
      w.zeros(3);
      w.string(c.name);
      w.string(c.bone);
      w.pod(static_cast<uint32_t>(c.times.size()));
      w.array(c.times);
      const float tail[4] = {c.axis.x, c.axis.y, c.axis.z, c.weight};
      w.raw(tail, sizeof tail);
    }
  });
  section(DatabaseSection::SkeletonNames, [&] {
    for (const std::string& n : db.skeleton.names()) w.string(n);
  });
  section(DatabaseSection::SkeletonParents, [&] {
    for (int p : db.skeleton.parents()) w.pod(static_cast<int32_t>(p));
  });
  section(DatabaseSection::SkeletonRest, [&] {
    for (const Transform& t : db.skeleton.rest()) write_rest(w, t);
  });
  section(DatabaseSection::LocalPositions, [&] { w.array(db.local_positions); });
  section(DatabaseSection::LocalRotations, [&] { w.array(db.local_rotations); });
  section(DatabaseSection::LocalVelocities, [&] { w.array(db.local_velocities); });
  section(DatabaseSection::LocalAngularVelocities, [&] { w.array(db.local_angular_velocities); });
  section(DatabaseSection::Contacts, [&] { w.array(db.contacts); });
  section(DatabaseSection::Features, [&] { w.array(db.features); });
  section(DatabaseSection::FeatureOffset, [&] { w.array(db.feature_offset); });
  section(DatabaseSection::FeatureScale, [&] { w.array(db.feature_scale); });
  section(DatabaseSection::Searchable, [&] { w.array(db.searchable); });
  section(DatabaseSection::Clips, [&] {
    for (const ClipRange& c : db.clips) {
      w.pod(static_cast<int32_t>(c.start));
      w.pod(static_cast<int32_t>(c.end));
      w.pod(c.tags);
      w.pod(static_cast<uint8_t>(c.mirrored ? 1 : 0));
      w.zeros(3);
      w.string(c.name);
    }
  });
  section(DatabaseSection::TagNames, [&] {
    for (const std::string& n : db.tag_names) w.string(n);
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

Result<DatabaseFileInfo> parse_database_header(std::span<const std::byte> bytes,
                                               std::string_view name_for_messages) {
  return parse_header(bytes, bytes.size(), name_for_messages);
}

Result<Database> deserialize_database(std::span<const std::byte> bytes,
                                      std::string_view name_for_messages) {
  const std::string name(name_for_messages);
  if (Status s = check_identity(bytes, bytes.size(), name); !s) return Error{s.message()};
  // check_identity() guarantees a whole header, so the checksum's 8 bytes are there.
  const std::span<const std::byte> covered = bytes.first(bytes.size() - kChecksumSize);
  uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + covered.size(), sizeof stored);
  auto checksum_error = [&](uint64_t computed) {
    return Error{name + ": checksum mismatch (stored " + hex(stored) + ", computed " +
                 hex(computed) + "): the file was changed or damaged after it was written"};
  };

  // Fresh memory for the arrays costs a page fault per 4 KiB, more than the copying itself, so
  // on a large file a second thread hashes and fills about half of the arrays while this one
  // parses and fills the rest. Only a file whose header parsed is split: every offset and
  // length used below was checked against the file, so reading before the checksum is verified
  // is safe, and a checksum failure is reported in preference to anything found.
  Result<DatabaseFileInfo> header = parse_header(bytes, bytes.size(), name);
  uint64_t computed = 0;
  Database db;
  bool worker_failed = false;
  std::thread worker;
  if (header && bytes.size() >= kParallelHashBytes) {
    try {
      worker =
          std::thread([&computed, &worker_failed, &db, covered, bytes, &info = header.value()] {
            computed = database_checksum(covered);
            try {
              copy_arrays_a(bytes, info, db);
            } catch (...) {
              worker_failed = true;  // out of memory
            }
          });
    } catch (...) {
      // No thread to be had: everything runs on this one below.
    }
  }
  const bool parallel = worker.joinable();
  if (!parallel) {
    computed = database_checksum(covered);
    if (computed != stored) return checksum_error(computed);
    if (!header) return header.error();
  }

  Status contents;
  try {
    contents = read_contents(bytes, header.value(), name, db);
    if (!parallel) copy_arrays_a(bytes, header.value(), db);
  } catch (const std::exception& e) {
    // Only allocation can throw here, and every size was checked against the file first.
    contents = Error{name + ": cannot load: " + e.what()};
  }
  if (parallel) {
    worker.join();
    if (computed != stored) return checksum_error(computed);
    if (worker_failed) return Error{name + ": cannot load: out of memory"};
  }
  if (!contents) return Error{contents.message()};
  if (Status s = db.validate(); !s) return Error{name + ": " + s.message()};
  return db;
}

Status save_database(const Database& db, const std::filesystem::path& path) {
  if (Status s = db.validate(); !s) {
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

namespace {

// An open file descriptor closed on scope exit.
struct FileDescriptor {
  int fd = -1;
  explicit FileDescriptor(int f) : fd(f) {}
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  ~FileDescriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// Reads up to `size` bytes from the current position; returns the count read or -1.
ssize_t read_fully(int fd, std::byte* out, size_t size) {
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(fd, out + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return -1;
    if (n == 0) break;
    done += static_cast<size_t>(n);
  }
  return static_cast<ssize_t>(done);
}

}  // namespace

Result<Database> load_database(const std::filesystem::path& path) {
  const std::string name = path.string();
  FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.fd < 0) return Error{"cannot open database '" + name + "': " + errno_text(errno)};
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) return Error{"cannot stat '" + name + "': " + errno_text(errno)};
  if (S_ISDIR(st.st_mode)) return Error{"'" + name + "' is a folder, not a database file"};
  const size_t size = static_cast<size_t>(st.st_size);
  if (S_ISREG(st.st_mode) && size > 0) {
    // Mapping avoids one copy of the whole file (and the page faults of a fresh buffer);
    // MAP_POPULATE maps it in one go. The price: another process truncating the file during
    // the load would fault here, an accepted risk for files written by rename.
    void* mapped = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, file.fd, 0);
    if (mapped != MAP_FAILED) {
      Result<Database> db =
          deserialize_database({static_cast<const std::byte*>(mapped), size}, name);
      ::munmap(mapped, size);
      return db;
    }
  }
  // Not mappable (a pipe, an empty or special file): read it instead.
  std::vector<std::byte> bytes;
  std::byte chunk[1 << 16];
  for (;;) {
    const ssize_t n = read_fully(file.fd, chunk, sizeof chunk);
    if (n < 0) return Error{"cannot read '" + name + "': " + errno_text(errno)};
    bytes.insert(bytes.end(), chunk, chunk + n);
    if (static_cast<size_t>(n) < sizeof chunk) break;
  }
  return deserialize_database(bytes, name);
}

Result<DatabaseFileInfo> read_database_header(const std::filesystem::path& path) {
  const std::string name = path.string();
  FileDescriptor file(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (file.fd < 0) return Error{"cannot open database '" + name + "': " + errno_text(errno)};
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) return Error{"cannot stat '" + name + "': " + errno_text(errno)};
  if (!S_ISREG(st.st_mode)) return Error{"'" + name + "' is not a regular file"};
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  std::vector<std::byte> prefix(static_cast<size_t>(std::min<uint64_t>(size, kDatabaseHeaderSize)));
  if (read_fully(file.fd, prefix.data(), prefix.size()) != static_cast<ssize_t>(prefix.size())) {
    return Error{"cannot read the header of '" + name + "': " + errno_text(errno)};
  }
  Result<DatabaseFileInfo> info = parse_header(prefix, size, name);
  if (!info) return info;
  std::byte trailer[kChecksumSize];
  if (::pread(file.fd, trailer, sizeof trailer, static_cast<off_t>(size - kChecksumSize)) ==
      static_cast<ssize_t>(sizeof trailer)) {
    std::memcpy(&info->stored_checksum, trailer, sizeof trailer);
  }
  return info;
}

}  // namespace mm
