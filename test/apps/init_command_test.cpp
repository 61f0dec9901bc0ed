#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test/apps/run_command_fixture.h"

namespace curvesfm {
namespace testing {
namespace {

using ::testing::HasSubstr;

class InitCommandTest : public RunCommandTest {
 protected:
  CommandResult init(const std::string& extra = "") const {
    return runCurvesfm("init --dataset " + folder_.string() + " --out " + path("out") + " " +
                       extra);
  }
};

TEST_F(InitCommandTest, ATexturelessSequenceSaysWhyInOneLineAndExitsOne) {
  writeTinyDataset();  // Three flat frames: no corner, no track.
  const CommandResult result = init();
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("init: 0 of 3 frames registered"));
  EXPECT_THAT(result.output, HasSubstr("not registered, no_model: frames 0-2"));
  EXPECT_THAT(result.output, HasSubstr("init: nothing reconstructed: no initial pair"));
  // The report still says what happened to every frame.
  const nlohmann::json report = testing::readReport(path("out"));
  EXPECT_EQ(report["counts"]["registered"], 0);
  EXPECT_EQ(report["frames"].size(), 3u);
  EXPECT_EQ(report["frames"][0]["status"], "no_model");
  EXPECT_EQ(report["scale_convention"], "median depth of the initial pair's points = 1");
}

TEST_F(InitCommandTest, BadOptionsAndLayoutsAreClearErrors) {
  writeTinyDataset();
  CommandResult result = init("--points-pnp-min-inliers 3");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--points-pnp-min-inliers = 3"));
  result = init("--layout kitti");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("IoError"));
  EXPECT_FALSE(std::filesystem::exists(path("out")));
}

}  // namespace
}  // namespace testing
}  // namespace curvesfm
