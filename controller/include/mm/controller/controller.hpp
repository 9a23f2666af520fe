#pragma once
// The motion-matching character controller: one per character, updated once per game frame.
//
// Every update(dt, input):
//   input -> desired velocity and facing (camera-relative stick, walk/run speeds per direction)
//   -> simulation object: a spring character (position, velocity, acceleration) and a rotation
//      spring (facing, angular velocity), with its trajectory predicted at the feature times
//   -> search every search_interval seconds, at once on a sharp change of the desired motion, a
//      new tag request or the end of the playing clip; switch only when the best candidate beats
//      continuing (the search's transition cost)
//   -> inertialized transition: joint and root offsets that decay with a halflife
//   -> playback advances continuously; poses between database frames are interpolated
//   -> root motion: the database root's motion re-expressed in the character's frame through
//      the transition source and destination
//   -> synchronization of the character and the simulation object
//   -> foot locking: a foot in contact keeps its toe where it landed (two-bone IK, then
//      distance-constraint relaxation for exact bone lengths), released smoothly
//   -> forward kinematics: global transforms and skinning matrices.
//
// update() never allocates, logs or touches files: every buffer is sized in create(). Any
// number of controllers may share one ControllerDatabase and update in parallel threads.
// Units: metres, seconds, radians; Y up (docs/conventions.md).
//
// Big worlds: the state is kept relative to a local origin that follows the character
// (local_origin.hpp), so a character 100 km from the world origin moves exactly as one at it.
// global_transforms() stay world transforms in float (exact as before near the world origin,
// rounded to float far from it); a game far away reads origin() (double) and
// origin_transforms() (float, relative to it) instead, and places characters with
// teleport_world() and adjust_root_world(). See docs/controller.md, "Big worlds".

#include <array>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mm/controller/character_mover.hpp"
#include "mm/controller/climb_pace.hpp"
#include "mm/controller/foot_placement.hpp"
#include "mm/controller/input.hpp"
#include "mm/controller/local_origin.hpp"
#include "mm/controller/obstacle_brake.hpp"
#include "mm/controller/world.hpp"
#include "mm/database/database.hpp"
#include "mm/runtime/dead_blending.hpp"
#include "mm/runtime/fk_plan.hpp"
#include "mm/runtime/inertialization.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/spring.hpp"
#include "mm/runtime/transform.hpp"
#include "mm/search/search.hpp"

namespace mm {

// How the animated character and the simulation object are kept together.
enum class SyncMode : uint8_t {
  CharacterFollowsSimulation,  // the character's root is pulled toward the simulation object
  SimulationFollowsCharacter,  // the simulation object is placed where the character went
  None,                        // each goes its own way (for debugging)
};

// How the body (every joint below the root) goes from one clip to the next. The root is always
// inertialized: the synchronization with the simulation works on its offsets.
enum class TransitionMode : uint8_t {
  DeadBlending,     // cross-fade from the extrapolated outgoing pose (dead_blending.hpp)
  Inertialization,  // decaying offsets on the incoming clip (inertialization.hpp)
};

// "character", "simulation" or "none".
std::string_view sync_mode_name(SyncMode mode);
// Parses the names of sync_mode_name(); false for an unknown name.
bool parse_sync_mode(std::string_view name, SyncMode& mode);

// Read-only data that many controllers share: the database, the candidate frames the
// controller may jump to, search structures (built once per method), default speeds measured
// on the data, and the tags that mean "locomotion" and "idle".
struct ControllerDatabaseOptions {
  // Frames this close to the end of their clip are never jumped to (seconds), on top of the
  // feature times' own margin: clip ends stop mid-stride, and a transition there lands on a
  // take that is about to run out.
  float clip_end_exclusion = 1.0f;
  // The same for the data's idle clips (seconds), at most half of each: a stand that starts
  // near an idle clip's end soon jumps to another idle frame, whose stance the feet then step
  // into.
  float idle_clip_end_exclusion = 3.0f;
  // Options of the search structures.
  SearchOptions search;
};

class ControllerDatabase {
 public:
  // Validates the database for a controller (joint roles, a trajectory in the schema, at least
  // one candidate) and measures its speeds. Does not build a searcher yet.
  static Result<std::shared_ptr<const ControllerDatabase>> create(
      std::shared_ptr<const Database> database, const ControllerDatabaseOptions& options = {});

  const Database& database() const { return *database_; }
  const ControllerDatabaseOptions& options() const { return options_; }

  // The searcher of this method over the controller's candidates, built on first use (cold;
  // thread-safe). Fails on an unknown method.
  Result<const Searcher*> searcher(std::string_view method) const;

  // Speeds measured on the database's locomotion (m/s): medians of the root's horizontal speed
  // over frames moving forward, sideways and backward relative to the facing, walking and
  // running. Directions the data lacks fall back to a fraction of the forward speed.
  struct Speeds {
    float walk_forward = 1.4f, walk_sideways = 1.0f, walk_backward = 1.0f;
    float run_forward = 3.5f, run_sideways = 2.5f, run_backward = 2.0f;
  };
  const Speeds& speeds() const { return speeds_; }

  // The lowest each leg's end joint (the toe when it hangs from the foot, else the foot; index 0
  // left, 1 right) comes above the ground in any frame of the data (m): foot IK never puts it
  // lower, so feet do not sink where the data's never do.
  float lowest_foot_end(int side) const { return lowest_foot_end_[side != 0 ? 1 : 0]; }
  // The axis each knee bends about in the data (index 0 left, 1 right), in the knee's own frame
  // (a unit vector; bending is a positive turn about it): the mean axis of the knee's local
  // rotations where it is bent, the data's knees bending far further forward than back. Zero
  // where a knee does not turn about one axis (foot IK then bends it toward a pole).
  glm::vec3 knee_hinge(int side) const { return knee_hinge_[side != 0 ? 1 : 0]; }
  // Where the clip playing `frame` next puts a leg's end down (index 0 left, 1 right): the end
  // joint (as lowest_foot_end) at the clip's first frame from `frame` on whose contact label is
  // on, within kLandingHorizon, in `frame`'s root frame (m); where the label is on, where it
  // stands (a foot the controller lets slide or step under its label lands there). Not found
  // where the clip ends or the horizon passes first, nor for frames out of range.
  struct FootLanding {
    glm::vec3 toe{0.0f};
    bool found = false;
  };
  static constexpr float kLandingHorizon = 0.6f;  // s
  FootLanding next_landing(int frame, int side) const {
    const size_t k = 2 * static_cast<size_t>(frame) + (side != 0 ? 1 : 0);
    return frame >= 0 && k < landings_.size() ? landings_[k] : FootLanding{};
  }

