#include "mm/database/database_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <system_error>
#include <type_traits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <glm/gtc/type_ptr.hpp>

#include "cpu_features.hpp"
#include "mm/database/files.hpp"
#include "mm/database/velocities.hpp"
#include "mm/internal/database_assembly.hpp"
#include "mm/internal/database_format.hpp"
#include "mm/internal/workers.hpp"
#include "mm/runtime/assert.hpp"
#include "validation.hpp"

namespace mm {

using namespace detail;  // the format shared with the writer (database_format.hpp)

namespace {

using LoadTarget = detail::DatabaseAssembly::Parts;

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
// Rotations: "smallest three" without loss (see database_file.hpp).

// The quaternion of a non-escape code. A corrupt code gives a non-unit or NaN quaternion, which
// validation reports; nothing here is undefined for any input.
glm::quat decode_rotation(const float* components, uint8_t code, const float* exact) {
  const int left_out = code & 3;
  float value;
  if (exact != nullptr) {
    value = *exact;
  } else {
    const uint32_t predicted =
        std::bit_cast<uint32_t>(unit_complement(components[0], components[1], components[2]));
    const uint32_t magnitude = predicted + static_cast<uint32_t>((code >> 3) - kUlpBias);
    value = std::bit_cast<float>(magnitude | static_cast<uint32_t>((code >> 2) & 1) << 31);
  }
  const float a = components[0], b = components[1], c = components[2];
  switch (left_out) {  // glm::quat(w, x, y, z)
    case 0:
      return glm::quat(c, value, a, b);
    case 1:
      return glm::quat(c, a, value, b);
    case 2:
      return glm::quat(c, a, b, value);
    default:
      return glm::quat(value, a, b, c);
  }
}

#if defined(__SSE2__)
// Lanes below, at and above a left-out index (0-3), for placing the left-out component.
struct PlacementMasks {
  alignas(16) uint32_t below[4][4];
  alignas(16) uint32_t at[4][4];
  alignas(16) uint32_t above[4][4];
};
constexpr PlacementMasks make_placement_masks() {
  PlacementMasks m{};
  for (int k = 0; k < 4; ++k) {
    for (int lane = 0; lane < 4; ++lane) {
      m.below[k][lane] = lane < k ? ~0u : 0u;
      m.at[k][lane] = lane == k ? ~0u : 0u;
      m.above[k][lane] = lane > k ? ~0u : 0u;
    }
  }
  return m;
}
constexpr PlacementMasks kPlacement = make_placement_masks();

// The same placement as a permutation of (a, b, c, value), for AVX's variable permute.
alignas(16) constexpr int32_t kPlacementOrder[4][4] = {
    {3, 0, 1, 2}, {0, 3, 1, 2}, {0, 1, 3, 2}, {0, 1, 2, 3}};

// Twelve floats a0 b0 c0 a1 | b1 c1 a2 b2 | c2 a3 b3 c3 into one register per component.
[[gnu::always_inline]] inline void load_components_x4(const std::byte* components, __m128& a,
                                                      __m128& b, __m128& c) {
  const auto load = [&](int k) {
    return _mm_loadu_ps(reinterpret_cast<const float*>(components + 16 * k));
  };
  const __m128 m0 = load(0), m1 = load(1), m2 = load(2);
  a = _mm_shuffle_ps(m0, _mm_shuffle_ps(m1, m2, _MM_SHUFFLE(1, 1, 2, 2)), _MM_SHUFFLE(2, 0, 3, 0));
  b = _mm_shuffle_ps(_mm_shuffle_ps(m0, m1, _MM_SHUFFLE(0, 0, 1, 1)),
                     _mm_shuffle_ps(m1, m2, _MM_SHUFFLE(2, 2, 3, 3)), _MM_SHUFFLE(2, 0, 2, 0));
  c = _mm_shuffle_ps(_mm_shuffle_ps(m0, m1, _MM_SHUFFLE(1, 1, 2, 2)), m2, _MM_SHUFFLE(3, 0, 2, 0));
}

// The left-out components of four samples: each predicted magnitude moved by its code's ulps,
// with its sign.
[[gnu::always_inline]] inline __m128 left_out_x4(__m128 predicted, const uint8_t* codes) {
  uint32_t word;
  std::memcpy(&word, codes, sizeof word);
  const __m128i zero = _mm_setzero_si128();
  const __m128i code =
      _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(word)), zero), zero);
  const __m128i ulps = _mm_sub_epi32(_mm_srli_epi32(code, 3), _mm_set1_epi32(kUlpBias));
  const __m128i sign =
      _mm_slli_epi32(_mm_and_si128(_mm_srli_epi32(code, 2), _mm_set1_epi32(1)), 31);
  return _mm_castsi128_ps(_mm_or_si128(_mm_add_epi32(_mm_castps_si128(predicted), ulps), sign));
}

