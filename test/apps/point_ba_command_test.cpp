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
  EXPECT_THAT(result.output, HasSubstr("PointSceneOptions.num_cameras = 1"));
  result = runCurvesfm("point-ba --pixel-sigma -1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("PointBundleAdjustmentOptions.pixel_sigma = -1"));
  result = runCurvesfm("point-ba --max-iterations -1");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("OptimizerOptions.max_iterations = -1"));
}

TEST(PointBaCommand, BadValueMessageIsOneLine) {
  const CommandResult result = runCurvesfm("point-ba --cameras 1");
  EXPECT_EQ(result.output.find('\n'), result.output.size() - 1) << result.output;
}

}  // namespace
}  // namespace curvesfm
