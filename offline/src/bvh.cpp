#include "mm/offline/bvh.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/gtx/euler_angles.hpp>

#include "mm/database/files.hpp"

namespace mm {
namespace {

// Guards every per-joint index and the frame value count against int overflow on absurd
// input; real skeletons have tens of joints, and the 100,000-deep stress case stays far below.
constexpr int kMaxJoints = 1'000'000;
constexpr int kMaxChannelsPerJoint = 6;
// Joints without channels cost hierarchy bytes once but a transform in every frame, so a small
// hostile file could expand quadratically. Real files stay far below this many transforms per
// byte of text (the clips here: 0.04); past it, the file is refused before allocating.
constexpr size_t kMaxTransformsPerByte = 16;
constexpr size_t kTransformAllowance = 1 << 16;
constexpr float kHalfDegreesToRadians = 3.14159265358979323846f / 360.0f;

// 10^-k rounded to double. Exact powers are not needed: see parse_plain_decimal.
constexpr double kNegativePowersOfTen[] = {1e-0,  1e-1,  1e-2,  1e-3,  1e-4,  1e-5,  1e-6,  1e-7,
                                           1e-8,  1e-9,  1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15,
                                           1e-16, 1e-17, 1e-18, 1e-19, 1e-20, 1e-21, 1e-22};
constexpr int kMaxFractionDigits = 22;
constexpr uint64_t kMaxExactDoubleMantissa = uint64_t{1} << 53;

inline bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}
// Whitespace that does not end a line: frames are one per line, so '\n' is significant there.
inline bool is_line_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
inline bool is_digit(char c) {
  return static_cast<unsigned char>(c - '0') < 10;
}

enum class NumberStatus { kOk, kNotANumber, kOutOfRange, kNotFinite };

// The general number path: whatever std::from_chars accepts as a whole token (exponents,
// long mantissas, "inf", "nan" which are then refused as non-finite). A value too small for a
// float becomes 0 or a subnormal; a value too large is refused.
[[gnu::noinline]] NumberStatus parse_number_slow(const char* begin, const char* token_end,
                                                 float& out) {
  const char* p = begin;
  if (p < token_end && *p == '+' && p + 1 < token_end && *(p + 1) != '-') ++p;
  float value = 0.0f;
  auto [ptr, ec] = std::from_chars(p, token_end, value);
  if (ec == std::errc::invalid_argument || ptr != token_end) return NumberStatus::kNotANumber;
  if (ec == std::errc::result_out_of_range) {
    // Out of range in either direction: only underflow (tiny magnitude) is representable.
    double wide = 0.0;
    auto [wide_ptr, wide_ec] = std::from_chars(p, token_end, wide);
    if (wide_ec != std::errc() || wide_ptr != token_end || !(std::abs(wide) < 1.0)) {
      return NumberStatus::kOutOfRange;
    }
    value = static_cast<float>(wide);
  }
  if (!std::isfinite(value)) return NumberStatus::kNotFinite;
  out = value;
  return NumberStatus::kOk;
}

// The fast path for what motion lines hold: a plain decimal "-?d*(.d*)?" with at most 19
// digits, followed by whitespace. The text must continue with a non-digit sentinel (a '\n'),
// so no loop needs a bounds check. Returns the end of the number, or nullptr when the number
// is not plain (the caller then uses parse_number_slow, which decides).
//
// The result is bit-identical to from_chars (correct rounding) without a division: the mantissa
// m <= 2^53 is an exact double and p = double(10^-k) is off by at most half an ulp, so
// q = m * p (one more rounding) is within 2 double ulps of the exact decimal x. Rounding q to
// float gives the float nearest x unless a float midpoint lies between x and q; a float
// midpoint is a double whose 29 low mantissa bits are 0x10000000, so when q's low bits are not
// within a few ulps of that pattern, no midpoint can be between them. The rare near-tie goes to
// from_chars. Such quotients are normal floats or zero (>= 1e-22), so the 29 low bits of q are
// exactly the part that float rounding removes.
//
// A scalar loop on purpose: real files print every value in the same format, so the digit
// branches predict perfectly and the CPU runs ahead across values; an eight-bytes-at-a-time
// version was slower because it makes each value's end a data dependency (bench/bvh_bench.cpp
// compares the parser with its baselines).
inline const char* parse_plain_decimal(const char* p, float& out) {
  const bool negative = *p == '-';
  const char* q = p + negative;
  uint64_t mantissa = 0;
  const char* digits_begin = q;
  while (is_digit(*q)) {
    mantissa = mantissa * 10 + static_cast<uint64_t>(*q - '0');
    ++q;
  }
  ptrdiff_t digit_count = q - digits_begin;
  ptrdiff_t fraction_digits = 0;
  if (*q == '.') {
    ++q;
    const char* fraction_begin = q;
    while (is_digit(*q)) {
      mantissa = mantissa * 10 + static_cast<uint64_t>(*q - '0');
      ++q;
    }
    fraction_digits = q - fraction_begin;
    digit_count += fraction_digits;
  }
  if (digit_count == 0 || digit_count > 19 || fraction_digits > kMaxFractionDigits ||
      mantissa > kMaxExactDoubleMantissa || !is_space(*q)) {
    return nullptr;
  }
  const double scaled = static_cast<double>(mantissa) * kNegativePowersOfTen[fraction_digits];
  // Refuse when the 29 low bits are within 8 ulps of the midpoint pattern (a 4x margin).
  constexpr uint64_t kLowBits = 0x1FFFFFFFull;
  constexpr uint64_t kMidpoint = 0x10000000ull;
  constexpr uint64_t kMargin = 8;
  if (((std::bit_cast<uint64_t>(scaled) - (kMidpoint - kMargin)) & kLowBits) <= 2 * kMargin) {
    return nullptr;
  }
  const float magnitude = static_cast<float>(scaled);
  out = negative ? -magnitude : magnitude;
  return q;
}

// Parses a whole token (header values: OFFSET, frame time) that has no sentinel after it.
NumberStatus parse_number_token(std::string_view token, float& out) {
  char padded[64];
  if (!token.empty() && token.size() < sizeof padded) {
    std::memcpy(padded, token.data(), token.size());
    padded[token.size()] = '\n';
    if (parse_plain_decimal(padded, out) == padded + token.size()) return NumberStatus::kOk;
  }
  return parse_number_slow(token.data(), token.data() + token.size(), out);
}

const char* describe_status(NumberStatus status) {
  switch (status) {
    case NumberStatus::kNotANumber:
      return "a number";
    case NumberStatus::kOutOfRange:
      return "a number within float range";
    case NumberStatus::kNotFinite:
      return "a finite number";
    case NumberStatus::kOk:
      break;
  }
  return "a number";
}

// How one joint's channels map into a frame's values, precomputed from its CHANNELS line so
// the per-frame work is a few indexed loads and one quaternion product per rotation channel.
struct JointLayout {
  int first_value = 0;                     // index of the joint's first channel in a frame
  int8_t position_slot[3] = {-1, -1, -1};  // per axis X, Y, Z: channel offset, or -1
  int8_t rotation_slot[3] = {-1, -1, -1};  // k-th listed rotation channel: channel offset
  int8_t rotation_axis[3] = {0, 0, 0};     // k-th listed rotation channel: axis 0, 1 or 2
  int8_t rotation_count = 0;
  glm::vec3 offset{0.0f};  // OFFSET in metres
};

// One open '{' of the hierarchy: the explicit stack that replaces recursion.
struct OpenJoint {
  int joint = 0;
  int64_t line = 0;  // where the joint keyword was
};

class BvhParser {
 public:
  BvhParser(std::string_view text, std::string_view path, const BvhOptions& options)
      : p_(text.data()),
        end_(text.data() + text.size()),
        text_size_(text.size()),
        path_(path),
        scale_(options.scale) {}

