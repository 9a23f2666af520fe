// A toe a wall keeps out, on the shipped courses (controller_world.cpp, place_feet): the capsule
// stands a radius back from a ledge's edge (the side of a stair's landing, a step higher than the
// tread the body stands on), the animation swings a toe out over the drop, and keep_toe_off_wall
// holds it on the landing. Its ground was probed where the animation had it, out over the drop
// (the body's ground there, a step lower), so the toe held on the landing sank below its top
// (1.66 and 1.40 cm in the two runs below). Probed where it is held, it stays above it.

#include <gtest/gtest.h>

#include <filesystem>

#include "../controller/controller_support.hpp"
#include "course_support.hpp"
#include "mm/controller/script.hpp"
#include "mm/programs/evaluation.hpp"

namespace mm {
namespace {

struct LedgeRun {
  const char* course;
  const char* script;
  glm::dvec2 start;
  float dt;
};

TEST(ToeOnLedge, AToeHeldOnALandingBesideItsDropStaysAboveTheLanding) {
  const std::filesystem::path source(MM_SOURCE_DIR);
  // The second course's stairs_20_25 (a 0.8 m landing, its side a ledge to the floor) walked
  // back and forth; the first course's stairs stopped on.
  const LedgeRun runs[] = {
      {"data/levels/course2.glb", "reversals.txt", {11.5, 2.0}, 1.0f / 60.0f},
      {"data/levels/course.glb", "stop-and-go.txt", {10.0, 3.0}, 1.0f / 30.0f}};
  for (const LedgeRun& run : runs) {
    const BulletWorld world = test::course_world(source / run.course);
    Result<InputScript> script = load_input_script(source / "scripts/input" / run.script);
    ASSERT_TRUE(script.ok()) << script.message();
    EvaluationOptions options;
    options.dt = run.dt;
    options.world = &world;
    options.start = run.start;
    const Result<EvaluationResult> result =
        evaluate_script(test::normal_controller_database(), *script, options);
    ASSERT_TRUE(result.ok()) << result.message();
    // The floor: a toe at least 1 cm above the surface under it.
    EXPECT_GE(result->metrics.ground.toe_clearance_cm_min, 1.0) << run.course << " " << run.script;
    EXPECT_EQ(result->metrics.ground.foot_penetration_cm_max, 0.0)
        << run.course << " " << run.script;
  }
}

}  // namespace
}  // namespace mm
