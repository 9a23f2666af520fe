// Feet never sink (issue 17): foot IK keeps each leg's end joint (the toe) at or above the
// lowest the data's own toes ever go, through reversals, stops and transitions at every rate.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <span>
#include <vector>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {
namespace {

using test::normal_controller_database;

constexpr float kEveryRate[] = {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f};

// Each shipped script in `names` run at each of `rates` on the normal database, its metrics
// handed to `check(name, dt, metrics)`.
template <typename Check>
void for_each_run(std::initializer_list<const char*> names, std::span<const float> rates,
                  Check check) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  for (const char* name : names) {
    Result<InputScript> script =
        load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input" / name);
    ASSERT_TRUE(script.ok()) << script.message();
    for (const float dt : rates) {
      EvaluationOptions options;
      options.dt = dt;
      Result<EvaluationResult> run = evaluate_script(shared, *script, options);
      ASSERT_TRUE(run.ok()) << run.message();
      check(name, dt, run->metrics);
    }
  }
}

// The data's lowest toe, found again here with the runtime's forward kinematics over every
// frame of the database.
TEST(FootFloorTest, TheDataLowestToeIsTheLowestOfEveryFrame) {
  const ControllerDatabase& shared = *normal_controller_database();
  const Database& db = shared.database();
  const size_t joints = static_cast<size_t>(db.joint_count());
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  float lowest[2] = {std::numeric_limits<float>::infinity(),
                     std::numeric_limits<float>::infinity()};
  std::vector<Transform> local(joints), global(joints);
  for (size_t f = 0; f < static_cast<size_t>(db.frame_count()); ++f) {
    for (size_t j = 0; j < joints; ++j) {
      local[j] =
          Transform{db.local_rotations()[f * joints + j], db.local_positions()[f * joints + j]};
    }
    forward_kinematics(db.skeleton().parents(), local, global);
    for (int side = 0; side < 2; ++side) {
      lowest[side] = std::min(lowest[side], global[static_cast<size_t>(toes[side])].translation.y);
    }
  }
  for (int side = 0; side < 2; ++side) {
    EXPECT_NEAR(shared.lowest_foot_end(side), lowest[side], 1e-5f) << "side " << side;
  }
}

// Where each clip next puts each toe down (ControllerDatabase::next_landing), found again here
// with the runtime's forward kinematics over every frame: the toe at the clip's first frame from
// this one on whose label is on, in this frame's root frame; nothing beyond the horizon or the
// clip's end. The frames at the horizon itself are left out (rounding decides them).
TEST(FootFloorTest, TheNextLandingIsWhereTheClipNextPutsTheToeDown) {
  const ControllerDatabase& shared = *normal_controller_database();
  const Database& db = shared.database();
  const size_t joints = static_cast<size_t>(db.joint_count());
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  const double horizon = ControllerDatabase::kLandingHorizon / db.frame_time();
  std::vector<Transform> local(joints), global(joints);
  std::vector<std::vector<Transform>> clip_globals;
  int found = 0, past_horizon = 0, in_the_air = 0;
  for (const ClipRange& clip : db.clips()) {
    clip_globals.clear();
    for (int f = clip.start; f < clip.end; ++f) {
      for (size_t j = 0; j < joints; ++j) {
        const size_t k = static_cast<size_t>(f) * joints + j;
        local[j] = Transform{db.local_rotations()[k], db.local_positions()[k]};
      }
      forward_kinematics(db.skeleton().parents(), local, global);
      clip_globals.push_back(global);
    }
    for (int side = 0; side < 2; ++side) {
      for (int f = clip.start; f < clip.end; ++f) {
        int next = f;
        while (next < clip.end && db.contacts()[2 * static_cast<size_t>(next) + side] == 0) ++next;
        const ControllerDatabase::FootLanding landing = shared.next_landing(f, side);
        const double ahead = next - f;
        if (next == clip.end || ahead > horizon + 1.0) {
          EXPECT_FALSE(landing.found) << clip.name << " frame " << f << " side " << side;
          ++past_horizon;
          continue;
        }
        if (ahead > horizon - 1.0) continue;
        in_the_air += next > f ? 1 : 0;
        ASSERT_TRUE(landing.found) << clip.name << " frame " << f << " side " << side;
        const Transform& root = clip_globals[static_cast<size_t>(f - clip.start)][0];
        const glm::vec3 toe =
            clip_globals[static_cast<size_t>(next - clip.start)][static_cast<size_t>(toes[side])]
                .translation;
        const glm::vec3 expected = glm::conjugate(root.rotation) * (toe - root.translation);
        EXPECT_LT(glm::length(landing.toe - expected), 1e-4f)
            << clip.name << " frame " << f << " side " << side;
        ++found;
      }
    }
  }
  EXPECT_GT(in_the_air, 1000);
  EXPECT_GT(found, in_the_air);
  EXPECT_GT(past_horizon, 0);
  EXPECT_FALSE(shared.next_landing(-1, 0).found);
  EXPECT_FALSE(shared.next_landing(db.frame_count(), 1).found);
}

