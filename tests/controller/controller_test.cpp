// The controller on the real database: settings, bad input, determinism, transitions, the root
// adjustment invariant, standing still, starting again, tags and the candidate rules.

#include <gtest/gtest.h>

#include <set>

#include <cmath>
#include <limits>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/script.hpp"

namespace mm {
namespace {

using test::horizontal_speed;
using test::normal_controller_database;
using test::push_toward;

constexpr float kDt = 1.0f / 60.0f;

Controller make(const ControllerSettings& settings = {}) {
  Result<Controller> c = Controller::create(normal_controller_database(), settings);
  EXPECT_TRUE(c.ok()) << (c.ok() ? "" : c.message());
  return std::move(c).value();
}

bool finite_pose(const Controller& c) {
  for (const Transform& t : c.global_transforms()) {
    const glm::vec3 p = t.translation;
    const glm::quat q = t.rotation;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(q.w) ||
        !std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
      return false;
    }
  }
  return true;
}

// An enum field can hold any value of its underlying type (a cast, a struct filled by other
// code); validate() refuses every value but the named ones.
TEST(ControllerSettingsTest, InterpolationOutsideItsValuesIsRefused) {
  ControllerSettings s;
  for (const int value : {0, 1, 2}) {
    s.interpolation = static_cast<InterpolationMethod>(value);
    EXPECT_TRUE(s.validate().ok()) << value;
  }
  for (const int value : {3, 255, -1}) {
    s.interpolation = static_cast<InterpolationMethod>(value);
    EXPECT_EQ(s.validate().message(),
              "controller settings: interpolation must be one of nlerp, slerp, sclerp (0 to 2), "
              "found " +
                  std::to_string(value));
  }
}

TEST(ControllerSettingsTest, SyncModeOutsideItsValuesIsRefused) {
  ControllerSettings s;
  for (const int value : {0, 1, 2}) {
    s.sync_mode = static_cast<SyncMode>(value);
    EXPECT_TRUE(s.validate().ok()) << value;
  }
  for (const int value : {3, 128, 255}) {
    s.sync_mode = static_cast<SyncMode>(value);
    EXPECT_EQ(s.validate().message(),
              "controller settings: sync_mode must be one of character, simulation, none (0 to "
              "2), found " +
                  std::to_string(value));
  }
  Result<Controller> bad = Controller::create(normal_controller_database(), s);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("sync_mode must be one of"), std::string::npos);
}

TEST(ControllerSettingsTest, TransitionModeOutsideItsValuesIsRefused) {
  ControllerSettings s;
  for (const int value : {0, 1}) {
    s.transition_mode = static_cast<TransitionMode>(value);
    EXPECT_TRUE(s.validate().ok()) << value;
  }
  for (const int value : {2, 255}) {
    s.transition_mode = static_cast<TransitionMode>(value);
    EXPECT_EQ(s.validate().message(),
              "controller settings: transition_mode must be one of dead-blending, "
              "inertialization (0 to 1), found " +
                  std::to_string(value));
  }
}

TEST(ControllerSettingsTest, EveryInvalidFieldIsNamed) {
  ControllerSettings s;
  EXPECT_TRUE(s.validate().ok());
  s.inertialization_halflife = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(s.validate().message().find("inertialization_halflife"), std::string::npos);
  s = {};
  s.search_interval = -1.0f;
  EXPECT_NE(s.validate().message().find("search_interval must be a number in"), std::string::npos);
  s = {};
  s.search_method = "nonsense";
  EXPECT_NE(s.validate().message().find("unknown search method 'nonsense'"), std::string::npos);
  s = {};
  s.bone_length_iterations = -1;
  EXPECT_NE(s.validate().message().find("bone_length_iterations"), std::string::npos);

  Result<Controller> bad = Controller::create(normal_controller_database(), s);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("bone_length_iterations"), std::string::npos);
}

TEST(ControllerSettingsTest, SetByName) {
  ControllerSettings s;
  EXPECT_TRUE(set_controller_setting(s, "inertialization_halflife", "0.25").ok());
  EXPECT_FLOAT_EQ(s.inertialization_halflife, 0.25f);
  EXPECT_TRUE(set_controller_setting(s, "ik_enabled", "off").ok());
  EXPECT_FALSE(s.ik_enabled);
  EXPECT_TRUE(set_controller_setting(s, "sync_mode", "none").ok());
  EXPECT_EQ(s.sync_mode, SyncMode::None);
  EXPECT_EQ(set_controller_setting(s, "inertialization_halflife", "fast").message(),
            "setting 'inertialization_halflife': expected a number, found 'fast'");
  EXPECT_EQ(set_controller_setting(s, "sync_mode", "both").message(),
            "setting 'sync_mode': expected character, simulation or none, found 'both'");
  EXPECT_TRUE(set_controller_setting(s, "transition_mode", "inertialization").ok());
  EXPECT_EQ(s.transition_mode, TransitionMode::Inertialization);
  EXPECT_TRUE(set_controller_setting(s, "transition_mode", "dead-blending").ok());
  EXPECT_EQ(s.transition_mode, TransitionMode::DeadBlending);
  EXPECT_EQ(set_controller_setting(s, "transition_mode", "crossfade").message(),
            "setting 'transition_mode': expected dead-blending or inertialization, found "
            "'crossfade'");
  EXPECT_EQ(set_controller_setting(s, "warp_speed", "9").message(), "unknown setting 'warp_speed'");
}

