// Feature schema, extraction and normalization, checked against hand computations on
// synthetic motion whose features have closed forms.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mm/database/features.hpp"
#include "mm/offline/feature_extraction.hpp"
#include "mm/offline/preprocess.hpp"

namespace mm {
namespace {

constexpr float kRate = 30.0f;
constexpr float kDt = 1.0f / kRate;

glm::quat yaw_quat(float yaw) {
  return glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f));
}

// ---- Schema ----------------------------------------------------------------------------------

TEST(FeatureSchema, DefaultHas27ColumnsInDesignOrder) {
  const FeatureSchema schema = FeatureSchema::default_schema();
  ASSERT_TRUE(schema.validate()) << schema.validate().message();
  EXPECT_EQ(schema.dims(), 27);
  ASSERT_EQ(schema.channels.size(), 7u);
  const int expected_offsets[] = {0, 3, 6, 9, 12, 15, 21};
  const int expected_dims[] = {3, 3, 3, 3, 3, 6, 6};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(schema.offset(i), expected_offsets[i]) << i;
    EXPECT_EQ(schema.channels[i].dims(), expected_dims[i]) << i;
  }
  EXPECT_EQ(schema.channels[5].kind, FeatureKind::TrajectoryPosition);
  EXPECT_EQ(schema.channels[6].kind, FeatureKind::TrajectoryDirection);
  EXPECT_EQ(schema.channels[5].times, (std::vector<float>{0.33f, 0.67f, 1.0f}));
  EXPECT_EQ(schema.channels[0].bone, "left_foot");
  EXPECT_EQ(schema.channels[4].bone, "hips");
}

TEST(FeatureSchema, EveryInvalidChannelIsRefusedWithItsName) {
  struct Case {
    const char* what;
    void (*edit)(FeatureSchema&);
    const char* expected_in_message;
  };
  const Case cases[] = {
      {"empty name", [](FeatureSchema& s) { s.channels[0].name.clear(); }, "empty name"},
      {"duplicate", [](FeatureSchema& s) { s.channels[1].name = s.channels[0].name; }, "duplicate"},
      {"zero weight", [](FeatureSchema& s) { s.channels[2].weight = 0.0f; }, "weight"},
      {"negative weight", [](FeatureSchema& s) { s.channels[2].weight = -1.0f; }, "weight"},
      {"nan weight", [](FeatureSchema& s) { s.channels[2].weight = std::nanf(""); }, "weight"},
      {"bone without bone", [](FeatureSchema& s) { s.channels[0].bone.clear(); }, "needs a bone"},
      {"bone with times", [](FeatureSchema& s) { s.channels[0].times = {0.5f}; }, "no times"},
      {"trajectory without times", [](FeatureSchema& s) { s.channels[5].times.clear(); },
       "at least one time"},
      {"infinite time", [](FeatureSchema& s) { s.channels[6].times[1] = INFINITY; }, "finite"},
      {"zero axis",
       [](FeatureSchema& s) {
         FeatureChannel c;
         c.name = "head_direction";
         c.kind = FeatureKind::BoneDirection;
         c.bone = "head";
         c.axis = glm::vec3(0.0f);
         s.channels.push_back(c);
       },
       "axis"},
      {"unknown kind", [](FeatureSchema& s) { s.channels[0].kind = static_cast<FeatureKind>(9); },
       "unknown feature kind"},
      {"no channels", [](FeatureSchema& s) { s.channels.clear(); }, "no channels"},
  };
  for (const Case& c : cases) {
    FeatureSchema schema = FeatureSchema::default_schema();
    c.edit(schema);
    const Status status = schema.validate();
    EXPECT_FALSE(status) << c.what;
    EXPECT_NE(status.message().find(c.expected_in_message), std::string::npos)
        << c.what << ": " << status.message();
  }
}