  // Tag bits: clips that are not locomotion (carry "action"), and the synthesized idle clip.
  uint64_t action_tags() const { return action_tags_; }
  uint64_t idle_tags() const { return idle_tags_; }
  // The bits of the tags a tag request names (ControllerInput::tag): a tag equal to `tag`, or
  // whose first word is it ("wave" names "wave-both-hands" and "wave-left-hand"); 0 for an
  // empty or unknown name. Compares strings: call it outside update() and pass the bits in
  // ControllerInput::tag_bits.
  uint64_t tag_bits(std::string_view tag) const;
  // Styles (controller_style.cpp). The id of a style name of the database, or an error naming
  // the style and the styles there are; call it outside update() and pass the id in
  // ControllerInput::style.
  Result<int> style_id(std::string_view name) const;
  int style_count() const { return static_cast<int>(style_tags_.size()); }
  // The tag bit that filters a style's clips (the builder makes every style a tag too), 0 for
  // an id out of range; and the bits of every style.
  uint64_t style_tags(int style) const {
    return style >= 0 && style < style_count() ? style_tags_[static_cast<size_t>(style)] : 0;
  }
  uint64_t all_style_tags() const { return all_style_tags_; }
  // A style's fallback order (docs/controller.md, Styles): rank 0 its nearest rich style,
  // rank 1 "normal" (when neither the style itself nor rank 0); -1 where there is none. Rich:
  // a style with at least a quarter of the largest style's searchable frames.
  int style_fallback(int style, int rank) const {
    if (style < 0 || style >= style_count() || rank < 0 || rank > 1) return -1;
    return style_fallbacks_[static_cast<size_t>(style)][static_cast<size_t>(rank)];
  }
  // The distinct tag masks of the clips without a style.
  std::span<const uint64_t> styleless_clip_tags() const { return styleless_clip_tags_; }
  bool style_rich(int style) const {
    return style >= 0 && style < style_count() && style_rich_[static_cast<size_t>(style)] != 0;
  }
  // The candidate flags the searchers are built over (searchable and not near a clip end).
  std::span<const uint8_t> candidates() const { return candidates_; }

  ControllerDatabase(const ControllerDatabase&) = delete;
  ControllerDatabase& operator=(const ControllerDatabase&) = delete;

 private:
  ControllerDatabase() = default;
  std::shared_ptr<const Database> database_;
  ControllerDatabaseOptions options_;
  std::vector<uint8_t> candidates_;
  Speeds speeds_;
  float lowest_foot_end_[2] = {0.0f, 0.0f};
  glm::vec3 knee_hinge_[2] = {glm::vec3(0.0f), glm::vec3(0.0f)};
  std::vector<FootLanding> landings_;  // [frame * 2 + side]
  uint64_t action_tags_ = 0;
  uint64_t idle_tags_ = 0;
  std::vector<uint64_t> style_tags_;  // per style id
  uint64_t all_style_tags_ = 0;
  std::vector<std::array<int, 2>> style_fallbacks_;  // per style id
  std::vector<uint8_t> style_rich_;                  // per style id
  std::vector<uint64_t> styleless_clip_tags_;
  void resolve_style_tags();
  void resolve_style_fallbacks();
  struct SearcherEntry {
    std::string method;
    std::unique_ptr<Searcher> searcher;
  };
  mutable std::mutex mutex_;
  mutable std::vector<SearcherEntry> searchers_;
};

// Every tunable of a controller, with its unit and default.
struct ControllerSettings {
  // ---- Desired motion. A speed of 0 (the default) takes the database's measured speed.
  float walk_speed_forward = 0.0f;   // m/s
  float walk_speed_sideways = 0.0f;  // m/s
  float walk_speed_backward = 0.0f;  // m/s
  float run_speed_forward = 0.0f;    // m/s
  float run_speed_sideways = 0.0f;   // m/s
  float run_speed_backward = 0.0f;   // m/s
  // Stick deflection below this counts as released (0..1).
  float stick_deadzone = 0.2f;
  // Stopping: when the stick is released and the simulation object is slower than this (m/s),
  // only the database's idle clip is matched (the data has no stops of its own).
  float stop_speed = 0.8f;

  // ---- Simulation object (halflives as in spring.hpp: a spring at rest closes half the
  // distance to its goal in one halflife).
  float simulation_velocity_halflife = 0.3f;   // s
  float simulation_rotation_halflife = 0.15f;  // s
  // The fastest the simulation's facing turns while moving (rad/s). A person running into a
  // reversal turns no faster than the data's own hips do; the rotation spring alone swings a
  // half turn at twice that, and the character, held near the simulation, spins with it.
  float simulation_max_turn_rate = 5.0f;
  // The fastest the body (the hips' facing across the upper legs) turns, standing or moving
  // (rad/s): whatever the clip, the transition and the pull toward the simulation add up to,
  // the root yields the excess. People do not spin their hips faster; 0: no limit.
  float body_max_turn_rate = 5.2f;

  // ---- Matching.
  std::string search_method = "boxtree";  // a name from search_method_names()
  float search_interval = 0.1f;           // s between searches while nothing changes
  // Extra cost every candidate but the continuation pays (normalized feature units).
  float transition_cost = 1.0f;
  // Extra cost a locomotion frame pays when its clip has a style other than the requested one
  // (normalized feature units; clips without a style pay none). Not a filter: where the style
  // has nothing close to what the stick asks, another style's frame wins (docs/controller.md,
  // Styles).
  float style_cost = 12.0f;
  // What each later step of a style's fallback order pays on top of style_cost: its nearest
  // rich style pays style_cost, "normal" style_cost + this, any other style style_cost + twice
  // this (normalized feature units).
  float style_fallback_step = 4.0f;
  // Frames within this time of the playing frame are not jumped to (s).
  float ignore_window = 0.2f;
  // The same while standing on an idle clip of the data (s). Such a clip plays through without
  // periodic searches; once its last candidate frame has passed, the next idle frame is at
  // least this far away, so a long stand moves on instead of replaying its last moments.
  float idle_ignore_window = 4.0f;
  // A change of the desired velocity (m/s) or facing (radians) since the last search this large
  // searches at once.
  float replan_velocity_change = 0.5f;
  float replan_facing_change = 0.35f;
  // Periodic searches wait this long after a transition (s); sharp changes of the input and
  // clip ends still search at once.
  float transition_cooldown = 0.25f;
  // The playing clip is about to end when less than this remains (s): search at once.
  float clip_end_lookahead = 0.1f;
  // Sampling between database frames: cubic Hermite through each frame's value and velocity
  // (smooth at the frames themselves), or else two-point interpolation by `interpolation`.
  bool cubic_playback = true;
  InterpolationMethod interpolation = InterpolationMethod::Nlerp;

