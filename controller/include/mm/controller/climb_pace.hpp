#pragma once
// The pace on steep ground (issue 29). The data walks on the flat: a walking stride of the
// Bandai takes 0.7 m, so up a stair of 25 cm treads every step climbs three risers, and the
// swinging foot is lifted half a metre or more within the third of a second its swing lasts,
// far faster than any foot of the data moves. People slow down on stairs and steep ramps: a
// stair is climbed at about a third of a metre a second, a step a tread. With no stair data
// to play, the controller slows the clip it plays instead: up or down ground steeper than the
// stick's speed can climb at `max_climb_speed`, the clip plays at a lower rate (down to
// `min_playback_rate`) and the desired velocity is scaled by the same rate, so the character
// covers the ground as slowly as its legs move, and every motion of the body (and the height
// the feet are lifted by) takes longer by the same factor: its accelerations fall with the
// rate's square. The search still matches clips at the stick's own speed (its trajectory is
// scaled back up), so the gait is the one asked for, slowed.
//
// Units: grades as rise over run (dimensionless), speeds in m/s, times in s. Robustness: a
// non-finite or negative input leaves the rate where it is; dt <= 0 changes nothing. Called per
// update: no allocation.

#include <span>

#include <glm/glm.hpp>

namespace mm {

// The steepest grade (absolute rise over horizontal run) from `from` to any of the predicted
// trajectory's positions at least kClimbMinRun away horizontally (0 when none is): the ground
// the character is about to climb or descend, as the simulation's collided trajectory found it.
inline constexpr float kClimbMinRun = 0.2f;  // m: closer samples give no grade
float grade_ahead(const glm::vec3& from, std::span<const glm::vec3> trajectory);

class ClimbPace {
 public:
  // The rate toward which the pace moves: the share of `speed` (m/s, horizontal) that climbs
  // at most `max_climb_speed` (m/s, vertical) on `grade`, no lower than `min_rate`; 1 with
  // `max_climb_speed` <= 0 (no limit).
  static float goal(float grade, float speed, float max_climb_speed, float min_rate);
  // The lowest rate whatever `min_rate` asks (times are divided by the rate).
  static constexpr float kMinRate = 0.1f;
  // Moves the rate toward goal(...) with kHalflife: the desired velocity it scales (and with it
  // the simulation object) changes smoothly when the ground ahead turns steep.
  static constexpr float kHalflife = 0.15f;  // s
  void update(float grade, float speed, float max_climb_speed, float min_rate, float dt);
  float rate() const { return rate_; }
  void reset() { rate_ = 1.0f; }

 private:
  float rate_ = 1.0f;  // in [min_rate, 1]
};

}  // namespace mm
