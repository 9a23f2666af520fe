#pragma once
// Preprocessing: what happens to one imported Clip before it joins a Database.
//
//   resample_clip       -> the database rate (slerp rotations, lerp translations and scales)
//   mirror_clip         -> optional left/right mirror across the YZ plane (x -> -x), each
//                          bone kept in its own axis convention
//   preprocess_clip     -> simulation root (joint 0), joint velocities and angular velocities,
//                          foot contacts, in the database's per-frame layout
//
// Everything here works on one clip and never looks past its ends: finite differences are
// one-sided at the first and last frame, and the smoothing filters shrink their windows there.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/database/database.hpp"
#include "mm/database/velocities.hpp"
#include "mm/offline/clip.hpp"
#include "mm/offline/joint_map.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// ---- Joint roles ---------------------------------------------------------------------------

// JointRoles (the names each role may have) and the role table are in joint_roles.hpp.

// Finds every role in `skeleton`, by name and then by structure (joint_roles.hpp). The hips,
// upper legs, lower legs and feet are required: a missing one is an error naming the role, the
// names looked for and the skeleton's joints; legs whose joints are not one chain below the hips
// are refused too. Every other role is optional (-1 when absent).
Result<JointRoleIndices> find_joint_roles(const Skeleton& skeleton, const JointRoles& roles);

// Every joint a map (or --role) names exists in `skeleton`; otherwise an error naming the map
// file and line, the role and the skeleton's joints.
Status check_joint_map(const Skeleton& skeleton, std::span<const JointRoleAssignment> assignments);

// ---- Mirroring -----------------------------------------------------------------------------

// Two joints that swap places when a clip is mirrored.
struct MirrorPair {
  std::string left;   // exact joint name
  std::string right;  // exact joint name
};

// The joint each joint takes its mirrored motion from: pairs detected from name patterns
// (suffixes _L/_R, .L/.R, -L/-R in either case, prefixes L_/R_ and l_/r_, and the words
// Left/Right or left/right anywhere), with `overrides` applied first (their names must exist).
// Unpaired joints map to themselves. Fails when a joint would pair with two others.
Result<std::vector<int>> mirror_joint_map(const Skeleton& skeleton,
                                          std::span<const MirrorPair> overrides = {});

// The constant rotation C_j, per joint, that mirror_clip puts behind each reflected rotation so
// that the joint keeps its own bone-axis convention. It is computed from the rest pose: a joint
// is mirrored by N_j = M C_j (M = diag(-1, 1, 1), N_j improper, in the joint's frame), where
// - a joint whose child bones point in several directions (hips, chest) takes the N that best
//   maps its rest child offsets onto its partner's (the plane its side bones are mirrored by);
// - a joint with one child takes the child's N carried through the rest rotations when that
//   keeps its bone on the partner's bone's side (a spine segment follows the chest it carries);
// - any other joint takes its parent's N (a root: M, the world's) carried through the rest
//   rotations, turned half a turn about the mirror normal when its bone would point away from
//   the partner's (limbs whose right-side offsets are the negated left ones);
// - a joint and its partner get inverse maps, and a joint that is its own partner an
//   involution, so that mirroring twice is the identity.
// For a rest pose that is already symmetric across the world's YZ plane, N_j = Q_m(j)^-1 M Q_j
// with Q the rest global rotations, so C_j = identity where a joint's rest frame is the mirror
// of its partner's. The result depends only on the rest transforms and joint_map.
std::vector<glm::quat> mirror_corrections(const Skeleton& skeleton, std::span<const int> joint_map);

// The clip mirrored across the world's YZ plane (x -> -x; the character's left/right plane when
// it faces +Z): every joint's GLOBAL transform is taken from its mirror joint (joint_map from
// mirror_joint_map) and reflected (position x -> -x, rotation R -> M R M, as a quaternion
// (w, x, -y, -z)), then turned by the joint's mirror_corrections so that its local axes keep
// the joint's own convention (no half turns against the original's local rotations); locals
// are recomputed from the globals. Global positions are exactly the reflected partner's; local
// translations equal the rest offsets where the skeleton is left/right symmetric. Named
// "<name>_mirror". Mirroring twice gives the original back (up to float rounding).
Clip mirror_clip(const Clip& clip, std::span<const int> joint_map);

// ---- Resampling ----------------------------------------------------------------------------

// True when the clip's frame time differs from 1 / rate by more than 0.1 % (BVH files store
// 0.0333333 for 30 Hz, which counts as 30 Hz).
bool needs_resampling(const Clip& clip, float rate);

// The clip sampled every 1 / rate seconds from 0 to its duration (a tail shorter than half a
// frame is dropped; a clip that needs no resampling is copied with its frame time set to exactly
// 1 / rate): rotations by slerp, translations and scales by lerp between the neighbouring frames.
Clip resample_clip(const Clip& clip, float rate);

// ---- Simulation root, velocities, contacts -------------------------------------------------

