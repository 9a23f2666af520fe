#pragma once
// Small readers of a built Database shared by the database test suites (header-only: the
// support library itself does not link the database).

#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/runtime/pose.hpp"

namespace mm::test {

// True when the clip carries the named tag (false when the database has no such tag).
inline bool has_tag(const Database& db, const ClipRange& clip, const std::string& tag) {
  const std::string names[] = {tag};
  const uint64_t mask = db.tag_mask(names);
  return mask != 0 && (clip.tags & mask) == mask;
}

// Global transforms of one database frame by forward kinematics of its stored locals.
inline std::vector<Transform> frame_globals(const Database& db, int frame) {
  const int joints = db.joint_count();
  std::vector<Transform> local(joints), global(joints);
  for (int j = 0; j < joints; ++j) {
    local[j].translation = db.local_positions[static_cast<size_t>(frame) * joints + j];
    local[j].rotation = db.local_rotations[static_cast<size_t>(frame) * joints + j];
  }
  forward_kinematics(db.skeleton.parents(), local, global);
  return global;
}

}  // namespace mm::test