  // ---- Transitions.
  TransitionMode transition_mode = TransitionMode::DeadBlending;
  float inertialization_halflife = 0.2f;  // s: the root's offsets, and the body's if inertialized
  // Dead blending: the cross-fade's length and the extrapolated pose's velocity halflife (s).
  // While the fade is under half way, a foot is down only where both poses have it down: what
  // shows is mostly the outgoing pose, whose feet may be swinging where the incoming clip's are
  // down, and the fade already moves a foot the incoming clip lifts.
  float dead_blend_time = 0.6f;
  float dead_blend_decay_halflife = 0.1f;

  // ---- Synchronization.
  SyncMode sync_mode = SyncMode::CharacterFollowsSimulation;
  float adjustment_halflife = 0.1f;  // s: how fast the character is pulled to the simulation
  // With CharacterFollowsSimulation, the simulation object's position is also pulled toward the
  // character with this halflife (s; 0: never), so that the character is pulled less.
  float simulation_yield_halflife = 0.1f;
  // The yield moves the simulation object no faster than this ratio of the character's own
  // speed: a character that does not follow (asked for a motion the data lacks, such as a side
  // step from standing) would otherwise hold the simulation back, and the pull (limited by the
  // character's own speed too) would never start it.
  float simulation_yield_max_velocity_ratio = 2.0f;
  // Standing (stick released, see stop_speed), the simulation object also comes to where the
  // character stopped at up to this speed (m/s): the data has no stops, so a character rarely
  // stops where the simulation does, and nothing else would ever close the gap (a standing
  // character is never slid).
  float simulation_yield_standing_speed = 0.5f;
  // The pull's speed is at most this ratio of the character's own speed, so a standing
  // character is never slid; and its turning at most this ratio of the character's own turning.
  // Pulling the body along slides a planted foot, turning it only twists the leg.
  float adjustment_max_velocity_ratio = 0.3f;
  float adjustment_max_angular_velocity_ratio = 2.0f;
  // The character never strays farther than this from the simulation (m, radians).
  float clamp_max_distance = 0.4f;
  float clamp_max_angle = 0.6f;

  // ---- Strafing. The data has no side steps: while strafing, the simulation (and with it the
  // legs) faces up to this far (radians) toward the travel direction, and the spine and chest
  // twist back to the facing (0: no warping).
  float strafe_warp_max = 0.6f;

  // ---- Turning on the spot. The data has no turns in place: while standing (stick released,
  // simulation slower than stop_speed) the simulation's facing turns toward the desired facing
  // no faster than stand_turn_max_rate, speeding up and slowing down at stand_turn_acceleration
  // (so it eases in and out and stops on the facing), the character's root turns with it, and
  // the feet step after the turning idle pose.
  float stand_turn_max_rate = 5.2f;       // rad/s (about 300 degrees per second)
  float stand_turn_acceleration = 10.0f;  // rad/s^2

  // ---- Foot locking and IK.
  bool ik_enabled = true;         // false: the animation's feet as they are
  bool foot_lock_enabled = true;  // hold a foot's toe where it landed while in contact
  // A locked toe is released when the animation drags it farther than this (m), or out of the
  // leg's reach; during a contact it then steps (lifted) to the animation.
  float foot_unlock_radius = 0.5f;
  // A released foot eases back onto the animation with this halflife (s).
  float foot_lock_release_halflife = 0.06f;
  // Passes of the distance-constraint solver that restores the leg's bone lengths.
  int bone_length_iterations = 2;

  // ---- The world (set_world; docs/world.md). The capsule the simulation object, its predicted
  // trajectory and the root are moved as through walls, steps and slopes (character_mover.hpp),
  // and how the body follows the ground's height. Unused on the flat plane (no world).
  float character_radius = 0.3f;  // m
  float character_height = 1.7f;  // m
  float step_height = 0.35f;      // m: a step up to this is climbed, a higher one is a wall
  float max_step_down = 0.5f;     // m: a drop deeper than this is a ledge the character stops at
  float max_slope = 0.8f;         // radians: ground steeper than this is not walkable
  float ground_height_halflife = 0.1f;  // s: the body rises and falls to the ground on a spring
  // Feet on the ground (foot_placement.hpp; with IK and foot locking on): the pelvis comes down
  // at most this far (m), on a spring of this halflife (s), so that the lower foot reaches its
  // ground; a foot pitches at most max_foot_tilt (radians) to put heel and toe on a slope.
  float max_pelvis_drop = 0.35f;
  float pelvis_drop_halflife = 0.24f;
  float max_foot_tilt = 0.6f;
  // Up and down steep ground the clip plays slower and the character moves slower by the same
  // rate (climb_pace.hpp), so that it climbs no faster than max_climb_speed (m/s, vertical;
  // 0: no limit), at a rate no lower than min_playback_rate.
  float max_climb_speed = 0.25f;
  float min_playback_rate = 0.4f;
  // Toward a wall or a ledge's edge the predicted trajectory stops at, the simulation object
  // slows down at no more than this deceleration (m/s^2) to arrive at rest (obstacle_brake.hpp;
  // 0: it walks on until the world stops it).
  float obstacle_deceleration = 3.0f;

  // ---- Robustness. A dt larger than this is clamped to it (s).
  float max_dt = 0.1f;
  // skinning_matrices() gives the pose of the last update (computed on their first read after
  // it, so a game that skins from the transforms pays nothing for them).
  bool compute_skinning = true;

