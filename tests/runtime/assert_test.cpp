// MM_ASSERT (mm/runtime/assert.hpp): a broken precondition reaches the installed handler with
// its expression, file and line, and the default handler prints it and aborts.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {
namespace {

struct PreconditionFailed {
  std::string expression, file;
  int line = 0;
};

[[noreturn]] void throw_failure(const char* expression, const char* file, int line) {
  throw PreconditionFailed{expression, file, line};
}

// Installs throw_failure for one scope.
class ThrowingHandler {
 public:
  ThrowingHandler() : previous_(set_assert_handler(&throw_failure)) {}
  ~ThrowingHandler() { set_assert_handler(previous_); }
  ThrowingHandler(const ThrowingHandler&) = delete;
  ThrowingHandler& operator=(const ThrowingHandler&) = delete;

 private:
  AssertHandler previous_;
};

TEST(Assert, ABrokenPreconditionReachesTheInstalledHandler) {
  const ThrowingHandler handler;
  const std::vector<int> parents = {-1, 0};
  const std::vector<Transform> local(2);
  std::vector<Transform> global(1);  // one joint short
  try {
    forward_kinematics(parents, local, global);
    FAIL() << "no precondition failed";
  } catch (const PreconditionFailed& failure) {
    EXPECT_EQ(failure.expression,
              "local.size() == parents.size() && global.size() == parents.size()");
    EXPECT_NE(failure.file.find("pose.cpp"), std::string::npos) << failure.file;
    EXPECT_GT(failure.line, 0);
  }
  // A joint listed before its parent.
  const std::vector<int> unordered = {1, -1};
  global.resize(2);
  EXPECT_THROW(forward_kinematics(unordered, local, global), PreconditionFailed);
  // Nothing fails when the preconditions hold.
  EXPECT_NO_THROW(forward_kinematics(parents, local, global));
}

TEST(Assert, TheInstalledHandlerIsReturnedAndNullRestoresTheDefault) {
  const AssertHandler original = set_assert_handler(&throw_failure);
  EXPECT_EQ(set_assert_handler(nullptr), &throw_failure);
  EXPECT_EQ(set_assert_handler(original), original);  // the default, installed by nullptr
}

TEST(AssertDeathTest, TheDefaultHandlerPrintsTheFailureAndAborts) {
  const std::vector<int> parents = {-1, 0};
  const std::vector<Transform> local(2);
  std::vector<Transform> global(1);
  EXPECT_DEATH(forward_kinematics(parents, local, global),
               "pose.cpp:[0-9]+: precondition failed: local.size\\(\\) == parents.size\\(\\)");
}

}  // namespace
}  // namespace mm
