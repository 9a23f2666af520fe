#pragma once
// Sampling the database between two of its frames: the controller's playback, and the
// evaluation's baseline (the data played straight through), so that both play alike.

#include <cstddef>
#include <span>

#include "mm/database/database.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose_hermite.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// One joint's local transform between database frames frame0 and frame1 (`weight` of frame1,
// in [0, 1]): cubic Hermite through both frames' values and velocities when `cubic` and the
// frames differ, else the two-point interpolation `method`.
inline Transform sample_database_joint(const Database& db, int frame0, int frame1, float weight,
                                       size_t joint, bool cubic, InterpolationMethod method) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  const size_t k0 = static_cast<size_t>(frame0) * joints + joint;
  const size_t k1 = static_cast<size_t>(frame1) * joints + joint;
  Transform t0, t1;
  t0.rotation = db.local_rotations()[k0];
  t0.translation = db.local_positions()[k0];
  t1.rotation = db.local_rotations()[k1];
  t1.translation = db.local_positions()[k1];
  if (cubic && frame1 != frame0) {
    return transform_hermite(t0, db.local_velocities()[k0], db.local_angular_velocities()[k0], t1,
                             db.local_velocities()[k1], db.local_angular_velocities()[k1],
                             db.frame_time(), weight);
  }
  return interpolate(t0, t1, weight, method);
}

// Every joint's sample_database_joint at once (`out`: one entry per joint), to the bit.
inline void sample_database_pose(const Database& db, int frame0, int frame1, float weight,
                                 bool cubic, InterpolationMethod method, std::span<Transform> out) {
  const size_t joints = static_cast<size_t>(db.joint_count());
  if (!cubic || frame1 == frame0) {
    for (size_t j = 0; j < joints; ++j) {
      out[j] = sample_database_joint(db, frame0, frame1, weight, j, cubic, method);
    }
    return;
  }
  const auto frame = [&](int f) {
    const size_t k = static_cast<size_t>(f) * joints;
    return PoseFrameView{
        db.local_rotations().subspan(k, joints), db.local_positions().subspan(k, joints),
        db.local_velocities().subspan(k, joints), db.local_angular_velocities().subspan(k, joints)};
  };
  pose_hermite(frame(frame0), frame(frame1), db.frame_time(), weight, out.first(joints));
}

}  // namespace mm