TEST(FeatureSchema, MarginsFollowTheTimes) {
  FeatureSchema schema = FeatureSchema::default_schema();
  FeatureFrameMargins m = feature_frame_margins(schema, kDt);
  EXPECT_EQ(m.before, 0);
  EXPECT_EQ(m.after, 30);  // 1.0 s at 30 Hz, despite 1.0f / (1 / 30.f) not being exactly 30
  schema.channels[5].times.push_back(-0.5f);
  m = feature_frame_margins(schema, kDt);
  EXPECT_EQ(m.before, 15);
  EXPECT_EQ(feature_frame_margins(schema, 1.0f / 60.0f).after, 60);
  schema.channels[6].times = {0.34f};  // 10.2 frames: needs frame 11
  schema.channels[5].times = {0.1f};
  EXPECT_EQ(feature_frame_margins(schema, kDt).after, 11);
}

TEST(FeatureSchema, BonesResolveThroughRolesOrJointNames) {
  Result<Skeleton> sk = Skeleton::create({"Simulation", "Hips", "LFoot", "RFoot", "Head"},
                                         {-1, 0, 1, 1, 1}, std::vector<Transform>(5));
  ASSERT_TRUE(sk);
  JointRoleIndices roles;
  roles.hips = 1;
  roles.left_foot = 2;
  roles.right_foot = 3;
  FeatureSchema schema = FeatureSchema::default_schema();
  FeatureChannel head;
  head.name = "head_position";
  head.bone = "Head";  // an exact joint name, not a role
  schema.channels.push_back(head);
  Result<std::vector<int>> bones = resolve_feature_bones(schema, *sk, roles);
  ASSERT_TRUE(bones) << bones.message();
  EXPECT_EQ(*bones, (std::vector<int>{2, 3, 2, 3, 1, -1, -1, 4}));

  schema.channels.back().bone = "head";  // the role, which this database lacks
  bones = resolve_feature_bones(schema, *sk, roles);
  ASSERT_FALSE(bones);
  EXPECT_NE(bones.message().find("head_position"), std::string::npos) << bones.message();
  schema.channels.back().bone = "Nose";
  bones = resolve_feature_bones(schema, *sk, roles);
  ASSERT_FALSE(bones);
  EXPECT_NE(bones.message().find("'Nose'"), std::string::npos) << bones.message();
}

// ---- Extraction --------------------------------------------------------------------------------

// A two-joint motion: joint 0 (the simulation root) slides along world +X at `speed` m/s while
// turning about +Y at `yaw_rate` rad/s; joint 1 (the "foot") is rigidly attached at `offset`,
// turned by `foot_yaw` about +Y. Values and derivatives are written in closed form.
struct TurningSlide {
  int frames = 90;
  float speed = 1.5f;
  float yaw_rate = 0.8f;
  glm::vec3 offset{0.1f, 0.05f, 0.2f};
  float foot_yaw = 0.4f;
  std::vector<int> parents{-1, 0};
  std::vector<glm::vec3> positions, velocities, angular_velocities;
  std::vector<glm::quat> rotations;

  void generate() {
    positions.clear();
    rotations.clear();
    velocities.clear();
    angular_velocities.clear();
    for (int f = 0; f < frames; ++f) {
      const float t = f * kDt;
      positions.push_back({speed * t, 0.0f, 0.0f});
      rotations.push_back(yaw_quat(yaw_rate * t));
      velocities.push_back({speed, 0.0f, 0.0f});
      angular_velocities.push_back({0.0f, yaw_rate, 0.0f});
      positions.push_back(offset);
      rotations.push_back(yaw_quat(foot_yaw));
      velocities.push_back(glm::vec3(0.0f));
      angular_velocities.push_back(glm::vec3(0.0f));
    }
  }
  ClipMotionView view() const {
    ClipMotionView v;
    v.parents = parents;
    v.local_positions = positions;
    v.local_rotations = rotations;
    v.local_velocities = velocities;
    v.local_angular_velocities = angular_velocities;
    v.frame_count = frames;
    v.frame_time = kDt;
    return v;
  }
};