  Result<Clip> run() {
    if (!std::isfinite(scale_) || !(scale_ >= 0.0f)) {
      return Error{std::string(path_) +
                   ": expected BvhOptions::scale to be finite and >= 0 (0: automatic), found " +
                   std::to_string(scale_)};
    }
    // Automatic units: the offsets are read as they are, then scaled once the skeleton's size
    // is known.
    const bool automatic = scale_ == 0.0f;
    if (automatic) scale_ = 1.0f;
    if (auto error = parse_hierarchy()) return std::move(*error);
    if (automatic) apply_scale(bvh_units_to_metres(rest_extent()));
    if (auto error = parse_motion_header()) return std::move(*error);
    if (auto error = parse_frames()) return std::move(*error);
    return build_clip();
  }

 private:
  using MaybeError = std::unique_ptr<Error>;

  MaybeError fail(int64_t line, const std::string& what) const {
    return std::make_unique<Error>(
        Error{std::string(path_) + ":" + std::to_string(line) + ": " + what});
  }

  // A token shown in a message: quoted, cut short and with control bytes escaped, so fuzzed
  // or binary input cannot flood or garble the message.
  static std::string describe(std::string_view token) {
    if (token.empty()) return "end of file";
    constexpr size_t kMaxShown = 40;
    std::string out = "'";
    for (size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
      const unsigned char c = static_cast<unsigned char>(token[i]);
      if (c >= 0x20 && c < 0x7f) {
        out += static_cast<char>(c);
      } else {
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02x", c);
        out += hex;
      }
    }
    if (token.size() > kMaxShown) out += "...";
    out += "'";
    return out;
  }

  // Skips whitespace (counting lines) and returns the next run of non-space bytes, empty at
  // the end of the text. token_line_ is the line the token is on.
  std::string_view next_token() {
    while (p_ < end_ && is_space(*p_)) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
    token_line_ = line_;
    const char* start = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return {start, static_cast<size_t>(p_ - start)};
  }

  // `context` is a callable returning where the keyword belongs ("after joint 'Hips'"); it only
  // runs on failure, so the success path builds no strings.
  template <class Context>
  MaybeError expect_keyword(std::string_view keyword, const Context& context) {
    const std::string_view token = next_token();
    if (token == keyword) return nullptr;
    return fail(token_line_, "expected '" + std::string(keyword) + "' " + context() + ", found " +
                                 describe(token));
  }

