#include "mm/database/database.hpp"

#include "validation.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <new>
#include <string_view>
#include <thread>
#include <utility>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include <glm/gtc/type_ptr.hpp>

#include "mm/database/files.hpp"
#include "mm/runtime/assert.hpp"

namespace mm {

namespace {

// The per-frame arrays' block: cache-line aligned, and so is every array in it.
constexpr size_t kBlockAlignment = 64;

constexpr size_t kNotFound = static_cast<size_t>(-1);
// Arrays are checked in blocks: a branch-free pass over a block vectorizes, and only a block
// that holds a bad value is scanned again to find which one.
constexpr size_t kBlock = 2048;
// Below this many values a second thread costs more than it saves.
constexpr size_t kParallelThreshold = size_t{1} << 20;

// Squared quaternion norms within this band count as unit (|length - 1| <= 1e-3, the
// importers' tolerance).
constexpr float kMinUnitNormSquared = (1.0f - 1e-3f) * (1.0f - 1e-3f);
constexpr float kMaxUnitNormSquared = (1.0f + 1e-3f) * (1.0f + 1e-3f);

size_t first_non_finite_serial(const float* values, size_t begin, size_t end) {
  for (size_t block = begin; block < end; block += kBlock) {
    const size_t block_end = std::min(end, block + kBlock);
    uint32_t bad = 0;
    for (size_t i = block; i < block_end; ++i)
      bad |= static_cast<uint32_t>(!detail::finite_bits(values[i]));
    if (bad != 0) {
      for (size_t i = block; i < block_end; ++i) {
        if (!std::isfinite(values[i])) return i;
      }
    }
  }
  return kNotFound;
}

bool is_unit(const float* q) {
  const float n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
  // Written so that NaN (and an infinite component, whose square is infinite) fails.
  return n >= kMinUnitNormSquared && n <= kMaxUnitNormSquared;
}

#if defined(__SSE2__)
// is_unit of quaternions i .. i + 3 as a 4-bit mask of the failures: the same float operations
// in the same order, four at a time.
int non_unit_x4(const float* quats) {
  __m128 x = _mm_loadu_ps(quats), y = _mm_loadu_ps(quats + 4);
  __m128 z = _mm_loadu_ps(quats + 8), w = _mm_loadu_ps(quats + 12);
  _MM_TRANSPOSE4_PS(x, y, z, w);
  const __m128 n =
      _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z)),
                 _mm_mul_ps(w, w));
  // Ordered comparisons: NaN fails both.
  const __m128 unit = _mm_and_ps(_mm_cmpge_ps(n, _mm_set1_ps(kMinUnitNormSquared)),
                                 _mm_cmple_ps(n, _mm_set1_ps(kMaxUnitNormSquared)));
  return _mm_movemask_ps(unit) ^ 0xF;
}
#endif

size_t first_non_unit_serial(const float* quats, size_t begin, size_t end) {
  for (size_t block = begin; block < end; block += kBlock) {
    const size_t block_end = std::min(end, block + kBlock);
    uint32_t bad = 0;
    size_t next = block;
#if defined(__SSE2__)
    for (; next + 4 <= block_end; next += 4) {
      bad |= static_cast<uint32_t>(non_unit_x4(quats + 4 * next));
    }
#endif
    for (; next < block_end; ++next) bad |= static_cast<uint32_t>(!is_unit(quats + 4 * next));
    if (bad != 0) {
      for (size_t i = block; i < block_end; ++i) {
        if (!is_unit(quats + 4 * i)) return i;
      }
    }
  }
  return kNotFound;
}

// Runs scan(begin, end) over [0, count) on two threads when count is large, and returns the
// smallest index found (kNotFound when none), so the message names the first bad value exactly
// as a serial scan would.
template <class Scan>
size_t first_bad(size_t count, const Scan& scan) {
  if (count < kParallelThreshold) return scan(size_t{0}, count);
  const size_t half = count / 2;
  size_t second = kNotFound;
  bool threaded = true;
  std::thread worker;
  try {
    worker = std::thread([&] { second = scan(half, count); });
  } catch (...) {
    threaded = false;  // no thread available: fall back to scanning both halves here
  }
  const size_t first = scan(size_t{0}, half);
  if (threaded) {
    worker.join();
  } else {
    second = scan(half, count);
  }
  return first != kNotFound ? first : second;
}