TEST(FeatureExtraction, MatchesHandComputationOnATurningSlide) {
  TurningSlide motion;
  motion.generate();
  FeatureSchema schema = FeatureSchema::default_schema();
  FeatureChannel direction;
  direction.name = "foot_x_axis";
  direction.kind = FeatureKind::BoneDirection;
  direction.bone = "left_foot";
  direction.axis = {2.0f, 0.0f, 0.0f};  // not unit on purpose: the extractor normalizes it
  schema.channels.push_back(direction);
  const int dims = schema.dims();
  ASSERT_EQ(dims, 30);
  // The single moving joint plays every bone role.
  const std::vector<int> bones = {1, 1, 1, 1, 1, -1, -1, 1};

  std::vector<float> raw(static_cast<size_t>(motion.frames) * dims);
  std::vector<uint8_t> searchable(motion.frames);
  FeatureScratch scratch;
  extract_clip_features(schema, bones, motion.view(), raw, searchable, scratch);

  const float w = motion.yaw_rate, v = motion.speed;
  const glm::vec3 o = motion.offset;
  for (int f = 0; f < motion.frames; ++f) {
    const float* row = raw.data() + static_cast<size_t>(f) * dims;
    const float theta = w * f * kDt;
    // The foot is rigid in the root frame: its position there is the offset itself.
    EXPECT_NEAR(row[0], o.x, 1e-5f);
    EXPECT_NEAR(row[1], o.y, 1e-5f);
    EXPECT_NEAR(row[2], o.z, 1e-5f);
    // World velocity = root velocity + omega x (R offset); in the root frame:
    // R(-theta) (v, 0, 0) + (0, w, 0) x offset = (v cos + w oz, 0, v sin - w ox).
    const glm::vec3 expected_velocity(v * std::cos(theta) + w * o.z, 0.0f,
                                      v * std::sin(theta) - w * o.x);
    for (int c : {6, 12}) {
      EXPECT_NEAR(row[c + 0], expected_velocity.x, 1e-4f) << "frame " << f;
      EXPECT_NEAR(row[c + 1], expected_velocity.y, 1e-4f) << "frame " << f;
      EXPECT_NEAR(row[c + 2], expected_velocity.z, 1e-4f) << "frame " << f;
    }
    // Trajectory: the root moved v * tau along world +X; seen from a frame turned by theta
    // that is (v tau cos theta, v tau sin theta); the facing turned by w * tau. Times past the
    // clip's end are clamped to the last frame.
    const float times[] = {0.33f, 0.67f, 1.0f};
    for (int k = 0; k < 3; ++k) {
      const float tau = std::min(times[k], (motion.frames - 1 - f) * kDt);
      EXPECT_NEAR(row[15 + 2 * k], v * tau * std::cos(theta), 1e-4f) << "frame " << f;
      EXPECT_NEAR(row[16 + 2 * k], v * tau * std::sin(theta), 1e-4f) << "frame " << f;
      EXPECT_NEAR(row[21 + 2 * k], std::sin(w * tau), 1e-4f) << "frame " << f;
      EXPECT_NEAR(row[22 + 2 * k], std::cos(w * tau), 1e-4f) << "frame " << f;
    }
    // The foot's local +X turned by foot_yaw about +Y, in the root frame: (cos, 0, -sin).
    EXPECT_NEAR(row[27], std::cos(motion.foot_yaw), 1e-5f);
    EXPECT_NEAR(row[28], 0.0f, 1e-5f);
    EXPECT_NEAR(row[29], -std::sin(motion.foot_yaw), 1e-5f);
    EXPECT_EQ(searchable[f], f + 30 <= motion.frames - 1 ? 1 : 0) << "frame " << f;
  }
  int count = 0;
  for (uint8_t s : searchable) count += s;
  EXPECT_EQ(count, motion.frames - 30);
}

