#pragma once
// The motion database: every clip resampled to one rate, expressed relative to a simulation
// root (joint 0), with velocities, foot contacts, clip ranges and tags, and the normalized
// feature matrix the search runs over.
//
// A game holds a Database: immutable, made only by loading a file (database_file.hpp) or by the
// builder (mm/offline/builder.hpp), both of which fill it in place and validate it. Its
// per-frame arrays live in one allocation and are read through spans. Anything else that makes
// one (a test, a tool changing one) fills a DatabaseContents (plain vectors) and calls
// Database::create(). Code that reads either takes a DatabaseView.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/database/features.hpp"
#include "mm/database/joint_roles.hpp"
#include "mm/runtime/pose_lanes.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"

namespace mm {

// One source take inside the database. Frames [start, end) belong to it; nothing is ever
// matched or blended across a clip boundary.
struct ClipRange {
  std::string name;   // source file stem; mirrored copies end in "_mirror"
  int start = 0;      // first database frame of the clip
  int end = 0;        // one past the last frame
  uint64_t tags = 0;  // bit i set when the clip carries the database's tag name i
  bool mirrored = false;
  // The clip's style: an index into the database's style names, or -1 for a clip without one
  // (idle clips), which serves every style (docs/controller.md, Styles). Last, so that the
  // positional initializers of the fields above keep their meaning.
  int style = -1;
  int frame_count() const { return end - start; }
};

// Everything a database holds, as plain vectors: what the builder (and a test) fills before
// Database::create() checks it and packs it. The fields mean what Database's accessors of the
// same names return.
struct DatabaseContents {
  // Joint 0 is the simulation root (hips projected on the ground, smoothed facing); the source
  // skeleton's joints follow it, depth-first. Rest transforms are the first clip's.
  Skeleton skeleton;
  JointRoleIndices roles;
  float frame_time = 1.0f / 30.0f;  // seconds
  int frame_count = 0;

  // Per-frame, per-joint arrays, frame-major: [frame * joint_count + joint]. Local to the
  // parent; joint 0's values are relative to the world (its clip's origin).
  std::vector<glm::vec3> local_positions;           // metres
  std::vector<glm::quat> local_rotations;           // unit
  std::vector<glm::vec3> local_velocities;          // metres / second, in the parent's frame
  std::vector<glm::vec3> local_angular_velocities;  // radians / second, in the parent's frame
  // Per-frame foot contacts: [frame * 2 + 0] left, [frame * 2 + 1] right; 1 = in contact.
  std::vector<uint8_t> contacts;

  std::vector<ClipRange> clips;          // tile [0, frame_count) in order
  std::vector<std::string> tag_names;    // at most 64
  std::vector<std::string> style_names;  // at most kMaxStyles, distinct, not empty

  // The feature matrix: frame_count rows of schema.dims() floats, row-major, normalized:
  // features[f * dims + c] = (raw - feature_offset[c]) / feature_scale[c]. The plain squared
  // Euclidean distance between rows is the weighted distance the search minimizes.
  FeatureSchema schema;
  std::vector<float> features;
  std::vector<float> feature_offset;  // dims: per-column mean
  std::vector<float> feature_scale;   // dims: group standard deviation / weight (never 0)
  // 1 when the frame may be matched: every feature time of the frame lies inside its clip.
  std::vector<uint8_t> searchable;

  int joint_count() const { return skeleton.joint_count(); }
  int feature_dims() const { return schema.dims(); }
};

// One per-frame, per-joint quantity of a pose (local positions, rotations, velocities or angular
// velocities), read by k = frame * joints + joint whichever layout holds it: a plain array (a
// DatabaseContents, a build being filled) or a Database's frames in the lanes' layout
// (pose_lanes.hpp). Reading by k divides by the joint count; a per-frame reader of a Database
// uses its (frame, joint) accessors instead.
template <class T>
class JointValues {
 public:
  JointValues() = default;
  JointValues(std::span<const T> values)  // NOLINT: implicit, as a span from a vector
      : values_(values.data()), size_(values.size()) {}
  JointValues(const std::vector<T>& values)  // NOLINT
      : JointValues(std::span<const T>(values)) {}
  // Row `row` of frames in the lanes' layout of `joints` joints (whole frames).
  JointValues(std::span<const float> lanes, size_t joints, size_t row)
      : lanes_(lanes.data()),
        size_(joints == 0 ? 0 : lanes.size() / pose_lane_floats(joints) * joints),
        joints_(joints),
        row_(row) {}

  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  // The values as one array when a plain array holds them, else empty.
  std::span<const T> plain() const {
    return values_ != nullptr ? std::span<const T>(values_, size_) : std::span<const T>();
  }
  T operator[](size_t k) const {
    if (values_ != nullptr) return values_[k];
    const float* frame = lanes_ + k / joints_ * pose_lane_floats(joints_);
    if constexpr (std::is_same_v<T, glm::quat>) {
      return pose_lane_rotation(frame, k % joints_);
    } else {
      return pose_lane_vec3(frame, k % joints_, row_);
    }
  }