size_t first_non_finite(std::span<const float> values) {
  return first_bad(values.size(), [&](size_t b, size_t e) {
    return first_non_finite_serial(values.data(), b, e);
  });
}

size_t first_non_unit(std::span<const glm::quat> quats) {
  const float* data = quats.empty() ? nullptr : glm::value_ptr(quats[0]);
  return first_bad(quats.size(),
                   [&](size_t b, size_t e) { return first_non_unit_serial(data, b, e); });
}

// First byte that is neither 0 nor 1.
size_t first_non_boolean(std::span<const uint8_t> values) {
  for (size_t block = 0; block < values.size(); block += kBlock) {
    const size_t block_end = std::min(values.size(), block + kBlock);
    uint8_t bad = 0;
    for (size_t i = block; i < block_end; ++i) bad |= static_cast<uint8_t>(values[i] > 1);
    if (bad != 0) {
      for (size_t i = block; i < block_end; ++i) {
        if (values[i] > 1) return i;
      }
    }
  }
  return kNotFound;
}

std::span<const float> floats_of(std::span<const glm::vec3> v) {
  return {v.empty() ? nullptr : glm::value_ptr(v[0]), v.size() * 3};
}

// The joint a role name refers to in this database, or -2 when the name is not a role.
int role_joint(const JointRoleIndices& roles, std::string_view name) {
  const JointRoleInfo* role = find_joint_role(name);
  return role ? roles.*role->index : -2;
}

bool is_bone_kind(FeatureKind kind) {
  return kind == FeatureKind::BonePosition || kind == FeatureKind::BoneVelocity ||
         kind == FeatureKind::BoneDirection;
}

std::string frame_joint(const DatabaseView& db, size_t index) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  const int joint = static_cast<int>(index % joints);
  return "[frame " + std::to_string(index / joints) + ", joint " + std::to_string(joint) + " '" +
         db.skeleton.name(joint) + "']";
}

Status check_size(std::string_view what, size_t actual, size_t expected, std::string_view how) {
  if (actual == expected) return Status::success();
  return Error{"database: " + std::string(what) + " has " + std::to_string(actual) +
               " values, expected " + std::to_string(expected) + " (" + std::string(how) + ")"};
}

}  // namespace

namespace {

uint64_t mask_of(std::span<const std::string> tag_names, std::span<const std::string> names) {
  uint64_t mask = 0;
  const size_t usable = std::min<size_t>(tag_names.size(), 64);
  for (const std::string& name : names) {
    for (size_t i = 0; i < usable; ++i) {
      if (tag_names[i] == name) mask |= uint64_t{1} << i;
    }
  }
  return mask;
}

// Rounds a byte offset up to a cache line, where every per-frame array of the block starts.
size_t aligned(size_t bytes) {
  return (bytes + kBlockAlignment - 1) / kBlockAlignment * kBlockAlignment;
}

}  // namespace

DatabaseView::DatabaseView(const Database& db)
    : skeleton(db.skeleton()),
      roles(db.roles()),
      frame_time(db.frame_time()),
      frame_count(db.frame_count()),
      local_positions(db.local_positions()),
      local_rotations(db.local_rotations()),
      local_velocities(db.local_velocities()),
      local_angular_velocities(db.local_angular_velocities()),
      contacts(db.contacts()),
      clips(db.clips()),
      tag_names(db.tag_names()),
      style_names(db.style_names()),
      schema(db.schema()),
      features(db.features()),
      feature_offset(db.feature_offset()),
      feature_scale(db.feature_scale()),
      searchable(db.searchable()),
      frame_clip(db.frame_clip()) {}