  // Reads the OFFSET line of `owner` (a callable naming the joint or End Site, for messages).
  template <class Owner>
  MaybeError read_offset(const Owner& owner, glm::vec3& offset) {
    if (auto error = expect_keyword("OFFSET", [&] { return "in " + owner(); })) return error;
    for (int axis = 0; axis < 3; ++axis) {
      const std::string_view token = next_token();
      float value = 0.0f;
      const NumberStatus status = parse_number_token(token, value);
      if (status != NumberStatus::kOk) {
        return fail(token_line_, "expected OFFSET value " + std::to_string(axis + 1) + " of 3 of " +
                                     owner() + " (" + describe_status(status) + "), found " +
                                     describe(token));
      }
      offset[axis] = value * scale_;
      if (!std::isfinite(offset[axis])) {
        return fail(token_line_, "expected an OFFSET value of " + owner() +
                                     " that stays finite in metres, found " + describe(token));
      }
    }
    return nullptr;
  }

  static bool is_structure_keyword(std::string_view token) {
    return token == "JOINT" || token == "End" || token == "}" || token == "{" ||
           token == "OFFSET" || token == "CHANNELS" || token == "ROOT" || token == "MOTION";
  }

  // Channel name to index 0..5 (X/Y/Z position, X/Y/Z rotation), or -1. Case-insensitive,
  // because exporters differ ("Xrotation", "XROTATION").
  static int channel_index(std::string_view token) {
    if (token.size() != 9) return -1;
    const char axis = static_cast<char>(token[0] | 0x20);
    if (axis < 'x' || axis > 'z') return -1;
    std::string lower(token.substr(1));
    for (char& c : lower) c = static_cast<char>(c | 0x20);
    if (lower == "position") return axis - 'x';
    if (lower == "rotation") return 3 + (axis - 'x');
    return -1;
  }

  // Reads "<name> { OFFSET x y z CHANNELS n <names>" of a ROOT or JOINT and opens it.
  MaybeError open_joint(int parent, std::string_view keyword) {
    const int64_t keyword_line = token_line_;
    const std::string_view name = next_token();
    if (name.empty() || name == "{" || name == "}") {
      return fail(token_line_, "expected a joint name after '" + std::string(keyword) +
                                   "', found " + describe(name));
    }
    if (static_cast<int>(names_.size()) >= kMaxJoints) {
      return fail(token_line_,
                  "expected at most " + std::to_string(kMaxJoints) + " joints, found more");
    }
    const int joint = static_cast<int>(names_.size());
    auto [it, inserted] = joint_lines_.emplace(name, token_line_);
    if (!inserted) {
      return fail(token_line_, "expected unique joint names, found " + describe(name) +
                                   " again (first on line " + std::to_string(it->second) + ")");
    }
    const auto owner = [name] { return "joint " + describe(name); };
    if (auto error = expect_keyword("{", [&] { return "after " + owner(); })) return error;

    JointLayout layout;
    if (auto error = read_offset(owner, layout.offset)) return error;

    if (auto error = expect_keyword("CHANNELS", [&] { return "after the OFFSET of " + owner(); })) {
      return error;
    }
    const int64_t channels_line = token_line_;
    const std::string_view count_token = next_token();
    int64_t count = -1;
    auto [ptr, ec] =
        std::from_chars(count_token.data(), count_token.data() + count_token.size(), count);
    if (count_token.empty() || ec != std::errc() ||
        ptr != count_token.data() + count_token.size() || count < 0 ||
        count > kMaxChannelsPerJoint) {
      return fail(token_line_, "expected a channel count from 0 to 6 after 'CHANNELS' of " +
                                   owner() + ", found " + describe(count_token));
    }
    layout.first_value = channel_total_;
    bool seen[6] = {false, false, false, false, false, false};
    for (int slot = 0; slot < count; ++slot) {
      const std::string_view channel = next_token();
      const int index = channel_index(channel);
      if (index < 0) {
        if (channel.empty() || is_structure_keyword(channel)) {
          return fail(channels_line, "expected " + std::to_string(count) +
                                         " channel names after 'CHANNELS " + std::to_string(count) +
                                         "' of " + owner() + ", found only " +
                                         std::to_string(slot) + " before " + describe(channel) +
                                         " on line " + std::to_string(token_line_));
        }
        return fail(token_line_,
                    "expected a channel name (Xposition, Yposition, Zposition, "
                    "Xrotation, Yrotation or Zrotation) for " +
                        owner() + ", found " + describe(channel));
      }
      if (seen[index]) {
        return fail(token_line_, "expected each channel at most once in " + owner() + ", found " +
                                     describe(channel) + " twice");
      }
      seen[index] = true;
      if (index < 3) {
        layout.position_slot[index] = static_cast<int8_t>(slot);
      } else {
        layout.rotation_slot[layout.rotation_count] = static_cast<int8_t>(slot);
        layout.rotation_axis[layout.rotation_count] = static_cast<int8_t>(index - 3);
        ++layout.rotation_count;
      }
    }
    channel_total_ += static_cast<int>(count);
    channel_count_line_.push_back(channels_line);
    channel_counts_.push_back(static_cast<int>(count));

    names_.emplace_back(name);
    parents_.push_back(parent);
    layouts_.push_back(layout);
    end_sites_.emplace_back(0.0f);
    open_.push_back({joint, keyword_line});
    return nullptr;
  }

