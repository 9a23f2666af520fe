#pragma once
// Scripted evaluation (`mm eval`): one controller runs a script at a fixed dt, headless, and
// the run is measured. Every metric is defined here once; `mm eval` prints and writes them.
// The metrics are computed frame by frame from per-frame records (EvaluationFrame) by an
// EvaluationAccumulator, so they can be fed synthetic frames and never need the whole run.
//
// Conventions: positions are relative to each frame's origin (the controller's local origin,
// see local_origin.hpp), and a frame whose origin moved has the previous frames shifted into
// its own before anything is compared, so no metric ever subtracts two world coordinates in
// float and a run 100 km from the world origin measures like one at it;
// speeds are horizontal, from positions one frame apart, unless said 3-D; a value
// that needs the previous frame starts at the second frame; a mean over no values is 0 and the
// count beside it (frames or events) says so; yaws are about +Y, atan2(x, z), and yaw errors
// and rates are absolute and wrapped to [0, 180] degrees per frame; percentiles are by nearest
// rank, read from a histogram whose bins are 2^-10 of their value wide (EvaluationAccumulator),
// so they are within 0.05 % of the exact nearest-rank value.
//
// Metrics:
// - foot_skate_cm_s_mean / _p95: the toe's speed on frames where that foot is in contact (the
//   contact the controller holds: the playing database frame's) on this and the previous frame,
//   over both feet;
// - root_sim_distance_cm_mean / _max: distance between the character's root and the simulation
//   object; facing_error_deg_mean: the angle between their facings;
// - speed_response_s: after the desired speed changes by at least kSpeedEventChange, the time
//   until the root's speed is within 10 % of the change from the new desired speed (mean over
//   the changes that got there before the next change);
// - heading_response_s: after the desired facing turns by at least kHeadingEventAngle in one
//   step, the time until the root's facing is within 10 degrees of it (mean, likewise);
// - stand_root_speed_cm_s_mean / stand_foot_speed_cm_s_mean: root and toe speed on frames where
//   the desired speed has been zero for at least kStandSettleSeconds and the desired facing has
//   not changed for kStandSettleSeconds either (a turn on the spot steps its feet);
//   stand_frames counts them;
// - transitions_per_s: jumps to a new database frame per second of script;
// - transition_accel_ratio: the 99th percentile of joint acceleration (second differences of
//   global joint positions, every joint but the simulation root) over the 10 frames from each
//   transition, divided by the same percentile over the database's locomotion clips (those the
//   controller plays when no tag is requested: not "action", not "idle") played straight
//   through at the same dt with linear interpolation between frames; the controller plays with
//   cubic Hermite sampling by default, which is smoother than that, so the same ratio against
//   the data played with the controller's own sampling is reported beside it
//   (transition_accel_ratio_same_sampling). The database's mix of moves is not the script's (a
//   script that runs half the time meets running's larger accelerations in half its
//   transitions, while the data mostly walks), so transition_accel_ratio_played divides the
//   same percentile by the one of the playing clips themselves at the same moments, played
//   straight through with the controller's sampling (played_accel_p99): what the blends add;
// - leg_accel_max: the largest acceleration (second difference of global positions) of a leg
//   joint (knee, ankle or toe, either side) on a frame outside every transition's 10-frame window
//   (transition_accel_ratio judges those), at leg_accel_max_t (s); leg_accel_played_max: the
//   same joints' largest acceleration in the playing clips at the same moments, played straight
//   through with the controller's sampling; leg_accel_ratio = leg_accel_max over the larger of
//   leg_accel_played_max and database_accel_p99_same_sampling (a standing run's idle moves its
//   legs so little that ordinary walking would read as a snap against it alone): what foot
//   locking, placement and IK add to the legs between transitions (a knee that snaps as a held
//   foot lets go, which no percentile sees);
// - search_us_mean: wall time per search; update_us_mean: wall time per update() (the only
//   figures that vary from run to run).
//
// The body metrics (issue 17). Body yaw: the yaw of the horizontal vector (L - R) x up, where L
// and R are the global positions of a left/right joint pair found by joint role: the hips'
// from the upper legs, the chest's from the upper arms. A frame where the pair has no
// horizontal separation keeps the previous frame's yaw. A missing pair leaves its metrics at 0
// (with their counts 0).
// - body_turn_rate_deg_s_p99 / _max: the hips' yaw rate, frame to frame, over the run (nearest
//   rank percentile);
// - foot_pivot_deg_s_mean: the yaw rate of the horizontal foot-to-toe vector on frames where
//   that toe is below kPivotToeHeight and its 3-D speed below kPivotToeSpeed on this and the
//   previous frame (so it starts at the third frame), over both feet. The 3-D speed, because a
//   toe lifting off is not planted: at a run's push-off the foot passes through vertical with
//   the toe still low, rising fast, and the yaw of its tiny horizontal part spins through half
//   a turn in a frame or two. And the foot pitched at most kPivotMaxFootPitchDegrees on both
//   frames: a foot standing near vertical on a still toe (the end of a push-off, the data's own
//   as well as a held toe's) has a horizontal part of a few millimetres whose yaw flips through
//   half a turn between two frames, a spin nobody sees; foot_pivot_frames
//   counts the samples (a side without a foot and a toe role gives none);
// - turning on the spot: an event starts on a frame where the desired speed is below
//   kStandTurnSpeed now and kStandTurnLookback earlier and the desired facing differs by at
//   least kStandTurnAngle from kStandTurnLookback earlier, when that did not hold on the
//   previous frame (a facing step satisfies it for the whole look-back; that is one event).
//   "Earlier" is the frame nearest kStandTurnLookback back, at least one. The event lasts until
//   the next event starts or the desired speed reaches kStandTurnSpeed (the stick moves), or
//   the run ends. stand_turns counts the events; stand_turn_unsettled those whose hips' yaw
//   never came within kSettleAngle of the desired facing (followed as it changes);
//   stand_turn_response_s: mean over events of the time from the event's first frame to the
//   first frame within kSettleAngle, an unsettled event counting its whole length (frames
//   times dt); stand_turn_final_error_deg_mean: mean of the hips' yaw error to the desired
//   facing on each event's last frame; stand_turn_peak_rate_deg_s_max: the largest hips' yaw
//   rate on any frame inside an event. stand_turn_interrupted counts the events that lasted
//   less than kStandTurnJudgeSeconds (a new turn or the stick cut them short: no turn could be
//   done by then), and stand_turn_final_error_deg_max is the largest final error of the
//   others, the turns given time to finish. With no events, all seven are 0;
// - strafe_chest_error_deg_mean: the chest's yaw error to the desired facing on frames where
//   the desired velocity is at least kStrafeMinSpeed, points at least kStrafeMinAngle away from
//   the desired facing, and neither has changed for kStrafeSettleSeconds; strafe_chest_frames
//   counts them;
// - idle_head_speed_cm_s_mean: the head's 3-D speed on frames where the desired speed has been
//   zero for at least kIdleSettleSeconds (a held-frame idle gives 0); idle_head_frames counts
//   them;
// - toe_height_min_cm: the lowest height either toe joint reaches over the run (the foot joint
//   where a side has no toe role, as for foot skating), every frame; 0 for no frames.
// - the ground metrics (foot_skate_geom_cm_s_mean, toe clearance, penetration and float, the
//   hips' height and vertical acceleration, straight knees, wall depth, time stuck): defined in
//   ground_metrics.hpp, measured against the world's ground when the run has a world.
// "Has not changed for S seconds": the value has stayed within a tolerance (kFacingTolerance
// for the desired facing, kVelocityTolerance as a vector for the desired velocity) of the value
// it was last held at for at least S seconds, counting this frame's dt (as the stand time
// does), so a slow drift also counts as a change once it adds up.

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/controller/world.hpp"
#include "mm/database/joint_roles.hpp"
#include "mm/programs/ground_metrics.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

