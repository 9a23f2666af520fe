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
  const float* f0 = db.frame_pose_lanes(frame0).data();
  const float* f1 = db.frame_pose_lanes(frame1).data();
  Transform t0, t1;
  t0.rotation = pose_lane_rotation(f0, joint);
  t0.translation = pose_lane_vec3(f0, joint, kPoseLanePosition);
  t1.rotation = pose_lane_rotation(f1, joint);
  t1.translation = pose_lane_vec3(f1, joint, kPoseLanePosition);
  if (cubic && frame1 != frame0) {
    return transform_hermite(t0, pose_lane_vec3(f0, joint, kPoseLaneVelocity),
                             pose_lane_vec3(f0, joint, kPoseLaneAngularVelocity), t1,
                             pose_lane_vec3(f1, joint, kPoseLaneVelocity),
                             pose_lane_vec3(f1, joint, kPoseLaneAngularVelocity), db.frame_time(),
                             weight);
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
  pose_hermite(db.frame_pose_lanes(frame0), db.frame_pose_lanes(frame1), db.frame_time(), weight,
               out.first(joints));
}

}  // namespace mm