  MaybeError parse_end_site() {
    const auto owner = [this] {
      return "the End Site of joint " + describe(names_[open_.back().joint]);
    };
    if (auto error = expect_keyword("Site", [] { return std::string("after 'End'"); })) {
      return error;
    }
    if (auto error = expect_keyword("{", [] { return std::string("after 'End Site'"); })) {
      return error;
    }
    glm::vec3 offset{0.0f};
    if (auto error = read_offset(owner, offset)) return error;
    glm::vec3& kept = end_sites_[static_cast<size_t>(open_.back().joint)];
    if (kept == glm::vec3(0.0f)) kept = offset;  // the first End Site of a joint
    return expect_keyword("}", [&] { return "closing " + owner(); });
  }

  // The largest distance from the root of any joint or End Site in the rest pose, in file units.
  float rest_extent() const {
    std::vector<glm::vec3> position(layouts_.size());
    float extent = 0.0f;
    for (size_t j = 0; j < layouts_.size(); ++j) {
      const int parent = parents_[j];
      position[j] = parent < 0 ? glm::vec3(0.0f) : position[parent] + layouts_[j].offset;
      extent =
          std::max({extent, glm::length(position[j]), glm::length(position[j] + end_sites_[j])});
    }
    return extent;
  }

  void apply_scale(float scale) {
    scale_ = scale;
    for (JointLayout& layout : layouts_) layout.offset *= scale;
    for (glm::vec3& end : end_sites_) end *= scale;
  }

  MaybeError parse_hierarchy() {
    if (auto error =
            expect_keyword("HIERARCHY", [] { return std::string("at the start of a BVH file"); })) {
      return error;
    }
    std::string_view token = next_token();
    if (token != "ROOT") {
      return fail(token_line_, "expected 'ROOT' after 'HIERARCHY', found " + describe(token));
    }
    for (;;) {
      if (auto error = open_joint(-1, "ROOT")) return error;
      while (!open_.empty()) {
        token = next_token();
        if (token == "JOINT") {
          if (auto error = open_joint(open_.back().joint, "JOINT")) return error;
        } else if (token == "End") {
          if (auto error = parse_end_site()) return error;
        } else if (token == "}") {
          open_.pop_back();
        } else {
          const OpenJoint& open = open_.back();
          const int joint = open.joint;
          std::string what = "expected 'JOINT', 'End Site' or '}' in joint " +
                             describe(names_[joint]) + " (opened on line " +
                             std::to_string(open.line) + "), found " + describe(token);
          if (channel_index(token) >= 0) {
            what += "; the joint has more channel names than 'CHANNELS " +
                    std::to_string(channel_counts_[joint]) + "' on line " +
                    std::to_string(channel_count_line_[joint]) + " declares";
          }
          return fail(token_line_, what);
        }
      }
      token = next_token();
      if (token == "MOTION") break;
      if (token != "ROOT") {
        return fail(token_line_,
                    "expected 'MOTION' (or another 'ROOT') after the hierarchy, "
                    "found " +
                        describe(token) + (token == "}" ? " (unbalanced braces)" : ""));
      }
    }
    motion_line_ = token_line_;
    return nullptr;
  }

  MaybeError parse_motion_header() {
    if (channel_total_ == 0) {
      return fail(motion_line_, "expected at least one channel in the hierarchy, found none");
    }
    if (auto error = expect_keyword("Frames:", [] { return std::string("after 'MOTION'"); })) {
      return error;
    }
    frames_line_ = token_line_;
    const std::string_view count_token = next_token();
    int64_t count = 0;
    auto [ptr, ec] =
        std::from_chars(count_token.data(), count_token.data() + count_token.size(), count);
    const bool whole = !count_token.empty() && ptr == count_token.data() + count_token.size();
    if (!whole || ec == std::errc::invalid_argument) {
      return fail(token_line_, "expected a whole number of frames after 'Frames:', found " +
                                   describe(count_token));
    }
    if (ec == std::errc::result_out_of_range || count > std::numeric_limits<int>::max()) {
      return fail(token_line_, "expected at most " +
                                   std::to_string(std::numeric_limits<int>::max()) +
                                   " frames after 'Frames:', found " + describe(count_token));
    }
    if (count <= 0) {
      return fail(token_line_, "expected a positive frame count after 'Frames:', found " +
                                   describe(count_token));
    }
    declared_frames_ = static_cast<int>(count);

    if (auto error = expect_keyword("Frame", [] { return std::string("after the frame count"); })) {
      return error;
    }
    if (auto error = expect_keyword("Time:", [] { return std::string("after 'Frame'"); })) {
      return error;
    }
    const std::string_view time_token = next_token();
    const NumberStatus status = parse_number_token(time_token, frame_time_);
    if (status != NumberStatus::kOk || !(frame_time_ > 0.0f)) {
      return fail(token_line_,
                  "expected a positive frame time in seconds after 'Frame Time:', "
                  "found " +
                      describe(time_token));
    }
    // Frames start on the next line: anything else on this one is a format error.
    while (p_ < end_ && is_line_space(*p_)) ++p_;
    if (p_ < end_ && *p_ != '\n') {
      return fail(line_, "expected the end of the line after the frame time, found " +
                             describe(next_token()));
    }
    return nullptr;
  }