DatabaseView::DatabaseView(const DatabaseContents& db)
    : skeleton(db.skeleton),
      roles(db.roles),
      frame_time(db.frame_time),
      frame_count(db.frame_count),
      local_positions(db.local_positions),
      local_rotations(db.local_rotations),
      local_velocities(db.local_velocities),
      local_angular_velocities(db.local_angular_velocities),
      contacts(db.contacts),
      clips(db.clips),
      tag_names(db.tag_names),
      style_names(db.style_names),
      schema(db.schema),
      features(db.features),
      feature_offset(db.feature_offset),
      feature_scale(db.feature_scale),
      searchable(db.searchable) {}

DatabaseFill::DatabaseFill(DatabaseContents& db)
    : skeleton(db.skeleton),
      schema(db.schema),
      frame_time(db.frame_time),
      frame_count(db.frame_count),
      local_positions(db.local_positions),
      local_rotations(db.local_rotations),
      local_velocities(db.local_velocities),
      local_angular_velocities(db.local_angular_velocities),
      contacts(db.contacts),
      features(db.features),
      searchable(db.searchable) {}

DatabaseFill::DatabaseFill(const DatabaseView& read, std::span<glm::vec3> positions,
                           std::span<glm::quat> rotations, std::span<glm::vec3> velocities,
                           std::span<glm::vec3> angular_velocities,
                           std::span<uint8_t> foot_contacts, std::span<float> feature_rows,
                           std::span<uint8_t> searchable_frames)
    : skeleton(read.skeleton),
      schema(read.schema),
      frame_time(read.frame_time),
      frame_count(read.frame_count),
      local_positions(positions),
      local_rotations(rotations),
      local_velocities(velocities),
      local_angular_velocities(angular_velocities),
      contacts(foot_contacts),
      features(feature_rows),
      searchable(searchable_frames) {}

uint64_t DatabaseView::tag_mask(std::span<const std::string> names) const {
  return mask_of(tag_names, names);
}

uint64_t Database::tag_mask(std::span<const std::string> names) const {
  return mask_of(tag_names_, names);
}

void Database::FreeBlock::operator()(std::byte* block) const {
  ::operator delete (block, std::align_val_t{kBlockAlignment});
}

Database::Database(Database&& other) noexcept {
  *this = std::move(other);
}

Database& Database::operator=(Database&& other) noexcept {
  if (this == &other) return *this;
  skeleton_ = std::move(other.skeleton_);
  roles_ = other.roles_;
  frame_time_ = other.frame_time_;
  frame_count_ = std::exchange(other.frame_count_, 0);
  clips_ = std::move(other.clips_);
  tag_names_ = std::move(other.tag_names_);
  style_names_ = std::move(other.style_names_);
  schema_ = std::move(other.schema_);
  // The block moves with its owner, so the views into it stay valid; the source keeps none.
  block_ = std::move(other.block_);
  pose_lanes_ = std::exchange(other.pose_lanes_, {});
  contacts_ = std::exchange(other.contacts_, {});
  features_ = std::exchange(other.features_, {});
  feature_offset_ = std::exchange(other.feature_offset_, {});
  feature_scale_ = std::exchange(other.feature_scale_, {});
  searchable_ = std::exchange(other.searchable_, {});
  frame_clip_ = std::exchange(other.frame_clip_, {});
  return *this;
}

