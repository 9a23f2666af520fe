#pragma once
// The feature schema is data: a list of channels, each a kind, a bone, times in seconds and a
// weight. Every channel fills a contiguous range of columns of the feature matrix, and forms
// one normalization group (its columns share one standard deviation).

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mm/runtime/result.hpp"

namespace mm {

enum class FeatureKind : uint8_t {
  BonePosition = 0,         // bone position in the simulation-root frame (3 floats)
  BoneVelocity = 1,         // bone velocity in the simulation-root frame (3 floats)
  TrajectoryPosition = 2,   // root position at each time, on the ground plane (x, z per time)
  TrajectoryDirection = 3,  // root facing at each time, on the ground plane (x, z per time)
  BoneDirection = 4,        // a bone's local `axis` in the simulation-root frame (3 floats)
};

struct FeatureChannel {
  std::string name;  // unique, e.g. "left_foot_position"
  FeatureKind kind = FeatureKind::BonePosition;
  std::string bone;          // role or joint name for bone kinds (empty for trajectory kinds)
  std::vector<float> times;  // seconds relative to the frame, for trajectory kinds (may be < 0)
  glm::vec3 axis{0.0f, 0.0f, 1.0f};  // the bone-local axis for BoneDirection
  float weight = 1.0f;               // > 0; larger means the channel matters more in the distance

  int dims() const;
};

struct FeatureSchema {
  std::vector<FeatureChannel> channels;

  int dims() const;
  // The first column of channel i.
  int offset(int channel) const;
  // One name per column, in column order: the channel's name and the axis for bone kinds
  // ("left_foot_position_x"), and the time too for trajectory kinds
  // ("trajectory_position_0.33s_x", times as the shortest decimal that reads back, in seconds).
  std::vector<std::string> column_names() const;
  // Names unique and non-empty, weights positive and finite, bone kinds name a bone,
  // trajectory kinds have at least one finite time.
  Status validate() const;

  // DESIGN.md's default 27 floats: left/right foot position and velocity, hip velocity,
  // future trajectory positions and directions at 0.33, 0.67 and 1.0 s. Its bones are role
  // names ("left_foot", "right_foot", "hips"): a channel's bone that equals a role name is
  // resolved through the builder's joint roles, any other string is an exact joint name.
  static FeatureSchema default_schema();
};

}  // namespace mm