// A desired speed change at least this large (m/s) starts a speed-response measurement.
inline constexpr float kSpeedEventChange = 0.5f;
// A desired facing turn at least this large (radians) in one frame starts a heading measurement.
inline constexpr float kHeadingEventAngle = 0.5f;
// Standing metrics count frames whose desired speed has been zero and whose desired facing has
// not changed for this long (s).
inline constexpr float kStandSettleSeconds = 1.0f;
// Within this many degrees of the desired facing a turn counts as done.
inline constexpr float kSettleAngleDegrees = 10.0f;
// "Has not changed": a smaller change of the desired facing (degrees) or of the desired
// velocity (m/s, as a vector) is noise, not a new request.
inline constexpr float kFacingToleranceDegrees = 1.0f;
inline constexpr float kVelocityTolerance = 0.01f;
// A pivoting toe: below this height (m) and slower than this (m/s).
inline constexpr float kPivotToeHeight = 0.06f;
inline constexpr float kPivotToeSpeed = 0.35f;
// A pivoting foot is pitched at most this far (degrees) from level, foot to toe.
inline constexpr float kPivotMaxFootPitchDegrees = 60.0f;
// Turning on the spot: the desired speed below this (m/s) now and kStandTurnLookback (s)
// earlier, and the desired facing at least kStandTurnAngleDegrees away from then.
inline constexpr float kStandTurnSpeed = 0.01f;
inline constexpr float kStandTurnLookback = 0.1f;
inline constexpr float kStandTurnAngleDegrees = 45.0f;
// A turn on the spot given at least this long (s) is judged by where it ended.
inline constexpr float kStandTurnJudgeSeconds = 1.5f;
// Strafing: desired speed at least this (m/s), at least this far (degrees) from the facing,
// both held this long (s).
inline constexpr float kStrafeMinSpeed = 0.3f;
inline constexpr float kStrafeMinAngleDegrees = 45.0f;
inline constexpr float kStrafeSettleSeconds = 0.5f;
// Idle: the desired speed zero for this long (s).
inline constexpr float kIdleSettleSeconds = 2.0f;