  // Checks every field (finite, in range, a known search method).
  Status validate() const;
};

// Sets one field of `settings`, named as in the struct (e.g. "inertialization_halflife"), from
// text: a number, "on"/"off" for flags, a search method, a sync mode name, an interpolation
// ("nlerp", "slerp", "sclerp") or a transition mode ("dead-blending", "inertialization"). Fails,
// naming the field and the value, on an unknown name or unreadable value; range checks are
// validate()'s.
Status set_controller_setting(ControllerSettings& settings, std::string_view name,
                              std::string_view value);

// The per-channel cost of the last search: squared normalized distance between the query and
// the chosen frame's features, channel by channel (as the database's schema lists them).
inline constexpr int kMaxDebugChannels = 16;

// What a debug drawing, a panel or an evaluation reads after update(). Every position in it
// is relative to `origin` (world() turns one into a world position).
struct ControllerDebug {
  // The controller's local origin (Controller::origin()): zero near the world origin.
  glm::dvec3 origin{0.0};
  // A position of this struct as a world position, rounded to float.
  glm::vec3 world(const glm::vec3& local) const { return glm::vec3(to_world(origin, local)); }
  // Desired motion.
  glm::vec3 desired_velocity{0.0f};                    // m/s, world
  glm::quat desired_rotation{1.0f, 0.0f, 0.0f, 0.0f};  // the desired facing
  // The simulation object.
  glm::vec3 simulation_position{0.0f};
  glm::vec3 simulation_velocity{0.0f};
  glm::vec3 simulation_acceleration{0.0f};
  glm::quat simulation_rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 simulation_angular_velocity{0.0f};
  // The predicted trajectory at the feature times (world positions and facings); the desired
  // trajectory is the same springs with their goals already reached, i.e. where the stick says.
  static constexpr int kMaxTrajectoryPoints = 8;
  int trajectory_count = 0;
  float trajectory_times[kMaxTrajectoryPoints] = {};
  glm::vec3 predicted_positions[kMaxTrajectoryPoints] = {};
  glm::quat predicted_rotations[kMaxTrajectoryPoints] = {};
  glm::vec3 desired_positions[kMaxTrajectoryPoints] = {};

  // Playback.
  int clip = -1;              // index into database().clips()
  int requested_style = -1;   // ControllerInput::style as understood (-1: any)
  int frame = -1;             // the database frame nearest the playback time
  float clip_time = 0.0f;     // seconds since the clip's first frame
  bool transitioned = false;  // this update jumped to a new frame
  int transitions = 0;        // since create()
  bool standing = false;      // the desired speed is zero

  // The last search.
  int searches = 0;             // since create()
  bool searched = false;        // this update searched
  float search_seconds = 0.0f;  // wall time of this update's search (0 when none)
  int channel_count = 0;
  float last_cost = 0.0f;  // the chosen candidate's cost (transition cost included)
  float last_channel_costs[kMaxDebugChannels] = {};
  int last_best_frame = -1;
  static constexpr int kMaxQueryDims = 64;
  int query_dims = 0;
  float last_query[kMaxQueryDims] = {};  // normalized; the first kMaxQueryDims columns

  // The world (none: all zero).
  float ground_height = 0.0f;          // the ground under the root the body stands on (m)
  float playback_rate = 1.0f;          // the clip's rate on steep ground (climb_pace.hpp)
  bool simulation_blocked = false;     // the simulation object's move met an obstacle
  glm::vec3 simulation_contact{0.0f};  // that obstacle's horizontal normal
  int64_t world_rejected = 0;          // the world's answers ignored (world.hpp), since create()
  // Feet on the ground (foot_placement.hpp): the probed points (per side: heel, toe, heel
  // ahead, toe ahead) and the ground found under each (the body's ground where none was), the
  // heights each foot's heel and toe stand on, and how far the pelvis came down.
  glm::vec3 foot_probes[FootPlacement::kProbes] = {};
  glm::vec3 foot_probe_grounds[FootPlacement::kProbes] = {};
  FootGround foot_ground[2] = {};
  float pelvis_drop = 0.0f;
  // Where each foot in the air lands by the playing clip (ControllerDatabase::next_landing), its
  // look-aheads shortened to a little past it; foot_lands false for a planted foot or none found.
  glm::vec3 foot_landing[2] = {};
  bool foot_lands[2] = {false, false};

  // Feet: 0 left, 1 right.
  bool contact[2] = {false, false};  // the playing frame's contact, false while stepping
  bool locked[2] = {false, false};   // the toe is held by the foot lock
  glm::vec3 lock_position[2] = {};   // where a locked toe is held
  glm::vec3 ik_target[2] = {};       // where IK put the toe (equals the animation when free)
};

class Controller {
 public:
  // A controller at the world origin facing +Z, standing on the calmest candidate frame until
  // its first update. Fails on invalid settings or an unknown search method.
  static Result<Controller> create(std::shared_ptr<const ControllerDatabase> database,
                                   const ControllerSettings& settings = {});

  // Advances by dt seconds of game time. dt <= 0 or non-finite changes nothing; dt above
  // settings.max_dt is clamped to it; non-finite or out-of-range input is sanitized.
  void update(float dt, const ControllerInput& input);
  // Level of detail (controller_lod.cpp; crowd_scheduler.hpp): advances only the simulation
  // object under this input and carries the character along with it rigidly. The root keeps
  // its offset to the simulation object; the pose, playback and transitions are held (no
  // search, sampling, IK or forward kinematics), foot locks are released. A later update()
  // goes on from there. dt as in update().
  //
  // Only the root (joint 0 of global_transforms()) moves: the other joints stay where the last
  // update left them, hanging from carried_from() rather than from the root, until
  // settle_carried_pose() carries them with it (update() and any other step that poses the
  // character do that themselves). A crowd draws the carried pose as the held pose moved by the
  // rigid motion from carried_from() to root_transform(), touching a few cache lines per
  // character instead of every joint. With settings.compute_skinning the pose is settled at
  // once (the skinning matrices need every joint).
  void update_move_only(float dt, const ControllerInput& input);
  // Ask the cache for what the next update_move_only() reads and writes, so a crowd's loop can
  // overlap one character's memory latency with the steps before it: first the members (the
  // simulation object, the root's state; nothing is read), a step or two ahead, then the heap
  // arrays (the root's joint; reads their pointers). No effect on any result.
  void prefetch_move_only_members() const;
  void prefetch_move_only() const;
  // Whether joints 1.. of global_transforms() are still those of the last update, hanging from
  // carried_from() (after update_move_only()).
  bool pose_carried() const { return pose_carried_; }
  // The root the held joints hang from while pose_carried() (world, as global_transforms()).
  Transform carried_from() const;
  // Carries the held joints rigidly with the root, and re-anchors the playback (the
  // transition's source) to where the moves left the root (no effect unless pose_carried()).
  void settle_carried_pose();