  // The hot loop: one frame per line, values straight into the frame-major transform array.
  MaybeError parse_frames() {
    const int joint_count = static_cast<int>(names_.size());
    const int value_count = channel_total_;
    // Every value needs at least a digit and a separator, so the remaining bytes bound how
    // many frames can follow; a declared count far beyond that allocates nothing up front.
    const size_t remaining = static_cast<size_t>(end_ - p_);
    const size_t max_frames_in_text = remaining / (2 * static_cast<size_t>(value_count)) + 1;
    const size_t reserve_frames =
        std::min(static_cast<size_t>(declared_frames_), max_frames_in_text);
    const size_t reserve_transforms = reserve_frames * static_cast<size_t>(joint_count);
    if (reserve_transforms > kMaxTransformsPerByte * text_size_ + kTransformAllowance) {
      return fail(motion_line_, "expected at most " + std::to_string(kMaxTransformsPerByte) +
                                    " joint transforms per byte of the file, found " +
                                    std::to_string(joint_count) + " joints but only " +
                                    std::to_string(value_count) + " channels per frame for up to " +
                                    std::to_string(reserve_frames) +
                                    " frames (too many joints without channels)");
    }
    local_.resize(reserve_transforms);
    std::vector<float> values(static_cast<size_t>(value_count));

    const char* p = p_;
    const char* const end = end_;
    // Every line that starts before the text's last '\n' ends in one: that '\n' is the sentinel
    // that bounds every loop of parse_frame_line. A last line without one is parsed from a copy.
    const char* lines_end = end;
    while (lines_end > p && lines_end[-1] != '\n') --lines_end;
    int64_t line = line_;
    int frames = 0;
    for (;;) {
      // Skip blank lines (and the rest of the previous line's end).
      while (p < end && is_space(*p)) {
        line += *p == '\n';
        ++p;
      }
      if (p == end) break;
      if (frames == declared_frames_) {
        // More frame lines than declared: the declared ones are the clip (as Blender and assimp
        // read such files), the rest is only counted, and said once.
        warn_extra_frame_lines(count_non_blank_lines(p, end), line);
        p = end;
        break;
      }
      if (p < lines_end) {
        if (auto error = parse_frame_line(p, line, frames, values.data(), false)) return error;
      } else {
        std::string last_line(p, end);
        last_line += '\n';
        const char* copy = last_line.data();
        if (auto error = parse_frame_line(copy, line, frames, values.data(), true)) return error;
        p = end;
      }
      if (auto error = store_frame(values.data(), frames, line)) return error;
      ++frames;
    }
    if (frames != declared_frames_) {
      return fail(line, "expected " + std::to_string(declared_frames_) +
                            " frames as declared by 'Frames:' on line " +
                            std::to_string(frames_line_) + ", found " + std::to_string(frames) +
                            " before the end of the file");
    }
    // Equal already, unless the size estimate was exceeded and the array grew past it.
    local_.resize(static_cast<size_t>(frames) * static_cast<size_t>(joint_count));
    p_ = p;
    line_ = line;
    return nullptr;
  }

  // The lines from p to `end` that hold anything but whitespace. One pass, nothing parsed.
  static int64_t count_non_blank_lines(const char* p, const char* end) {
    int64_t count = 0;
    bool blank = true;
    for (; p < end; ++p) {
      if (*p == '\n') {
        count += !blank;
        blank = true;
      } else if (!is_line_space(*p)) {
        blank = false;
      }
    }
    return count + !blank;
  }

  void warn_extra_frame_lines(int64_t count, int64_t first_line) {
    warnings_.push_back(std::string(path_) + ":" + std::to_string(first_line) + ": ignored " +
                        std::to_string(count) + (count == 1 ? " frame line" : " frame lines") +
                        " beyond 'Frames: " + std::to_string(declared_frames_) + "' on line " +
                        std::to_string(frames_line_));
  }