void Database::allocate(size_t frames, size_t joints, size_t dims) {
  const size_t pose_floats = frames * pose_lane_floats(joints);
  // Each array starts on a cache line.
  size_t bytes = 0;
  const auto place = [&](size_t count, size_t size) {
    const size_t at = bytes;
    bytes = aligned(bytes + count * size);
    return at;
  };
  const size_t pose = place(pose_floats, sizeof(float));
  const size_t features = place(frames * dims, sizeof(float));
  const size_t offset = place(dims, sizeof(float));
  const size_t scale = place(dims, sizeof(float));
  const size_t clip = place(frames, sizeof(int));
  const size_t contacts = place(frames * 2, 1);
  const size_t searchable = place(frames, 1);
  block_.reset(static_cast<std::byte*>(
      ::operator new (std::max<size_t>(bytes, 1), std::align_val_t{kBlockAlignment})));
  advise_huge_pages(block_.get(), bytes);
  std::byte* const base = block_.get();
  const auto array = [&]<class T>(size_t at, size_t count, T*) {
    return std::span<T>(reinterpret_cast<T*>(base + at), count);
  };
  pose_lanes_ = array(pose, pose_floats, static_cast<float*>(nullptr));
  features_ = array(features, frames * dims, static_cast<float*>(nullptr));
  feature_offset_ = array(offset, dims, static_cast<float*>(nullptr));
  feature_scale_ = array(scale, dims, static_cast<float*>(nullptr));
  frame_clip_ = array(clip, frames, static_cast<int*>(nullptr));
  contacts_ = array(contacts, frames * 2, static_cast<uint8_t*>(nullptr));
  searchable_ = array(searchable, frames, static_cast<uint8_t*>(nullptr));
}

void Database::keep_frames(size_t frames) {
  MM_ASSERT(frames <= frame_clip_.size());
  const size_t joints = static_cast<size_t>(joint_count());
  const size_t dims = static_cast<size_t>(feature_dims());
  frame_count_ = static_cast<int>(frames);
  pose_lanes_ = pose_lanes_.first(frames * pose_lane_floats(joints));
  features_ = features_.first(frames * dims);
  frame_clip_ = frame_clip_.first(frames);
  contacts_ = contacts_.first(frames * 2);
  searchable_ = searchable_.first(frames);
}

void Database::lay_out_pose(const PoseFrameView& pose) {
  const size_t joints = static_cast<size_t>(joint_count());
  const size_t floats = pose_lane_floats(joints);
  for (size_t f = 0; f < static_cast<size_t>(frame_count_); ++f) {
    const size_t k = f * joints;
    pose_to_lanes(
        PoseFrameView{pose.rotations.subspan(k, joints), pose.positions.subspan(k, joints),
                      pose.velocities.subspan(k, joints),
                      pose.angular_velocities.subspan(k, joints)},
        pose_lanes_.subspan(f * floats, floats));
  }
}

void Database::derive_frame_clip() {
  for (size_t c = 0; c < clips_.size(); ++c) {
    std::fill(frame_clip_.begin() + clips_[c].start, frame_clip_.begin() + clips_[c].end,
              static_cast<int>(c));
  }
}

Result<Database> Database::create(const DatabaseContents& contents) {
  if (Status s = validate_database(contents); !s) return Error{s.message()};
  Database db;
  db.skeleton_ = contents.skeleton;
  db.roles_ = contents.roles;
  db.frame_time_ = contents.frame_time;
  db.frame_count_ = contents.frame_count;
  db.clips_ = contents.clips;
  db.tag_names_ = contents.tag_names;
  db.style_names_ = contents.style_names;
  db.schema_ = contents.schema;
  db.allocate(static_cast<size_t>(contents.frame_count),
              static_cast<size_t>(contents.joint_count()),
              static_cast<size_t>(contents.feature_dims()));
  const auto copy = [](const auto& from, auto to) {
    std::copy(from.begin(), from.end(), to.begin());
  };
  db.lay_out_pose(PoseFrameView{contents.local_rotations, contents.local_positions,
                                contents.local_velocities, contents.local_angular_velocities});
  copy(contents.contacts, db.contacts_);
  copy(contents.features, db.features_);
  copy(contents.feature_offset, db.feature_offset_);
  copy(contents.feature_scale, db.feature_scale_);
  copy(contents.searchable, db.searchable_);
  db.derive_frame_clip();
  return db;
}