  // Places the character and its simulation object (cold; clears any transition).
  void teleport(const glm::vec3& position, float yaw);
  // The same from a double-precision world position (only x and z count on the flat plane; in a
  // world, the character stands on the highest walkable ground from character_height above
  // the position's height down to max_step_down below it); also moves origin() to the
  // character.
  void teleport_world(const glm::dvec3& position, float yaw);

  // Global (model = world) transforms of every database joint after the last update, in float:
  // exact near the world origin, rounded to float's steps far from it (at 100 km, 8 mm). Far
  // away, use origin() and origin_transforms(). Ask again after each update: once the origin
  // leaves zero the span views another buffer.
  std::span<const Transform> global_transforms() const {
    return origin_ == glm::dvec3(0.0) ? std::span<const Transform>(globals_) : world_globals_;
  }
  // The controller's local origin in the world (metres, double; on the ground, at whole metres).
  // It follows the character (local_origin.hpp) and is zero near the world origin.
  const glm::dvec3& origin() const { return origin_; }
  // Global transforms relative to origin(): world = origin() + translation. Full float
  // precision wherever the character is; what a game far from the world origin renders with.
  std::span<const Transform> origin_transforms() const { return globals_; }
  // The root's world position in double precision.
  glm::dvec3 world_root_position() const { return to_world(origin_, globals_[0].translation); }
  // The inverse bind matrices of skinning_matrices(): a game far away computes its own skinning
  // matrices relative to origin() from origin_transforms() (runtime/skinning.hpp).
  std::span<const glm::mat4> inverse_bind_matrices() const { return inverse_bind_; }
  // Local transforms after inertialization and IK; the root's (joint 0) is relative to origin().
  std::span<const Transform> local_transforms() const { return locals_; }
  // global * inverse(bind global), with the database skeleton's rest pose as the bind pose
  // (from global_transforms(), so in world space). The first read after an update computes
  // them: like the update itself, not to be called from two threads at once.
  std::span<const glm::mat4> skinning_matrices() const;
  // The character's root (joint 0): its ground position and facing (world, as
  // global_transforms()).
  const Transform& root_transform() const { return global_transforms()[0]; }
  const ControllerDebug& debug() const { return debug_; }
  const ControllerSettings& settings() const { return settings_; }
  const ControllerDatabase& controller_database() const { return *shared_; }
  // The speeds in use (settings, or the database's where the settings say 0).
  const ControllerDatabase::Speeds& speeds() const { return speeds_; }

  // The game's world (world.hpp): the simulation object, its predicted trajectory and the root
  // meet its walls, steps and slopes, and the body stands on its ground (docs/world.md). Not
  // owned: it must outlive its use here. nullptr (the default) is the flat plane y = 0, exactly
  // as without a world. Cold: the character is placed on the new ground where it stands.
  void set_world(const WorldQueries* world);
  const WorldQueries* world() const { return world_; }

  // A game that moves the character's capsule with its own physics (docs/world.md): after
  // update() it moves its capsule toward simulation_position_world() (the step the controller
  // asks for; simulation_velocity() is its rate), resolves the collisions its own way, and hands
  // the capsule's resolved foot position back here. The simulation object moves there (what the
  // game's physics refused of the step is taken out of its velocity, as a wall does), the
  // character follows it as always (adjustment and clamping), and from then on the body stands
  // at the height the game gives. Ignored when not finite. Works with or without set_world().
  void set_simulation_position_world(const glm::dvec3& position);
  // The same relative to origin().
  void set_simulation_position(const glm::vec3& position);
  // The simulation object after the last update: where it stands (world, double) and its
  // velocity (m/s; what the game's capsule is asked to move at).
  glm::dvec3 simulation_position_world() const { return to_world(origin_, sim_position_); }
  const glm::vec3& simulation_velocity() const { return sim_velocity_; }

  // Live tuning between updates (cold). Fails, changing nothing, on invalid settings.
  Status set_settings(const ControllerSettings& settings);

  // Moves the character's root to this transform now, keeping the transition source and
  // destination consistent so that playback continues from there (seed 004). Used by the
  // synchronization; public for games that move characters (teleports, collisions).
  void adjust_root(const glm::vec3& position, const glm::quat& rotation);
  // The same from a double-precision world position.
  void adjust_root_world(const glm::dvec3& position, const glm::quat& rotation);

