// Strafing (issue 17): the data has no side steps, so a strafe plays clips whose body faces
// more or less where it walks; the chest still faces the requested facing.

#include <gtest/gtest.h>

#include <filesystem>

#include "controller_support.hpp"
#include "mm/controller/controller.hpp"
#include "mm/controller/evaluation.hpp"
#include "mm/controller/script.hpp"

namespace mm {
namespace {

// Running strafes in every direction while facing forward, at every rate: the chest's facing
// error (the evaluation's strafe_chest_error_deg_mean) stays small. The clips alone leave it
// near 10 degrees.
TEST(StrafeTest, TheChestFacesTheFacingWhileRunningSideways) {
  Result<InputScript> script =
      load_input_script(std::filesystem::path(MM_SOURCE_DIR) / "scripts/input/strafe-run.txt");
  ASSERT_TRUE(script.ok()) << script.message();
  for (const float dt : {1.0f / 30.0f, 1.0f / 60.0f, 1.0f / 144.0f}) {
    EvaluationOptions options;
    options.dt = dt;
    Result<EvaluationResult> run =
        evaluate_script(test::normal_controller_database(), *script, options);
    ASSERT_TRUE(run.ok()) << run.message();
    EXPECT_GT(run->metrics.strafe_chest_error_deg_mean, 0.0) << "dt " << dt;  // measured at all
    EXPECT_LT(run->metrics.strafe_chest_error_deg_mean, 5.0) << "dt " << dt;
  }
}

}  // namespace
}  // namespace mm
