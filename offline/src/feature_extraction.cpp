#include "mm/offline/feature_extraction.hpp"

#include <algorithm>
#include <cmath>
#include "mm/runtime/assert.hpp"

#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm {

namespace {

int role_index(const std::string& bone, const JointRoleIndices& roles, bool& is_role) {
  const JointRoleInfo* role = find_joint_role(bone);
  is_role = role != nullptr;
  return role ? roles.*role->index : -1;
}

bool is_bone_kind(FeatureKind kind) {
  return kind == FeatureKind::BonePosition || kind == FeatureKind::BoneVelocity ||
         kind == FeatureKind::BoneDirection;
}

// A fractional frame index snapped to the whole frame when it is within 1e-3 frames of it, so
// that times like 1.0 s at 30 Hz read exactly frame + 30 despite float rounding.
float snapped_frame(float frame) {
  const float nearest = std::round(frame);
  return std::abs(frame - nearest) < 1e-3f ? nearest : frame;
}

}  // namespace

int resolve_feature_bone(const std::string& bone, const Skeleton& skeleton,
                         const JointRoleIndices& roles) {
  bool is_role = false;
  const int index = role_index(bone, roles, is_role);
  if (is_role) return index;
  return skeleton.find(bone);
}

Result<std::vector<int>> resolve_feature_bones(const FeatureSchema& schema,
                                               const Skeleton& skeleton,
                                               const JointRoleIndices& roles) {
  std::vector<int> bones(schema.channels.size(), -1);
  for (size_t i = 0; i < schema.channels.size(); ++i) {
    const FeatureChannel& c = schema.channels[i];
    if (!is_bone_kind(c.kind)) continue;
    bool is_role = false;
    role_index(c.bone, roles, is_role);
    const int joint = resolve_feature_bone(c.bone, skeleton, roles);
    if (joint < 0 || joint >= skeleton.joint_count()) {
      return Error{"feature channel '" + c.name + "': bone '" + c.bone + "' " +
                   (is_role ? std::string("is a joint role that this skeleton does not have")
                            : "is neither a role name (" + joint_role_names() +
                                  ") nor a joint of the skeleton")};
    }
    bones[i] = joint;
  }
  return bones;
}

FeatureFrameMargins feature_frame_margins(const FeatureSchema& schema, float frame_time) {
  FeatureFrameMargins margins;
  for (const FeatureChannel& c : schema.channels) {
    if (is_bone_kind(c.kind)) continue;
    for (float t : c.times) {
      const float frames = t / frame_time;
      if (frames > 0.0f) {
        margins.after = std::max(margins.after, clamped_integer<int>(std::ceil(frames - 1e-3f)));
      } else if (frames < 0.0f) {
        margins.before = std::max(margins.before, clamped_integer<int>(std::ceil(-frames - 1e-3f)));
      }
    }
  }
  return margins;
}

