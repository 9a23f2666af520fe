// The velocities the builder makes and the loader recomputes (velocities.hpp), on motion with
// known answers.

#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <vector>

#include "mm/database/velocities.hpp"
#include "mm/runtime/interpolation.hpp"

namespace mm {
namespace {

constexpr float kDt = 1.0f / 30.0f;

TEST(LocalVelocities, CentralInsideOneSidedAtTheEndsAndShortestPath) {
  // Position p(t) = (t^2, 3t, 0): central differences of a quadratic are exact (2t, 3, 0);
  // the one-sided ends give the slope of the first/last interval.
  // Rotation q(t) = exp(w t) * q0 with w in the parent frame: angular velocity exactly w, also
  // when every other sample is stored negated (q and -q are one rotation).
  const int frames = 12, joints = 1;
  const glm::vec3 w(0.3f, -1.2f, 0.5f);
  const glm::quat q0 = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3)));
  std::vector<glm::vec3> p(frames), v(frames), av(frames);
  std::vector<glm::quat> q(frames);
  for (int f = 0; f < frames; ++f) {
    const float t = f * kDt;
    p[f] = {t * t, 3.0f * t, 0.0f};
    const glm::quat r = glm::angleAxis(glm::length(w) * t, glm::normalize(w)) * q0;
    q[f] = f % 2 ? -r : r;
  }
  compute_local_velocities(p, q, frames, joints, kDt, v, av);
  for (int f = 0; f < frames; ++f) {
    const float t = f * kDt;
    float expected_x = 2.0f * t;
    if (f == 0) expected_x = kDt;                        // (dt^2 - 0) / dt
    if (f == frames - 1) expected_x = (2.0f * t - kDt);  // (t^2 - (t - dt)^2) / dt
    EXPECT_NEAR(v[f].x, expected_x, 1e-4f) << f;
    EXPECT_NEAR(v[f].y, 3.0f, 1e-4f) << f;
    EXPECT_NEAR(av[f].x, w.x, 1e-3f) << f;
    EXPECT_NEAR(av[f].y, w.y, 1e-3f) << f;
    EXPECT_NEAR(av[f].z, w.z, 1e-3f) << f;
  }
  // A single frame has no motion.
  std::vector<glm::vec3> v1(1), a1(1);
  compute_local_velocities(std::span(p).first(1), std::span(q).first(1), 1, 1, kDt, v1, a1);
  EXPECT_EQ(v1[0], glm::vec3(0.0f));
  EXPECT_EQ(a1[0], glm::vec3(0.0f));
}

TEST(LocalVelocities, EveryJointGetsTheSameBitsWhereverItSitsInTheFrame) {
  // Four joints at a time go through SSE, the rest through the scalar code: the same column of
  // samples must give the same bits at any joint index (so in any lane or in the tail), and agree
  // with the exact rotation vector. Steps between frames from tiny to large (the series and the
  // exact path), some with w < 0 (the shorter way round).
  const int frames = 11, columns = 9;
  std::vector<std::vector<glm::vec3>> p(columns, std::vector<glm::vec3>(frames));
  std::vector<std::vector<glm::quat>> q(columns, std::vector<glm::quat>(frames));
  for (int c = 0; c < columns; ++c) {
    const glm::vec3 axis = glm::normalize(glm::vec3(1.0f + c, 2.0f - c, 0.5f * c - 1.0f));
    glm::quat r = glm::angleAxis(0.3f * c, axis);
    for (int f = 0; f < frames; ++f) {
      p[c][f] = glm::vec3(0.1f * c * f, std::sin(0.7f * f + c), 0.01f * f * f);
      q[c][f] = (c + f) % 3 == 0 ? -r : r;
      // Central differences span two steps: up to the series' limit (~0.49 rad) and beyond.
      constexpr float kSteps[] = {0.003f, 0.08f, 0.17f, 0.2f, 0.22f, 0.235f, 0.7f};
      const float step = kSteps[(c * 3 + f) % 7];
      r = glm::angleAxis(step, glm::normalize(axis + glm::vec3(0.0f, 0.1f * f, 0.0f))) * r;
    }
  }
  std::vector<glm::vec3> first_velocity, first_angular;
  for (int joints = columns; joints >= 1; --joints) {
    std::vector<glm::vec3> pos(frames * joints), v(frames * joints), av(frames * joints);
    std::vector<glm::quat> rot(frames * joints);
    for (int f = 0; f < frames; ++f) {
      for (int j = 0; j < joints; ++j) {
        pos[f * joints + j] = p[j][f];
        rot[f * joints + j] = q[j][f];
      }
    }
    compute_local_velocities(pos, rot, frames, joints, kDt, v, av);
    if (first_velocity.empty()) {
      first_velocity = v;
      first_angular = av;
    }
    for (int f = 0; f < frames; ++f) {
      const int a = std::max(0, f - 1), b = std::min(frames - 1, f + 1);
      for (int j = 0; j < joints; ++j) {
        const size_t here = f * joints + j, there = f * columns + j;
        ASSERT_EQ(v[here], first_velocity[there])
            << joints << " joints, frame " << f << " joint " << j;
        ASSERT_EQ(av[here], first_angular[there])
            << joints << " joints, frame " << f << " joint " << j;
        const glm::vec3 exact =
            quat_to_scaled_angle_axis(q[j][b] * glm::conjugate(q[j][a])) / ((b - a) * kDt);
        EXPECT_NEAR(glm::length(av[here] - exact), 0.0f, 1e-5f * (1.0f + glm::length(exact)))
            << "frame " << f << " joint " << j;
      }
    }
  }
}

}  // namespace
}  // namespace mm