TEST(ControllerDatabaseTest, CandidatesLeaveClipEndsOutAndSpeedsComeFromTheData) {
  const auto shared = normal_controller_database();
  const Database& db = shared->database();
  const int excluded =
      static_cast<int>(std::lround(shared->options().clip_end_exclusion / db.frame_time()));
  ASSERT_GT(excluded, 0);
  int candidates = 0;
  for (const ClipRange& clip : db.clips()) {
    const bool idle = (clip.tags & shared->idle_tags()) != 0;
    for (int f = clip.start; f < clip.end; ++f) {
      const bool candidate = shared->candidates()[static_cast<size_t>(f)] != 0;
      candidates += candidate ? 1 : 0;
      if (candidate) {
        EXPECT_TRUE(db.searchable()[static_cast<size_t>(f)]) << clip.name << " " << f;
      }
      if (!idle && f >= clip.end - excluded) {
        EXPECT_FALSE(candidate) << clip.name << " " << f;
      }
    }
  }
  EXPECT_GT(candidates, 1000);
  const ControllerDatabase::Speeds& s = shared->speeds();
  // Bandai walks are about 1 m/s and runs two to three times that.
  EXPECT_GT(s.walk_forward, 0.7f);
  EXPECT_LT(s.walk_forward, 1.6f);
  EXPECT_GT(s.run_forward, 1.8f * s.walk_forward);
  EXPECT_NE(shared->action_tags(), 0u);
}

TEST(ControllerTest, BadInputNeverPoisonsTheState) {
  Controller c = make();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  ControllerInput bad;
  bad.left_stick = glm::vec2(nan, inf);
  bad.right_stick = glm::vec2(-inf, nan);
  bad.camera_yaw = nan;
  bad.strafe = true;
  for (int i = 0; i < 60; ++i) c.update(kDt, bad);
  EXPECT_TRUE(finite_pose(c));

  ControllerInput huge = push_toward(0.0f);
  huge.left_stick *= 1e30f;
  huge.camera_yaw = 1e30f;
  for (int i = 0; i < 60; ++i) c.update(kDt, huge);
  EXPECT_TRUE(finite_pose(c));
  // An oversized stick is read as a full one: the desired speed is the run or walk speed.
  EXPECT_NEAR(glm::length(c.debug().desired_velocity), c.speeds().walk_forward, 1e-3f);

  // dt <= 0 or non-finite changes nothing at all.
  const std::vector<Transform> before(c.global_transforms().begin(), c.global_transforms().end());
  for (float dt : {0.0f, -1.0f, nan, inf, -inf}) c.update(dt, push_toward(90.0f));
  for (size_t j = 0; j < before.size(); ++j) {
    EXPECT_EQ(before[j].translation, c.global_transforms()[j].translation);
    EXPECT_EQ(before[j].rotation, c.global_transforms()[j].rotation);
  }

  // A huge dt is clamped to max_dt: one such step moves no farther than max_dt at a run.
  const glm::vec3 root = c.root_transform().translation;
  c.update(1e6f, push_toward(0.0f, true));
  EXPECT_TRUE(finite_pose(c));
  EXPECT_LT(horizontal_speed(c.root_transform().translation, root, c.settings().max_dt), 10.0f);

  // An unknown tag matches nothing and locomotion goes on.
  ControllerInput tagged = push_toward(0.0f);
  tagged.tag = "no-such-tag";
  for (int i = 0; i < 30; ++i) c.update(kDt, tagged);
  EXPECT_TRUE(finite_pose(c));
}

TEST(ControllerTest, SameInputSameOutputBitForBit) {
  Controller a = make();
  Controller b = make();
  for (int i = 0; i < 600; ++i) {
    ControllerInput input = push_toward(static_cast<float>((i / 90) * 70), (i / 200) % 2 == 1);
    if (i > 450) input.left_stick = glm::vec2(0.0f);
    a.update(kDt, input);
    b.update(kDt, input);
  }
  for (size_t j = 0; j < a.global_transforms().size(); ++j) {
    EXPECT_EQ(a.global_transforms()[j].translation, b.global_transforms()[j].translation);
    EXPECT_EQ(a.global_transforms()[j].rotation, b.global_transforms()[j].rotation);
  }
  EXPECT_EQ(a.debug().transitions, b.debug().transitions);
  EXPECT_GT(a.debug().transitions, 3);
}