// unit_complement of four samples: the same double-precision sums in the same order, and sqrtpd
// rounds correctly like std::sqrt, so the bits are the scalar ones.
__m128 unit_complement_x4(__m128 a, __m128 b, __m128 c) {
  const auto half = [](__m128 low_a, __m128 low_b, __m128 low_c) {
    const __m128d ad = _mm_cvtps_pd(low_a), bd = _mm_cvtps_pd(low_b), cd = _mm_cvtps_pd(low_c);
    const __m128d sum =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(ad, ad), _mm_mul_pd(bd, bd)), _mm_mul_pd(cd, cd));
    // max(x, 0) gives 0 for NaN too, as std::max(0.0, x) does.
    return _mm_cvtpd_ps(
        _mm_sqrt_pd(_mm_max_pd(_mm_sub_pd(_mm_set1_pd(1.0), sum), _mm_setzero_pd())));
  };
  return _mm_movelh_ps(half(a, b, c),
                       half(_mm_movehl_ps(a, a), _mm_movehl_ps(b, b), _mm_movehl_ps(c, c)));
}

// decode_rotation of four consecutive samples, none of them an escape, in SSE2.
void decode_rotations_x4(const std::byte* components, const uint8_t* codes, glm::quat* out) {
  __m128 a, b, c;
  load_components_x4(components, a, b, c);
  // One register per sample, (a, b, c, value), then the value moved to its place.
  __m128 rows[4] = {a, b, c, left_out_x4(unit_complement_x4(a, b, c), codes)};
  _MM_TRANSPOSE4_PS(rows[0], rows[1], rows[2], rows[3]);
  for (int i = 0; i < 4; ++i) {
    const int k = codes[i] & 3;
    const __m128 row = rows[i];
    const __m128 shifted = _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(row), 4));
    const __m128 left_out = _mm_shuffle_ps(row, row, _MM_SHUFFLE(3, 3, 3, 3));
    const auto mask = [](const uint32_t* lanes) {
      return _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(lanes)));
    };
    const __m128 placed = _mm_or_ps(_mm_and_ps(mask(kPlacement.below[k]), row),
                                    _mm_or_ps(_mm_and_ps(mask(kPlacement.at[k]), left_out),
                                              _mm_and_ps(mask(kPlacement.above[k]), shifted)));
    _mm_storeu_ps(&out[i].x, placed);
  }
}

// The same with AVX: the four square roots in one instruction and the placement by permute.
__attribute__((target("avx"))) void decode_rotations_x4_avx(const std::byte* components,
                                                            const uint8_t* codes, glm::quat* out) {
  __m128 a, b, c;
  load_components_x4(components, a, b, c);
  const __m256d ad = _mm256_cvtps_pd(a), bd = _mm256_cvtps_pd(b), cd = _mm256_cvtps_pd(c);
  const __m256d sum = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ad, ad), _mm256_mul_pd(bd, bd)),
                                    _mm256_mul_pd(cd, cd));
  const __m128 predicted = _mm256_cvtpd_ps(
      _mm256_sqrt_pd(_mm256_max_pd(_mm256_sub_pd(_mm256_set1_pd(1.0), sum), _mm256_setzero_pd())));
  __m128 rows[4] = {a, b, c, left_out_x4(predicted, codes)};
  _MM_TRANSPOSE4_PS(rows[0], rows[1], rows[2], rows[3]);
  for (int i = 0; i < 4; ++i) {
    const __m128i order =
        _mm_load_si128(reinterpret_cast<const __m128i*>(kPlacementOrder[codes[i] & 3]));
    _mm_storeu_ps(&out[i].x, _mm_permutevar_ps(rows[i], order));
  }
}
#endif