struct EvaluationMetrics {
  double foot_skate_cm_s_mean = 0.0;
  double foot_skate_cm_s_p95 = 0.0;
  double root_sim_distance_cm_mean = 0.0;
  double root_sim_distance_cm_max = 0.0;
  double facing_error_deg_mean = 0.0;
  double speed_response_s = 0.0;
  int speed_events = 0;          // changes measured
  int speed_events_reached = 0;  // of which reached before the next change
  double heading_response_s = 0.0;
  int heading_events = 0;
  int heading_events_reached = 0;
  double stand_root_speed_cm_s_mean = 0.0;
  double stand_foot_speed_cm_s_mean = 0.0;
  int stand_frames = 0;
  double transitions_per_s = 0.0;
  // Styles (docs/controller.md, Styles): the share of moving frames (desired speed above
  // kStyleMovingSpeed) with a style requested whose clip has that style (a clip without a
  // style does not count as a match: while moving it is the idle playing, not the style); -1
  // when no such frame. style_response_s: the mean time from a request of a style to the first
  // frame of a clip of it, over the requests that got one before the next (style_requests of
  // them, style_requests_reached reached).
  double style_match = -1.0;
  int style_frames = 0;
  double style_response_s = 0.0;
  double style_response_s_max = 0.0;  // the slowest of those requests
  int style_requests = 0;
  int style_requests_reached = 0;
  double transition_accel_ratio = 0.0;
  double transition_accel_p99 = 0.0;              // m/s^2
  double database_accel_p99 = 0.0;                // m/s^2, linear interpolation
  double database_accel_p99_same_sampling = 0.0;  // m/s^2, the controller's sampling
  double transition_accel_ratio_same_sampling = 0.0;
  double transition_accel_ratio_played = 0.0;
  double played_accel_p99 = 0.0;  // m/s^2, the playing clips on their own
  double leg_accel_ratio = 0.0;
  double leg_accel_max = 0.0;         // m/s^2
  double leg_accel_max_t = 0.0;       // s
  double leg_accel_played_max = 0.0;  // m/s^2
  double search_us_mean = 0.0;
  double update_us_mean = 0.0;
  // The body metrics (definitions at the top of this file).
  double body_turn_rate_deg_s_p99 = 0.0;
  double body_turn_rate_deg_s_max = 0.0;
  double foot_pivot_deg_s_mean = 0.0;
  int foot_pivot_frames = 0;
  int stand_turns = 0;
  int stand_turn_unsettled = 0;
  int stand_turn_interrupted = 0;
  double stand_turn_final_error_deg_max = 0.0;
  double stand_turn_response_s = 0.0;
  double stand_turn_final_error_deg_mean = 0.0;
  double stand_turn_peak_rate_deg_s_max = 0.0;
  double strafe_chest_error_deg_mean = 0.0;
  int strafe_chest_frames = 0;
  double idle_head_speed_cm_s_mean = 0.0;
  int idle_head_frames = 0;
  double toe_height_min_cm = 0.0;
  // Feet and body against the ground (ground_metrics.hpp), and the database's own geometric
  // skating at the run's dt, the floor foot_skate_geom_cm_s_mean is read against.
  GroundMetrics ground;
  double foot_skate_geom_data_cm_s_mean = 0.0;
  int frames = 0;
  double seconds = 0.0;
};