// The skinning matrices are computed when read, from the last update's pose: each maps the
// bind pose onto that pose (the rest pose's joint origins land on the joints' positions), however
// many updates went by unread. With compute_skinning off they are never filled.
TEST(ControllerTest, SkinningMatricesShowTheLastUpdatesPose) {
  Controller c = make();
  ControllerSettings off;
  off.compute_skinning = false;
  Controller unskinned = make(off);
  for (int read = 0; read < 3; ++read) {
    for (int i = 0; i < 50 + 40 * read; ++i) {
      c.update(kDt, push_toward(static_cast<float>(read * 90)));
      unskinned.update(kDt, push_toward(0.0f));
    }
    const std::span<const glm::mat4> skin = c.skinning_matrices();
    for (size_t j = 0; j < skin.size(); ++j) {
      const glm::vec4 bind_origin =
          glm::inverse(c.inverse_bind_matrices()[j]) * glm::vec4(0, 0, 0, 1);
      const glm::vec3 shown = glm::vec3(skin[j] * bind_origin);
      EXPECT_LT(glm::length(shown - c.global_transforms()[j].translation), 1e-4f)
          << "read " << read << ", joint " << j;
    }
  }
  for (const glm::mat4& m : unskinned.skinning_matrices()) EXPECT_EQ(m, glm::mat4(1.0f));
}

// Largest per-joint displacement between two frames of global transforms.
float largest_step(std::span<const Transform> a, std::span<const Transform> b) {
  float step = 0.0f;
  for (size_t j = 1; j < a.size(); ++j) {
    step = std::max(step, glm::length(a[j].translation - b[j].translation));
  }
  return step;
}

// Over a run of turns: the largest joint displacement on frames with a transition, and on the
// others.
std::pair<float, float> transition_steps(const ControllerSettings& settings) {
  Controller c = make(settings);
  std::vector<Transform> previous(c.global_transforms().begin(), c.global_transforms().end());
  float at_transitions = 0.0f, elsewhere = 0.0f;
  int transitions = 0;
  for (int i = 0; i < 1200; ++i) {
    c.update(kDt, push_toward(static_cast<float>((i / 100) * 100)));
    const float step = largest_step(c.global_transforms(), previous);
    if (c.debug().transitioned) {
      at_transitions = std::max(at_transitions, step);
      ++transitions;
    } else {
      elsewhere = std::max(elsewhere, step);
    }
    previous.assign(c.global_transforms().begin(), c.global_transforms().end());
  }
  EXPECT_GT(transitions, 10);
  return {at_transitions, elsewhere};
}

TEST(ControllerTest, TransitionsAreContinuousInEveryMode) {
  for (const TransitionMode mode :
       {TransitionMode::DeadBlending, TransitionMode::Inertialization}) {
    SCOPED_TRACE(static_cast<int>(mode));
    ControllerSettings settings;
    settings.ik_enabled = false;  // the animation alone
    settings.transition_mode = mode;
    const auto [at_transitions, elsewhere] = transition_steps(settings);
    // A transition frame moves no joint more than ordinary playback does.
    EXPECT_LE(at_transitions, elsewhere);
  }
  // With no time to blend or decay in, the same run pops: the test can tell.
  ControllerSettings popping;
  popping.ik_enabled = false;
  popping.inertialization_halflife = 0.0f;
  popping.dead_blend_time = 0.0f;
  const auto [pops, ordinary] = transition_steps(popping);
  EXPECT_GT(pops, ordinary);
}

// Early in a dead blend the pose shown is mostly the outgoing one: until half the blend a foot
// is down only where both poses have it down (a swinging foot is not locked in mid-swing because
// the incoming clip has it down, nor a foot the fade already lifts held back).
TEST(ControllerTest, EarlyInADeadBlendAFootIsDownOnlyWhereBothPosesHaveItDown) {
  ControllerSettings settings;
  ASSERT_EQ(settings.transition_mode, TransitionMode::DeadBlending);
  settings.ik_enabled = false;  // no stepping feet: debug().contact is exactly the contact shown
  Controller c = make(settings);
  const Database& db = c.controller_database().database();
  bool held[2] = {false, false};
  float blend_time = 1e9f;  // since the last transition, summed as the blend sums it
  int early = 0, differing = 0;
  for (int i = 0; i < 1200; ++i) {
    const bool previous[2] = {c.debug().contact[0], c.debug().contact[1]};
    c.update(kDt, push_toward(static_cast<float>((i / 100) * 100)));
    const ControllerDebug& d = c.debug();
    if (d.transitioned) {
      held[0] = previous[0];
      held[1] = previous[1];
      blend_time = 0.0f;
    }
    blend_time += kDt;
    const bool is_early = blend_time < 0.5f * settings.dead_blend_time;
    early += is_early;
    for (int side = 0; side < 2; ++side) {
      const bool label = db.contacts()[static_cast<size_t>(d.frame) * 2 + side] != 0;
      EXPECT_EQ(d.contact[side], label && (!is_early || held[side]))
          << "frame " << i << " " << side;
      differing += is_early && label != held[side];
    }
  }
  EXPECT_GT(early, 100);
  EXPECT_GT(differing, 10);  // the incoming clips' contacts often differed: the test can tell
}

