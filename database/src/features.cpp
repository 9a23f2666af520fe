#include "mm/database/features.hpp"

#include <charconv>
#include <cmath>
#include <unordered_set>

namespace mm {

namespace {

bool is_bone_kind(FeatureKind kind) {
  return kind == FeatureKind::BonePosition || kind == FeatureKind::BoneVelocity ||
         kind == FeatureKind::BoneDirection;
}

bool is_trajectory_kind(FeatureKind kind) {
  return kind == FeatureKind::TrajectoryPosition || kind == FeatureKind::TrajectoryDirection;
}

}  // namespace

int FeatureChannel::dims() const {
  switch (kind) {
    case FeatureKind::BonePosition:
    case FeatureKind::BoneVelocity:
    case FeatureKind::BoneDirection:
      return 3;
    case FeatureKind::TrajectoryPosition:
    case FeatureKind::TrajectoryDirection:
      return 2 * static_cast<int>(times.size());
  }
  return 0;
}

int FeatureSchema::dims() const {
  int total = 0;
  for (const FeatureChannel& c : channels) total += c.dims();
  return total;
}

int FeatureSchema::offset(int channel) const {
  int column = 0;
  for (int i = 0; i < channel && i < static_cast<int>(channels.size()); ++i) {
    column += channels[i].dims();
  }
  return column;
}

std::vector<std::string> FeatureSchema::column_names() const {
  std::vector<std::string> names;
  names.reserve(static_cast<size_t>(dims()));
  for (const FeatureChannel& c : channels) {
    if (is_trajectory_kind(c.kind)) {
      for (const float time : c.times) {
        char text[32];
        const auto end = std::to_chars(text, text + sizeof text, time).ptr;
        const std::string prefix = c.name + "_" + std::string(text, end) + "s_";
        names.push_back(prefix + "x");
        names.push_back(prefix + "z");
      }
    } else {
      for (const char* axis : {"_x", "_y", "_z"}) names.push_back(c.name + axis);
    }
  }
  return names;
}

Status FeatureSchema::validate() const {
  if (channels.empty()) return Error{"feature schema: no channels (at least one is needed)"};
  std::unordered_set<std::string> names;
  for (size_t i = 0; i < channels.size(); ++i) {
    const FeatureChannel& c = channels[i];
    const std::string where = "feature schema: channel " + std::to_string(i) +
                              (c.name.empty() ? std::string() : " '" + c.name + "'");
    if (c.name.empty()) return Error{where + " has an empty name"};
    if (!names.insert(c.name).second) return Error{where + ": duplicate channel name"};
    if (static_cast<uint8_t>(c.kind) > static_cast<uint8_t>(FeatureKind::BoneDirection)) {
      return Error{where + ": unknown feature kind " + std::to_string(static_cast<int>(c.kind))};
    }
    if (!(c.weight > 0.0f) || !std::isfinite(c.weight)) {
      return Error{where + ": weight must be positive and finite, found " +
                   std::to_string(c.weight)};
    }
    if (is_bone_kind(c.kind)) {
      if (c.bone.empty())
        return Error{where + ": a bone feature needs a bone (role or joint name)"};
      if (!c.times.empty()) {
        return Error{where + ": bone features are taken at the current frame and take no times"};
      }
      if (c.kind == FeatureKind::BoneDirection) {
        const float length = glm::length(c.axis);
        if (!std::isfinite(length) || length < 1e-6f) {
          return Error{where + ": a bone direction needs a finite, non-zero axis"};
        }
      }
    }
    if (is_trajectory_kind(c.kind)) {
      if (c.times.empty()) return Error{where + ": a trajectory feature needs at least one time"};
      for (float t : c.times) {
        if (!std::isfinite(t)) return Error{where + ": times must be finite seconds"};
      }
    }
  }
  return Status::success();
}

FeatureSchema FeatureSchema::default_schema() {
  const std::vector<float> future = {0.33f, 0.67f, 1.0f};
  FeatureSchema schema;
  auto bone = [&](const char* name, FeatureKind kind, const char* role) {
    FeatureChannel c;
    c.name = name;
    c.kind = kind;
    c.bone = role;
    schema.channels.push_back(std::move(c));
  };
  bone("left_foot_position", FeatureKind::BonePosition, "left_foot");
  bone("right_foot_position", FeatureKind::BonePosition, "right_foot");
  bone("left_foot_velocity", FeatureKind::BoneVelocity, "left_foot");
  bone("right_foot_velocity", FeatureKind::BoneVelocity, "right_foot");
  bone("hips_velocity", FeatureKind::BoneVelocity, "hips");
  FeatureChannel positions;
  positions.name = "trajectory_position";
  positions.kind = FeatureKind::TrajectoryPosition;
  positions.times = future;
  schema.channels.push_back(positions);
  FeatureChannel directions;
  directions.name = "trajectory_direction";
  directions.kind = FeatureKind::TrajectoryDirection;
  directions.times = future;
  schema.channels.push_back(directions);
  return schema;
}

}  // namespace mm