// How joint 0, the simulation root, is derived from the hips.
struct SimulationRootOptions {
  // The hips' bone-local axis that points forward; the Bandai hips' local +Z does.
  glm::vec3 hips_forward_axis{0.0f, 0.0f, 1.0f};
  // Standard deviation in seconds of the centred Gaussian that smooths the facing direction
  // vectors (window +-3 sigma, shrunk at the clip ends). 0.3 s brings the hips' +-5..9 degree
  // swing of a walk (about 1.2 s per stride) down to about a third, and a run's to almost
  // nothing, while a 90 degree turn over 1.5 s keeps its shape. 0 disables smoothing.
  float facing_smoothing = 0.3f;
  // The same for the ground position; 0 (the default) keeps exactly the hips projected to the
  // ground, including the hips' +-3 cm sideways sway.
  float position_smoothing = 0.0f;
  // Holds joint 0 still at the clip's mean ground position and mean facing (the two smoothings
  // are then moot): the builder sets it for idle clips, whose sways and weight shifts must
  // move the body, never the character.
  bool fixed = false;
};

// How foot contacts are detected. A foot is in contact on a frame when its toe joint is low and
// slow, or its foot (ankle) joint is low and slow (speeds are 3D, in world space, by central
// differences). Defaults come from the Bandai data: planted toes sit at 0.042-0.046 m and
// planted ankles at 0.117-0.125 m above y = 0, planted joints move under 0.3 m/s while a
// swinging foot of a walk moves at 1-4 m/s.
struct ContactOptions {
  float toe_height = 0.06f;   // metres above y = 0
  float foot_height = 0.15f;  // metres above y = 0
  float speed = 0.6f;         // metres per second
  // Width in seconds of the majority (median) filter that removes one-frame flickers; it is
  // rounded to an odd number of frames (0.1 s at 30 Hz: 3 frames). 0 disables the filter.
  float filter_window = 0.1f;
};

// Everything preprocess_clip needs besides the clip.
struct PreprocessOptions {
  SimulationRootOptions root;
  ContactOptions contacts;
};

// The name of the joint preprocess_clip inserts in front of the source skeleton.
inline constexpr const char* kSimulationJointName = "Simulation";

// The database skeleton of a source skeleton: a new root joint 0 named "Simulation" (identity
// rest) followed by the source joints, whose roots become its children. Fails when the source
// already has a joint with that name.
Result<Skeleton> add_simulation_root(const Skeleton& source);

// One preprocessed clip in database layout: joint 0 is the simulation root, joints 1.. are the
// source joints; arrays are frame-major ([frame * joint_count + joint]).
struct ProcessedClip {
  std::string name;         // clip name ("<stem>_mirror" for mirrored copies)
  std::string source_path;  // the file it came from
  bool mirrored = false;
  int frame_count = 0;
  int joint_count = 0;  // source joints + 1
  float frame_time = 1.0f / 30.0f;
  std::vector<glm::vec3> local_positions;           // metres
  std::vector<glm::quat> local_rotations;           // unit
  std::vector<glm::vec3> local_velocities;          // metres / second, parent frame
  std::vector<glm::vec3> local_angular_velocities;  // radians / second, parent frame
  std::vector<uint8_t> contacts;                    // [frame * 2 + 0] left, + 1 right
};

// Where preprocess_clip writes one clip's database arrays (e.g. straight into a Database's
// arrays at the clip's first frame). The four joint arrays hold frame_count * (source joints
// + 1) values, frame-major; contacts hold frame_count * 2.
struct ClipMotionOutput {
  std::span<glm::vec3> local_positions;
  std::span<glm::quat> local_rotations;
  std::span<glm::vec3> local_velocities;
  std::span<glm::vec3> local_angular_velocities;
  std::span<uint8_t> contacts;
};

// Buffers preprocess_clip reuses between clips so that its per-frame loops do not allocate.
struct PreprocessScratch {
  std::vector<Transform> globals;  // frames * source joints (only the joints needed are set)
  std::vector<uint8_t> needed;     // per source joint: its global transform is computed
  std::vector<glm::vec3> directions;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> smoothed;
  std::vector<float> weights;
  std::vector<uint8_t> raw_contacts;
};

// Preprocesses one clip already at the database rate. `roles` are indices into the clip's own
// (source) skeleton, from find_joint_roles.
//
// - Simulation root (joint 0): position = the global hips position projected to y = 0
//   (optionally smoothed); rotation = the yaw-only facing of the hips' forward axis projected on
//   the ground and smoothed (see SimulationRootOptions). Its local +Z is the facing.
// - Source root joints: local = inverse(simulation global) * original global, so globals are
//   unchanged (joint_Root's own translation, present in some takes, is kept). Other joints keep
//   their locals. Scales are dropped (the database stores rigid transforms).
// - Velocities by finite differences of the locals (central inside the clip, one-sided at its
//   ends); angular velocities = scaled angle axis of q[f+1] * conjugate(q[f-1]) / (2 dt) (the
//   shortest path), a rotation vector in the PARENT's frame (for joint 0: the world).
// - Contacts as described by ContactOptions.
Status preprocess_clip(const Clip& clip, const JointRoleIndices& roles,
                       const PreprocessOptions& options, ProcessedClip& out,
                       PreprocessScratch& scratch);

// The same, writing into caller-owned arrays of exactly the sizes ClipMotionOutput describes
// (a size mismatch is an error).
Status preprocess_clip(const Clip& clip, const JointRoleIndices& roles,
                       const PreprocessOptions& options, const ClipMotionOutput& out,
                       PreprocessScratch& scratch);

}  // namespace mm