TEST(ControllerTest, RootAdjustmentKeepsTransitionSourceAndDestinationConsistent) {
  ControllerSettings settings;
  settings.sync_mode = SyncMode::None;
  settings.search_interval = 10.0f;  // no search while the invariant is checked
  settings.ik_enabled = false;
  Controller adjusted = make(settings);
  for (int i = 0; i < 90; ++i) adjusted.update(kDt, push_toward(0.0f));
  Controller twin = adjusted;

  const glm::vec3 requested(3.0f, 0.0f, -2.0f);
  const glm::quat requested_rotation = glm::angleAxis(1.0f, glm::vec3(0.0f, 1.0f, 0.0f));
  adjusted.adjust_root(requested, requested_rotation);
  EXPECT_LT(glm::length(adjusted.root_transform().translation - requested), 1e-5f);
  EXPECT_LT(quat_angle_between(adjusted.root_transform().rotation, requested_rotation), 1e-4f);

  // Every later frame: the adjusted root moves exactly as the twin's, turned by the adjustment.
  const float turn =
      wrap_angle(quat_yaw(requested_rotation) - quat_yaw(twin.root_transform().rotation));
  const glm::quat turn_rotation = glm::angleAxis(turn, glm::vec3(0.0f, 1.0f, 0.0f));
  const glm::vec3 twin_start = twin.root_transform().translation;
  for (int i = 0; i < 20; ++i) {
    adjusted.update(kDt, push_toward(0.0f));
    twin.update(kDt, push_toward(0.0f));
    ASSERT_FALSE(adjusted.debug().searched);
    const glm::vec3 expected =
        requested + turn_rotation * (twin.root_transform().translation - twin_start);
    EXPECT_LT(glm::length(adjusted.root_transform().translation - expected), 1e-4f) << i;
    EXPECT_NEAR(wrap_angle(quat_yaw(adjusted.root_transform().rotation) -
                           quat_yaw(twin.root_transform().rotation)),
                turn, 1e-4f);
  }
}

TEST(ControllerTest, StopsWithinASecondAndStandsStillThenStartsAgain) {
  Controller c = make();
  for (int i = 0; i < 180; ++i) c.update(kDt, push_toward(0.0f));
  ASSERT_GT(glm::length(c.debug().simulation_velocity), 0.5f);
  const Database& db = c.controller_database().database();
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  // Released: after about a second the root and the toes are still, and stay so.
  ControllerInput released;
  std::vector<Transform> previous(c.global_transforms().begin(), c.global_transforms().end());
  for (int i = 0; i < 240; ++i) {
    c.update(kDt, released);
    if (i >= 75) {
      EXPECT_LT(horizontal_speed(c.root_transform().translation, previous[0].translation, kDt),
                0.02f)
          << "frame " << i;
      for (int toe : toes) {
        EXPECT_LT(horizontal_speed(c.global_transforms()[static_cast<size_t>(toe)].translation,
                                   previous[static_cast<size_t>(toe)].translation, kDt),
                  0.02f)
            << "frame " << i;
      }
    }
    previous.assign(c.global_transforms().begin(), c.global_transforms().end());
  }
  EXPECT_TRUE(c.controller_database().database().clips()[static_cast<size_t>(c.debug().clip)].tags &
              c.controller_database().idle_tags());
  // Pushed again: the search answers on the first frame, and the character is walking off
  // within a second (the Bandai walks that start from rest take about that to reach speed, and
  // cover 20 to 30 cm in it).
  const glm::vec3 start = c.root_transform().translation;
  c.update(kDt, push_toward(90.0f));
  EXPECT_TRUE(c.debug().searched);
  EXPECT_FALSE(
      c.controller_database().database().clips()[static_cast<size_t>(c.debug().clip)].tags &
      c.controller_database().idle_tags());
  glm::vec3 before_last = start;
  for (int i = 1; i < 60; ++i) {
    before_last = c.root_transform().translation;
    c.update(kDt, push_toward(90.0f));
  }
  const glm::vec3 moved = c.root_transform().translation - start;
  EXPECT_GT(glm::length(moved), 0.15f);
  EXPECT_GT(moved.x, 0.7f * glm::length(moved));  // toward +X, where the stick points
  EXPECT_GT(horizontal_speed(c.root_transform().translation, before_last, kDt), 0.3f);
}

