// transform_sse.hpp: each function against GLM's scalar code (and compose), to the bit, on random
// quaternions (unit and not), vectors and transforms with and without scales.

#include <gtest/gtest.h>

#include <cstring>

#include "mm/runtime/transform_sse.hpp"
#include "test_math.hpp"

namespace mm {
namespace {

template <typename T>
::testing::AssertionResult same_bits(const T& a, const T& b) {
  if (std::memcmp(&a, &b, sizeof(T)) == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "the bits differ";
}

// A quaternion of any length: a rotation scaled by up to 4 (the solve's products are not all of
// unit quaternions), or a random sign pattern with zeros.
glm::quat random_quat(int trial) {
  glm::quat q = test::random_rotation(0.0f, 6.2f) * test::uniform(0.25f, 4.0f);
  if (trial % 7 == 3) q.x = 0.0f;
  if (trial % 11 == 5) q.w = -0.0f;
  return q;
}

#if defined(__SSE2__)

TEST(TransformSse, QuaternionArithmeticEqualsGlmToTheBit) {
  for (int trial = 0; trial < 20000; ++trial) {
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    const glm::quat p = random_quat(trial), q = random_quat(trial + 1);
    const glm::vec3 v = test::random_vec3(-3.0f, 3.0f);
    const __m128 sp = sse::load(p), sq = sse::load(q);
    ASSERT_TRUE(same_bits(sse::to_quat(sse::product(sp, sq)), p * q));
    ASSERT_TRUE(same_bits(sse::to_quat(sse::conjugate(sp)), glm::conjugate(p)));
    ASSERT_TRUE(same_bits(sse::to_quat(sse::normalize(sp)), glm::normalize(p)));
    ASSERT_TRUE(same_bits(sse::to_vec3(sse::rotate(sp, sse::load(v))), p * v));
    ASSERT_TRUE(
        same_bits(sse::to_vec3(sse::cross(sse::load(v), sse::load(p * v))), glm::cross(v, p * v)));
  }
}

TEST(TransformSse, NormalizeOfZeroIsTheIdentityAsInGlm) {
  const glm::quat zero(0.0f, 0.0f, 0.0f, 0.0f);
  EXPECT_TRUE(same_bits(sse::to_quat(sse::normalize(sse::load(zero))), glm::normalize(zero)));
}

#endif

TEST(TransformSse, ComposeIntoEqualsComposeToTheBit) {
  for (int trial = 0; trial < 20000; ++trial) {
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    Transform parent = test::random_transform(2.0f), child = test::random_transform(2.0f);
    if (trial % 2 == 1) {
      parent.scale = test::random_vec3(0.5f, 2.0f);
      child.scale = test::random_vec3(0.5f, 2.0f);
    }
    const Transform expected = compose(parent, child);
    Transform out;
    sse::compose_into(parent, child, out);
    ASSERT_TRUE(same_bits(out.rotation, expected.rotation));
    ASSERT_TRUE(same_bits(out.translation, expected.translation));
    ASSERT_TRUE(same_bits(out.scale, expected.scale));
    // Into one of its arguments, as a pose's refresh writes a global over its old value.
    Transform in_place = child;
    sse::compose_into(parent, in_place, in_place);
    ASSERT_TRUE(same_bits(in_place.rotation, expected.rotation));
    ASSERT_TRUE(same_bits(in_place.translation, expected.translation));
    ASSERT_TRUE(same_bits(in_place.scale, expected.scale));
  }
}

// The last Transform of an array: the loads and stores stay inside it (the sanitizer build
// would see a read past the end).
TEST(TransformSse, ComposeIntoTheLastElementStaysInside) {
  std::vector<Transform> pose(2, test::random_transform(1.0f));
  pose[1].scale = glm::vec3(1.5f, 0.5f, 2.0f);
  const Transform expected = compose(pose[0], pose[1]);
  sse::compose_into(pose[0], pose[1], pose[1]);
  EXPECT_TRUE(same_bits(pose[1].translation, expected.translation));
  EXPECT_TRUE(same_bits(pose[1].scale, expected.scale));
}

}  // namespace
}  // namespace mm
