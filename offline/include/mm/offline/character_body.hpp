#pragma once
// The character's body: a skinned mesh generated from the skeleton, for databases whose motion
// capture comes without one (BVH never carries a mesh), and the loader of a body made
// elsewhere (a .glb whose joint names match the database's).
//
// Generation has three phases:
// 1. Bind pose (make_bind_pose). Limbs must stand clear of the torso, or the generated surface
//    merges them and skinning tears them apart. A standing frame (bind_source_frame: the idle
//    clip's pose, which stands still on both feet with the arms down) is turned into an
//    A-pose: each upper and lower arm is aimed outward and down at
//    BindPoseOptions::arm_angle_degrees below the horizontal, each thigh and shin straight down
//    and BindPoseOptions::leg_angle_degrees outward, the feet keep their captured orientation,
//    the whole pose is shifted vertically so the feet stay at their captured height, turned
//    about the vertical so the hips' lateral axis (right thigh to left thigh) is +X (the
//    character faces +Z) and moved so the hips are above the origin. The joints above the
//    hips (a database's simulation root, Bandai's ground-projected joint_Root) are put at the
//    origin with the identity rotation.
// 2. Bone segments (character_bone_segments): tapered capsules in bind space with radii by
//    role, for an adult of hips height 0.92 m scaled by the skeleton's hips height: the spine
//    from hips to head as two capsules side by side (a torso is wider than deep), the neck,
//    the head an elongated sphere above the neck, clavicles, arms and legs tapering toward the
//    hands and feet, a heel under each ankle; hands and toes, which are leaves without length
//    in the Bandai skeleton, are given length along their parent bone, and a lower arm without
//    a hand (ReActIdle's) a forearm as long as its upper arm and a hand, along the axis of its
//    frame that the upper arm runs along in its own (the bind pose aims it likewise). Joints the
//    roles do not explain (fingers, tails, a skeleton without roles) get capsules to their children
//    whose radius follows the bone's length. Joints above the hips get no geometry. Each segment
//    belongs to the joint it starts at.
// 3. Mesh and weights: generate_body_mesh (runtime/body.hpp) and compute_bone_weights
//    (runtime/bone_weights.hpp) with the caller's method, heat diffusion by default.
//
// Units: metres, Y up, right-handed; the bind pose faces +Z (the character's left is +X).

#include <filesystem>
#include <span>
#include <vector>

#include "mm/database/database.hpp"
#include "mm/offline/body.hpp"
#include "mm/offline/bone_weights.hpp"
#include "mm/runtime/mesh.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/skeleton.hpp"

namespace mm {

struct BindPoseOptions {
  // Angle of the arms below the horizontal, in the frontal plane (0: T-pose, 90: hanging).
  float arm_angle_degrees = 40.0f;
  // Angle of the legs out from the vertical, in the frontal plane.
  float leg_angle_degrees = 6.0f;
};

struct CharacterBodyOptions {
  BindPoseOptions pose;
  BodyMeshOptions mesh;
  BoneWeightOptions weights;  // heat diffusion unless the caller chooses otherwise
};

// A generated body and what it was made from.
struct CharacterBody {
  SkinnedMesh skinned;                // the mesh in bind pose, its weights, bind_global per joint
  std::vector<Transform> bind_local;  // the bind pose as local transforms, one per joint
  std::vector<BoneSegment> segments;  // the capsules the surface was built around
  double mesh_seconds = 0.0;          // wall time of generate_body_mesh
  double weight_seconds = 0.0;        // wall time of compute_bone_weights
};

// The database frame the bind pose starts from: the idle clip's first frame, else the calmest
// standing frame (find_calmest_standing_frame), else frame 0; -1 for an empty database.
int bind_source_frame(const DatabaseView& db);

// The bind pose (phase 1 above) from any pose of the skeleton (local transforms, one per
// joint). Limbs are found from the roles: the legs are the chains from the hips to each foot,
// the arms the chains from the spine (hips to head) to each arm end (arm_end_joints); a role
// that is missing leaves its limbs as they are.
std::vector<Transform> make_bind_pose(const Skeleton& skeleton, std::span<const Transform> local,
                                      const JointRoleIndices& roles,
                                      const BindPoseOptions& options = {});

// The tapered capsules around the skeleton in a bind pose (phase 2 above), given the bind
// pose's global transforms. No radius is below min_radius (use the mesh's voxel size, so thin
// bones do not fall between grid points).
std::vector<BoneSegment> character_bone_segments(const Skeleton& skeleton,
                                                 std::span<const Transform> bind_global,
                                                 const JointRoleIndices& roles, float min_radius);

// The body of a skeleton in the given bind pose (local transforms, one per joint): segments,
// mesh and weights. Fails with a message when the pose does not match the skeleton, when no
// bone has any length, or when mesh generation or weighting fails.
Result<CharacterBody> build_character_body(const Skeleton& skeleton,
                                           std::span<const Transform> bind_local,
                                           const JointRoleIndices& roles,
                                           const CharacterBodyOptions& options = {});

// The body of a database's character: make_bind_pose of bind_source_frame, then the above.
Result<CharacterBody> build_character_body(const DatabaseView& db,
                                           const CharacterBodyOptions& options = {});

// Loads a skinned glTF body (load_gltf with read_skinned_mesh) and maps its joints onto
// `skeleton` by name: the influences refer to `skeleton`'s joint indices and bind_global has
// one transform per `skeleton` joint (joints the body's skin lacks are bound where the
// skeleton's rest pose puts them under their parent's bind transform; nothing weights them).
// Fails naming the file when it cannot be read or has no skinned mesh, and listing every
// weighted joint name `skeleton` lacks.
Result<SkinnedMesh> load_body_gltf(const std::filesystem::path& path, const Skeleton& skeleton);

}  // namespace mm