Result<Database> with_channel_weight(const Database& db, int channel, float weight) {
  const FeatureSchema& schema = db.schema();
  if (channel < 0 || channel >= static_cast<int>(schema.channels.size())) {
    return Error{"feature weight: no channel " + std::to_string(channel) + " (the schema has " +
                 std::to_string(schema.channels.size()) + ")"};
  }
  if (!std::isfinite(weight) || weight <= 0.0f) {
    return Error{"feature weight: the weight of " + schema.channels[channel].name +
                 " must be finite and > 0"};
  }
  DatabaseContents contents = db.contents();
  const float ratio = weight / contents.schema.channels[channel].weight;
  contents.schema.channels[channel].weight = weight;
  const int first = schema.offset(channel);
  const int dims = schema.dims();
  const int count = schema.channels[channel].dims();
  for (int c = first; c < first + count; ++c) {
    contents.feature_scale[c] /= ratio;
    for (int f = 0; f < contents.frame_count; ++f) {
      contents.features[static_cast<size_t>(f) * dims + c] *= ratio;
    }
  }
  return Database::create(contents);
}

DatabaseContents Database::contents() const {
  DatabaseContents out;
  out.skeleton = skeleton_;
  out.roles = roles_;
  out.frame_time = frame_time_;
  out.frame_count = frame_count_;
  const size_t samples = static_cast<size_t>(frame_count_) * static_cast<size_t>(joint_count());
  out.local_positions.resize(samples);
  out.local_rotations.resize(samples);
  out.local_velocities.resize(samples);
  out.local_angular_velocities.resize(samples);
  for (int f = 0; f < frame_count_; ++f) {
    for (int j = 0; j < joint_count(); ++j) {
      const size_t k =
          static_cast<size_t>(f) * static_cast<size_t>(joint_count()) + static_cast<size_t>(j);
      out.local_positions[k] = local_position(f, j);
      out.local_rotations[k] = local_rotation(f, j);
      out.local_velocities[k] = local_velocity(f, j);
      out.local_angular_velocities[k] = local_angular_velocity(f, j);
    }
  }
  out.contacts.assign(contacts_.begin(), contacts_.end());
  out.clips = clips_;
  out.tag_names = tag_names_;
  out.style_names = style_names_;
  out.schema = schema_;
  out.features.assign(features_.begin(), features_.end());
  out.feature_offset.assign(feature_offset_.begin(), feature_offset_.end());
  out.feature_scale.assign(feature_scale_.begin(), feature_scale_.end());
  out.searchable.assign(searchable_.begin(), searchable_.end());
  return out;
}

bool is_idle_clip(const DatabaseView& db, const ClipRange& clip) {
  if (clip.name != kIdleClipName || clip.mirrored) return false;
  for (size_t t = 0; t < db.tag_names.size() && t < 64; ++t) {
    if (db.tag_names[t] == kIdleTag) return ((clip.tags >> t) & 1u) != 0;
  }
  return false;
}

int find_idle_clip(const DatabaseView& db) {
  for (size_t c = db.clips.size(); c-- > 0;) {
    if (is_idle_clip(db, db.clips[c])) return static_cast<int>(c);
  }
  return -1;
}

Status validate_clip_ranges(std::span<const ClipRange> clips, int frame_count, size_t tag_count) {
  const uint64_t known_tags = tag_count >= 64 ? ~uint64_t{0} : (uint64_t{1} << tag_count) - 1;
  if (clips.empty()) return Error{"database: has frames but no clips"};
  int expected_start = 0;
  for (size_t c = 0; c < clips.size(); ++c) {
    const ClipRange& clip = clips[c];
    const std::string where = "database: clip " + std::to_string(c) + " '" + clip.name + "'";
    if (clip.name.empty())
      return Error{"database: clip " + std::to_string(c) + " has an empty name"};
    if (clip.start != expected_start) {
      return Error{where + " starts at frame " + std::to_string(clip.start) + ", expected " +
                   std::to_string(expected_start) +
                   " (clips must be sorted, non-overlapping and cover every frame)"};
    }
    if (clip.end <= clip.start || clip.end > frame_count) {
      return Error{where + " has range [" + std::to_string(clip.start) + ", " +
                   std::to_string(clip.end) + "); expected a non-empty range within [0, " +
                   std::to_string(frame_count) + ")"};
    }
    if ((clip.tags & ~known_tags) != 0) {
      return Error{where + " has tag bit " +
                   std::to_string(std::countr_zero(clip.tags & ~known_tags)) + " set, but only " +
                   std::to_string(tag_count) + " tags exist"};
    }
    expected_start = clip.end;
  }
  if (expected_start != frame_count) {
    return Error{"database: the clips end at frame " + std::to_string(expected_start) +
                 " but there are " + std::to_string(frame_count) + " frames"};
  }
  return Status::success();
}