// The shipped scripts where toes sank below the data's lowest before foot IK held them
// (reversals at a walk and a run, walks and runs with stops), at every rate.
TEST(FootFloorTest, ToesStayAtOrAboveTheDataLowestWithIk) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  const float floor = std::min(shared->lowest_foot_end(0), shared->lowest_foot_end(1));
  for_each_run({"reversals.txt", "walk-run.txt", "showcase.txt"}, kEveryRate,
               [&](const char* name, float dt, const EvaluationMetrics& m) {
                 EXPECT_GE(m.toe_height_min_cm, 100.0 * floor - 0.01) << name << " dt " << dt;
               });
}

// The played clips' own float (foot_float_data_cm_mean) is what the animation alone plants:
// without IK the planted toes are the played clip's but for the blends, so the two floats
// agree within a few millimetres; a read of any other frame than the playing time's would
// not.
TEST(FootFloorTest, WithoutIkThePlantedToesFloatAsThePlayedClipsOwn) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  for (const char* name : {"stop-and-go.txt", "circle.txt"}) {
    Result<InputScript> script =
        load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input" / name);
    ASSERT_TRUE(script.ok()) << script.message();
    EvaluationOptions options;
    options.dt = 1.0f / 60.0f;
    options.settings.ik_enabled = false;
    Result<EvaluationResult> run = evaluate_script(shared, *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    const GroundMetrics& g = run->metrics.ground;
    EXPECT_GT(g.foot_float_data_cm_mean, 2.0) << name;
    EXPECT_NEAR(g.foot_float_cm_mean, g.foot_float_data_cm_mean, 0.3) << name;
  }
}

// Planted through blends (issue 29): counted by geometry alone (low and slow), the toes slide
// well under the data's own under the same rule, on the shipped scripts where a held toe
// was dragged beyond the leg's softened reach or let go mid-blend, at the coarsest and the
// finest rate; and the transitions stay as smooth as the target.
TEST(FootFloorTest, GeometricSkatingIsNoMoreThanTheDataOwn) {
  const float rates[] = {1.0f / 30.0f, 1.0f / 144.0f};
  for_each_run(
      {"circle.txt", "reversals.txt", "zigzag.txt"}, rates,
      [](const char* name, float dt, const EvaluationMetrics& m) {
        EXPECT_GT(m.foot_skate_geom_data_cm_s_mean, 0.0) << name << " dt " << dt;
        // On this database (the idles are the Bandai ones, which shuffle) the data's
        // own is high; held toes reached by the heel's lift, not dragged, stay under
        // half of it.
        EXPECT_LE(m.ground.foot_skate_geom_cm_s_mean, 0.5 * m.foot_skate_geom_data_cm_s_mean)
            << name << " dt " << dt;
        EXPECT_LE(m.transition_accel_ratio, 0.9) << name << " dt " << dt;
      });
}

