#pragma once
// Feature extraction and normalization: turns a clip's motion (local transforms and velocities,
// joint 0 the simulation root) into rows of raw feature values laid out by a FeatureSchema, and
// raw rows into the normalized matrix the search runs over.
//
// Conventions. Every feature is expressed in the simulation-root frame of the frame it belongs
// to: a world vector v becomes conjugate(root_rotation) * v, a world point p becomes
// conjugate(root_rotation) * (p - root_position). Trajectory features read the root at
// fractional times (frame + time / frame_time): positions are interpolated linearly and
// rotations by slerp between the two neighbouring frames, and a time outside the clip is
// clamped to its first or last frame (such frames are not searchable). The root's facing is its
// local +Z axis. Bone velocities are world velocities obtained by forward kinematics of the
// stored local velocities and angular velocities (the exact derivative of the pose), then
// rotated into the root frame; they do not include the apparent motion the root's own turning
// would add.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/database/database.hpp"
#include "mm/database/features.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"

namespace mm {

// The joint index a bone string refers to: a role name (see kJointRoles) resolved through
// `roles`, otherwise an exact joint name; -1 when neither matches.
int resolve_feature_bone(const std::string& bone, const Skeleton& skeleton,
                         const JointRoleIndices& roles);

// The joint index of every channel's bone (-1 for trajectory channels). Fails, naming the
// channel and the bone, when a bone kind's bone is neither a known role nor a joint.
Result<std::vector<int>> resolve_feature_bones(const FeatureSchema& schema,
                                               const Skeleton& skeleton,
                                               const JointRoleIndices& roles);

// One clip's motion as the extractor reads it. Arrays are frame-major
// ([frame * joint_count + joint]), hold frame_count * parents.size() values each, and are local
// to the parent; joint 0 is the simulation root and its values are world values.
struct ClipMotionView {
  std::span<const int> parents;                         // parent-before-child, joint 0 a root
  std::span<const glm::vec3> local_positions;           // metres
  std::span<const glm::quat> local_rotations;           // unit
  std::span<const glm::vec3> local_velocities;          // metres / second, parent frame
  std::span<const glm::vec3> local_angular_velocities;  // radians / second, parent frame
  int frame_count = 0;
  float frame_time = 1.0f / 30.0f;  // seconds
};

// Buffers the extractor reuses between clips so its per-frame loop never allocates.
struct FeatureScratch {
  std::vector<glm::vec3> global_positions;
  std::vector<glm::quat> global_rotations;
  std::vector<glm::vec3> global_velocities;
  std::vector<glm::vec3> global_angular_velocities;
  std::vector<uint8_t> needed;  // per joint: a channel bone or one of their ancestors
};

// Whole frames a frame needs before and after it (so that every time of every trajectory
// channel lies inside the clip) at this frame time: e.g. 0 and 30 for the default schema at
// 30 Hz. Times within 1e-3 frames of a whole frame count as that frame.
struct FeatureFrameMargins {
  int before = 0;  // frames needed before the frame (from negative times)
  int after = 0;   // frames needed after the frame (from positive times)
};
FeatureFrameMargins feature_frame_margins(const FeatureSchema& schema, float frame_time);

// Fills `raw` (frame_count rows of schema.dims() floats) with the un-normalized features of one
// clip and `searchable` (frame_count flags) with 1 where every feature time of the frame lies
// inside the clip. `channel_bones` comes from resolve_feature_bones. Sizes are the caller's
// duty (asserted). Does not allocate once `scratch` has grown to the joint count.
void extract_clip_features(const FeatureSchema& schema, std::span<const int> channel_bones,
                           const ClipMotionView& clip, std::span<float> raw,
                           std::span<uint8_t> searchable, FeatureScratch& scratch);

// Extracts one clip range of a database in place: reads its motion arrays, writes its raw
// (un-normalized) rows of db.features and its db.searchable flags. Arrays must be sized.
void extract_range_features(const DatabaseFill& db, const ClipRange& range,
                            std::span<const int> channel_bones, FeatureScratch& scratch);

// Per-column offsets and scales that normalize a feature matrix, and warnings for channels
// that could not be scaled.
struct FeatureNormalization {
  std::vector<float> offset;          // per column: the mean
  std::vector<float> scale;           // per column: the channel's deviation / weight (never 0)
  std::vector<std::string> warnings;  // one per channel with (near) zero deviation
};

// Deviations below this (metres, metres per second or unit-vector components) count as zero.
inline constexpr float kMinFeatureDeviation = 1e-6f;

// Statistics over the rows of `raw` whose `searchable` flag is 1 (the rows the search can
// return; non-searchable rows carry clamped trajectories that would bias the statistics), or
// over all rows when no row is searchable. offset = column mean; each channel's deviation is
// sqrt(mean over its columns of the column variances), and its columns' scale = deviation /
// weight. A channel whose deviation is below kMinFeatureDeviation is left unscaled
// (scale = 1 / weight) and named in a warning.
FeatureNormalization compute_feature_normalization(const FeatureSchema& schema,
                                                   std::span<const float> raw,
                                                   std::span<const uint8_t> searchable);

// In place, every row: x = (x - offset) / scale. `rows` holds a whole number of rows of
// offset.size() columns. Works for the matrix and for a single query row.
void normalize_features(std::span<float> rows, std::span<const float> offset,
                        std::span<const float> scale);

// The inverse of normalize_features: x = x * scale + offset.
void denormalize_features(std::span<float> rows, std::span<const float> offset,
                          std::span<const float> scale);

// Recomputes db.features, db.feature_offset, db.feature_scale and db.searchable from the
// motion arrays, clip ranges, roles and db.schema (e.g. after changing weights). Warnings from
// the normalization are appended to `warnings` when given.
Status compute_database_features(DatabaseContents& db,
                                 std::vector<std::string>* warnings = nullptr);

}  // namespace mm