  // Reads exactly channel_total_ numbers from the line starting at p, which ends in '\n', and
  // leaves p on that '\n'.
  MaybeError parse_frame_line(const char*& p, int64_t line, int frame, float* values,
                              bool last_line) const {
    const int value_count = channel_total_;
    for (int i = 0; i < value_count; ++i) {
      while (is_line_space(*p)) ++p;
      if (*p == '\n') {
        return fail(line, "expected " + std::to_string(value_count) +
                              " values on the line of frame " + std::to_string(frame + 1) +
                              " (one per channel), found " + std::to_string(i) +
                              (last_line ? " (the file ends here)" : ""));
      }
      const char* after = parse_plain_decimal(p, values[i]);
      if (after == nullptr) {
        after = p;
        while (!is_space(*after)) ++after;
        const NumberStatus status = parse_number_slow(p, after, values[i]);
        if (status != NumberStatus::kOk) {
          return fail(line, "expected " + std::string(describe_status(status)) + " for value " +
                                std::to_string(i + 1) + " of " + std::to_string(value_count) +
                                " in frame " + std::to_string(frame + 1) + ", found " +
                                describe(std::string_view(p, static_cast<size_t>(after - p))));
        }
      }
      p = after;
    }
    while (is_line_space(*p)) ++p;
    if (*p != '\n') {
      return fail(line, "expected " + std::to_string(value_count) +
                            " values on the line of frame " + std::to_string(frame + 1) +
                            " (one per channel), found more");
    }
    return nullptr;
  }

  // Turns one frame's channel values into local transforms.
  MaybeError store_frame(const float* values, int frame, int64_t line) {
    const size_t joint_count = layouts_.size();
    const size_t first = static_cast<size_t>(frame) * joint_count;
    // The array was sized for every frame the text can hold; this never triggers, but keeps
    // the write in bounds should that estimate ever be wrong.
    if (first + joint_count > local_.size()) local_.resize(first + joint_count);
    Transform* out = local_.data() + first;
    const float scale = scale_;
    for (size_t j = 0; j < joint_count; ++j) {
      const JointLayout& layout = layouts_[j];
      const float* v = values + layout.first_value;
      Transform& t = out[j];
      t.translation = layout.offset;
      for (int axis = 0; axis < 3; ++axis) {
        if (layout.position_slot[axis] >= 0) {
          t.translation[axis] = v[layout.position_slot[axis]] * scale;
        }
      }
      glm::quat rotation(1.0f, 0.0f, 0.0f, 0.0f);
      for (int k = 0; k < layout.rotation_count; ++k) {
        const float half_angle = v[layout.rotation_slot[k]] * kHalfDegreesToRadians;
        const float s = std::sin(half_angle);
        const float c = std::cos(half_angle);
        // Right-multiplying by the axis quaternion applies the listed order: R = R1 * R2 * R3.
        const float w = rotation.w, x = rotation.x, y = rotation.y, z = rotation.z;
        switch (layout.rotation_axis[k]) {
          case 0:
            rotation = glm::quat(w * c - x * s, x * c + w * s, y * c + z * s, z * c - y * s);
            break;
          case 1:
            rotation = glm::quat(w * c - y * s, x * c - z * s, y * c + w * s, z * c + x * s);
            break;
          default:
            rotation = glm::quat(w * c - z * s, x * c + y * s, y * c - x * s, z * c + w * s);
            break;
        }
      }
      t.rotation = rotation;
    }
    // A scale above 1 could push a large finite value past float range; check only then.
    if (scale > 1.0f) {
      for (size_t j = 0; j < joint_count; ++j) {
        const glm::vec3& tr = out[j].translation;
        if (!std::isfinite(tr.x) || !std::isfinite(tr.y) || !std::isfinite(tr.z)) {
          return fail(line,
                      "expected position values that stay finite in metres, found an "
                      "overflow for joint " +
                          describe(names_[j]));
        }
      }
    }
    return nullptr;
  }

  Result<Clip> build_clip() {
    std::vector<Transform> rest(layouts_.size());
    for (size_t j = 0; j < layouts_.size(); ++j) rest[j].translation = layouts_[j].offset;
    Result<Skeleton> skeleton =
        Skeleton::create(std::move(names_), std::move(parents_), std::move(rest));
    if (!skeleton) return Error{std::string(path_) + ": " + skeleton.message()};
    Clip clip;
    clip.name = std::filesystem::path(path_).stem().string();
    clip.source_path = std::string(path_);
    clip.skeleton = std::move(skeleton).value();
    clip.frame_time = frame_time_;
    clip.frame_count = declared_frames_;
    clip.local = std::move(local_);
    clip.end_sites = std::move(end_sites_);
    clip.warnings = std::move(warnings_);
    return clip;
  }

  const char* p_;
  const char* end_;
  size_t text_size_;
  std::string_view path_;
  float scale_;
  int64_t line_ = 1;  // 64-bit: a multi-gigabyte file of newlines must not overflow a counter
  int64_t token_line_ = 1;
  int64_t motion_line_ = 0;
  int64_t frames_line_ = 0;
  int declared_frames_ = 0;
  float frame_time_ = 0.0f;
  int channel_total_ = 0;

  std::vector<std::string> names_;
  std::vector<int> parents_;
  std::vector<JointLayout> layouts_;
  std::vector<glm::vec3> end_sites_;  // per joint, zero when it has none
  std::vector<int> channel_counts_;
  std::vector<int64_t> channel_count_line_;
  std::vector<OpenJoint> open_;
  std::unordered_map<std::string_view, int64_t> joint_lines_;
  std::vector<Transform> local_;
  std::vector<std::string> warnings_;  // becomes Clip::warnings
};

}  // namespace