namespace {

// The skeleton: structure, then rest transforms.
Status check_skeleton(const DatabaseView& db) {
  const int joints = db.joint_count();
  if (joints <= 0) return Error{"database: the skeleton has no joints"};
  if (Status s =
          Skeleton::validate(db.skeleton.names(), db.skeleton.parents(), db.skeleton.rest().size());
      !s) {
    return Error{"database: " + s.message()};
  }
  for (int j = 0; j < joints; ++j) {
    const Transform& t = db.skeleton.rest(j);
    const glm::quat& q = t.rotation;
    const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if (!detail::finite3(t.translation) || !detail::finite3(t.scale) ||
        !(n2 >= kMinUnitNormSquared && n2 <= kMaxUnitNormSquared)) {
      return Error{"database: skeleton rest transform of joint " + std::to_string(j) + " '" +
                   db.skeleton.name(j) + "' is not finite or its rotation is not unit length"};
    }
  }
  return Status::success();
}

// Roles name existing joints or nothing.
Status check_roles(const DatabaseView& db) {
  const int joints = db.joint_count();
  for (const JointRoleInfo& role : kJointRoles) {
    const int joint = db.roles.*role.index;
    if (joint < -1 || joint >= joints) {
      return Error{"database: role " + std::string(role.name) + " is joint " +
                   std::to_string(joint) + ", out of range [-1, " + std::to_string(joints) + ")"};
    }
  }
  return Status::success();
}

// The per-frame, per-joint arrays and the contacts hold one value per frame (and joint).
Status check_frame_arrays(const DatabaseView& db) {
  const int joints = db.joint_count();
  if (db.frame_count <= 0)
    return Error{"database: has no frames (frame_count " + std::to_string(db.frame_count) + ")"};
  const size_t frames = static_cast<size_t>(db.frame_count);
  const size_t samples = frames * static_cast<size_t>(joints);
  const std::string per_joint =
      std::to_string(db.frame_count) + " frames x " + std::to_string(joints) + " joints";
  if (Status s = check_size("local_positions", db.local_positions.size(), samples, per_joint); !s)
    return s;
  if (Status s = check_size("local_rotations", db.local_rotations.size(), samples, per_joint); !s)
    return s;
  if (Status s = check_size("local_velocities", db.local_velocities.size(), samples, per_joint); !s)
    return s;
  if (Status s = check_size("local_angular_velocities", db.local_angular_velocities.size(), samples,
                            per_joint);
      !s) {
    return s;
  }
  if (Status s = check_size("contacts", db.contacts.size(), frames * 2,
                            std::to_string(db.frame_count) + " frames x 2 feet");
      !s) {
    return s;
  }
  return Status::success();
}

// The schema, the bones its channels name, and the feature arrays' sizes.
Status check_schema_and_features(const DatabaseView& db) {
  const size_t frames = static_cast<size_t>(db.frame_count);
  if (Status s = db.schema.validate(); !s) return Error{"database: schema: " + s.message()};
  for (size_t c = 0; c < db.schema.channels.size(); ++c) {
    const FeatureChannel& channel = db.schema.channels[c];
    if (!is_bone_kind(channel.kind)) continue;
    const int role = role_joint(db.roles, channel.bone);
    if (role == -1) {
      return Error{"database: schema channel " + std::to_string(c) + " '" + channel.name +
                   "' uses role '" + channel.bone + "', which this database's skeleton lacks"};
    }
    if (role == -2 && db.skeleton.find(channel.bone) < 0) {
      return Error{"database: schema channel " + std::to_string(c) + " '" + channel.name +
                   "' names bone '" + channel.bone + "', which is neither a role nor a joint"};
    }
  }
  const int dims_int = db.feature_dims();
  if (dims_int <= 0) return Error{"database: the feature schema has no columns"};
  const size_t dims = static_cast<size_t>(dims_int);
  if (Status s = check_size("features", db.features.size(), frames * dims,
                            std::to_string(db.frame_count) + " frames x " + std::to_string(dims) +
                                " feature columns");
      !s) {
    return s;
  }
  if (Status s =
          check_size("feature_offset", db.feature_offset.size(), dims, "one per feature column");
      !s) {
    return s;
  }
  if (Status s =
          check_size("feature_scale", db.feature_scale.size(), dims, "one per feature column");
      !s) {
    return s;
  }
  if (Status s = check_size("searchable", db.searchable.size(), frames, "one per frame"); !s)
    return s;
  return Status::success();
}

// Tag names: at most 64, non-empty, distinct.
Status check_tags(const DatabaseView& db) {
  if (db.tag_names.size() > 64) {
    return Error{"database: " + std::to_string(db.tag_names.size()) +
                 " tag names; at most 64 fit the 64-bit clip tag masks"};
  }
  for (size_t i = 0; i < db.tag_names.size(); ++i) {
    if (db.tag_names[i].empty())
      return Error{"database: tag name " + std::to_string(i) + " is empty"};
    for (size_t k = 0; k < i; ++k) {
      if (db.tag_names[k] == db.tag_names[i]) {
        return Error{"database: duplicate tag name '" + db.tag_names[i] + "' (tags " +
                     std::to_string(k) + " and " + std::to_string(i) + ")"};
      }
    }
  }
  return Status::success();
}

// Style names: at most kMaxStyles, non-empty, distinct; every clip's style one of them or -1.
Status check_styles(const DatabaseView& db) {
  if (db.style_names.size() > kMaxStyles) {
    return Error{"database: " + std::to_string(db.style_names.size()) + " style names; at most " +
                 std::to_string(kMaxStyles) + " are allowed"};
  }
  for (size_t i = 0; i < db.style_names.size(); ++i) {
    if (db.style_names[i].empty())
      return Error{"database: style name " + std::to_string(i) + " is empty"};
    for (size_t k = 0; k < i; ++k) {
      if (db.style_names[k] == db.style_names[i]) {
        return Error{"database: duplicate style name '" + db.style_names[i] + "' (styles " +
                     std::to_string(k) + " and " + std::to_string(i) + ")"};
      }
    }
  }
  const int style_count = static_cast<int>(db.style_names.size());
  for (size_t c = 0; c < db.clips.size(); ++c) {
    const ClipRange& clip = db.clips[c];
    if (clip.style < -1 || clip.style >= style_count) {
      return Error{"database: clip " + std::to_string(c) + " '" + clip.name + "' has style " +
                   std::to_string(clip.style) + ", but only " + std::to_string(style_count) +
                   " styles exist (-1: none)"};
    }
  }
  return Status::success();
}

// Clips tile [0, frame_count) in order (frame_clip is derived from them).
Status check_clips(const DatabaseView& db) {
  return validate_clip_ranges(db.clips, db.frame_count, db.tag_names.size());
}

// Values: the large arrays last, with the vectorized scans.
// The per-frame joint arrays: finite unit rotations, finite positions and velocities.
// One pass in index order over values a plain array does not hold (a Database's lanes).
template <class T, class Bad>
size_t first_bad_value(const JointValues<T>& values, const Bad& bad) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (bad(values[i])) return i;
  }
  return kNotFound;
}

