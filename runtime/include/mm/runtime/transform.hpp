#pragma once
// Rigid transforms (rotation + translation, optional scale) on GLM. See docs/conventions.md:
// metres, Y up, right-handed, column vectors (M * v), quaternions glm::quat(w, x, y, z).

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm {

// A local or global joint transform. Applying it to a point p gives
// rotation * (scale * p) + translation.
struct Transform {
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // unit quaternion
  glm::vec3 translation{0.0f};                 // metres
  glm::vec3 scale{1.0f};                       // per-axis; 1 for rigid joints

  static Transform identity() { return {}; }
};

// parent * child: the child's transform expressed in the parent's parent space. Rotations
// compose parent-first; the child's translation is rotated (and scaled) by the parent.
inline Transform compose(const Transform& parent, const Transform& child) {
  Transform out;
  out.rotation = parent.rotation * child.rotation;
  out.translation = parent.rotation * (parent.scale * child.translation) + parent.translation;
  out.scale = parent.scale * child.scale;
  return out;
}

// The inverse of a rigid transform (exact when scale is uniform).
inline Transform inverse(const Transform& t) {
  Transform out;
  out.rotation = glm::conjugate(t.rotation);
  out.scale = 1.0f / t.scale;
  out.translation = out.scale * (out.rotation * -t.translation);
  return out;
}

inline glm::vec3 transform_point(const Transform& t, const glm::vec3& p) {
  return t.rotation * (t.scale * p) + t.translation;
}

inline glm::vec3 transform_vector(const Transform& t, const glm::vec3& v) {
  return t.rotation * (t.scale * v);
}

// The 4x4 column-major matrix of a transform (T * R * S).
glm::mat4 to_matrix(const Transform& t);

}  // namespace mm