float bvh_units_to_metres(float extent) {
  if (extent < 5.0f) return 1.0f;      // metres: a person is 1-2 m tall
  if (extent < 50.0f) return 0.0254f;  // inches: 40-80
  if (extent < 500.0f) return 0.01f;   // centimetres: 100-200
  return 0.001f;                       // millimetres
}

Result<Clip> parse_bvh(std::string_view text, std::string_view path_for_messages,
                       const BvhOptions& options) {
  // Nothing may escape to the caller: an allocation failure becomes an error like any other.
  try {
    BvhParser parser(text, path_for_messages, options);
    return parser.run();
  } catch (const std::exception& exception) {
    return Error{std::string(path_for_messages) + ": cannot import (" + exception.what() + ")"};
  }
}

namespace {

Result<Clip> read_and_parse(const std::filesystem::path& path, const std::string& name,
                            const BvhOptions& options) {
  auto contents = read_whole_file(path);
  if (!contents) return contents.error();
  return parse_bvh(contents->text(), name, options);
}

}  // namespace

Result<Clip> load_bvh(const std::filesystem::path& path, const BvhOptions& options) {
  const std::string name = path.string();
  try {
    return read_and_parse(path, name, options);
  } catch (const std::exception& exception) {
    return Error{name + ": cannot import (" + exception.what() + ")"};
  }
}

// ---------------------------------------------------------------------------------------------
// Export.

