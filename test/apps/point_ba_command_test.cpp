// `curvesfm point-ba` on the real executable: bad values are usage errors (exit 2) naming the
// field, as for `run`.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using ::testing::HasSubstr;

using testing::CommandResult;
using testing::runCurvesfm;

TEST(PointBaCommand, BadValuesAreUsageErrorsNamingTheField) {
  CommandResult result = runCurvesfm("point-ba --cameras 1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr("--cameras = 1: must be >= 2 (PointSceneOptions.num_cameras)"));
  result = runCurvesfm("point-ba --pixel-sigma -1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(
      result.output,
      HasSubstr(
          "--pixel-sigma = -1: must be > 0 and finite (PointBundleAdjustmentOptions.pixel_sigma)"));
  result = runCurvesfm("point-ba --max-iterations -1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr("--max-iterations = -1: must be >= 0 (OptimizerOptions.max_iterations)"));
}

TEST(PointBaCommand, BadValueMessageIsOneLine) {
  const CommandResult result = runCurvesfm("point-ba --cameras 1");
  EXPECT_EQ(result.output.find('\n'), result.output.size() - 1) << result.output;
}

}  // namespace
}  // namespace curvesfm
