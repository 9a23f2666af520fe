// backed_into_face (sweep_start.hpp): which contacts at the start of a sweep started a radius
// behind its toe are the start being inside a face the toe moves away from.

#include <gtest/gtest.h>

#include "mm/controller/sweep_start.hpp"

namespace mm {
namespace {

constexpr float kRadius = 0.03f;

// A toe moving 10 cm along +Z, swept from a radius behind where it was.
ShapeSweep toe_moving_along_z() {
  return ShapeSweep{glm::vec3(0.0f, 0.2f, -kRadius), glm::vec3(0.0f, 0.2f, 0.1f), kRadius,
                    2.0f * kRadius};
}

SweepHit contact(float fraction, const glm::vec3& normal) {
  SweepHit hit;
  hit.hit = true;
  hit.fraction = fraction;
  hit.normal = normal;
  return hit;
}

TEST(SweepStart, AContactAtTheStartFacingBackAlongTheWayIsTheStartInsideAFace) {
  // The toe leaves a face behind it (its normal +Z); the engine answers with the reverse.
  EXPECT_TRUE(backed_into_face(toe_moving_along_z(), contact(0.0f, {0.0f, 0.0f, -1.0f}), kRadius));
  // Facing back at 45 degrees still counts.
  EXPECT_TRUE(
      backed_into_face(toe_moving_along_z(), contact(0.0f, {0.7071f, 0.0f, -0.7071f}), kRadius));
}

TEST(SweepStart, AFaceAcrossTheWayOrAheadIsAFaceTheToeMeets) {
  // Sliding along a riser it is kept off: the face's own normal, across the way.
  EXPECT_FALSE(backed_into_face(toe_moving_along_z(), contact(0.0f, {1.0f, 0.0f, 0.0f}), kRadius));
  // A riser ahead, met head on.
  EXPECT_FALSE(backed_into_face(toe_moving_along_z(), contact(0.5f, {0.0f, 0.0f, -1.0f}), kRadius));
  // Facing back, but met farther than half a radius from the start (13 cm of sweep: 2 cm).
  EXPECT_FALSE(
      backed_into_face(toe_moving_along_z(), contact(0.16f, {0.0f, 0.0f, -1.0f}), kRadius));
}

TEST(SweepStart, NoMissAndNoSweepOfNoLengthIsBackedIntoAFace) {
  SweepHit miss = contact(0.0f, {0.0f, 0.0f, -1.0f});
  miss.hit = false;
  EXPECT_FALSE(backed_into_face(toe_moving_along_z(), miss, kRadius));
  const ShapeSweep still{glm::vec3(0.0f, 0.2f, 0.0f), glm::vec3(0.0f, 0.5f, 0.0f), kRadius,
                         2.0f * kRadius};
  EXPECT_FALSE(backed_into_face(still, contact(0.0f, {0.0f, 0.0f, -1.0f}), kRadius));
}

}  // namespace
}  // namespace mm
