#pragma once
// The motion database: every clip resampled to one rate, expressed relative to a simulation
// root (joint 0), with velocities, foot contacts, clip ranges and tags, and the normalized
// feature matrix the search runs over. Built by the builder (builder.hpp), saved and loaded as
// one versioned binary file (database_file.hpp).

#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/database/features.hpp"
#include "mm/database/joint_roles.hpp"
#include "mm/runtime/skeleton.hpp"

namespace mm {

// One source take inside the database. Frames [start, end) belong to it; nothing is ever
// matched or blended across a clip boundary.
struct ClipRange {
  std::string name;   // source file stem; mirrored copies end in "_mirror"
  int start = 0;      // first database frame of the clip
  int end = 0;        // one past the last frame
  uint64_t tags = 0;  // bit i set when the clip carries Database::tag_names[i]
  bool mirrored = false;
  int frame_count() const { return end - start; }
};

namespace detail {
// Set only while the builder or the loader sizes arrays it is about to fill completely
// (detail::resize_large): value-initializing ~200 MB first would write every byte twice.
inline thread_local bool skip_value_initialization = false;
}  // namespace detail

// std::allocator, except that while detail::skip_value_initialization is set, a value-initialized
// element (resize(n), vector(n)) is left unwritten. Every other use behaves as std::allocator.
template <class T>
struct FrameAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = FrameAllocator<U>;
  };
  FrameAllocator() = default;
  template <class U>
  FrameAllocator(const FrameAllocator<U>&) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    // GLM's vectors and quaternions are plain floats (with GLM_FORCE_CTOR_INIT their
    // constructors only zero them, so they do not count as trivially copyable).
    if constexpr (sizeof...(Args) == 0 && std::is_standard_layout_v<U> &&
                  std::is_trivially_destructible_v<U>) {
      if (detail::skip_value_initialization) return;
    }
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

// The per-frame arrays of the database: a std::vector with that allocator.
template <class T>
using FrameArray = std::vector<T, FrameAllocator<T>>;

struct Database {
  // Joint 0 is the simulation root (hips projected on the ground, smoothed facing); the source
  // skeleton's joints follow it, depth-first. Rest transforms are the first clip's.
  Skeleton skeleton;
  JointRoleIndices roles;
  float frame_time = 1.0f / 30.0f;  // seconds
  int frame_count = 0;

  // Per-frame, per-joint arrays, frame-major: [frame * joint_count + joint]. Local to the
  // parent; joint 0's values are relative to the world (its clip's origin).
  FrameArray<glm::vec3> local_positions;           // metres
  FrameArray<glm::quat> local_rotations;           // unit
  FrameArray<glm::vec3> local_velocities;          // metres / second, in the parent's frame
  FrameArray<glm::vec3> local_angular_velocities;  // radians / second, in the parent's frame
  // Per-frame foot contacts: [frame * 2 + 0] left, [frame * 2 + 1] right; 1 = in contact.
  std::vector<uint8_t> contacts;

  std::vector<ClipRange> clips;
  std::vector<std::string> tag_names;  // at most 64

  // The feature matrix: frame_count rows of schema.dims() floats, row-major, normalized:
  // features[f * dims + c] = (raw - feature_offset[c]) / feature_scale[c]. The plain squared
  // Euclidean distance between rows is the weighted distance the search minimizes.
  FeatureSchema schema;
  FrameArray<float> features;
  std::vector<float> feature_offset;  // dims: per-column mean
  std::vector<float> feature_scale;   // dims: group standard deviation / weight (never 0)
  // 1 when the frame may be matched: every feature time of the frame lies inside its clip.
  std::vector<uint8_t> searchable;
  // Clip index of every frame (derived from clips on build and load).
  std::vector<int> frame_clip;

  int joint_count() const { return skeleton.joint_count(); }
  int feature_dims() const { return schema.dims(); }
  std::span<const float> feature_row(int frame) const {
    const size_t d = static_cast<size_t>(feature_dims());
    return {features.data() + frame * d, d};
  }
  // Bit mask of the named tags (unknown names give no bits), for search filters.
  uint64_t tag_mask(std::span<const std::string> names) const;
  // Consistency of sizes and indices between all the arrays above.
  Status validate() const;
};

// The name and the tag of the idle clip the builder synthesizes (mm/offline/idle.hpp).
inline constexpr const char* kIdleClipName = "idle";
inline constexpr const char* kIdleTag = "idle";

// True for that clip: named kIdleClipName, tagged kIdleTag, not mirrored. (A source file that
// happens to be called "idle.bvh" carries no such tag.)
bool is_idle_clip(const Database& db, const ClipRange& clip);

// Index of the last clip is_idle_clip accepts, -1 when there is none.
int find_idle_clip(const Database& db);

// The clip checks of Database::validate() on their own: the clips are named, tile
// [0, frame_count) in order and carry only the bits of `tag_count` tags. The file loader runs
// them before it lays out the per-clip sections.
Status validate_clip_ranges(std::span<const ClipRange> clips, int frame_count, size_t tag_count);

}  // namespace mm