// Over a walk with turns: the mean horizontal speed of a toe on frames where the controller
// holds it locked (now and the frame before), and the largest change of a leg bone's length.
struct LockRun {
  double locked_toe_speed = 0.0;
  int locked_frames = 0;
  double contact_toe_speed = 0.0;  // the same over frames in contact (the skating measure)
  float bone_length_error = 0.0f;
};

LockRun locked_toes(const ControllerSettings& settings) {
  Controller c = make(settings);
  const Database& db = c.controller_database().database();
  const int toes[2] = {db.roles().left_toe, db.roles().right_toe};
  const int feet[2] = {db.roles().left_foot, db.roles().right_foot};
  LockRun run;
  double sum = 0.0, contact_sum = 0.0;
  int contact_frames = 0;
  glm::vec3 previous[2];
  bool was_locked[2] = {false, false};
  bool was_in_contact[2] = {false, false};
  for (int i = 0; i < 900; ++i) {
    c.update(kDt, push_toward(static_cast<float>((i / 150) * 60)));
    const std::span<const Transform> g = c.global_transforms();
    for (int side = 0; side < 2; ++side) {
      const glm::vec3 toe = g[static_cast<size_t>(toes[side])].translation;
      if (was_locked[side] && c.debug().locked[side]) {
        sum += horizontal_speed(toe, previous[side], kDt);
        ++run.locked_frames;
      }
      if (was_in_contact[side] && c.debug().contact[side]) {
        contact_sum += horizontal_speed(toe, previous[side], kDt);
        ++contact_frames;
      }
      previous[side] = toe;
      // Upper and lower leg keep the lengths of the pose being played.
      const int foot = feet[side];
      const int knee = db.skeleton().parent(foot);
      const int hip = db.skeleton().parent(knee);
      const std::span<const Transform> l = c.local_transforms();
      const float upper = glm::length(g[static_cast<size_t>(knee)].translation -
                                      g[static_cast<size_t>(hip)].translation);
      const float lower = glm::length(g[static_cast<size_t>(foot)].translation -
                                      g[static_cast<size_t>(knee)].translation);
      run.bone_length_error =
          std::max({run.bone_length_error,
                    std::abs(upper - glm::length(l[static_cast<size_t>(knee)].translation)),
                    std::abs(lower - glm::length(l[static_cast<size_t>(foot)].translation))});
    }
    for (int side = 0; side < 2; ++side) {
      was_locked[side] = c.debug().locked[side];
      was_in_contact[side] = c.debug().contact[side];
    }
  }
  run.locked_toe_speed = run.locked_frames ? sum / run.locked_frames : 0.0;
  run.contact_toe_speed = contact_frames ? contact_sum / contact_frames : 0.0;
  return run;
}

// The search the stick's change starts matches the trajectory toward the new request: the query's
// farthest predicted point, in the character's frame, lies ahead by a good part of the distance
// the stick asks for. (A query built from the last update's prediction, made while standing,
// held that point at the feet, and the answer could be a frame walking away backwards.)
TEST(ControllerTest, TheSearchForAChangedStickMatchesTheNewRequest) {
  Controller c = make();
  for (int i = 0; i < 120; ++i) c.update(kDt, ControllerInput{});
  c.update(kDt, push_toward(0.0f, /*run=*/true));
  const ControllerDebug& d = c.debug();
  ASSERT_TRUE(d.searched);
  const Database& db = c.controller_database().database();
  const FeatureSchema& schema = db.schema();
  int channel = -1;
  for (size_t ch = 0; ch < schema.channels.size(); ++ch) {
    if (schema.channels[ch].name == "trajectory_position") channel = static_cast<int>(ch);
  }
  ASSERT_GE(channel, 0);
  const std::vector<float>& times = schema.channels[static_cast<size_t>(channel)].times;
  ASSERT_FALSE(times.empty());
  // The farthest point's forward (z) column, back from its normalization.
  const int z = schema.offset(channel) + 2 * static_cast<int>(times.size() - 1) + 1;
  ASSERT_LT(z, d.query_dims);
  const float forward = d.last_query[z] * db.feature_scale()[static_cast<size_t>(z)] +
                        db.feature_offset()[static_cast<size_t>(z)];
  const float asked = glm::length(d.desired_velocity) * times.back();
  EXPECT_GT(forward, 0.25f * asked) << "asked for " << asked << " m ahead";
}

