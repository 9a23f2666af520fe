#pragma once
// Level of detail for a crowd under a frame budget (docs/performance.md, "Level of detail"), in
// the manner of engines' animation budget allocators: the game gives every character a
// significance (larger is more important, e.g. minus its distance to the camera) and the
// scheduler decides each frame which characters update at full rate, which at a reduced rate,
// and which only move (Controller::update_move_only). A reduced-rate character's displayed pose
// goes from what was shown to each update's pose over the frames until the next (one period
// late, never jumping).
//
// Deterministic: the tiers depend only on the significances, the settings (whose cost model
// stands in for measured time) and the tiers of the frame before, never on timings or on the
// thread count, so the poses do not either. The scheduler owns every displayed pose (pose()),
// in buffers sized at create(): plan() and step() never allocate.
//
// Per frame: plan(significances) on one thread, then step(i, controller_i, dt, input_i) once for
// every character, from any number of threads (distinct characters in parallel), then read
// pose(i).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "mm/controller/controller.hpp"
#include "mm/runtime/result.hpp"
#include "mm/runtime/transform.hpp"

namespace mm {

// From the most to the least work. The names are the keys of crowd-bench's `tier_counts`.
enum class CrowdTier : uint8_t {
  Full,      // Controller::update every frame
  Half,      // every 2nd frame with the time since the last, interpolated in between
  Quarter,   // every 4th frame, the same
  MoveOnly,  // Controller::update_move_only every frame: the pose carried rigidly
};
inline constexpr int kCrowdTierCount = 4;

// "full", "half", "quarter", "move_only".
std::string_view crowd_tier_name(CrowdTier tier);
// Frames from one Controller::update to the next: 1, 2, 4; 0 for MoveOnly (never updated).
int crowd_tier_period(CrowdTier tier);

struct CrowdSchedulerSettings {
  // The frame budget for all characters together (ms of wall time); 0 or infinite: no budget,
  // every character at full rate.
  float budget_ms = 0.0f;
  // The threads the game steps the crowd on: the budget holds threads * budget_ms of work. The
  // plan reads this number, never how many threads run it, so a run on fewer threads shows the
  // same poses (late).
  int threads = 1;
  // The cost model: one character's work per frame on one thread (us), averaged over its
  // tier's period, displaying included. Measured on the target machine once (mm crowd-bench
  // calibrates them, docs/performance.md); the defaults are of the development machine.
  std::array<float, kCrowdTierCount> cost_us = {8.0f, 4.4f, 2.4f, 0.5f};
  // The share of the budget the most significant characters get at full rate first, before the
  // rest is spread over the others a tier at a time (0: no character at full rate unless every
  // other is raised to half first).
  float full_share = 0.4f;
  // The share of the budget the plan leaves unspent, so that the frames the cost model
  // underestimates (the spread of real frames about their mean: other processes, cache misses,
  // searches falling together) still fit: the plan spends (1 - headroom) of the capacity. It is
  // taken from the tiers below full (full_share stays a share of the whole capacity), so the
  // most significant characters keep their rate. 0: the plan spends the whole budget.
  float headroom = 0.0f;
  // Hysteresis (significance units): a character ranks as if its significance were this much
  // higher per tier it holds above MoveOnly, so one near a tier's boundary is not swapped back
  // and forth by small changes of significance.
  float hysteresis = 1.0f;
  // After a step that continues another kind of step (a reduced-rate update after held frames,
  // a promotion, a demotion to MoveOnly), the displayed pose eases from what it would have shown
  // into the new one with this halflife (s): no pop.
  float blend_halflife = 0.06f;

  // Finite, budget >= 0, threads in [1, 1024], costs positive and not increasing from Full to
  // MoveOnly, full_share in [0, 1], headroom in [0, 1), hysteresis >= 0, blend_halflife > 0.
  Status validate() const;
};

class CrowdScheduler {
 public:
  // A scheduler for `characters` controllers of `joints` joints each (their database's skeleton).
  // Fails on invalid settings or no characters or joints.
  static Result<CrowdScheduler> create(size_t characters, size_t joints,
                                       const CrowdSchedulerSettings& settings);

  // Decides this frame's tiers: `significance` has one value per character (non-finite counts
  // as the least). Under the budget every character gets at least the highest tier that all of
  // them can afford (the floor; MoveOnly when none is); the most significant are raised to full
  // rate within full_share of the budget; what is left raises the others, in order of
  // significance, one tier at a time (all that can go from the floor up one tier, then up
  // another). Without a budget, or one that holds every character at full rate: all at full
  // rate. One thread, no allocation.
  void plan(std::span<const float> significance);
  // Every character at one tier this frame, budget ignored (tests, calibration).
  void plan_all(CrowdTier tier);
  // A new frame budget for the next plan() (ms; 0: none), e.g. from a game's settings or its
  // measured frame time. Fails, changing nothing, when the budget is not a number >= 0.
  Status set_budget_ms(float budget_ms);

