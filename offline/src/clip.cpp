#include "mm/offline/clip.hpp"
#include "mm/runtime/finite.hpp"

#include <cmath>

namespace mm {

namespace {}  // namespace

Status Clip::validate() const {
  const std::string where = "clip '" + name + "': ";
  if (!(frame_time > 0.0f) || !std::isfinite(frame_time)) {
    return Error{where + "frame time must be a positive finite number of seconds"};
  }
  if (frame_count <= 0) return Error{where + "has no frames"};
  if (joint_count() == 0) return Error{where + "has no joints"};
  if (local.size() != static_cast<size_t>(frame_count) * joint_count()) {
    return Error{where + "expected " + std::to_string(frame_count * joint_count()) +
                 " local transforms, found " + std::to_string(local.size())};
  }
  if (!end_sites.empty() && end_sites.size() != static_cast<size_t>(joint_count())) {
    return Error{where + "expected no End Sites or one per joint (" +
                 std::to_string(joint_count()) + "), found " + std::to_string(end_sites.size())};
  }
  for (const glm::vec3& end : end_sites) {
    if (!finite(end)) return Error{where + "an End Site offset is not finite"};
  }
  for (size_t i = 0; i < local.size(); ++i) {
    const Transform& t = local[i];
    const float n = glm::length(t.rotation);
    if (!finite(t.translation) || !finite(t.scale) || !std::isfinite(n) ||
        std::abs(n - 1.0f) > 1e-3f) {
      return Error{where + "frame " + std::to_string(i / joint_count()) + ", joint '" +
                   skeleton.name(static_cast<int>(i % joint_count())) +
                   "': non-finite transform or non-unit rotation"};
    }
  }
  return Status::success();
}

}  // namespace mm