TEST(ControllerTest, LockedFeetStayPutAndLegsKeepTheirLength) {
  const LockRun locked = locked_toes(ControllerSettings{});
  EXPECT_GT(locked.locked_frames, 300);
  EXPECT_LT(locked.locked_toe_speed, 0.01);  // m/s
  EXPECT_LT(locked.contact_toe_speed, 0.02);
  EXPECT_LT(locked.bone_length_error, 1e-4f);
  // The same run with IK off: the animation's own toes slide in contact, so the test can tell.
  ControllerSettings off;
  off.ik_enabled = false;
  const LockRun free = locked_toes(off);
  EXPECT_EQ(free.locked_frames, 0);
  EXPECT_GT(free.contact_toe_speed, 0.05);
}

TEST(ControllerTest, TagRequestPlaysTaggedClipsThenLocomotionResumes) {
  Controller c = make();
  const auto shared = normal_controller_database();
  const Database& db = shared->database();
  uint64_t wave = 0;
  for (size_t i = 0; i < db.tag_names().size(); ++i) {
    if (db.tag_names()[i].rfind("wave-", 0) == 0) wave |= uint64_t{1} << i;
  }
  ASSERT_NE(wave, 0u);
  ControllerInput input;
  input.tag = "wave";
  for (int i = 0; i < 60; ++i) c.update(kDt, input);
  EXPECT_TRUE(db.clips()[static_cast<size_t>(c.debug().clip)].tags & wave)
      << db.clips()[static_cast<size_t>(c.debug().clip)].name;
  for (int i = 0; i < 60; ++i) c.update(kDt, push_toward(0.0f));
  EXPECT_FALSE(db.clips()[static_cast<size_t>(c.debug().clip)].tags & shared->action_tags())
      << db.clips()[static_cast<size_t>(c.debug().clip)].name;
}

// A tag request resolved outside update(): the database names the tags a request covers, and
// update() follows the resolved bits, not the text, once they are given.
TEST(ControllerTest, ResolvedTagBitsDecideTheRequest) {
  const auto shared = normal_controller_database();
  const Database& db = shared->database();
  uint64_t wave = 0;
  for (size_t i = 0; i < db.tag_names().size(); ++i) {
    if (db.tag_names()[i].rfind("wave-", 0) == 0) wave |= uint64_t{1} << i;
  }
  ASSERT_NE(wave, 0u);
  EXPECT_EQ(shared->tag_bits("wave"), wave);  // the first word names every wave-* tag
  EXPECT_EQ(shared->tag_bits("wav"), 0u);     // a prefix that is not a whole word names none
  EXPECT_EQ(shared->tag_bits("no-such-tag"), 0u);
  EXPECT_EQ(shared->tag_bits(""), 0u);

  auto clip_tags = [&](const Controller& c) {
    return db.clips()[static_cast<size_t>(c.debug().clip)].tags;
  };
  // Bits without text play the tagged clips...
  Controller bits_only = make();
  ControllerInput input;
  input.tag_bits = wave;
  for (int i = 0; i < 60; ++i) bits_only.update(kDt, input);
  EXPECT_TRUE(clip_tags(bits_only) & wave);
  // ...and resolved bits of 0 win over the text: locomotion, no wave.
  Controller zero_bits = make();
  input.tag = "wave";
  input.tag_bits = uint64_t{0};
  for (int i = 0; i < 60; ++i) zero_bits.update(kDt, input);
  EXPECT_FALSE(clip_tags(zero_bits) & wave);
}

TEST(ControllerTest, DifferentFrameRatesTrackTheSameTrajectory) {
  // The game's rate is not the database's: at 30, 60 and 144 Hz the character ends up near the
  // same place after the same script.
  glm::vec3 ends[3];
  const float rates[3] = {30.0f, 60.0f, 144.0f};
  for (int r = 0; r < 3; ++r) {
    Controller c = make();
    const float dt = 1.0f / rates[r];
    for (int i = 0; i < static_cast<int>(4.0f * rates[r]); ++i) {
      c.update(dt, push_toward(i * dt < 2.0f ? 0.0f : 90.0f));
    }
    ends[r] = c.root_transform().translation;
    EXPECT_TRUE(finite_pose(c));
  }
  EXPECT_LT(glm::length(ends[0] - ends[1]), 0.35f);
  EXPECT_LT(glm::length(ends[2] - ends[1]), 0.35f);
}

// Two walks and two real idle takes (ReActIdle, retargeted), built once.
std::shared_ptr<const Database> real_idle_database() {
  static const std::shared_ptr<const Database> shared = [] {
    const std::filesystem::path inputs[] = {
        test::clip_path("dataset-2_walk_normal_001"), test::clip_path("dataset-2_walk_normal_002"),
        test::mocap_dir() / "reactidle" / "genuine" / "008_genuine.bvh",
        test::mocap_dir() / "reactidle" / "genuine" / "012_genuine.bvh"};
    BuildOptions options;
    options.bvh.scale = 0.0f;  // centimetres and metres
    Result<Database> db = build_database(inputs, options);
    EXPECT_TRUE(db) << (db ? "" : db.message());
    return db ? std::make_shared<const Database>(std::move(db).value()) : nullptr;
  }();
  return shared;
}