namespace {

// The channels every exported joint gets; store_frame composes "Zrotation Xrotation Yrotation"
// as R = Rz * Rx * Ry, the order glm::extractEulerAngleZXY decomposes.
constexpr const char* kExportChannels =
    "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation";

// The shortest fixed-notation decimal that reads back as the same float: exact round trips
// without the 9 digits "%.9g" always prints, and no exponent, which some BVH readers refuse.
void append_number(std::string& out, float value) {
  // "-0" (from atan2 of a negative zero, or a negated zero offset) reads back the same but
  // looks like a sign error to whoever reads the file.
  if (value == 0.0f) value = 0.0f;
  char digits[64];  // the longest float in fixed notation (a subnormal) needs 48 bytes
  const auto [end, ec] =
      std::to_chars(digits, digits + sizeof digits, value, std::chars_format::fixed);
  out.append(digits, ec == std::errc() ? end : digits);
}

void append_vector(std::string& out, const glm::vec3& v, float units_per_metre) {
  for (int axis = 0; axis < 3; ++axis) {
    out += ' ';
    append_number(out, v[axis] * units_per_metre);
  }
}

// Degrees (Z, X, Y) with Rz(z) * Rx(x) * Ry(y) = the rotation. glm::extractEulerAngleZXY is
// the decomposition for exactly this order (glm::eulerAngles is for another) and stays exact at
// gimbal lock (X at +-90 degrees, where only Z + Y or Z - Y is defined): it takes Y from the
// matrix with Z's rotation undone rather than from entries that vanish there, and atan2 of two
// zeros is still finite. Double only keeps its rounding well below that of the float angles
// written; float measures about the same in the round-trip tests.
glm::dvec3 zxy_degrees(const glm::quat& rotation) {
  const glm::dmat4 m = glm::mat4_cast(glm::normalize(glm::dquat(rotation)));
  double z = 0.0, x = 0.0, y = 0.0;
  glm::extractEulerAngleZXY(m, z, x, y);
  return glm::degrees(glm::dvec3(z, x, y));
}

void append_indent(std::string& out, size_t depth) {
  out.append(depth, '\t');
}

void append_end_site(std::string& out, size_t depth, const glm::vec3& offset,
                     float units_per_metre) {
  append_indent(out, depth);
  out += "End Site\n";
  append_indent(out, depth);
  out += "{\n";
  append_indent(out, depth + 1);
  out += "OFFSET";
  append_vector(out, offset, units_per_metre);
  out += '\n';
  append_indent(out, depth);
  out += "}\n";
}

// Writes the HIERARCHY section and returns the joints in the order it lists them (which the
// frame lines follow). Iterative, as the importer is: a deep chain needs no deep call stack.
std::vector<int> append_hierarchy(std::string& out, const Clip& clip, float units_per_metre) {
  const Skeleton& skeleton = clip.skeleton;
  const int joint_count = skeleton.joint_count();
  std::vector<std::vector<int>> children(static_cast<size_t>(joint_count));
  for (int j = 0; j < joint_count; ++j) {
    if (skeleton.parent(j) >= 0) children[static_cast<size_t>(skeleton.parent(j))].push_back(j);
  }
  const auto end_site = [&](int joint) {
    return clip.end_sites.empty() ? glm::vec3(0.0f) : clip.end_sites[static_cast<size_t>(joint)];
  };
  std::vector<int> order;
  order.reserve(static_cast<size_t>(joint_count));
  struct Open {
    int joint;
    size_t next_child;
  };
  std::vector<Open> open;
  // Writes a joint's head and opens it at the depth the stack gives.
  const auto open_joint = [&](int joint) {
    const size_t depth = open.size();
    append_indent(out, depth);
    out += depth == 0 ? "ROOT " : "JOINT ";
    out += skeleton.name(joint);
    out += '\n';
    append_indent(out, depth);
    out += "{\n";
    append_indent(out, depth + 1);
    out += "OFFSET";
    append_vector(out, skeleton.rest(joint).translation, units_per_metre);
    out += '\n';
    append_indent(out, depth + 1);
    out += kExportChannels;
    out += '\n';
    order.push_back(joint);
    open.push_back({joint, 0});
  };

  out += "HIERARCHY\n";
  for (int root = 0; root < joint_count; ++root) {
    if (skeleton.parent(root) >= 0) continue;
    open_joint(root);
    while (!open.empty()) {
      const int joint = open.back().joint;
      const std::vector<int>& kids = children[static_cast<size_t>(joint)];
      if (open.back().next_child < kids.size()) {
        open_joint(kids[open.back().next_child++]);
        continue;
      }
      // The importer keeps an End Site wherever it is; a leaf always gets one, as BVH readers
      // take the bone's direction and length from it.
      const size_t depth = open.size();
      if (kids.empty() || end_site(joint) != glm::vec3(0.0f)) {
        append_end_site(out, depth, end_site(joint), units_per_metre);
      }
      append_indent(out, depth - 1);
      out += "}\n";
      open.pop_back();
    }
  }
  return order;
}

// Everything format_bvh needs beyond Clip::validate(), so that what it writes reads back.
Status check_exportable(const Clip& clip, float units_per_metre) {
  if (!std::isfinite(units_per_metre) || !(units_per_metre > 0.0f)) {
    return Error{"expected units_per_metre to be finite and > 0, found " +
                 std::to_string(units_per_metre)};
  }
  if (Status valid = clip.validate(); !valid) return valid;
  const Skeleton& skeleton = clip.skeleton;
  for (const std::string& name : skeleton.names()) {
    // Names are whitespace-separated tokens in BVH, and a lone brace reads as structure.
    const bool has_space = std::any_of(name.begin(), name.end(), is_space);
    if (has_space || name == "{" || name == "}") {
      return Error{"joint '" + name +
                   "' cannot be written as BVH (names must be one token without whitespace and "
                   "not a brace)"};
    }
  }
  // Validated values are finite in metres but may overflow a float in file units.
  const auto fits = [units_per_metre](const glm::vec3& v) {
    const glm::vec3 scaled = v * units_per_metre;
    return std::isfinite(scaled.x) && std::isfinite(scaled.y) && std::isfinite(scaled.z);
  };
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    if (!fits(skeleton.rest(j).translation) ||
        (!clip.end_sites.empty() && !fits(clip.end_sites[static_cast<size_t>(j)]))) {
      return Error{"joint '" + skeleton.name(j) +
                   "': its rest offset or End Site is not finite in file units"};
    }
  }
  for (size_t i = 0; i < clip.local.size(); ++i) {
    if (!fits(clip.local[i].translation)) {
      return Error{"frame " + std::to_string(i / static_cast<size_t>(clip.joint_count())) +
                   ", joint '" +
                   skeleton.name(static_cast<int>(i % static_cast<size_t>(clip.joint_count()))) +
                   "': the translation is not finite in file units"};
    }
  }
  return Status::success();
}

}  // namespace

std::string format_bvh(const Clip& clip, float units_per_metre) {
  std::string out;
  const std::vector<int> order = append_hierarchy(out, clip, units_per_metre);
  out += "MOTION\nFrames: " + std::to_string(clip.frame_count) + "\nFrame Time: ";
  append_number(out, clip.frame_time);
  out += '\n';
  for (int frame = 0; frame < clip.frame_count; ++frame) {
    const std::span<const Transform> pose = clip.pose(frame);
    bool first = true;
    for (const int joint : order) {
      const Transform& t = pose[static_cast<size_t>(joint)];
      const glm::dvec3 zxy = zxy_degrees(t.rotation);
      const float values[6] = {t.translation.x * units_per_metre, t.translation.y * units_per_metre,
                               t.translation.z * units_per_metre, static_cast<float>(zxy[0]),
                               static_cast<float>(zxy[1]),        static_cast<float>(zxy[2])};
      for (const float value : values) {
        if (!first) out += ' ';
        first = false;
        append_number(out, value);
      }
    }
    out += '\n';
  }
  return out;
}

Status save_bvh(const Clip& clip, const std::filesystem::path& out, float units_per_metre) {
  if (Status s = check_exportable(clip, units_per_metre); !s) {
    return Error{out.string() + ": " + s.message()};
  }
  try {
    return write_whole_file(out, format_bvh(clip, units_per_metre), "BVH file");
  } catch (const std::exception& exception) {
    return Error{out.string() + ": cannot export (" + exception.what() + ")"};
  }
}

}  // namespace mm