 private:
  Controller() = default;
  Status resolve_schema();
  Status resolve_joints();
  void size_buffers();
  void start_standing();
  // Big worlds (controller_origin.cpp): placing relative to the origin, rebasing it, and the
  // world transforms.
  void place(const glm::vec3& position, float yaw);
  void adjust_root_local(const glm::vec3& position, const glm::quat& rotation);
  void follow_character();
  void shift_origin(const glm::vec3& shift);
  void publish_world_transforms();
  // The world (controller_world.cpp): the moves of the simulation object, its trajectory and
  // the root through it, and the body's height over its ground.
  CharacterShape character_shape() const;
  void collide_simulation(const glm::vec3& before);
  void collide_trajectory(std::span<glm::vec3> positions);
  void collide_root_motion(float dt);
  void move_displayed_root(const glm::vec3& position, const glm::quat& rotation);
  void lift_to_ground(float dt);
  void settle_on_ground();
  void keep_body_off_walls(float dt);
  void keep_arms_off_walls();
  bool in_arm(int joint) const;
  bool wall_beside(glm::vec3& point, glm::vec3& normal) const;
  void find_walls(const std::array<PlacementLeg, 2>& legs,
                  const std::array<glm::vec3, 2>& shown_toes);
  bool deepest_trunk_joint(const glm::vec3& point, const glm::vec3& n, int& joint,
                           glm::vec3& position) const;
  void keep_toe_off_wall(int side, glm::vec3& target) const;
  void ease_wall_push(int side, const glm::vec3& toe, float dt);
  void ease_ledge_push(int side, const glm::vec3& toe, float dt);
  glm::vec3 toe_push(int side) const;
  glm::vec3 without_slide_back(const glm::vec3& step, float dt) const;
  void place_feet(float dt);
  void climb_trajectory(std::span<const glm::vec3> goals,
                        std::span<glm::vec3, CharacterMover::kMaxMoves> starts,
                        std::span<MoveResult, CharacterMover::kMaxMoves> moved);
  void face_along_obstacle();
  bool held_by_obstacle() const;
  void track_held_by_obstacle(float dt);
  bool standing_at_obstacle() const;
  void desired_motion(const ControllerInput& input);
  void pace_to_ground(float dt);
  void simulate(float dt);
  void stand_turn(float dt);
  void limit_turn_rate(const glm::quat& before, float dt);
  float body_yaw() const;
  void limit_body_turn(float dt);
  void turn_chest_to_facing(float dt);
  glm::quat warped_facing() const;
  void predict();
  bool prediction_stale() const;
  bool should_search() const;
  void build_query();
  void search();
  SearchResult search_candidates() const;
  bool on_idle_clip() const;
  bool playing_idle_through() const;
  void record_search(const SearchResult& best);
  // `incoming_body`: also sample the incoming clip's body (joints 1..) at the jump; without it
  // only its root is sampled and sampled_'s body is stale until the next sample_playback.
  void transition_to(int frame, bool incoming_body = true);
  void start_transition();
  void show_transitions(float dt);
  void clear_transitions();
  float clip_duration() const;
  void advance_playback(float dt);
  // Where playback is: two database frames and the weight of the second.
  struct PlaybackPoint {
    int frame0 = 0;
    int frame1 = 0;
    float weight = 0.0f;
  };
  PlaybackPoint playback_point() const;
  Transform sample_joint(const PlaybackPoint& at, size_t joint) const;
  Transform database_root(const PlaybackPoint& at) const;
  // The playing clip at `at` (playback_point() of the present clip and time): the update passes
  // the point it keeps in sampled_at_.
  void sample_playback(const PlaybackPoint& at, std::span<Transform> local,
                       std::span<glm::vec3> velocities, std::span<glm::vec3> angular_velocities,
                       bool body_velocities) const;
  void sample_playback_root(std::span<Transform> local, std::span<glm::vec3> velocities,
                            std::span<glm::vec3> angular_velocities) const;
  void map_playback_root(const PlaybackPoint& at, std::span<Transform> local,
                         std::span<glm::vec3> velocities,
                         std::span<glm::vec3> angular_velocities) const;
  void sample_body_velocities(const PlaybackPoint& at, std::span<glm::vec3> velocities,
                              std::span<glm::vec3> angular_velocities) const;
  void root_motion(float dt);
  void synchronize(float dt);
  void move_root(const glm::vec3& position, const glm::quat& rotation);
  void foot_lock(float dt);
  glm::vec3 foot_target(int side, const glm::vec3& animated, const glm::vec3& on_ground,
                        bool contact, bool grounded, bool settling, float dt);
  bool on_its_ground(int side, const glm::vec3& on_ground) const;
  float toe_ground(int side) const;
  float ground_under_toe(int side) const;
  bool low_and_slow(int side, const glm::vec3& on_ground, float dt);
  bool contact_label_holds(int side) const;
  void decay_offset(int side, glm::vec3& offset, glm::vec3& velocity, float dt);
  void hold_heading(int side, float dt);
  glm::vec3 playing_leg_end(int side);
  int leg_end(int side) const;
  bool in_early_blend() const;
  float foot_heading(int side) const;
  void align_hips(float dt);
  void reach(int side, const glm::vec3& animated, const glm::vec3& target, float dt);
  void ease_heel_down(int side, float dt);
  void restore_leg_lengths(int side);
  void refresh_subtree(int joint);    // globals of a joint and its descendants from the locals
  float leg_length(int side) const;   // upper plus lower leg in the played pose (m)
  float foot_length(int side) const;  // ankle to toe in the played pose (m; 0 without a toe)
  float release_halflife(float distance) const;
  void finish_pose();
  void refresh_outputs(float dt);

  std::shared_ptr<const ControllerDatabase> shared_;
  const Database* db_ = nullptr;
  const Searcher* searcher_ = nullptr;
  ControllerSettings settings_;
  ControllerDatabase::Speeds speeds_;

  // Schema facts resolved at create().
  std::vector<float> trajectory_times_;  // unique trajectory times of the schema (s)
  // The prediction's spring coefficients at those times, kept while the halflives stay.
  SpringPredictionTable position_springs_;
  SpringPredictionTable rotation_springs_;
  RotationPredictionCache rotation_prediction_;  // the rotations predicted from the table
  float predicted_yaws_[SpringPredictionTable::kMaxTimes] = {};  // quat_yaw of each of them
  // The per-update steps of the springs whose halflife and dt rarely change: the root's (and
  // an inertialized body's) offsets, the simulation's rotation.
  CriticalSpringStepCache offset_step_;
  CriticalSpringStepCache sim_rotation_step_;
  // The same for the springs the feet and the chest run every update, per foot: the release
  // offset, the heading offset, the heel's rise; and the chest's twist.
  struct FootSprings {
    CriticalSpringStepCache offset, wall_push;
    CriticalSpringScalarCache heading, heel;
  };
  FootSprings foot_springs_[2];
  CriticalSpringScalarCache chest_twist_spring_;
  // pull_fraction (controller.cpp) of one pull, kept while its halflife and dt stay the same (bit
  // for bit): its exp2 is then computed once, not every update.
  class PullFractionCache {
   public:
    float of(float halflife, float dt);

   private:
    SpringStepKey key_;
    float fraction_ = 0.0f;
  };
  PullFractionCache yield_pull_, adjustment_pull_, hips_align_pull_, standing_reach_pull_,
      sweep_pull_;
  struct TrajectoryColumn {
    int column = 0;      // first column in the feature row
    int time_index = 0;  // index into trajectory_times_
    bool direction = false;
  };
  std::vector<TrajectoryColumn> trajectory_columns_;
  std::vector<int> leg_joints_[2];  // upper leg, lower leg, foot, toe per side
  std::vector<int> folded_joints_;  // source roots played as identity (see sample_playback)
  std::vector<std::array<int, 2>> folded_children_;  // {folded joint, one of its children}