size_t first_non_unit(const JointValues<glm::quat>& quats) {
  if (quats.plain().size() == quats.size()) return first_non_unit(quats.plain());
  return first_bad_value(quats, [](const glm::quat& q) { return !is_unit(&q.x); });
}

// Of the three floats of each value: the first index (3 * value + component) not finite.
size_t first_non_finite(const JointValues<glm::vec3>& vectors) {
  if (vectors.plain().size() == vectors.size()) return first_non_finite(floats_of(vectors.plain()));
  for (size_t i = 0; i < vectors.size(); ++i) {
    const glm::vec3 v = vectors[i];
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(v[c])) return 3 * i + static_cast<size_t>(c);
    }
  }
  return kNotFound;
}

Status check_joint_values(const DatabaseView& db) {
  if (size_t i = first_non_unit(db.local_rotations); i != kNotFound) {
    const glm::quat q = db.local_rotations[i];
    return Error{"database: local_rotations" + frame_joint(db, i) +
                 " is not a finite unit quaternion (squared length " +
                 std::to_string(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w) + ")"};
  }
  const std::pair<const char*, const JointValues<glm::vec3>&> vector_arrays[] = {
      {"local_positions", db.local_positions},
      {"local_velocities", db.local_velocities},
      {"local_angular_velocities", db.local_angular_velocities}};
  for (const auto& [name, array] : vector_arrays) {
    if (size_t i = first_non_finite(array); i != kNotFound) {
      return Error{"database: " + std::string(name) + frame_joint(db, i / 3) + " is not finite"};
    }
  }
  return Status::success();
}