 private:
  const T* values_ = nullptr;
  const float* lanes_ = nullptr;
  size_t size_ = 0;
  size_t joints_ = 0;
  size_t row_ = 0;
};

class Database;

// A read-only view of a database, a Database or a DatabaseContents alike (it converts from
// both), for code that reads either: validation, the idle search, the generated body. Valid
// while what it views lives and is not changed. frame_clip is empty for a DatabaseContents.
struct DatabaseView {
  DatabaseView(const Database& db);          // NOLINT: implicit, as a span from a vector
  DatabaseView(const DatabaseContents& db);  // NOLINT

  const Skeleton& skeleton;
  const JointRoleIndices& roles;
  float frame_time;
  int frame_count;
  JointValues<glm::vec3> local_positions;
  JointValues<glm::quat> local_rotations;
  JointValues<glm::vec3> local_velocities;
  JointValues<glm::vec3> local_angular_velocities;
  std::span<const uint8_t> contacts;
  std::span<const ClipRange> clips;
  std::span<const std::string> tag_names;
  std::span<const std::string> style_names;
  const FeatureSchema& schema;
  std::span<const float> features;
  std::span<const float> feature_offset;
  std::span<const float> feature_scale;
  std::span<const uint8_t> searchable;
  std::span<const int> frame_clip;

  int joint_count() const { return skeleton.joint_count(); }
  int feature_dims() const { return schema.dims(); }
  std::span<const float> feature_row(int frame) const {
    const size_t d = static_cast<size_t>(feature_dims());
    return features.subspan(static_cast<size_t>(frame) * d, d);
  }
  uint64_t tag_mask(std::span<const std::string> names) const;
};

// The per-frame arrays of a database being made, writable, with what writing them reads: what
// the build side's writers (a range's features, the idle clip) take, over a DatabaseContents'
// vectors (it converts) or over the builder's new database (its pose in per-joint arrays until
// it is laid out in the database's lanes).
struct DatabaseFill {
  DatabaseFill(DatabaseContents& db);  // NOLINT: implicit, as a span from a vector
  DatabaseFill(const DatabaseView& read, std::span<glm::vec3> local_positions,
               std::span<glm::quat> local_rotations, std::span<glm::vec3> local_velocities,
               std::span<glm::vec3> local_angular_velocities, std::span<uint8_t> contacts,
               std::span<float> features, std::span<uint8_t> searchable);

  const Skeleton& skeleton;
  const FeatureSchema& schema;
  float frame_time;
  int frame_count;
  std::span<glm::vec3> local_positions;
  std::span<glm::quat> local_rotations;
  std::span<glm::vec3> local_velocities;
  std::span<glm::vec3> local_angular_velocities;
  std::span<uint8_t> contacts;
  std::span<float> features;
  std::span<uint8_t> searchable;

  int joint_count() const { return skeleton.joint_count(); }
};

namespace detail {
// Fills a database in place: the file loader and the builder, the two ways a Database is made
// from raw data (database/internal/, never installed).
class DatabaseAssembly;
}  // namespace detail

class Database {
 public:
  // Checks `contents` (validate()) and copies it into a database, its per-frame arrays in one
  // allocation; frame_clip is derived from the clips.
  static Result<Database> create(const DatabaseContents& contents);

  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;  // one copy of the frames; share it (shared_ptr)
  Database& operator=(const Database&) = delete;
  ~Database() = default;

  // A copy of everything as plain vectors, to change and create() again (tools, tests).
  DatabaseContents contents() const;

  const Skeleton& skeleton() const { return skeleton_; }
  const JointRoleIndices& roles() const { return roles_; }
  float frame_time() const { return frame_time_; }  // seconds
  int frame_count() const { return frame_count_; }
  int joint_count() const { return skeleton_.joint_count(); }

  // The pose: every frame's local rotations, positions, velocities and angular velocities in the
  // lanes' layout of pose_lanes.hpp (pose_lane_floats(joint_count()) floats a frame), the one
  // copy the database holds, so that playback loads four joints' components without
  // transposing them. The file stores them per joint; loading lays them out.
  std::span<const float> pose_lanes() const { return pose_lanes_; }
  std::span<const float> frame_pose_lanes(int frame) const {
    const size_t floats = pose_lane_floats(static_cast<size_t>(joint_count()));
    return pose_lanes_.subspan(static_cast<size_t>(frame) * floats, floats);
  }
  // One joint of one frame.
  glm::vec3 local_position(int frame, int joint) const {
    return pose_lane_vec3(frame_pose_lanes(frame).data(), static_cast<size_t>(joint),
                          kPoseLanePosition);
  }
  glm::quat local_rotation(int frame, int joint) const {
    return pose_lane_rotation(frame_pose_lanes(frame).data(), static_cast<size_t>(joint));
  }
  glm::vec3 local_velocity(int frame, int joint) const {
    return pose_lane_vec3(frame_pose_lanes(frame).data(), static_cast<size_t>(joint),
                          kPoseLaneVelocity);
  }
  glm::vec3 local_angular_velocity(int frame, int joint) const {
    return pose_lane_vec3(frame_pose_lanes(frame).data(), static_cast<size_t>(joint),
                          kPoseLaneAngularVelocity);
  }
  // DatabaseContents' arrays of the same names, read by k = frame * joints + joint.
  JointValues<glm::vec3> local_positions() const {
    return pose_values<glm::vec3>(kPoseLanePosition);
  }
  JointValues<glm::quat> local_rotations() const {
    return pose_values<glm::quat>(kPoseLaneRotationW);
  }
  JointValues<glm::vec3> local_velocities() const {
    return pose_values<glm::vec3>(kPoseLaneVelocity);
  }
  JointValues<glm::vec3> local_angular_velocities() const {
    return pose_values<glm::vec3>(kPoseLaneAngularVelocity);
  }
  std::span<const uint8_t> contacts() const { return contacts_; }
  std::span<const ClipRange> clips() const { return clips_; }
  std::span<const std::string> tag_names() const { return tag_names_; }
  std::span<const std::string> style_names() const { return style_names_; }