  // Every position below is relative to this world position (local_origin.hpp).
  glm::dvec3 origin_{0.0};

  // quat_yaw of the rotation last asked about, kept: several phases of an update ask for the yaw
  // of the same rotation (the simulation's, the root's, the desired facing), and comparing the
  // rotation's bits costs less than the yaw.
  class YawMemo {
   public:
    float of(const glm::quat& q) const {
      if (!known_ || std::memcmp(&q, &rotation_, sizeof(glm::quat)) != 0) {
        rotation_ = q;
        yaw_ = quat_yaw(q);
        known_ = true;
      }
      return yaw_;
    }

   private:
    mutable glm::quat rotation_{1.0f, 0.0f, 0.0f, 0.0f};
    mutable float yaw_ = 0.0f;
    mutable bool known_ = false;
  };
  YawMemo sim_yaw_, root_yaw_, desired_yaw_;

  // Simulation object.
  glm::vec3 sim_position_{0.0f}, sim_velocity_{0.0f}, sim_acceleration_{0.0f};
  glm::quat sim_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 sim_angular_velocity_{0.0f};
  glm::vec3 desired_velocity_{0.0f};
  glm::quat desired_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 desired_velocity_at_search_{0.0f};
  glm::quat desired_rotation_at_search_{1.0f, 0.0f, 0.0f, 0.0f};
  // The goals the predicted trajectory was made toward (predict()): a search whose goals
  // differ predicts again first.
  glm::vec3 predicted_velocity_goal_{0.0f};
  glm::quat predicted_rotation_goal_{1.0f, 0.0f, 0.0f, 0.0f};
  bool predicted_stopping_ = false;
  uint64_t tag_bits_ = 0;  // resolved tag request (0: locomotion)
  uint64_t tag_bits_at_search_ = 0;
  int style_ = -1;  // requested style id (-1: any)
  int style_at_search_ = -1;
  bool stopping_ = false;  // stick released and slow: the idle clip only
  bool stopping_at_search_ = false;
  float search_timer_ = 0.0f;
  float since_transition_ = 0.0f;
  bool force_search_ = true;

  // Playback: the clip and the time since its first frame.
  int clip_ = -1;
  float clip_time_ = 0.0f;

  // Root: world = source * inverse(destination) * database root (seed 004).
  glm::vec3 transition_src_position_{0.0f};
  glm::quat transition_src_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 transition_dst_position_{0.0f};
  glm::quat transition_dst_rotation_{1.0f, 0.0f, 0.0f, 0.0f};

  // Transitions: the root's offsets (one joint), and the body's (joints 1..) by transition_mode.
  InertializationOffsets root_offsets_;
  InertializationOffsets body_offsets_;
  DeadBlend body_blend_;
  // The contacts of the pose shown (finish_pose), and of the pose a dead blend started from.
  bool shown_contact_[2] = {false, false};
  bool blend_source_contact_[2] = {false, false};
  // Per-joint buffers, sized at create().
  std::vector<Transform> sampled_;  // the playing animation (root in world space)
  std::vector<glm::vec3> sampled_velocities_;
  std::vector<glm::vec3> sampled_angular_velocities_;
  // Where sampled_ was sampled, and whether its body (joints 1..) has velocities: only a
  // transition reads them, so each update samples the root's alone and a transition the rest.
  PlaybackPoint sampled_at_;
  bool sampled_body_velocities_ = false;
  // The database root (unmapped) of sample_playback's last sample, where and how it was taken:
  // move_root needs that sample again in the same update (database_root).
  struct RootSample {
    PlaybackPoint at;
    bool cubic = false;
    InterpolationMethod method = InterpolationMethod::Nlerp;
    Transform root;
    bool valid = false;
  };
  mutable RootSample root_sample_;
  std::vector<Transform> other_;  // the other side of a transition
  std::vector<glm::vec3> other_velocities_;
  std::vector<glm::vec3> other_angular_velocities_;
  std::vector<Transform> locals_;       // displayed: inertialized, adjusted, with IK
  glm::vec3 displayed_velocity_{0.0f};  // of the root
  glm::vec3 displayed_angular_velocity_{0.0f};
  std::vector<Transform> globals_;        // relative to origin_
  std::vector<Transform> world_globals_;  // globals_ in the world, while origin_ is not zero
  // update_move_only(): joints 1.. of globals_ (and world_globals_) are held, relative to this
  // root (relative to origin_ like globals_) rather than to globals_[0].
  bool pose_carried_ = false;
  Transform carried_from_;
  std::vector<glm::mat4> inverse_bind_;
  ForwardKinematicsPlan fk_plan_;  // the database skeleton's
  // Computed by skinning_matrices() from the transforms when stale.
  mutable std::vector<glm::mat4> skinning_;
  mutable bool skinning_stale_ = false;
  std::vector<float> query_;

