// pose_hermite: every joint of a pose at once, lane by lane, against transform_hermite joint by
// joint, to the bit.

#include <gtest/gtest.h>

#include <span>
#include <vector>

#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose_hermite.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

struct Frame {
  std::vector<glm::quat> rotations;
  std::vector<glm::vec3> positions, velocities, angular_velocities;
  PoseFrameView view() const { return {rotations, positions, velocities, angular_velocities}; }
};

Frame random_frame(size_t joints) {
  Frame f;
  for (size_t j = 0; j < joints; ++j) {
    f.rotations.push_back(test::random_rotation());
    f.positions.push_back(test::random_vec3(-2.0f, 2.0f));
    f.velocities.push_back(test::random_vec3(-3.0f, 3.0f));
    f.angular_velocities.push_back(test::random_vec3(-8.0f, 8.0f));
  }
  return f;
}

// Every joint of `out` (the first a.rotations.size()) equals transform_hermite's result to the bit.
void expect_transform_hermite(const Frame& a, const Frame& b, float duration, float t,
                              std::span<const Transform> out) {
  const size_t joints = a.rotations.size();
  for (size_t j = 0; j < joints; ++j) {
    Transform ta, tb;
    ta.rotation = a.rotations[j];
    ta.translation = a.positions[j];
    tb.rotation = b.rotations[j];
    tb.translation = b.positions[j];
    const Transform expected =
        transform_hermite(ta, a.velocities[j], a.angular_velocities[j], tb, b.velocities[j],
                          b.angular_velocities[j], duration, t);
    EXPECT_EQ(out[j].rotation, expected.rotation) << joints << " joints, joint " << j;
    EXPECT_EQ(out[j].translation, expected.translation) << joints << " joints, joint " << j;
    EXPECT_EQ(out[j].scale, glm::vec3(1.0f));
  }
}

constexpr float kDuration = 1.0f / 30.0f;
// Times at both frames and between.
constexpr float kTimes[] = {0.0f, 0.25f, 0.5f, 0.731f, 1.0f};

// `check(a, b, joints)` for 20 random frame pairs at each joint count below, at and above one
// block of four, and the Bandai skeleton's 23 (whose last block overlaps the one before), b's
// first rotation on the other side of a's (a far rotation).
template <class Check>
void for_each_pose_pair(Check check) {
  for (const size_t joints : {1u, 3u, 4u, 5u, 8u, 23u}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Frame a = random_frame(joints);
      Frame b = random_frame(joints);
      b.rotations[0] = -b.rotations[0];
      check(a, b, joints);
    }
  }
}

TEST(PoseHermite, EveryJointEqualsTransformHermiteToTheBit) {
  for_each_pose_pair([](const Frame& a, const Frame& b, size_t joints) {
    for (const float t : kTimes) {
      std::vector<Transform> out(joints);
      pose_hermite(a.view(), b.view(), kDuration, t, out);
      expect_transform_hermite(a, b, kDuration, t, out);
    }
  });
}

// The same from the lanes' layout (pose_to_lanes): every joint, including those of a last group
// that padding completes, equals transform_hermite's result to the bit.
TEST(PoseHermite, FromTheLanesLayoutEqualsTransformHermiteToTheBit) {
  for_each_pose_pair([](const Frame& a, const Frame& b, size_t joints) {
    std::vector<float> la(pose_lane_floats(joints)), lb(pose_lane_floats(joints));
    pose_to_lanes(a.view(), la);
    pose_to_lanes(b.view(), lb);
    for (const float t : kTimes) {
      // One joint more than the pose, to see that nothing is written past it.
      std::vector<Transform> out(joints + 1);
      out[joints].translation = glm::vec3(7.0f);
      pose_hermite(la, lb, kDuration, t, std::span(out).first(joints));
      expect_transform_hermite(a, b, kDuration, t, out);
      EXPECT_EQ(out[joints].translation, glm::vec3(7.0f)) << joints << " joints";
    }
  });
}

// The velocities' mix from the lanes' layout, every joint from `first` on, against glm::mix of
// each joint's values; the joints before `first` untouched.
TEST(PoseHermite, TheVelocityMixEqualsGlmMixToTheBit) {
  for_each_pose_pair([](const Frame& a, const Frame& b, size_t joints) {
    std::vector<float> la(pose_lane_floats(joints)), lb(pose_lane_floats(joints));
    pose_to_lanes(a.view(), la);
    pose_to_lanes(b.view(), lb);
    for (const size_t first : {size_t{0}, size_t{1}, joints - 1}) {
      for (const float t : kTimes) {
        const glm::vec3 untouched(7.0f, -7.0f, 7.0f);
        std::vector<glm::vec3> v(joints, untouched), w(joints, untouched);
        pose_velocity_mix(la, lb, t, first, v, w);
        for (size_t j = 0; j < joints; ++j) {
          const bool mixed = j >= first;
          EXPECT_EQ(v[j], mixed ? glm::mix(a.velocities[j], b.velocities[j], t) : untouched)
              << joints << " joints, joint " << j;
          EXPECT_EQ(w[j], mixed ? glm::mix(a.angular_velocities[j], b.angular_velocities[j], t)
                                : untouched)
              << joints << " joints, joint " << j;
        }
      }
    }
  });
}

}  // namespace
}  // namespace mm
