// How far a leg reaches toward its target (leg_reach.hpp).

#include "mm/controller/leg_reach.hpp"

#include <algorithm>
#include <cmath>

namespace mm {

glm::vec3 soft_reach(const glm::vec3& hip_to_ankle, float animated_distance, float keep_animated,
                     float length) {
  const float d = glm::length(hip_to_ankle);
  const float soft = kSoftReach * length;
  // Kept no nearer full length than the softening's least span: kept nearer, the reach went on
  // past the leg's length (the leg clamped straight, where its knee moves fastest).
  const float straightest = (1.0f - kMinSoftSpan) * length;
  const float kept =
      std::min(soft + keep_animated * std::max(0.0f, std::min(animated_distance, length) - soft),
               straightest);
  if (d <= kept || d < 1e-6f) return hip_to_ankle;
  const float span = length - kept;
  const float reached = kept + span * (1.0f - std::exp(-(d - kept) / span));
  return hip_to_ankle * (reached / d);
}

glm::vec3 short_below(const glm::vec3& hip_to_ankle, float length) {
  glm::vec2 across(hip_to_ankle.x, hip_to_ankle.z);
  const float out = glm::length(across);
  if (out > length) across *= length / out;
  const float down = std::sqrt(std::max(0.0f, length * length - glm::dot(across, across)));
  return glm::vec3(across.x, -down, across.y);
}

glm::vec3 reach_down(const glm::vec3& hip_to_ankle, const glm::vec3& reached, float weight) {
  const float w = std::clamp(weight, 0.0f, 1.0f);
  const float length = glm::length(reached);
  if (!(w > 0.0f) || !(hip_to_ankle.y < 0.0f) || !(length < glm::length(hip_to_ankle))) {
    return reached;
  }
  const glm::vec3 mixed = glm::mix(reached, short_below(hip_to_ankle, length), w);
  const float mixed_length = glm::length(mixed);
  return mixed_length > 1e-6f ? mixed * (length / mixed_length) : reached;
}

glm::vec3 reach_at_most(const glm::vec3& hip_to_ankle, float length, float weight) {
  const float d = glm::length(hip_to_ankle);
  if (!(d > length)) return hip_to_ankle;
  return reach_down(hip_to_ankle, hip_to_ankle * (length / d), weight);
}

}  // namespace mm