// ---------------------------------------------------------------------------------------------
// Positions: a column (one joint in one clip) whose value never changes is stored once.

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

// Reads the counts, frame time and roles of a header whose identity check passed.
DatabaseFileInfo read_header_fields(std::span<const std::byte> prefix) {
  DatabaseFileInfo info;
  info.format_version = read_at<uint32_t>(prefix, kOffVersion);
  info.file_size = read_at<uint64_t>(prefix, kOffFileSize);
  uint32_t counts[6];
  std::memcpy(counts, prefix.data() + kOffCounts, sizeof counts);
  info.joint_count = counts[0];
  info.frame_count = counts[1];
  info.clip_count = counts[2];
  info.tag_count = counts[3];
  info.feature_dims = counts[4];
  info.channel_count = counts[5];
  info.frame_time = read_at<float>(prefix, kOffFrameTime);
  return info;
}

// Sane limits, so that nothing later allocates from a corrupt count.
Status check_header_counts(const DatabaseFileInfo& info, const std::string& where) {
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
  return Status::success();
}

// What the counts say about a section's length: exactly `exact` bytes, or (variable sections)
// at least `minimum` and at most `maximum` bytes in whole records of `unit` bytes.
struct SectionSize {
  uint64_t exact = 0;  // 0: variable
  uint64_t minimum = 0;
  uint64_t maximum = std::numeric_limits<uint64_t>::max();
  uint64_t unit = 1;
  std::string how;
};

SectionSize expected_section_size(DatabaseSection section, const DatabaseFileInfo& info) {
  const uint64_t frames = info.frame_count;
  const uint64_t samples = frames * info.joint_count;
  const uint64_t dims = info.feature_dims;
  const uint64_t columns = uint64_t{info.clip_count} * info.joint_count;
  auto records = [](uint64_t minimum, uint32_t count, const char* what) {
    return SectionSize{0, minimum * count, std::numeric_limits<uint64_t>::max(), 1,
                       std::string(what) + " " + std::to_string(count) + " records"};
  };
  switch (section) {
    case DatabaseSection::Schema:
      return records(kMinChannelBytes, info.channel_count, "channel_count");
    case DatabaseSection::SkeletonNames:
      return records(kMinStringBytes, info.joint_count, "joint_count");
    case DatabaseSection::SkeletonParents:
      return {4 * uint64_t{info.joint_count}, 0, 0, 1, "joint_count x 4"};
    case DatabaseSection::SkeletonRest:
      return {kRestTransformBytes * info.joint_count, 0, 0, 1, "joint_count x 40"};
    case DatabaseSection::SkeletonRoles:
      return {4 * kJointRoleCount, 0, 0, 1, "one int32 per joint role"};
    case DatabaseSection::Clips:
      return records(kMinClipBytes, info.clip_count, "clip_count");
    case DatabaseSection::TagNames:
      return records(kMinStringBytes, info.tag_count, "tag_count");
    case DatabaseSection::PositionColumns:
      return {columns, 0, 0, 1, "clip_count x joint_count"};
    case DatabaseSection::ConstantPositions:
      return {0, 0, columns * 12, 12, "at most clip_count x joint_count x 12"};
    case DatabaseSection::VaryingPositions:
      return {0, 0, samples * 12, 12, "at most frame_count x joint_count x 12"};
    case DatabaseSection::RotationComponents:
      return {samples * 12, 0, 0, 1, "frame_count x joint_count x 12"};
    case DatabaseSection::RotationCodes:
      return {samples, 0, 0, 1, "frame_count x joint_count"};
    case DatabaseSection::RotationExceptions:
      return {0, 0, samples * kRotationExceptionBytes, kRotationExceptionBytes,
              "at most frame_count x joint_count x 16"};
    case DatabaseSection::Contacts:
      return {frames * 2, 0, 0, 1, "frame_count x 2"};
    case DatabaseSection::Features:
      return {frames * dims * 4, 0, 0, 1, "frame_count x feature_dims x 4"};
    case DatabaseSection::FeatureOffset:
    case DatabaseSection::FeatureScale:
      return {dims * 4, 0, 0, 1, "feature_dims x 4"};
    case DatabaseSection::Searchable:
      return {frames, 0, 0, 1, "frame_count"};
    case DatabaseSection::StyleNames:
      return {0, 4, std::numeric_limits<uint64_t>::max(), 1, "a count and the style names"};
    case DatabaseSection::Count:
      break;
  }
  return {};
}

