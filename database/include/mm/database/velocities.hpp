#pragma once
// Velocities of frame-major joint values by finite differences: the builder's preprocessing
// computes them, and the file loader recomputes them with the same code instead of storing them,
// so what a file loads to is fixed by the format's side of the tree, not by the build pipeline.

#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace mm {

// The angular velocity (radians / second, as a rotation vector) that turns `from` into `to` in
// 1 / inv_dt seconds, one sample as compute_local_velocities computes it (which does four at a
// time where it can, with the same bits).
glm::vec3 angular_velocity_between(const glm::quat& from, const glm::quat& to, float inv_dt);

// Finite-difference velocities and angular velocities of frame-major local positions and
// rotations (frame_count * joint_count each) into the two output arrays of the same size:
// central differences inside, one-sided at the ends, zero for a single frame. Returns whether
// every value written is finite (finite positions far apart can give an infinite velocity).
bool compute_local_velocities(std::span<const glm::vec3> positions,
                              std::span<const glm::quat> rotations, int frame_count,
                              int joint_count, float frame_time, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> angular_velocities);

}  // namespace mm
