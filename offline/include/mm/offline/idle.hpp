#pragma once
// The idle clip. A controller needs something to play while the character stands still, and
// motion capture made of takes that never stop (the Bandai set has no idle at all) offers
// none. The builder (builder.hpp) therefore appends one synthetic clip that holds a single
// pose: the calmest frame of the database that stands on both feet, placed at the origin with
// every velocity zero. This file chooses that frame and fills the clip; the builder reserves
// the clip's frames, extracts its features and normalizes them with the rest.
//
// Choosing the pose. A frame is a candidate when
//   - it belongs to a clip that is neither a mirrored copy (its pose exists unmirrored, and a
//     copy's energy differs from its original's only by float rounding, which would then
//     decide between two equal poses) nor the idle clip itself (is_idle_clip);
//   - both foot contacts are set;
//   - the simulation root (joint 0) moves horizontally slower than
//     IdleCriteria::max_root_speed (the character is not travelling);
//   - the two feet (the left_foot and right_foot roles) are closer than
//     IdleCriteria::max_feet_distance horizontally, by forward kinematics of the frame (side
//     by side, not the double support of a stride);
//   - the arms hang: every arm end (arm_end_joints: the hands, or the lower arms) is lower
//     than the hips plus IdleCriteria::max_arm_end_over_hips (a lower arm's joint is the elbow,
//     which hangs at the waist: it is measured from two thirds of the way from the hips to its
//     upper arm). Without this the calmest frame of a gesture take can be a hand held still above
//     the head at the top of the gesture.
// The candidate with the least motion energy wins, the lowest frame on a tie:
//   energy = sum over every joint but joint 0 of |local angular velocity|^2 (rad^2/s^2)
//          + sum over the source roots (the children of joint 0) of |local velocity|^2
//            (m^2/s^2),
// so nothing turns at any joint and the body does not drift over its root: a pose held still
// looks natural only if it was still when captured.

#include <string>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/offline/clip.hpp"

namespace mm {

// The thresholds a candidate frame must meet (see the top of this file).
struct IdleCriteria {
  float max_root_speed = 0.05f;    // metres / second, horizontal speed of joint 0
  float max_feet_distance = 0.4f;  // metres, horizontal distance between the two feet
  // Metres: how far above the hips an arm end may be (0: the hands must be below the hips).
  float max_arm_end_over_hips = 0.0f;
};

// What search_idle_source found, with the counts that explain an empty answer.
struct IdleSourceSearch {
  int frame = -1;         // database frame of the calmest standing frame, -1 when none
  double energy = 0.0;    // its motion energy
  int on_both_feet = 0;   // frames (of the clips searched) with both contacts
  int slow = 0;           // ... of which the root is slower than max_root_speed
  int feet_together = 0;  // ... of which the feet are closer than max_feet_distance
  int arms_down = 0;      // ... of which the arm ends are low enough: the candidates
};

// The motion energy of one frame (see the top of this file).
double idle_motion_energy(const DatabaseView& db, int frame);

// Horizontal distance in metres between the left_foot and right_foot roles' global positions
// on one frame; infinity when the database lacks either role.
float horizontal_feet_distance(const DatabaseView& db, int frame);

// The joints the arm check looks at: the two hand roles (or, without hands, the lower arms,
// whose ends are the wrists) when the joint map has both sides; otherwise the leaves of the
// skeleton (joints without children) that lie neither in the head role's subtree nor in a foot
// role's. Empty, without arm roles, when the head or hips role is missing (the head itself
// would then pass for a raised hand), which leaves the check out.
std::vector<int> arm_end_joints(const Skeleton& skeleton, const JointRoleIndices& roles);

// How far in metres the highest arm end of one frame is above the hips (negative: below), a
// lower arm above two thirds of the way from the hips to its upper arm; minus infinity when
// there are no arm ends.
float highest_arm_end_over_hips(const DatabaseView& db, int frame);

// The calmest standing frame and the candidate counts. Reads the motion arrays, contacts,
// clips and roles; deterministic (one pass in frame order).
IdleSourceSearch search_idle_source(const DatabaseView& db, const IdleCriteria& criteria = {});

// search_idle_source(db, criteria).frame: the calmest standing frame, -1 when none qualifies.
int find_calmest_standing_frame(const DatabaseView& db, const IdleCriteria& criteria = {});

// A sentence saying why `search` found no frame ("no frame stands with both feet in contact",
// ...), for the builder's warning; empty when it found one.
std::string idle_search_failure(const IdleSourceSearch& search, const IdleCriteria& criteria = {});

// Fills the motion arrays of `range` (frames already allocated in db) with `source_frame`
// held still: joint 0 at the origin with the identity rotation (facing +Z), every other
// joint's local transform copied from the source frame (they are relative to the simulation
// root already, so the pose stands on the ground exactly as captured), every velocity and
// angular velocity zero, both contacts 1. The source frame must lie outside `range`. Features,
// searchable flags and frame_clip are the caller's (extract_range_features).
void fill_idle_clip(const DatabaseFill& db, const ClipRange& range, int source_frame);

// ---- Idle clips of the data -------------------------------------------------------------

// Where real idle motion (a person standing, e.g. ReActIdle's) is calm enough to play while
// the character stands: both feet planted and the body facing one way. Steps and turns inside a
// long take would otherwise slide or turn a character that should stand.
struct CalmIdleCriteria {
  // Metres / second: the horizontal speed of each foot (the foot roles) on a calm frame.
  float max_foot_speed = 0.1f;
  // Radians: how far the body's facing (across the upper legs) may turn from a segment's start.
  float max_turn = 0.26f;
  // Seconds: segments shorter than this are dropped (the features look 1 s ahead and the
  // controller never jumps into the last second of a clip).
  float min_seconds = 4.0f;
};

// The calm segments of an idle clip, each a clip of its own named "<name>_at<start>s" (start in
// whole seconds into the take), in time order. `roles` are indices in the clip's skeleton.
std::vector<Clip> calm_idle_segments(const Clip& clip, const JointRoleIndices& roles,
                                     const CalmIdleCriteria& criteria = {});

}  // namespace mm
