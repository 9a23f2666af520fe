#pragma once
// Filling a Database in place: what the file loader (database_file.cpp) and the builder
// (mm/offline/builder.hpp) do, the two ways a database is made from raw data without a copy.
// Internal (database/internal/, never installed): a game gets a Database only from those two,
// already validated, and cannot change it.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "mm/database/database.hpp"

namespace mm::detail {

class DatabaseAssembly {
 public:
  // A database's members under their public names, for the loader's and the builder's code.
  struct Parts {
    Skeleton& skeleton;
    JointRoleIndices& roles;
    float& frame_time;
    int& frame_count;
    std::vector<ClipRange>& clips;
    std::vector<std::string>& tag_names;
    std::vector<std::string>& style_names;
    FeatureSchema& schema;
    std::span<float>& pose_lanes;  // pose_lanes.hpp's layout, frame after frame
    std::span<uint8_t>& contacts;
    std::span<float>& features;
    std::span<float>& feature_offset;
    std::span<float>& feature_scale;
    std::span<uint8_t>& searchable;

    int joint_count() const { return skeleton.joint_count(); }
  };

  // A database with nothing in it, to fill.
  static Database empty() { return Database(); }
  static Parts parts(Database& db) {
    return {db.skeleton_,  db.roles_,          db.frame_time_,    db.frame_count_, db.clips_,
            db.tag_names_, db.style_names_,    db.schema_,        db.pose_lanes_,  db.contacts_,
            db.features_,  db.feature_offset_, db.feature_scale_, db.searchable_};
  }
  // The per-frame arrays for `frames` frames of the skeleton's joints and the schema's columns,
  // their values unwritten: the caller writes every one.
  static void allocate(Database& db, size_t frames) {
    db.allocate(frames, static_cast<size_t>(db.joint_count()),
                static_cast<size_t>(db.feature_dims()));
  }
  // Drops the frames from `frames` on (the builder's reserved idle frames, when it finds no
  // source for them).
  static void keep_frames(Database& db, size_t frames) { db.keep_frames(frames); }
  // frame_clip from the clips, which must tile the frames.
  static void derive_frame_clip(Database& db) { db.derive_frame_clip(); }
  // The pose, per joint as the build side writes it (`pose`: one value per joint of each of the
  // database's frames), laid out in the database's lanes.
  static void lay_out_pose(Database& db, const PoseFrameView& pose) { db.lay_out_pose(pose); }
  // The per-frame arrays, writable, for the build side's writers: the pose in `pose`'s per-joint
  // arrays (laid out by lay_out_pose when they are final), the rest in the database.
  struct WritablePose {
    std::span<glm::vec3> positions;
    std::span<glm::quat> rotations;
    std::span<glm::vec3> velocities;
    std::span<glm::vec3> angular_velocities;
  };
  static DatabaseFill fill(Database& db, const WritablePose& pose) {
    return DatabaseFill(db, pose.positions, pose.rotations, pose.velocities,
                        pose.angular_velocities, db.contacts_, db.features_, db.searchable_);
  }
};

}  // namespace mm::detail