void extract_clip_features(const FeatureSchema& schema, std::span<const int> channel_bones,
                           const ClipMotionView& clip, std::span<float> raw,
                           std::span<uint8_t> searchable, FeatureScratch& scratch) {
  const int joints = static_cast<int>(clip.parents.size());
  const int frames = clip.frame_count;
  const int dims = schema.dims();
  const size_t values = static_cast<size_t>(frames) * joints;
  MM_ASSERT(channel_bones.size() == schema.channels.size());
  MM_ASSERT(clip.local_positions.size() == values && clip.local_rotations.size() == values);
  MM_ASSERT(clip.local_velocities.size() == values &&
            clip.local_angular_velocities.size() == values);
  MM_ASSERT(raw.size() == static_cast<size_t>(frames) * dims);
  MM_ASSERT(searchable.size() == static_cast<size_t>(frames));
  (void)values;

  scratch.global_positions.resize(joints);
  scratch.global_rotations.resize(joints);
  scratch.global_velocities.resize(joints);
  scratch.global_angular_velocities.resize(joints);
  glm::vec3* gp = scratch.global_positions.data();
  glm::quat* gq = scratch.global_rotations.data();
  glm::vec3* gv = scratch.global_velocities.data();
  glm::vec3* gw = scratch.global_angular_velocities.data();

  scratch.needed.assign(joints, 0);
  for (const int bone : channel_bones) {
    for (int j = bone; j >= 0 && !scratch.needed[j]; j = clip.parents[j]) scratch.needed[j] = 1;
  }

  const FeatureFrameMargins margins = feature_frame_margins(schema, clip.frame_time);
  const float rate = 1.0f / clip.frame_time;
  const glm::vec3 forward(0.0f, 0.0f, 1.0f);

  for (int f = 0; f < frames; ++f) {
    searchable[f] = (f >= margins.before && f + margins.after <= frames - 1) ? 1 : 0;

    // Forward kinematics of positions, rotations and their derivatives down the hierarchy,
    // for the channel bones and their ancestors only.
    const size_t base = static_cast<size_t>(f) * joints;
    for (int j = 0; j < joints; ++j) {
      if (!scratch.needed[j]) continue;
      const glm::vec3& lp = clip.local_positions[base + j];
      const glm::quat& lq = clip.local_rotations[base + j];
      const glm::vec3& lv = clip.local_velocities[base + j];
      const glm::vec3& lw = clip.local_angular_velocities[base + j];
      const int p = clip.parents[j];
      if (p < 0) {
        gp[j] = lp;
        gq[j] = lq;
        gv[j] = lv;
        gw[j] = lw;
      } else {
        const glm::vec3 offset = gq[p] * lp;
        gp[j] = gp[p] + offset;
        gq[j] = gq[p] * lq;
        gv[j] = gv[p] + glm::cross(gw[p], offset) + gq[p] * lv;
        gw[j] = gw[p] + gq[p] * lw;
      }
    }

    const glm::vec3 root_position = clip.local_positions[base];
    const glm::quat root_inverse = glm::conjugate(clip.local_rotations[base]);
    float* row = raw.data() + static_cast<size_t>(f) * dims;
    for (size_t c = 0; c < schema.channels.size(); ++c) {
      const FeatureChannel& channel = schema.channels[c];
      const int bone = channel_bones[c];
      switch (channel.kind) {
        case FeatureKind::BonePosition: {
          const glm::vec3 v = root_inverse * (gp[bone] - root_position);
          *row++ = v.x;
          *row++ = v.y;
          *row++ = v.z;
          break;
        }
        case FeatureKind::BoneVelocity: {
          const glm::vec3 v = root_inverse * gv[bone];
          *row++ = v.x;
          *row++ = v.y;
          *row++ = v.z;
          break;
        }
        case FeatureKind::BoneDirection: {
          const glm::vec3 v = root_inverse * (gq[bone] * glm::normalize(channel.axis));
          *row++ = v.x;
          *row++ = v.y;
          *row++ = v.z;
          break;
        }
        case FeatureKind::TrajectoryPosition:
        case FeatureKind::TrajectoryDirection: {
          for (float t : channel.times) {
            const float x = std::clamp(snapped_frame(static_cast<float>(f) + t * rate), 0.0f,
                                       static_cast<float>(frames - 1));
            const int i0 = clamped_integer<int>(std::floor(x));
            const int i1 = std::min(i0 + 1, frames - 1);
            const float a = x - static_cast<float>(i0);
            const size_t k0 = static_cast<size_t>(i0) * joints;
            const size_t k1 = static_cast<size_t>(i1) * joints;
            glm::vec3 v;
            if (channel.kind == FeatureKind::TrajectoryPosition) {
              const glm::vec3 position =
                  glm::mix(clip.local_positions[k0], clip.local_positions[k1], a);
              v = root_inverse * (position - root_position);
            } else {
              const glm::quat rotation =
                  quat_slerp(clip.local_rotations[k0], clip.local_rotations[k1], a);
              v = root_inverse * (rotation * forward);
            }
            *row++ = v.x;
            *row++ = v.z;
          }
          break;
        }
      }
    }
  }
}

FeatureNormalization compute_feature_normalization(const FeatureSchema& schema,
                                                   std::span<const float> raw,
                                                   std::span<const uint8_t> searchable) {
  const int dims = schema.dims();
  FeatureNormalization out;
  out.offset.assign(dims, 0.0f);
  out.scale.assign(dims, 1.0f);
  if (dims == 0) return out;
  const size_t rows = raw.size() / dims;
  MM_ASSERT(searchable.size() == rows);

  size_t counted = 0;
  for (size_t r = 0; r < rows; ++r) counted += searchable[r] ? 1 : 0;
  const bool use_all = counted == 0;
  if (use_all) counted = rows;

  // Two passes in double: exact enough for 200k rows and independent of any threading.
  std::vector<double> mean(dims, 0.0), variance(dims, 0.0);
  for (size_t r = 0; r < rows; ++r) {
    if (!use_all && !searchable[r]) continue;
    const float* row = raw.data() + r * dims;
    for (int c = 0; c < dims; ++c) mean[c] += row[c];
  }
  for (int c = 0; c < dims; ++c) mean[c] = counted ? mean[c] / static_cast<double>(counted) : 0.0;
  for (size_t r = 0; r < rows; ++r) {
    if (!use_all && !searchable[r]) continue;
    const float* row = raw.data() + r * dims;
    for (int c = 0; c < dims; ++c) {
      const double d = row[c] - mean[c];
      variance[c] += d * d;
    }
  }
  for (int c = 0; c < dims; ++c) {
    variance[c] = counted ? variance[c] / static_cast<double>(counted) : 0.0;
    out.offset[c] = static_cast<float>(mean[c]);
  }

  for (size_t i = 0; i < schema.channels.size(); ++i) {
    const FeatureChannel& channel = schema.channels[i];
    const int first = schema.offset(static_cast<int>(i));
    const int count = channel.dims();
    double sum = 0.0;
    for (int c = first; c < first + count; ++c) sum += variance[c];
    const double deviation = count > 0 ? std::sqrt(sum / count) : 0.0;
    float scale = static_cast<float>(deviation) / channel.weight;
    if (!(deviation >= kMinFeatureDeviation) || !std::isfinite(scale) || scale <= 0.0f) {
      out.warnings.push_back("feature channel '" + channel.name + "' does not vary over the " +
                             std::to_string(counted) + (use_all ? " " : " searchable ") +
                             "frames (standard deviation " + std::to_string(deviation) +
                             "); it is left unscaled (scale = 1 / weight)");
      scale = 1.0f / channel.weight;
    }
    for (int c = first; c < first + count; ++c) out.scale[c] = scale;
  }
  return out;
}