  // Character i's work of this frame (after plan()): updates, moves or holds `controller`
  // (always the same one for i) by its tier and phase, and sets pose(i). Reduced-rate
  // characters update on staggered frames ((frame + i) % period == 0), so the work is even over
  // the frames. Thread-safe for distinct i. `input` is read only when updates(i).
  void step(size_t i, Controller& controller, float dt, const ControllerInput& input);
  // Ask the cache for what step(i, controller) will touch, in two stages a crowd's loop calls
  // ahead of its steps: prefetch_ahead for the character after next (a moving character's
  // controller members: nothing read, so nothing waited for), prefetch for the next one (the
  // scheduler's per-character state and poses, and a moving controller's root joint, whose
  // heap pointers prefetch_ahead brought in). No effect on any result; no allocation.
  void prefetch_ahead(size_t i, const Controller& controller) const;
  void prefetch(size_t i, const Controller& controller) const;
  // Whether step(i) calls the controller this frame (so needs an input).
  bool updates(size_t i) const;

  // What to display for character i after this frame's step: global transforms (as
  // Controller::global_transforms()) moved by the rigid motion carry(i). Only a character that
  // only moves has a carry: its held pose stays as it was and carry(i) takes it along with the
  // root (one transform per step, not every joint; a renderer applies it per instance).
  std::span<const Transform> pose(size_t i) const {
    return {(shows_last_[i] != 0 ? last_ : shown_).data() + i * joints_, joints_};
  }
  // The rigid motion (a turn about +Y and a translation, unit scale) to apply to every joint of
  // pose(i): compose(carry(i), pose(i)[j]). The identity for every tier but MoveOnly.
  Transform carry(size_t i) const {
    return shows_last_[i] != 0 && carried_[i] != 0 ? carry_[i] : Transform{};
  }
  // pose(i) with carry(i) applied, into `out` (joints() transforms): the displayed globals.
  void displayed_pose(size_t i, std::span<Transform> out) const;
  CrowdTier tier(size_t i) const { return static_cast<CrowdTier>(tier_[i]); }
  // Characters per tier in this frame's plan, and the plan's work by the cost model (us).
  const std::array<int, kCrowdTierCount>& tier_counts() const { return counts_; }
  double planned_cost_us() const { return planned_cost_us_; }
  size_t characters() const { return tier_.size(); }
  size_t joints() const { return joints_; }
  const CrowdSchedulerSettings& settings() const { return settings_; }

 private:
  CrowdScheduler() = default;
  enum class Step : uint8_t { None, Update, Hold, Move };
  void rank(std::span<const float> significance);
  void assign(CrowdTier floor, double capacity, double spendable);
  void start_blend(size_t i, std::span<const Transform> predicted);
  void keep_update(size_t i, const Controller& controller, Step now, Step last_step);
  // Joint j of the last step's pose: last_, carried when the step only moved.
  Transform updated_joint(size_t i, size_t j) const {
    const Transform& held = last_[i * joints_ + j];
    return carried_[i] != 0 ? compose(carry_[i], held) : held;
  }
  void show(size_t i);

  CrowdSchedulerSettings settings_;
  size_t joints_ = 0;
  int64_t frame_ = 0;
  std::array<int, kCrowdTierCount> counts_{};
  double planned_cost_us_ = 0.0;
  // Per character.
  std::vector<uint8_t> tier_;
  std::vector<Step> last_step_;
  std::vector<uint8_t> held_frames_;    // frames since the last update
  std::vector<float> pending_dt_;       // game time since the last update (s)
  std::vector<uint8_t> update_period_;  // frames the last update's pose is chased over
  std::vector<float> blend_weight_;     // of the offsets: 1 at a blend's start, decaying to 0
  std::vector<uint8_t> shows_last_;     // pose() is the last update's pose as it is
  // After a move: last_ is the pose held since the character started moving, its root where
  // the held joints hang from, and carry_ the rigid motion from there to the controller's root.
  std::vector<uint8_t> carried_;
  std::vector<Transform> carry_;
  std::vector<float> keys_;      // significance with hysteresis, this frame
  std::vector<uint32_t> order_;  // characters by key, most significant first
  // Per character and joint (character-major): what was shown when the last update came, that
  // update's pose, the offsets a blend eases out, what is shown.
  std::vector<Transform> from_;
  std::vector<Transform> last_;
  std::vector<glm::vec3> offset_translations_;
  std::vector<glm::quat> offset_rotations_;
  std::vector<Transform> shown_;
};

}  // namespace mm