// A controller on real_idle_database() (the test fails if it cannot be made).
Result<Controller> make_on_real_idles(const ControllerDatabaseOptions& options = {}) {
  Result<std::shared_ptr<const ControllerDatabase>> shared =
      ControllerDatabase::create(real_idle_database(), options);
  if (!shared) return Error{shared.message()};
  return Controller::create(*shared, ControllerSettings{});
}

// The data's idle takes keep their last idle_clip_end_exclusion seconds (at most half of each)
// out of the candidates, the synthesized held frame none.
TEST(ControllerDatabaseTest, IdleTakesKeepTheirLastSecondsOut) {
  Result<std::shared_ptr<const ControllerDatabase>> made =
      ControllerDatabase::create(real_idle_database());
  ASSERT_TRUE(made) << made.message();
  const ControllerDatabase& shared = **made;
  const Database& db = shared.database();
  const int excluded =
      static_cast<int>(std::lround(shared.options().idle_clip_end_exclusion / db.frame_time()));
  int takes = 0;
  for (const ClipRange& clip : db.clips()) {
    if ((clip.tags & shared.idle_tags()) == 0 || clip.name == "idle") continue;
    ++takes;
    const int end_frames = std::min(excluded, (clip.end - clip.start) / 2);
    for (int f = clip.end - end_frames; f < clip.end; ++f) {
      EXPECT_FALSE(shared.candidates()[static_cast<size_t>(f)]) << clip.name << " " << f;
    }
    EXPECT_TRUE(shared.candidates()[static_cast<size_t>(clip.end - end_frames - 1)]) << clip.name;
  }
  EXPECT_GE(takes, 2);
  ControllerDatabaseOptions negative;
  negative.idle_clip_end_exclusion = -1.0f;
  EXPECT_EQ(ControllerDatabase::create(real_idle_database(), negative).message(),
            "controller database: idle_clip_end_exclusion must be >= 0 seconds");
}

// A database with real idle takes: a long stand plays them through, breathing and swaying, and
// moves on at their ends instead of replaying their last moments.
TEST(ControllerTest, ALongStandOnRealIdleClipsStaysAliveAndVaries) {
  Result<Controller> made = make_on_real_idles();
  ASSERT_TRUE(made) << made.message();
  Controller& c = *made;
  for (int i = 0; i < 120; ++i) c.update(kDt, push_toward(0.0f));
  const Database& base = c.controller_database().database();
  const uint64_t idle = base.tag_mask(std::vector<std::string>{"idle"});
  ControllerInput released;
  const int head = base.roles().head;
  ASSERT_GE(head, 0);
  std::set<int> frames;
  int jumps = 0, last_frame = -1;
  double head_path = 0.0;
  glm::vec3 previous{0.0f};
  // 3 s to come to rest, then a minute: longer than any calm segment of these two takes.
  const int settle = 180, stand = 3600;
  for (int i = 0; i < settle + stand; ++i) {
    c.update(kDt, released);
    const glm::vec3 h = c.global_transforms()[static_cast<size_t>(head)].translation;
    if (i > settle) {
      ASSERT_NE(base.clips()[static_cast<size_t>(c.debug().clip)].tags & idle, 0u) << i;
      head_path += glm::distance(h, previous);
      frames.insert(c.debug().frame);
      const int step = c.debug().frame - last_frame;
      jumps += step < 0 || step > 2 ? 1 : 0;
    }
    last_frame = c.debug().frame;
    previous = h;
  }
  const double head_speed_cm_s = 100.0 * head_path / (stand * kDt);
  EXPECT_GT(head_speed_cm_s, 0.5);
  EXPECT_LT(head_speed_cm_s, 5.0);
  // Played through at 30 Hz, a minute visits about 1800 frames; a loop of a segment's last
  // moments, a few.
  EXPECT_GT(frames.size(), 1200u);
  // Jumps only where a calm segment ends (or a better one starts), not every search interval.
  EXPECT_LT(jumps, 12);
}

bool subnormal(float value) {
  return std::fpclassify(value) == FP_SUBNORMAL;
}

bool any_subnormal(const glm::vec3& v) {
  return subnormal(v.x) || subnormal(v.y) || subnormal(v.z);
}

bool any_subnormal(const glm::quat& q) {
  return subnormal(q.w) || subnormal(q.x) || subnormal(q.y) || subnormal(q.z);
}