  const FeatureSchema& schema() const { return schema_; }
  int feature_dims() const { return schema_.dims(); }
  std::span<const float> features() const { return features_; }
  std::span<const float> feature_offset() const { return feature_offset_; }
  std::span<const float> feature_scale() const { return feature_scale_; }
  std::span<const uint8_t> searchable() const { return searchable_; }
  // Clip index of every frame.
  std::span<const int> frame_clip() const { return frame_clip_; }

  std::span<const float> feature_row(int frame) const {
    const size_t d = static_cast<size_t>(feature_dims());
    return features_.subspan(static_cast<size_t>(frame) * d, d);
  }
  // Bit mask of the named tags (unknown names give no bits), for search filters.
  uint64_t tag_mask(std::span<const std::string> names) const;
  // Consistency of sizes and indices between all the arrays, and their values (finite, unit
  // rotations, boolean flags). A created or loaded database always passes.
  Status validate() const;

 private:
  friend class detail::DatabaseAssembly;
  Database() = default;
  // Sizes the per-frame arrays (one allocation, huge pages where the system has them, the
  // values left unwritten for the caller to fill).
  void allocate(size_t frames, size_t joints, size_t dims);
  // Keeps the first `frames` frames of every per-frame array (no reallocation).
  void keep_frames(size_t frames);
  // Fills frame_clip from the clips (which tile the frames).
  void derive_frame_clip();
  // The pose given per joint as DatabaseContents holds it (each span: every frame's joints, frame
  // after frame), laid out in pose_lanes_.
  void lay_out_pose(const PoseFrameView& pose);
  template <class T>
  JointValues<T> pose_values(size_t row) const {
    return JointValues<T>(pose_lanes_, static_cast<size_t>(joint_count()), row);
  }

  struct FreeBlock {
    void operator()(std::byte* block) const;
  };

  Skeleton skeleton_;
  JointRoleIndices roles_;
  float frame_time_ = 1.0f / 30.0f;
  int frame_count_ = 0;
  std::vector<ClipRange> clips_;
  std::vector<std::string> tag_names_;
  std::vector<std::string> style_names_;
  FeatureSchema schema_;
  std::unique_ptr<std::byte[], FreeBlock> block_;
  std::span<float> pose_lanes_;
  std::span<uint8_t> contacts_;
  std::span<float> features_;
  std::span<float> feature_offset_;
  std::span<float> feature_scale_;
  std::span<uint8_t> searchable_;
  std::span<int> frame_clip_;
};

// A copy of `db` whose feature channel `channel` (an index into its schema's channels) has
// weight `weight` instead, as if it had been built with it: the channel's columns of features
// and feature_scale rescaled (features = (raw - offset) / (std / weight)), nothing else
// changed. Fails, naming what is wrong, on a channel out of range or a weight not finite and
// > 0. Costs a copy of the database (the viewer's weight slider, feature-weight sweeps).
Result<Database> with_channel_weight(const Database& db, int channel, float weight);

// Checks of a database being built or loaded: the whole of Database::validate().
Status validate_database(const DatabaseView& db);

// The name and the tag of the idle clip the builder synthesizes (mm/offline/idle.hpp).
inline constexpr const char* kIdleClipName = "idle";
inline constexpr const char* kIdleTag = "idle";

// Most distinct styles a database holds (a clip's style is an index below it).
inline constexpr size_t kMaxStyles = 256;

// True for that clip: named kIdleClipName, tagged kIdleTag, not mirrored. (A source file that
// happens to be called "idle.bvh" carries no such tag.)
bool is_idle_clip(const DatabaseView& db, const ClipRange& clip);

// Index of the last clip is_idle_clip accepts, -1 when there is none.
int find_idle_clip(const DatabaseView& db);

// The clip checks of Database::validate() on their own: the clips are named, tile
// [0, frame_count) in order and carry only the bits of `tag_count` tags. The file loader runs
// them before it lays out the per-clip sections.
Status validate_clip_ranges(std::span<const ClipRange> clips, int frame_count, size_t tag_count);

}  // namespace mm