TEST(FeatureExtraction, PastTrajectoryAndSearchableCount) {
  TurningSlide motion;
  motion.frames = 75;
  motion.generate();
  FeatureSchema schema;
  FeatureChannel past;
  past.name = "past_positions";
  past.kind = FeatureKind::TrajectoryPosition;
  past.times = {-0.5f, -0.1f};
  schema.channels.push_back(past);
  std::vector<float> raw(static_cast<size_t>(motion.frames) * 4);
  std::vector<uint8_t> searchable(motion.frames);
  FeatureScratch scratch;
  extract_clip_features(schema, std::vector<int>{-1}, motion.view(), raw, searchable, scratch);
  int count = 0;
  for (int f = 0; f < motion.frames; ++f) {
    count += searchable[f];
    EXPECT_EQ(searchable[f], f >= 15 ? 1 : 0) << f;
    const float theta = motion.yaw_rate * f * kDt;
    const float tau = -std::min(0.5f, f * kDt);
    EXPECT_NEAR(raw[f * 4 + 0], motion.speed * tau * std::cos(theta), 1e-4f) << f;
    EXPECT_NEAR(raw[f * 4 + 1], motion.speed * tau * std::sin(theta), 1e-4f) << f;
  }
  EXPECT_EQ(count, motion.frames - 15);
}