// What one frame of a run leaves behind for the metrics. Yaws in radians, positions in metres,
// relative to `origin`.
struct EvaluationFrame {
  float t = 0.0f;
  glm::dvec3 origin{0.0};  // world position of this frame's positions' origin
  glm::vec3 sim_position{0.0f};
  float sim_yaw = 0.0f;
  glm::vec3 root_position{0.0f};
  float root_yaw = 0.0f;
  glm::vec3 desired_velocity{0.0f};
  float desired_yaw = 0.0f;
  bool transition = false;
  bool contact[2] = {false, false};  // left, right
  bool locked[2] = {false, false};   // the foot lock holds the toe (left, right)
  int clip = -1;                     // playing: index into the database's clips
  int clip_style = -1;               // the playing clip's style (-1: none)
  int requested_style = -1;          // the input's style (-1: any)
  int frame = -1;                    // playing: the database frame
  double update_seconds = 0.0;
  bool searched = false;
  double search_seconds = 0.0;
  // Every joint's global position, indexed like the skeleton; read during add() only.
  std::span<const glm::vec3> joints;
  // The ground under the toes (left, right) and the hips (world y; 0 on the flat plane), the
  // deepest a joint is inside a wall (m) and whether the simulation object was stuck
  // (ground_metrics.hpp; from the world, else 0 and false).
  float toe_ground[2] = {0.0f, 0.0f};
  float toe_support[2] = {-kNoSupport, -kNoSupport};  // foot_support_height, ground_metrics.hpp
  float hips_ground = 0.0f;
  float wall_depth = 0.0f;
  bool stuck = false;
  // The playing clip's own toe heights (left, right) above its flat ground at the playing time
  // (m; NaN where none was read): GroundFrame::played_toe.
  float played_toe[2] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::quiet_NaN()};
  // The controller's own view (ControllerDebug): the ground the body stands on, the ground each
  // toe is placed on (foot_placement.hpp) and how far the pelvis came down (m). Heights, like
  // toe_ground's: the controller's origin moves only horizontally.
  float body_ground = 0.0f;
  float placed_toe_ground[2] = {0.0f, 0.0f};
  float pelvis_drop = 0.0f;
  float playback_rate = 1.0f;  // climb_pace.hpp
};

// One joint's acceleration among those transition_accel_p99 is taken over: which joint, when
// (the frame it is the second difference at) and what played then, and how many transitions'
// 10-frame windows counted it.
struct TransitionSample {
  double acceleration = 0.0;  // m/s^2
  float t = 0.0f;             // s
  int joint = -1;
  int windows = 0;
  int clip = -1;   // the playing clip (index into the database's clips), or -1
  int frame = -1;  // the database frame
};