// The section table: ordered, aligned, inside the file, sized as the counts say.
Status read_section_table(std::span<const std::byte> prefix, const std::string& where,
                          DatabaseFileInfo& info) {
  const uint64_t data_end = info.file_size - kChecksumSize;
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

    const SectionSize size = expected_section_size(section, info);
    if (size.exact != 0 && s.length != size.exact) {
      return Error{sec + ": " + std::to_string(s.length) + " bytes, expected " +
                   std::to_string(size.exact) + " (" + size.how + ")"};
    }
    if (size.exact == 0 &&
        (s.length < size.minimum || s.length > size.maximum || s.length % size.unit != 0)) {
      return Error{sec + ": " + std::to_string(s.length) + " bytes cannot hold " + size.how +
                   (size.minimum > 0 ? " (at least " + std::to_string(size.minimum) + " bytes)"
                                     : std::string(" in whole records of ") +
                                           std::to_string(size.unit) + " bytes")};
    }
  }
  return Status::success();
}

// Checks the whole header: check_identity(), then the sizes, counts and section table.
Result<DatabaseFileInfo> parse_header(std::span<const std::byte> prefix, uint64_t actual_size,
                                      std::string_view name) {
  if (Status s = check_identity(prefix, actual_size, name); !s) return Error{s.message()};
  const std::string where(name);
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
  DatabaseFileInfo info = read_header_fields(prefix);
  if (Status s = check_header_counts(info, where); !s) return Error{s.message()};
  if (Status s = read_section_table(prefix, where, info); !s) return Error{s.message()};
  if (prefix.size() >= info.file_size) {
    info.stored_checksum = read_at<uint64_t>(prefix, info.file_size - kChecksumSize);
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
  static_assert(std::is_trivially_copyable_v<T>);
  const std::span<const std::byte> bytes = section_bytes(file, info, s);
  out.resize(bytes.size() / sizeof(T));
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
}

// The same into a database's array, which the header's counts sized to the section's length.
template <class T>
void copy_array(std::span<const std::byte> file, const DatabaseFileInfo& info, DatabaseSection s,
                std::span<T> out) {
  static_assert(std::is_trivially_copyable_v<T>);
  const std::span<const std::byte> bytes = section_bytes(file, info, s);
  MM_ASSERT(bytes.size() == out.size_bytes());
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());
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

Status read_style_names(std::span<const std::byte> file, const DatabaseFileInfo& info,
                        std::string_view name, std::vector<std::string>& out) {
  SectionReader r(section_bytes(file, info, DatabaseSection::StyleNames),
                  DatabaseSection::StyleNames, name);
  uint32_t count = 0;
  if (Status s = r.pod(count, "style count"); !s) return s;
  if (count > kMaxStyles) {
    return r.fail("style count " + std::to_string(count) + " is above the limit of " +
                  std::to_string(kMaxStyles));
  }
  out.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    if (Status s = r.string(out[i], "style " + std::to_string(i)); !s) return s;
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
    int32_t style = -1;
    if (Status s = r.pod(style, where + " style"); !s) return s;
    if (Status s = r.string(c.name, where + " name"); !s) return s;
    c.style = style;
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

Status read_position_layout(std::span<const std::byte> file, const DatabaseFileInfo& info,
                            const std::vector<ClipRange>& clips, std::string_view name,
                            PositionLayout& layout) {
  copy_array(file, info, DatabaseSection::PositionColumns, layout.constant);
  SectionReader columns(section_bytes(file, info, DatabaseSection::PositionColumns),
                        DatabaseSection::PositionColumns, name);
  const size_t joints = info.joint_count;
  for (size_t i = 0; i < layout.constant.size(); ++i) {
    if (layout.constant[i] > 1) {
      return columns.fail("clip " + std::to_string(i / joints) + ", joint " +
                          std::to_string(i % joints) + ": flag " +
                          std::to_string(layout.constant[i]) + ", expected 0 or 1");
    }
  }
  lay_out_positions(clips, joints, layout);
  const std::pair<DatabaseSection, size_t> sizes[] = {
      {DatabaseSection::ConstantPositions, layout.constant_count},
      {DatabaseSection::VaryingPositions, layout.varying_count}};
  for (const auto& [section, count] : sizes) {
    if (info.section(section).length != count * sizeof(glm::vec3)) {
      return SectionReader(section_bytes(file, info, section), section, name)
          .fail(std::to_string(info.section(section).length) + " bytes, but position_columns " +
                "and the clips call for " + std::to_string(count) + " positions of 12 bytes");
    }
  }
  return Status::success();
}

Status read_rotation_exceptions(std::span<const std::byte> file, const DatabaseFileInfo& info,
                                std::string_view name, std::vector<RotationException>& out) {
  SectionReader r(section_bytes(file, info, DatabaseSection::RotationExceptions),
                  DatabaseSection::RotationExceptions, name);
  const uint64_t samples = uint64_t{info.frame_count} * info.joint_count;
  out.resize(info.section(DatabaseSection::RotationExceptions).length / kRotationExceptionBytes);
  for (size_t i = 0; i < out.size(); ++i) {
    const std::string where = "exception " + std::to_string(i);
    if (Status s = r.pod(out[i].sample, where + " sample"); !s) return s;
    if (Status s = r.pod(out[i].value, where + " value"); !s) return s;
    if (Status s = r.zero_padding(4, where + " padding"); !s) return s;
    if (out[i].sample >= samples || (i > 0 && out[i].sample <= out[i - 1].sample)) {
      return r.fail(where + ": sample " + std::to_string(out[i].sample) +
                    " is not in increasing order within [0, " + std::to_string(samples) + ")");
    }
  }
  return r.finish();
}

// Everything but the per-frame arrays: schema, skeleton, clips, tags and the layout of the
// position and rotation sections, checked record by record.
struct LoadPlan {
  PositionLayout positions;
  std::vector<RotationException> exceptions;
};

Status read_small_sections(std::span<const std::byte> file, const DatabaseFileInfo& info,
                           std::string_view name, LoadTarget& db, LoadPlan& plan) {
  if (Status s = read_schema(file, info, name, db.schema); !s) return s;
  if (db.schema.dims() != static_cast<int>(info.feature_dims)) {
    return Error{std::string(name) + ": section 'schema': its channels have " +
                 std::to_string(db.schema.dims()) + " feature columns but the header says " +
                 std::to_string(info.feature_dims)};
  }
  if (Status s = read_skeleton(file, info, name, db.skeleton); !s) return s;
  const std::span<const std::byte> roles =
      section_bytes(file, info, DatabaseSection::SkeletonRoles);
  for (size_t r = 0; r < kJointRoleCount; ++r) {
    int32_t joint = 0;
    std::memcpy(&joint, roles.data() + 4 * r, sizeof joint);
    db.roles.*kJointRoles[r].index = joint;
  }
  db.frame_time = info.frame_time;
  db.frame_count = static_cast<int>(info.frame_count);
  if (Status s = read_clips(file, info, name, db.clips); !s) return s;
  if (Status s = read_string_list(file, info, DatabaseSection::TagNames, info.tag_count, name,
                                  db.tag_names);
      !s) {
    return s;
  }
  if (Status s = read_style_names(file, info, name, db.style_names); !s) return s;
  // The per-clip sections are laid out by the clips, so these must tile the frames first.
  if (Status s = validate_clip_ranges(db.clips, db.frame_count, db.tag_names.size()); !s) {
    return Error{std::string(name) + ": " + s.message()};
  }
  if (Status s = read_position_layout(file, info, db.clips, name, plan.positions); !s) return s;
  return read_rotation_exceptions(file, info, name, plan.exceptions);
}

// The positions of one clip: its constant columns (one value for the whole clip) and its
// varying ones (one value per frame, frame by frame, in joint order). Returns whether every
// value is finite (each stored value is checked once, as it is read).
bool decode_positions(const std::byte* constant, const std::byte* varying,
                      const uint8_t* is_constant, size_t joints, size_t frames, float* out) {
  if (frames == 0) return true;
  uint32_t infinite = 0;
  const auto copy = [&](float* to, const std::byte* from) {
    std::memcpy(to, from, 12);
    for (int k = 0; k < 3; ++k) infinite |= static_cast<uint32_t>(!detail::finite_bits(to[k]));
  };
  for (size_t j = 0; j < joints; ++j) {
    const std::byte*& from = is_constant[j] ? constant : varying;
    copy(out + 3 * j, from);
    from += 12;
  }
  // Every later frame: the previous one, which has the constants, with the varying ones replaced.
  for (size_t f = 1; f < frames; ++f) {
    float* frame = out + 3 * joints * f;
    std::memcpy(frame, frame - 3 * joints, 12 * joints);
    for (size_t j = 0; j < joints; ++j) {
      if (is_constant[j]) continue;
      copy(frame + 3 * j, varying);
      varying += 12;
    }
  }
  return infinite == 0;
}

// The rotations of samples [first, first + count), with their exceptions in sample order.
Status decode_rotations(std::span<const std::byte> file, const DatabaseFileInfo& info,
                        const LoadPlan& plan, size_t first, size_t count, std::string_view name,
                        glm::quat* rotations) {
  const std::byte* components =
      section_bytes(file, info, DatabaseSection::RotationComponents).data() + 12 * first;
  const auto* codes = reinterpret_cast<const uint8_t*>(
      section_bytes(file, info, DatabaseSection::RotationCodes).data() + first);
  auto exception = std::lower_bound(
      plan.exceptions.begin(), plan.exceptions.end(), first,
      [](const RotationException& e, uint64_t sample) { return e.sample < sample; });
  const auto escape_free = [&](size_t i) {
    return !is_escape(codes[i]) && !is_escape(codes[i + 1]) && !is_escape(codes[i + 2]) &&
           !is_escape(codes[i + 3]);
  };
#if defined(__SSE2__)
  const auto decode_x4 = detail::cpu_has_avx() ? &decode_rotations_x4_avx : &decode_rotations_x4;
#endif
  size_t i = 0;
  while (i < count) {
#if defined(__SSE2__)
    if (i + 4 <= count && escape_free(i)) {
      decode_x4(components + 12 * i, codes + i, rotations + i);
      i += 4;
      continue;
    }
#endif
    const float* exact = nullptr;
    if (is_escape(codes[i])) {
      if (exception == plan.exceptions.end() || exception->sample != first + i) {
        return SectionReader({}, DatabaseSection::RotationExceptions, name)
            .fail("no exception for the escape code of sample " + std::to_string(first + i) +
                  " [frame " + std::to_string((first + i) / info.joint_count) + ", joint " +
                  std::to_string(i % info.joint_count) + "]");
      }
      exact = &exception->value;
      ++exception;
    }
    float three[3];
    std::memcpy(three, components + 12 * i, sizeof three);
    rotations[i] = decode_rotation(three, codes[i], exact);
    ++i;
  }
  if (exception != plan.exceptions.end() && exception->sample < first + count) {
    return SectionReader({}, DatabaseSection::RotationExceptions, name)
        .fail("exception for sample " + std::to_string(exception->sample) +
              ", whose rotation code is not an escape");
  }
  return Status::success();
}

// One clip's pose per joint, as the file stores it and the velocities are derived: a worker's
// scratch, laid out in the database's lanes once the clip is decoded (the database holds the
// pose only in the lanes' layout).
struct ClipPose {
  std::vector<glm::vec3> positions, velocities, angular_velocities;
  std::vector<glm::quat> rotations;
  void reserve(size_t count) {
    positions.reserve(count);
    velocities.reserve(count);
    angular_velocities.reserve(count);
    rotations.reserve(count);
  }
  void resize(size_t count) {
    positions.resize(count);
    velocities.resize(count);
    angular_velocities.resize(count);
    rotations.resize(count);
  }
};

// Positions, rotations and velocities of one clip, decoded into `pose` and laid out in the
// database's lanes at the clip's frames. `valid` tells whether they are all what validate()
// accepts (finite, unit rotations).
Status decode_clip(std::span<const std::byte> file, const DatabaseFileInfo& info,
                   const LoadPlan& plan, size_t c, std::string_view name, LoadTarget& db,
                   ClipPose& pose, bool& valid) {
  const ClipRange& clip = db.clips[c];
  const size_t joints = info.joint_count;
  const size_t frames = static_cast<size_t>(clip.frame_count());
  const size_t first = static_cast<size_t>(clip.start) * joints;
  const size_t count = frames * joints;
  pose.resize(count);
  const bool positions_finite =
      decode_positions(section_bytes(file, info, DatabaseSection::ConstantPositions).data() +
                           12 * plan.positions.first_constant[c],
                       section_bytes(file, info, DatabaseSection::VaryingPositions).data() +
                           12 * plan.positions.first_varying[c],
                       plan.positions.constant.data() + c * joints, joints, frames,
                       glm::value_ptr(pose.positions[0]));
  glm::quat* rotations = pose.rotations.data();
  if (Status s = decode_rotations(file, info, plan, first, count, name, rotations); !s) return s;
  const bool velocities_finite = compute_local_velocities(
      std::span(pose.positions).first(count), std::span(rotations, count), clip.frame_count(),
      static_cast<int>(joints), db.frame_time, std::span(pose.velocities).first(count),
      std::span(pose.angular_velocities).first(count));
  valid = positions_finite && velocities_finite && detail::rotations_unit(rotations, count);
  const size_t floats = pose_lane_floats(joints);
  for (size_t f = 0; f < frames; ++f) {
    const size_t k = f * joints;
    pose_to_lanes(
        PoseFrameView{std::span<const glm::quat>(pose.rotations).subspan(k, joints),
                      std::span<const glm::vec3>(pose.positions).subspan(k, joints),
                      std::span<const glm::vec3>(pose.velocities).subspan(k, joints),
                      std::span<const glm::vec3>(pose.angular_velocities).subspan(k, joints)},
        db.pose_lanes.subspan((static_cast<size_t>(clip.start) + f) * floats, floats));
  }
  return Status::success();
}

// Phase 2 of a load, on `threads` threads pulling jobs in order: the checksum, the plain
// copies (features, contacts, searchable), then decode_clip() of every clip, whose joint values
// are checked while they are in cache. Decoding does not wait for the checksum: it reads only
// inside sections whose sizes phase 1 checked, so a damaged file decodes to values that are
// dropped for the checksum mismatch.
struct DecodedFile {
  uint64_t checksum = 0;
  Status status;                    // the first failing clip's, in clip order
  bool joint_values_valid = false;  // every clip's values passed decode_clip's checks
};

DecodedFile decode_file(std::span<const std::byte> file, const DatabaseFileInfo& info,
                        const LoadPlan& plan, std::string_view name, int threads, LoadTarget& db) {
  DecodedFile out;
  constexpr size_t kFirstClipJob = 2;
  std::vector<Status> status(db.clips.size());
  std::vector<uint8_t> valid(db.clips.size(), 0);
  // Each worker's scratch holds the longest clip, allocated once.
  size_t longest = 0;
  for (const ClipRange& clip : db.clips) {
    longest = std::max(longest, static_cast<size_t>(clip.frame_count()) * info.joint_count);
  }
  std::vector<ClipPose> poses(static_cast<size_t>(std::max(threads, 1)));
  for (ClipPose& pose : poses) pose.reserve(longest);
  detail::run_workers(kFirstClipJob + db.clips.size(), threads, [&](int worker, size_t job) {
    if (job == 0) {
      out.checksum = database_checksum(file.first(file.size() - kChecksumSize));
    } else if (job == 1) {
      copy_array(file, info, DatabaseSection::Features, db.features);
      copy_array(file, info, DatabaseSection::Contacts, db.contacts);
      copy_array(file, info, DatabaseSection::FeatureOffset, db.feature_offset);
      copy_array(file, info, DatabaseSection::FeatureScale, db.feature_scale);
      copy_array(file, info, DatabaseSection::Searchable, db.searchable);
    } else {
      const size_t c = job - kFirstClipJob;
      bool clip_valid = false;
      status[c] = decode_clip(file, info, plan, c, name, db, poses[static_cast<size_t>(worker)],
                              clip_valid);
      valid[c] = status[c] && clip_valid;
    }
  });
  out.joint_values_valid =
      std::all_of(valid.begin(), valid.end(), [](uint8_t v) { return v != 0; });
  const auto failed =
      std::find_if(status.begin(), status.end(), [](const Status& s) { return !s; });
  if (failed != status.end()) out.status = *failed;
  return out;
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
    case DatabaseSection::SkeletonRoles:
      return "skeleton_roles";
    case DatabaseSection::Clips:
      return "clips";
    case DatabaseSection::TagNames:
      return "tag_names";
    case DatabaseSection::PositionColumns:
      return "position_columns";
    case DatabaseSection::ConstantPositions:
      return "constant_positions";
    case DatabaseSection::VaryingPositions:
      return "varying_positions";
    case DatabaseSection::RotationComponents:
      return "rotation_components";
    case DatabaseSection::RotationCodes:
      return "rotation_codes";
    case DatabaseSection::RotationExceptions:
      return "rotation_exceptions";
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
    case DatabaseSection::StyleNames:
      return "style_names";
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

Result<DatabaseFileInfo> parse_database_header(std::span<const std::byte> bytes,
                                               std::string_view name_for_messages) {
  return parse_header(bytes, bytes.size(), name_for_messages);
}

// Phases: 1. identity, header and the small sections (schema, skeleton, clips, tags, the layout
// of the position and rotation sections); 2. on two threads, the checksum, the plain copies and
// the clips' positions, rotations and velocities (decode_file); 3. Database::validate(). A
// checksum mismatch is reported in preference to anything else; phase 2 reads only what phase 1
// checked.
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
  const int threads = bytes.size() >= kParallelBytes ? 2 : 1;

  Database db = detail::DatabaseAssembly::empty();
  LoadTarget parts = detail::DatabaseAssembly::parts(db);
  LoadPlan plan;
  Status phase1;
  Result<DatabaseFileInfo> header = parse_header(bytes, bytes.size(), name);
  try {
    phase1 =
        header ? read_small_sections(bytes, *header, name, parts, plan) : Error{header.message()};
  } catch (const std::exception& e) {
    phase1 = Error{name + ": cannot load: " + e.what()};  // only allocation can throw
  }
  if (!phase1) {
    if (const uint64_t computed = database_checksum(covered); computed != stored) {
      return checksum_error(computed);
    }
    return Error{phase1.message()};
  }

  DecodedFile decoded;
  try {
    detail::DatabaseAssembly::allocate(db, header->frame_count);
    decoded = decode_file(bytes, *header, plan, name, threads, parts);
  } catch (const std::exception& e) {
    return Error{name + ": cannot load: " + e.what()};
  }
  if (decoded.checksum != stored) return checksum_error(decoded.checksum);
  if (!decoded.status) return Error{decoded.status.message()};
  // frame_clip is derived, not stored (the clips tile the frames: checked before decoding).
  detail::DatabaseAssembly::derive_frame_clip(db);
  // A bad joint value is reported by the full validation, which names the first one.
  const Status valid =
      decoded.joint_values_valid ? detail::validate_except_joint_values(db) : db.validate();
  if (!valid) return Error{name + ": " + valid.message()};
  return db;
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