TEST(FeatureExtraction, FractionalTimesInterpolateBetweenFrames) {
  // A root that stops: frames 0..9 move at 1 m/s along +Z, then it stands still. The position
  // 0.33 s (9.9 frames) ahead of frame 0 is 0.9 + 0.9 * (frame 10 - frame 9) = 0.33 m when
  // the motion is linear up to frame 10 (it reaches 10/30 m there).
  const int frames = 45;
  std::vector<glm::vec3> p, v, w;
  std::vector<glm::quat> q;
  for (int f = 0; f < frames; ++f) {
    p.push_back({0.0f, 0.0f, std::min(f, 10) * kDt});
    q.push_back(glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
    v.push_back(glm::vec3(0.0f));
    w.push_back(glm::vec3(0.0f));
  }
  const std::vector<int> parents = {-1};
  ClipMotionView view{parents, p, q, v, w, frames, kDt};
  FeatureSchema schema;
  FeatureChannel c;
  c.name = "ahead";
  c.kind = FeatureKind::TrajectoryPosition;
  c.times = {0.33f, 0.2f};
  schema.channels.push_back(c);
  std::vector<float> raw(frames * 4);
  std::vector<uint8_t> searchable(frames);
  FeatureScratch scratch;
  extract_clip_features(schema, std::vector<int>{-1}, view, raw, searchable, scratch);
  EXPECT_NEAR(raw[1], 0.33f, 1e-5f);
  EXPECT_NEAR(raw[3], 0.2f, 1e-5f);
  // From frame 5, 9.9 frames ahead is past the stop at frame 10: 5 frames of motion = 1/6 m.
  EXPECT_NEAR(raw[5 * 4 + 1], 5.0f * kDt, 1e-5f);
  EXPECT_NEAR(raw[5 * 4 + 3], 5.0f * kDt, 1e-5f);  // 6 frames ahead, only 5 of them moving
}

// ---- Normalization -----------------------------------------------------------------------------

TEST(FeatureNormalization, StatisticsMatchABruteForceComputationAndRoundTrip) {
  const FeatureSchema schema = FeatureSchema::default_schema();
  FeatureSchema weighted = schema;
  weighted.channels[5].weight = 2.0f;
  weighted.channels[0].weight = 0.5f;
  const int dims = schema.dims();
  const int rows = 500;
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<float> raw(static_cast<size_t>(rows) * dims);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < dims; ++c) raw[r * dims + c] = 3.0f * c + (1.0f + 0.1f * c) * normal(rng);
  }
  std::vector<uint8_t> searchable(rows, 1);
  for (int r = 0; r < rows; r += 3) searchable[r] = 0;
  // Rows that are not searchable get absurd values: they must not move the statistics.
  for (int r = 0; r < rows; r += 3) {
    for (int c = 0; c < dims; ++c) raw[r * dims + c] = 1e6f;
  }

  const FeatureNormalization n = compute_feature_normalization(weighted, raw, searchable);
  EXPECT_TRUE(n.warnings.empty());
  ASSERT_EQ(n.offset.size(), static_cast<size_t>(dims));
  // Brute force, in long double, column by column.
  std::vector<long double> mean(dims, 0.0L), var(dims, 0.0L);
  int counted = 0;
  for (int r = 0; r < rows; ++r) {
    if (!searchable[r]) continue;
    ++counted;
    for (int c = 0; c < dims; ++c) mean[c] += raw[r * dims + c];
  }
  for (int c = 0; c < dims; ++c) mean[c] /= counted;
  for (int r = 0; r < rows; ++r) {
    if (!searchable[r]) continue;
    for (int c = 0; c < dims; ++c)
      var[c] += (raw[r * dims + c] - mean[c]) * (raw[r * dims + c] - mean[c]);
  }
  for (int c = 0; c < dims; ++c) var[c] /= counted;
  for (size_t ch = 0; ch < weighted.channels.size(); ++ch) {
    const int first = weighted.offset(static_cast<int>(ch));
    const int count = weighted.channels[ch].dims();
    long double sum = 0.0L;
    for (int c = first; c < first + count; ++c) sum += var[c];
    const double expected =
        std::sqrt(static_cast<double>(sum / count)) / weighted.channels[ch].weight;
    for (int c = first; c < first + count; ++c) {
      EXPECT_NEAR(n.offset[c], static_cast<double>(mean[c]), 1e-4) << c;
      EXPECT_NEAR(n.scale[c], expected, 1e-4 * expected) << c;
    }
  }

  std::vector<float> rows_copy = raw;
  normalize_features(rows_copy, n.offset, n.scale);
  // A normalized searchable column has mean 0.
  for (int c = 0; c < dims; ++c) {
    double m = 0.0;
    for (int r = 0; r < rows; ++r) {
      if (searchable[r]) m += rows_copy[r * dims + c];
    }
    EXPECT_NEAR(m / counted, 0.0, 1e-4) << c;
  }
  denormalize_features(rows_copy, n.offset, n.scale);
  for (size_t i = 0; i < raw.size(); ++i) {
    EXPECT_NEAR(rows_copy[i], raw[i], 1e-6f * std::max(1.0f, std::abs(raw[i]))) << i;
  }
}

TEST(FeatureNormalization, ZeroDeviationIsReportedAndLeftUnscaled) {
  // A straight walk that never turns: the facing columns are constant.
  TurningSlide motion;
  motion.yaw_rate = 0.0f;
  motion.generate();
  FeatureSchema schema = FeatureSchema::default_schema();
  schema.channels[6].weight = 4.0f;
  const int dims = schema.dims();
  std::vector<float> raw(static_cast<size_t>(motion.frames) * dims);
  std::vector<uint8_t> searchable(motion.frames);
  FeatureScratch scratch;
  extract_clip_features(schema, std::vector<int>{1, 1, 1, 1, 1, -1, -1}, motion.view(), raw,
                        searchable, scratch);
  const FeatureNormalization n = compute_feature_normalization(schema, raw, searchable);
  // The foot positions and velocities are constant too in a rigid slide; the trajectory
  // positions are the same for every searchable frame as well.
  bool named_direction = false;
  for (const std::string& w : n.warnings) {
    if (w.find("'trajectory_direction'") != std::string::npos) named_direction = true;
  }
  EXPECT_TRUE(named_direction);
  for (int c = 21; c < 27; ++c) EXPECT_FLOAT_EQ(n.scale[c], 1.0f / 4.0f) << c;
  normalize_features(raw, n.offset, n.scale);
  for (float x : raw) EXPECT_TRUE(std::isfinite(x));
}