// Two minutes standing after a walk: the stopping simulation's velocity and acceleration end
// exactly zero, and no state the controller shows (the simulation, the pose) is ever a
// subnormal float, whose slow arithmetic would make a long-standing crowd cost more and more.
TEST(ControllerTest, ALongStandLeavesNoSubnormalState) {
  Controller c = make();
  for (int i = 0; i < 120; ++i) c.update(kDt, push_toward(30.0f));
  const ControllerInput released;
  for (int i = 0; i < 120 * 60; ++i) {
    c.update(kDt, released);
    const ControllerDebug& d = c.debug();
    ASSERT_FALSE(any_subnormal(d.simulation_position) || any_subnormal(d.simulation_velocity) ||
                 any_subnormal(d.simulation_acceleration) || any_subnormal(d.simulation_rotation) ||
                 any_subnormal(d.simulation_angular_velocity))
        << "frame " << i;
    for (const Transform& t : c.local_transforms()) {
      ASSERT_FALSE(any_subnormal(t.translation) || any_subnormal(t.rotation)) << "frame " << i;
    }
    for (int side = 0; side < 2; ++side) ASSERT_FALSE(any_subnormal(d.ik_target[side])) << i;
  }
  EXPECT_EQ(c.debug().simulation_velocity, glm::vec3(0.0f));
  EXPECT_EQ(c.debug().simulation_acceleration, glm::vec3(0.0f));
}

}  // namespace
}  // namespace mm

namespace mm {
namespace {

TEST(ControllerStyles, StyleNamesResolveToIdsAndAnUnknownOneIsAClearError) {
  const auto shared = normal_controller_database();
  const Result<int> normal = shared->style_id("normal");
  ASSERT_TRUE(normal) << normal.message();
  EXPECT_EQ(shared->database().style_names()[static_cast<size_t>(*normal)], "normal");
  EXPECT_NE(shared->style_tags(*normal), 0u);
  EXPECT_EQ(shared->style_tags(-1), 0u);
  const Result<int> elderly = shared->style_id("elderly");
  ASSERT_FALSE(elderly);
  EXPECT_EQ(elderly.message(), "unknown style 'elderly'; the database's styles are normal");
}

TEST(ControllerStyles, AScriptStyleResolvesAndAnUnknownOneNamesTheLine) {
  const auto shared = normal_controller_database();
  Result<InputScript> script =
      parse_input_script("0 0 1 0 0 style=normal\n1 0 1 0 0\n", "styles.txt");
  ASSERT_TRUE(script) << script.message();
  ASSERT_TRUE(script->resolve_styles(*shared, "styles.txt", -1).ok());
  EXPECT_EQ(script->at(0.5f).style, *shared->style_id("normal"));
  EXPECT_EQ(script->at(1.5f).style, -1);  // no style on the line, no default: any

  // The same step resolves each line's tag, so that update() compares no strings.
  Result<InputScript> tagged =
      parse_input_script("0 0 0 0 0 tag=wave\n1 0 1 0 0\n2 0 0 0 0 tag=nothing\n", "tags.txt");
  ASSERT_TRUE(tagged) << tagged.message();
  EXPECT_FALSE(tagged->at(0.5f).tag_bits.has_value());  // parsed, not resolved yet
  ASSERT_TRUE(tagged->resolve_styles(*shared, "tags.txt", -1).ok());
  EXPECT_EQ(tagged->at(0.5f).tag_bits, shared->tag_bits("wave"));
  EXPECT_NE(shared->tag_bits("wave"), 0u);
  EXPECT_EQ(tagged->at(1.5f).tag_bits, uint64_t{0});
  EXPECT_EQ(tagged->at(2.5f).tag_bits, uint64_t{0});  // an unknown tag: locomotion

  Result<InputScript> bad = parse_input_script("0 0 1 0 0\n\n2 0 1 0 0 style=proud\n", "bad.txt");
  ASSERT_TRUE(bad) << bad.message();
  const Status s = bad->resolve_styles(*shared, "bad.txt", -1);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "bad.txt:3: unknown style 'proud'; the database's styles are normal");
}

TEST(ControllerStyles, TheRequestedStyleIsWhatPlaysOnTheNormalData) {
  const auto shared = normal_controller_database();
  Result<Controller> made = Controller::create(shared);
  ASSERT_TRUE(made) << made.message();
  Controller& controller = *made;
  ControllerInput input;
  input.left_stick = {0.0f, 1.0f};
  input.style = *shared->style_id("normal");
  for (int i = 0; i < 120; ++i) controller.update(1.0f / 60.0f, input);
  EXPECT_EQ(controller.debug().requested_style, input.style);
  const int clip = controller.debug().clip;
  ASSERT_GE(clip, 0);
  EXPECT_EQ(shared->database().clips()[static_cast<size_t>(clip)].style, input.style);
  input.style = 99;  // not a style of the database: any
  controller.update(1.0f / 60.0f, input);
  EXPECT_EQ(controller.debug().requested_style, -1);
}

}  // namespace
}  // namespace mm