void normalize_features(std::span<float> rows, std::span<const float> offset,
                        std::span<const float> scale) {
  const size_t dims = offset.size();
  MM_ASSERT(scale.size() == dims && dims > 0 && rows.size() % dims == 0);
  for (size_t i = 0; i < rows.size(); i += dims) {
    for (size_t c = 0; c < dims; ++c) rows[i + c] = (rows[i + c] - offset[c]) / scale[c];
  }
}

void denormalize_features(std::span<float> rows, std::span<const float> offset,
                          std::span<const float> scale) {
  const size_t dims = offset.size();
  MM_ASSERT(scale.size() == dims && dims > 0 && rows.size() % dims == 0);
  for (size_t i = 0; i < rows.size(); i += dims) {
    for (size_t c = 0; c < dims; ++c) rows[i + c] = rows[i + c] * scale[c] + offset[c];
  }
}

void extract_range_features(const DatabaseFill& db, const ClipRange& range,
                            std::span<const int> channel_bones, FeatureScratch& scratch) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  const size_t dims = static_cast<size_t>(db.schema.dims());
  const size_t first = static_cast<size_t>(range.start) * joints;
  const size_t count = static_cast<size_t>(range.frame_count()) * joints;
  ClipMotionView view;
  view.parents = db.skeleton.parents();
  view.local_positions = std::span(db.local_positions).subspan(first, count);
  view.local_rotations = std::span(db.local_rotations).subspan(first, count);
  view.local_velocities = std::span(db.local_velocities).subspan(first, count);
  view.local_angular_velocities = std::span(db.local_angular_velocities).subspan(first, count);
  view.frame_count = range.frame_count();
  view.frame_time = db.frame_time;
  extract_clip_features(
      db.schema, channel_bones, view,
      std::span(db.features).subspan(range.start * dims, range.frame_count() * dims),
      std::span(db.searchable).subspan(range.start, range.frame_count()), scratch);
}

Status compute_database_features(DatabaseContents& db, std::vector<std::string>* warnings) {
  if (Status s = db.schema.validate(); !s) return s;
  const int joints = db.joint_count();
  const size_t values = static_cast<size_t>(db.frame_count) * joints;
  if (joints == 0 || db.frame_count <= 0) return Error{"database: no joints or no frames"};
  if (db.local_positions.size() != values || db.local_rotations.size() != values ||
      db.local_velocities.size() != values || db.local_angular_velocities.size() != values) {
    return Error{
        "database: the per-frame joint arrays do not hold frame_count * joint_count "
        "values"};
  }
  if (!(db.frame_time > 0.0f) || !std::isfinite(db.frame_time)) {
    return Error{"database: the frame time must be a positive number of seconds"};
  }
  Result<std::vector<int>> bones = resolve_feature_bones(db.schema, db.skeleton, db.roles);
  if (!bones) return Error{bones.message()};

  const int dims = db.schema.dims();
  db.features.assign(static_cast<size_t>(db.frame_count) * dims, 0.0f);
  db.searchable.assign(db.frame_count, 0);
  FeatureScratch scratch;
  for (const ClipRange& range : db.clips) {
    if (range.start < 0 || range.end > db.frame_count || range.start >= range.end) {
      return Error{"database: clip '" + range.name + "' has an invalid frame range [" +
                   std::to_string(range.start) + ", " + std::to_string(range.end) + ")"};
    }
    extract_range_features(db, range, *bones, scratch);
  }
  FeatureNormalization normalization =
      compute_feature_normalization(db.schema, db.features, db.searchable);
  normalize_features(db.features, normalization.offset, normalization.scale);
  db.feature_offset = std::move(normalization.offset);
  db.feature_scale = std::move(normalization.scale);
  if (warnings) {
    warnings->insert(warnings->end(), normalization.warnings.begin(), normalization.warnings.end());
  }
  return Status::success();
}

}  // namespace mm