TEST(FeatureNormalization, AllRowsCountWhenNoneIsSearchable) {
  FeatureSchema schema;
  FeatureChannel c;
  c.name = "x";
  c.bone = "hips";
  schema.channels.push_back(c);
  const std::vector<float> raw = {0, 0, 0, 2, 2, 2};
  const std::vector<uint8_t> searchable = {0, 0};
  const FeatureNormalization n = compute_feature_normalization(schema, raw, searchable);
  EXPECT_FLOAT_EQ(n.offset[0], 1.0f);
  EXPECT_FLOAT_EQ(n.scale[0], 1.0f);  // deviation of {0, 2} is 1
}

// ---- Whole database ----------------------------------------------------------------------------

TEST(FeatureExtraction, DatabaseFeaturesNeverReadAcrossClips) {
  // Two clips back to back: the first slides along +X, the second along -X from far away.
  // Trajectory features near the end of clip 0 must clamp to its last frame, not read clip 1.
  DatabaseContents db;
  Result<Skeleton> sk = Skeleton::create({"Simulation", "Hips", "Foot_L", "Foot_R"}, {-1, 0, 1, 1},
                                         std::vector<Transform>(4));
  ASSERT_TRUE(sk);
  db.skeleton = *sk;
  db.roles.hips = 1;
  db.roles.left_foot = 2;
  db.roles.right_foot = 3;
  db.schema = FeatureSchema::default_schema();
  db.frame_time = kDt;
  const int n0 = 50, n1 = 40;
  db.frame_count = n0 + n1;
  for (int f = 0; f < db.frame_count; ++f) {
    const bool second = f >= n0;
    const float t = (second ? f - n0 : f) * kDt;
    const float dir = second ? -1.0f : 1.0f;
    const glm::vec3 root(second ? 100.0f - 2.0f * t : 2.0f * t, 0.0f, 0.0f);
    const glm::vec3 locals[4] = {root, {0, 0.9f, 0}, {0.1f, -0.8f, 0}, {-0.1f, -0.8f, 0}};
    for (int j = 0; j < 4; ++j) {
      db.local_positions.push_back(locals[j]);
      db.local_rotations.push_back(glm::quat(1, 0, 0, 0));
      db.local_velocities.push_back(j == 0 ? glm::vec3(2.0f * dir, 0, 0) : glm::vec3(0.0f));
      db.local_angular_velocities.push_back(glm::vec3(0.0f));
    }
  }
  db.clips = {{"a", 0, n0, 0, false}, {"b", n0, n0 + n1, 0, false}};
  std::vector<std::string> warnings;
  ASSERT_TRUE(compute_database_features(db, &warnings));
  int searchable = 0;
  for (uint8_t s : db.searchable) searchable += s;
  EXPECT_EQ(searchable, (n0 - 30) + (n1 - 30));
  std::vector<float> raw = db.features;
  denormalize_features(raw, db.feature_offset, db.feature_scale);
  const int dims = 27;
  // Frame n0 - 5 of clip 0: 4 frames left, every future time clamps to 4 frames of motion.
  const float* row = raw.data() + static_cast<size_t>(n0 - 5) * dims;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(row[15 + 2 * k], 2.0f * 4 * kDt, 1e-4f) << k;
    EXPECT_NEAR(row[16 + 2 * k], 0.0f, 1e-4f) << k;
  }
  // The hips velocity of clip 1 points to -X.
  EXPECT_NEAR(raw[static_cast<size_t>(n0 + 3) * dims + 12], -2.0f, 1e-4f);
}

}  // namespace
}  // namespace mm
