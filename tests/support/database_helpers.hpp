#pragma once
// Small readers and comparisons of a built database (a Database or a DatabaseContents) shared by
// the database test suites (header-only: the support library itself does not link the database).

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mm/database/database.hpp"
#include "mm/database/joint_roles.hpp"
#include "mm/runtime/pose.hpp"

namespace mm::test {

// True when the clip carries the named tag (false when the database has no such tag).
inline bool has_tag(const DatabaseView& db, const ClipRange& clip, const std::string& tag) {
  const std::string names[] = {tag};
  const uint64_t mask = db.tag_mask(names);
  return mask != 0 && (clip.tags & mask) == mask;
}

// Global transforms of one database frame by forward kinematics of its stored locals.
inline std::vector<Transform> frame_globals(const DatabaseView& db, int frame) {
  const int joints = db.joint_count();
  std::vector<Transform> local(joints), global(joints);
  for (int j = 0; j < joints; ++j) {
    local[j].translation = db.local_positions[static_cast<size_t>(frame) * joints + j];
    local[j].rotation = db.local_rotations[static_cast<size_t>(frame) * joints + j];
  }
  forward_kinematics(db.skeleton.parents(), local, global);
  return global;
}

// Exact equality of every field, float for float.
inline void expect_same_database(const DatabaseView& a, const DatabaseView& b) {
  EXPECT_EQ(a.skeleton.names(), b.skeleton.names());
  EXPECT_EQ(a.skeleton.parents(), b.skeleton.parents());
  EXPECT_EQ(a.skeleton.subtree_sizes(), b.skeleton.subtree_sizes());
  ASSERT_EQ(a.skeleton.rest().size(), b.skeleton.rest().size());
  for (size_t j = 0; j < a.skeleton.rest().size(); ++j) {
    EXPECT_EQ(a.skeleton.rest()[j].rotation, b.skeleton.rest()[j].rotation) << j;
    EXPECT_EQ(a.skeleton.rest()[j].translation, b.skeleton.rest()[j].translation) << j;
    EXPECT_EQ(a.skeleton.rest()[j].scale, b.skeleton.rest()[j].scale) << j;
  }
  for (const JointRoleInfo& role : kJointRoles) {
    EXPECT_EQ(a.roles.*role.index, b.roles.*role.index) << role.name;
  }
  EXPECT_EQ(a.frame_time, b.frame_time);
  EXPECT_EQ(a.frame_count, b.frame_count);
  // The pose value by value, whichever layout holds it (a DatabaseContents' arrays, a
  // Database's lanes).
  const auto same = [](const auto& x, const auto& y) {
    if (x.size() != y.size()) return false;
    for (size_t k = 0; k < x.size(); ++k) {
      if (x[k] != y[k]) return false;
    }
    return true;
  };
  EXPECT_TRUE(same(a.local_positions, b.local_positions));
  EXPECT_TRUE(same(a.local_rotations, b.local_rotations));
  EXPECT_TRUE(same(a.local_velocities, b.local_velocities));
  EXPECT_TRUE(same(a.local_angular_velocities, b.local_angular_velocities));
  EXPECT_TRUE(std::ranges::equal(a.contacts, b.contacts));
  ASSERT_EQ(a.clips.size(), b.clips.size());
  for (size_t c = 0; c < a.clips.size(); ++c) {
    EXPECT_EQ(a.clips[c].name, b.clips[c].name);
    EXPECT_EQ(a.clips[c].start, b.clips[c].start);
    EXPECT_EQ(a.clips[c].end, b.clips[c].end);
    EXPECT_EQ(a.clips[c].tags, b.clips[c].tags);
    EXPECT_EQ(a.clips[c].mirrored, b.clips[c].mirrored);
  }
  EXPECT_TRUE(std::ranges::equal(a.tag_names, b.tag_names));
  ASSERT_EQ(a.schema.channels.size(), b.schema.channels.size());
  for (size_t c = 0; c < a.schema.channels.size(); ++c) {
    const FeatureChannel& x = a.schema.channels[c];
    const FeatureChannel& y = b.schema.channels[c];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.kind, y.kind);
    EXPECT_EQ(x.bone, y.bone);
    EXPECT_EQ(x.times, y.times);
    EXPECT_EQ(x.axis, y.axis);
    EXPECT_EQ(x.weight, y.weight);
  }
  EXPECT_TRUE(std::ranges::equal(a.features, b.features));
  EXPECT_TRUE(std::ranges::equal(a.feature_offset, b.feature_offset));
  EXPECT_TRUE(std::ranges::equal(a.feature_scale, b.feature_scale));
  EXPECT_TRUE(std::ranges::equal(a.searchable, b.searchable));
  // frame_clip is derived from the clips; a DatabaseContents has none.
  if (!a.frame_clip.empty() && !b.frame_clip.empty()) {
    EXPECT_TRUE(std::ranges::equal(a.frame_clip, b.frame_clip));
  }
}

}  // namespace mm::test