  // Foot locks: 0 left, 1 right.
  struct FootLock {
    bool locked = false;
    glm::vec3 position{0.0f};  // the held toe position
    float lock_ground = 0.0f;  // the toe's ground (toe_ground) when the lock last followed it
    glm::vec3 offset{0.0f};    // target - (lock point or animation), decaying
    glm::vec3 offset_velocity{0.0f};
    float release_halflife = 0.0f;    // the offset's, since the release (s)
    glm::vec3 target{0.0f};           // the toe's target last update (without a step's lift)
    glm::vec3 target_velocity{0.0f};  // its rate then (m/s)
    bool has_target = false;
    bool previous_contact = false;
    bool stepping = false;  // released during a contact: stepping, in the air until it lands
    float lift = 0.0f;      // the step's height above the target (m), and its rate
    float lift_velocity = 0.0f;
    // The foot's heading (yaw of its foot-to-toe line, radians): held while locked, and the
    // displayed heading minus the animated one, decaying after a release, with its rate.
    float heading = 0.0f;
    float heading_offset = 0.0f;
    float heading_offset_velocity = 0.0f;
    float heading_release_halflife = 0.0f;  // the heading offset's, since the release (s)
    bool heading_held = false;              // on the last update
    // How far (radians) the heel is lifted about the held toe (reach), about which axis, and
    // the rate at which it comes down after a release.
    float heel_rise = 0.0f;
    float heel_rise_velocity = 0.0f;
    glm::vec3 heel_axis{1.0f, 0.0f, 0.0f};
    // What of the lift a lock needed as it began is still to come (radians), and its rate: made
    // up with a bounded acceleration (reach); and whether the lock began this update.
    float heel_lag = 0.0f;
    float heel_lag_velocity = 0.0f;
    bool lock_began = false;
    // The animated toe on its ground last update, its velocity and horizontal speed (m/s)
    // then, and whether it was low and slow.
    glm::vec3 animated{0.0f};
    glm::vec3 velocity{0.0f};
    float speed = 0.0f;
    bool has_animated = false;
    bool low_and_slow = false;
    // The animated toe's height without its ground's offset last update, and its rate (m/s).
    float animated_height = 0.0f;
    float animated_rise = 0.0f;
    // How far (horizontally) walls keep the toe out this update (place_feet), and its rate: it
    // comes back onto the animation on a spring when a wall lets go, at once when one pushes.
    glm::vec3 wall_push{0.0f};
    glm::vec3 wall_push_velocity{0.0f};
    bool wall_pushing = false;  // a wall pushed the toe out on the last update
    // The ledge's edge the simulation object stands at keeps the toe back over it by
    // ledge_need - ledge_lag (horizontal, m): what the edge needs, less what of a jump in that
    // need is still to come (made up with a bounded acceleration) at its rate; and the edge's
    // normal (zero: none) (ease_ledge_push).
    glm::vec3 ledge_lag{0.0f};
    glm::vec3 ledge_lag_velocity{0.0f};
    glm::vec3 ledge_need{0.0f};
    glm::vec3 ledge_normal{0.0f};
  };
  FootLock feet_[2];
  // How much of a standing pose's own leg extension foot IK keeps (0 to 1, eased).
  float standing_reach_ = 0.0f;
  // Where the playing clip puts each leg's end this update (playing_leg_end), once known.
  std::array<glm::vec3, 2> playing_leg_ends_{};
  bool playing_leg_ends_known_ = false;
  // The body's facing after the last update (see body_max_turn_rate), unknown after a placement.
  float body_yaw_ = 0.0f;
  bool body_yaw_known_ = false;
  // The displayed hips' yaw off the root's (radians, last update), and how far the root's
  // standing facing goal is turned against it (align_hips).
  float hips_offset_ = 0.0f;
  float hips_align_ = 0.0f;
  // Strafing (the strafe button held, the stick pushed), and the chest's twist toward the
  // facing (radians about the vertical) with its rate.
  bool strafing_ = false;
  // The facing the simulation turns to: the desired facing, warped toward the travel direction
  // while strafing (warped_facing).
  glm::quat simulation_goal_rotation_{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat warp_facing_{1.0f, 0.0f, 0.0f, 0.0f};  // the facing the root last turned to
  bool warp_facing_reached_ = true;
  float chest_twist_ = 0.0f;
  float chest_twist_velocity_ = 0.0f;

  // The world (null: the flat plane), the capsule's mover, the ground's height under the root on
  // its spring, and the root's ground position after the last update (its next move's start).
  const WorldQueries* world_ = nullptr;
  CharacterMover mover_;
  float ground_height_ = 0.0f;
  float ground_velocity_ = 0.0f;
  // The rate the clip plays at, and the desired velocity is scaled by, on steep ground.
  ClimbPace climb_pace_;
  glm::vec3 last_root_{0.0f};
  // The walls and ledges' edges the root's own moves met lately (collide_root_motion).
  HeldContacts root_contacts_;
  // The game moves the capsule (set_simulation_position): the simulation object keeps the
  // height the game gave it, and the body stands at it. With a world or the game's capsule, the
  // displayed root (locals_[0]) is lifted by ground_height_ between updates.
  bool game_capsule_ = false;
  // Feet on the world's ground, and per foot how far its toe's ground is above where the
  // animation puts it (the body's ground, less the pelvis drop); zero without a world.
  FootPlacement foot_placement_;
  // The wall the simulation object last met (its horizontal normal; zero: none) and where.
  glm::vec3 obstacle_normal_{0.0f};
  glm::vec3 edge_normal_{0.0f};  // the ledge edge the simulation stands at, or zero
  glm::vec3 obstacle_point_{0.0f};
  bool obstacle_edge_ = false;    // that obstacle is a ledge's edge (a drop), not a wall's face
  ObstacleAhead obstacle_ahead_;  // where the last prediction's way was blocked
  float held_time_ = 0.0f;        // how long the simulation has been held at it (s)
  // The velocity the stick asks for (desired_velocity_ before standing at an obstacle).
  glm::vec3 stick_velocity_{0.0f};
  // How far (m) the body above the root is moved back from walls (horizontal), and its rate.
  glm::vec3 wall_push_{0.0f};
  glm::vec3 wall_push_velocity_{0.0f};
  // What of the push an arm's depth raised at once the body has still to follow, and its rate
  // (keep_body_off_walls): made up with a bounded acceleration.
  glm::vec3 arm_push_lag_{0.0f};
  glm::vec3 arm_push_lag_velocity_{0.0f};
  // A wall found between the body and each toe, and each hand, elbow and the head, this update
  // (find_walls): a point on its face and its horizontal normal.
  struct WallHit {
    bool found = false;
    int joint = -1;
    glm::vec3 point{0.0f};
    glm::vec3 normal{0.0f};
  };
  static constexpr int kReachingJoints = 5;
  // How deep the body is in a wall along its normal (keep_body_off_walls), and whether an arm's
  // joints are (the push follows those with a bounded acceleration).
  struct WallDepth {
    glm::vec3 normal{0.0f};
    float depth = 0.0f;
    bool arm = false;
  };
  static constexpr int kMaxWallDepths = 1 + 2 * kReachingJoints;
  size_t wall_depths(std::span<WallDepth, kMaxWallDepths> out) const;
  void follow_arm_push(std::span<const WallDepth> walls, float dt);
  WallHit toe_walls_[2];
  WallHit beside_toe_walls_[2];  // the wall beside, where a toe is in its plane (find_walls)
  WallHit riser_walls_[2];
  WallHit body_walls_[kReachingJoints];
  // Toward the trunk's joint deepest in the plane of the wall beside (find_walls).
  WallHit trunk_wall_;
  glm::vec3 body_shift_{0.0f};  // what moved the body above the root this update
  float ground_offset_[2] = {0.0f, 0.0f};

  ControllerDebug debug_;
};

}  // namespace mm