// Turning the body over a planted foot twists the leg, not the foot (issue 29, foot pivot <=
// 25 deg/s): on the scripts where labelled contacts sweep in at landings or out at push-offs,
// and where a held heading was kept on a foot the blend had lifted, at every rate.
TEST(FootFloorTest, PlantedFeetPivotNoFasterThanTheTarget) {
  for_each_run({"walk-run.txt", "reversals.txt"}, kEveryRate,
               [](const char* name, float dt, const EvaluationMetrics& m) {
                 EXPECT_GT(m.foot_pivot_frames, 100) << name << " dt " << dt;
                 EXPECT_LE(m.foot_pivot_deg_s_mean, 25.0) << name << " dt " << dt;
               });
}

// Each frame's foot direction (ankle to toe) of both legs, and the toes' heights.
struct FootFrames {
  std::vector<glm::vec3> along[2];
  std::vector<float> toe_height[2];
};

FootFrames foot_frames(const InputScript& script, float dt, bool ik) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  const JointRoleIndices& roles = shared->database().roles();
  const int feet[2] = {roles.left_foot, roles.right_foot};
  const int toes[2] = {roles.left_toe, roles.right_toe};
  FootFrames frames;
  EvaluationOptions options;
  options.dt = dt;
  options.settings.ik_enabled = ik;
  options.on_frame = [&](const EvaluationFrame& f) {
    for (int side = 0; side < 2; ++side) {
      const glm::vec3 toe = f.joints[static_cast<size_t>(toes[side])];
      frames.along[side].push_back(toe - f.joints[static_cast<size_t>(feet[side])]);
      frames.toe_height[side].push_back(toe.y);
    }
  };
  Result<EvaluationResult> run = evaluate_script(shared, script, options);
  EXPECT_TRUE(run.ok()) << run.message();
  return frames;
}

// A foot the animation lifts off the ground is not held to the heading it had there: at a
// push-off the foot turns steep and its heading swings round, so a held heading turned the whole
// foot about its toe, 58 degrees from the animation's at worst on walk-run at 1/30 (a dead blend
// began as the toe rose). IK changes no search, so the run without it plays the same frames.
TEST(FootFloorTest, ALiftedFootKeepsTheAnimationsDirection) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/walk-run.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  const float dt = 1.0f / 30.0f;
  const FootFrames with_ik = foot_frames(*script, dt, true);
  const FootFrames without = foot_frames(*script, dt, false);
  int lifted = 0;
  float worst = 0.0f;
  for (int side = 0; side < 2; ++side) {
    ASSERT_EQ(with_ik.along[side].size(), without.along[side].size());
    for (size_t i = 0; i < without.along[side].size(); ++i) {
      if (without.toe_height[side][i] < 0.1f) continue;
      ++lifted;
      const float cosine =
          glm::dot(glm::normalize(with_ik.along[side][i]), glm::normalize(without.along[side][i]));
      worst = std::max(worst, glm::degrees(std::acos(std::clamp(cosine, -1.0f, 1.0f))));
    }
  }
  EXPECT_GT(lifted, 300);
  EXPECT_LT(worst, 30.0f);
}