// The other per-frame values: contacts and searchable flags, features and their normalization.
Status check_other_values(const DatabaseView& db) {
  const size_t dims = static_cast<size_t>(db.feature_dims());
  if (size_t i = first_non_boolean(db.contacts); i != kNotFound) {
    return Error{"database: contacts[frame " + std::to_string(i / 2) + ", " +
                 (i % 2 == 0 ? "left" : "right") + "] is " + std::to_string(db.contacts[i]) +
                 "; expected 0 or 1"};
  }
  if (size_t i = first_non_finite(db.features); i != kNotFound) {
    return Error{"database: features[frame " + std::to_string(i / dims) + ", column " +
                 std::to_string(i % dims) + "] is not finite"};
  }
  for (size_t c = 0; c < dims; ++c) {
    if (!std::isfinite(db.feature_offset[c])) {
      return Error{"database: feature_offset[" + std::to_string(c) + "] is not finite"};
    }
    if (!std::isfinite(db.feature_scale[c]) || db.feature_scale[c] == 0.0f) {
      return Error{"database: feature_scale[" + std::to_string(c) + "] is " +
                   std::to_string(db.feature_scale[c]) + "; expected a finite non-zero scale"};
    }
  }
  if (size_t i = first_non_boolean(db.searchable); i != kNotFound) {
    return Error{"database: searchable[" + std::to_string(i) + "] is " +
                 std::to_string(db.searchable[i]) + "; expected 0 or 1"};
  }
  return Status::success();
}

}  // namespace

Status validate_database(const DatabaseView& db) {
  if (Status s = detail::validate_except_joint_values(db); !s) return s;
  return check_joint_values(db);
}

Status Database::validate() const {
  return validate_database(*this);
}

namespace detail {

Status validate_except_joint_values(const DatabaseView& db) {
  if (!(db.frame_time > 0.0f) || !std::isfinite(db.frame_time)) {
    return Error{"database: frame_time " + std::to_string(db.frame_time) +
                 " s; expected a positive finite number of seconds"};
  }
  for (Status (*check)(const DatabaseView&) :
       {check_skeleton, check_roles, check_frame_arrays, check_schema_and_features, check_tags,
        check_styles, check_clips, check_other_values}) {
    if (Status s = check(db); !s) return s;
  }
  return Status::success();
}

bool rotations_unit(const glm::quat* rotations, size_t count) {
  return count == 0 || first_non_unit_serial(glm::value_ptr(rotations[0]), 0, count) == kNotFound;
}

}  // namespace detail

}  // namespace mm
