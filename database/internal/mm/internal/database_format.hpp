#pragma once
// What the database file's reader (database_file.cpp) and writer (mm/offline/database_writer.hpp)
// share beyond the public layout in database_file.hpp: header field offsets, record sizes, the
// rotation code's constants and prediction, the position sections' layout. Internal
// (database/internal/, never installed).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/database/database.hpp"
#include "mm/database/database_file.hpp"

namespace mm::detail {

// Files (and rotation sections) at least this large are loaded (and written) on two threads.
constexpr size_t kParallelBytes = size_t{8} << 20;

// Header field offsets (see the layout in database_file.hpp).
constexpr size_t kOffVersion = 8;
constexpr size_t kOffEndian = 12;
constexpr size_t kOffFileSize = 16;
constexpr size_t kOffHeaderSize = 24;
constexpr size_t kOffSectionCount = 28;
constexpr size_t kOffCounts = 32;
constexpr size_t kOffFrameTime = 56;
constexpr size_t kOffReserved = 60;
constexpr size_t kOffSectionTable = 88;
constexpr size_t kChecksumSize = 8;
static_assert(kOffSectionTable + kDatabaseSectionCount * 16 <= kDatabaseHeaderSize);
static_assert(kDatabaseHeaderSize % 16 == 0);
static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::quat) == 16);

// Smallest encoded size of one record of each variable section (with empty strings and lists).
constexpr uint64_t kMinStringBytes = 4;
constexpr uint64_t kMinChannelBytes = 4 + 4 + 4 + 4 + 12 + 4;
constexpr uint64_t kMinClipBytes = 4 + 4 + 8 + 4 + 4 + 4;
constexpr uint64_t kRestTransformBytes = 10 * 4;
constexpr uint64_t kRotationExceptionBytes = 16;

// ---- Rotations: "smallest three" without loss (see database_file.hpp) ----------------------

constexpr int kUlpBias = 16;        // code bits 3-7 hold 16 + the distance in ulps
constexpr uint8_t kEscape = 31;     // ... or this: the value is in rotation_exceptions
constexpr int kMinUlp = -kUlpBias;  // the distances a code can hold
constexpr int kMaxUlp = kEscape - 1 - kUlpBias;

// The magnitude a unit quaternion's fourth component has given the other three, rounded to
// float. The squares are exact in double, so the result does not depend on FMA contraction.
inline float unit_complement(float a, float b, float c) {
  const double sum =
      static_cast<double>(a) * a + static_cast<double>(b) * b + static_cast<double>(c) * c;
  return static_cast<float>(std::sqrt(std::max(0.0, 1.0 - sum)));
}

inline bool is_escape(uint8_t code) {
  return (code >> 3) == kEscape;
}

// One escape's exact value: the record of section rotation_exceptions.
struct RotationException {
  uint64_t sample = 0;
  float value = 0.0f;
};

// ---- Positions: a column (one joint in one clip) whose value never changes is stored once -----

// Where each clip's positions lie in the two position sections, in values.
struct PositionLayout {
  std::vector<uint8_t> constant;       // per clip and joint, clip-major
  std::vector<size_t> first_constant;  // per clip: its first value in constant_positions
  std::vector<size_t> first_varying;   // per clip: its first value in varying_positions
  size_t constant_count = 0;           // values in constant_positions
  size_t varying_count = 0;            // values in varying_positions
};

// Fills first_constant, first_varying and the counts from `constant`.
inline void lay_out_positions(std::span<const ClipRange> clips, size_t joints,
                              PositionLayout& layout) {
  layout.first_constant.resize(clips.size());
  layout.first_varying.resize(clips.size());
  layout.constant_count = 0;
  layout.varying_count = 0;
  for (size_t c = 0; c < clips.size(); ++c) {
    layout.first_constant[c] = layout.constant_count;
    layout.first_varying[c] = layout.varying_count;
    size_t constants = 0;
    for (size_t j = 0; j < joints; ++j) constants += layout.constant[c * joints + j];
    layout.constant_count += constants;
    layout.varying_count += static_cast<size_t>(clips[c].frame_count()) * (joints - constants);
  }
}

inline std::string errno_text(int error) {
  return std::generic_category().message(error);
}

}  // namespace mm::detail