// The largest acceleration (m/s^2) of a toe on the two updates from its lock's release, over a
// run of `name` at `dt`.
float largest_release_acceleration(const char* name, float dt) {
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  const JointRoleIndices& roles = shared->database().roles();
  const int toes[2] = {roles.left_toe, roles.right_toe};
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input" / name);
  EXPECT_TRUE(script.ok()) << script.message();
  if (!script) return 0.0f;
  std::vector<glm::dvec3> toe[2];  // in the world: the frame's origin moves with the character
  std::vector<bool> locked[2];
  EvaluationOptions options;
  options.dt = dt;
  options.on_frame = [&](const EvaluationFrame& f) {
    for (int side = 0; side < 2; ++side) {
      toe[side].push_back(f.origin + glm::dvec3(f.joints[static_cast<size_t>(toes[side])]));
      locked[side].push_back(f.locked[side]);
    }
  };
  Result<EvaluationResult> run = evaluate_script(shared, *script, options);
  EXPECT_TRUE(run.ok()) << run.message();
  float largest = 0.0f;
  for (int side = 0; side < 2; ++side) {
    for (size_t i = 3; i + 1 < toe[side].size(); ++i) {
      if (!locked[side][i - 1] || locked[side][i]) continue;
      for (const size_t j : {i, i + 1}) {
        const glm::dvec3 a = (toe[side][j] - 2.0 * toe[side][j - 1] + toe[side][j - 2]) /
                             static_cast<double>(dt * dt);
        largest = std::max(largest, static_cast<float>(glm::length(a)));
      }
    }
  }
  return largest;
}

// A released toe eases back onto the animation on a spring that starts at no more than
// kReleaseMaxAcceleration (docs/controller.md, foot lock): a transition whose new clip has the
// held foot far away released it at the halflife's own pace, the largest acceleration of the
// whole window after the transition (random-long and zigzag at 1/30 s: 63 m/s^2 each on the
// tests' database, the toe's own motion included; 48 and 41 now).
TEST(FootFloorTest, AToeReleasedFarFromItsAnimationStartsBackGently) {
  for (const char* name : {"random-long.txt", "zigzag.txt"}) {
    EXPECT_LT(largest_release_acceleration(name, 1.0f / 30.0f), 55.0f) << name;
  }
}

// A toe whose contact begins while it is still coming down (a heel strike) comes down with the
// animation's toe and stands where the data's standing toes do, not where the lock caught it: on
// the tests' database, stand-turns.txt at 1/144 s, two locks (42.5 s and 42.98 s) stood their toe
// at 7.4 and 7.0 cm for 0.5 and 0.2 s, the foot floating 3 cm over the floor, when every other
// held toe stands at 4.4 cm. Every lock held for 0.15 s or more now brings its toe within 1 cm of
// where the median such lock does.
TEST(FootFloorTest, AToeHeldFromAHeelStrikeComesDownWithTheAnimation) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/stand-turns.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  const std::shared_ptr<const ControllerDatabase> shared = normal_controller_database();
  const JointRoleIndices& roles = shared->database().roles();
  const int toes[2] = {roles.left_toe, roles.right_toe};
  constexpr float kDt = 1.0f / 144.0f;
  // Each finished lock's length (s) and its toe's lowest height.
  struct Lock {
    float seconds = 0.0f;
    float lowest = std::numeric_limits<float>::infinity();
  };
  std::vector<Lock> locks;
  Lock open[2];
  EvaluationOptions options;
  options.dt = kDt;
  options.on_frame = [&](const EvaluationFrame& frame) {
    for (int side = 0; side < 2; ++side) {
      if (frame.locked[side]) {
        open[side].seconds += kDt;
        open[side].lowest =
            std::min(open[side].lowest, frame.joints[static_cast<size_t>(toes[side])].y);
      } else if (open[side].seconds > 0.0f) {
        locks.push_back(open[side]);
        open[side] = Lock{};
      }
    }
  };
  Result<EvaluationResult> run = evaluate_script(shared, *script, options);
  ASSERT_TRUE(run.ok()) << run.message();
  std::vector<float> lowest;
  for (const Lock& l : locks) {
    if (l.seconds >= 0.15f) lowest.push_back(l.lowest);
  }
  ASSERT_GT(lowest.size(), 20u);
  std::vector<float> sorted = lowest;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const float median = sorted[sorted.size() / 2];
  for (const float l : lowest) EXPECT_LT(l, median + 0.01f);
}

}  // namespace
}  // namespace mm