// The metrics of a run, fed one frame at a time. Holds the previous frames it needs, running
// sums and fixed-size histograms for the percentiles (foot_skate_cm_s_p95,
// transition_accel_p99, body_turn_rate_deg_s_p99: nearest rank, within 0.05 % of the exact
// value), never the whole run: its memory does not depend on the run's length. Not copyable
// (one run each).
class EvaluationAccumulator {
 public:
  // `roles` picks the joints; every frame carries `joint_count` joints; `dt` is the frame time.
  EvaluationAccumulator(const JointRoleIndices& roles, size_t joint_count, float dt);
  ~EvaluationAccumulator();
  EvaluationAccumulator(const EvaluationAccumulator&) = delete;
  EvaluationAccumulator& operator=(const EvaluationAccumulator&) = delete;

  // The next frame (asserts it carries joint_count joints).
  void add(const EvaluationFrame& frame);
  // The metrics of the frames so far, events still open closed at the last frame. The database
  // figures (database_accel_p99*, the ratios) are left 0: evaluate_script fills them.
  EvaluationMetrics metrics() const;
  // Keeps the `count` largest of the joint accelerations transition_accel_p99 is taken over
  // (memory for them reserved now; 0: none), for transition_samples(). Call before add().
  void keep_transition_samples(int count);
  // Those kept so far, largest first.
  std::vector<TransitionSample> transition_samples() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

struct EvaluationOptions {
  // Seconds per update, in [kMinRunDt, kMaxRunDt] (script.hpp).
  float dt = kDefaultRunDt;
  // Seconds to run; 0: the script's duration plus 2 s (so its last line is seen through). The
  // run may take at most kMaxRunFrames updates (script.hpp).
  float seconds = 0.0f;
  ControllerSettings settings;
  // The game's world the controller runs in (world.hpp; not owned), and the ground metrics are
  // measured against; null: the flat plane.
  const WorldQueries* world = nullptr;
  // Where the character stands at t = 0 (world x and z, metres; `mm eval --start X,Z`), facing
  // +Z. The dump's positions are world positions, so they include it.
  glm::dvec2 start{0.0};
  // When set, `mm eval --dump`: a CSV header line, then one row per frame written as the frame
  // is made (t, simulation, root, desired motion, transition, contacts, every joint's global
  // position). The caller checks the stream's state afterwards.
  std::ostream* dump = nullptr;
  // When set, called with every frame's record right after its update, before the next one
  // (the record's joints are valid during the call only): how a caller other than the CSV dump
  // (the Python module's run_script) keeps the run frame by frame.
  std::function<void(const EvaluationFrame&)> on_frame;
  // How many of the largest accelerations the transition metric counts to list in the result
  // (`mm eval --transition-report N`): where a transition_accel_ratio comes from.
  int transition_report = 0;  // at most kMaxTransitionReport
};

inline constexpr int kMaxTransitionReport = 10000;

// Desired speeds above this count as moving for style_match (m/s).
inline constexpr float kStyleMovingSpeed = 0.1f;

struct EvaluationResult {
  EvaluationMetrics metrics;
  std::vector<TransitionSample> transition_samples;  // EvaluationOptions::transition_report
};

// The database's own joint acceleration, 99th percentile (m/s^2): every clip that carries none
// of `excluded_tags` played straight through at dt with linear interpolation between frames
// (the baseline of transition_accel_ratio), or with cubic Hermite sampling when `cubic`.
double database_acceleration_p99(const Database& db, float dt, uint64_t excluded_tags = 0,
                                 bool cubic = false);

// Runs the script and measures it. Fails on invalid options or settings.
Result<EvaluationResult> evaluate_script(std::shared_ptr<const ControllerDatabase> database,
                                         const InputScript& script,
                                         const EvaluationOptions& options);

}  // namespace mm
