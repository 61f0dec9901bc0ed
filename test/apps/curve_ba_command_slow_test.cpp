// `curvesfm curve-ba` solved to the end on a small scene (ctest label "slow").
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "apps/curve_ba_command.h"
#include "test/apps/curve_ba_command_fixture.h"

namespace curvesfm {
namespace {

using testing::CurveBaCommandTest;

TEST_F(CurveBaCommandTest, TinyRunLowersTheAteAndEchoesTheConfiguration) {
  const nlohmann::json report =
      runWithReport({"--keyframes", "8", "--curves", "8", "--max-iterations", "30", "--lambda1",
                     "150", "--lambda2", "2", "--kernel", "cauchy", "--strategy", "joint"});
  const nlohmann::json& config = report["config"];
  EXPECT_EQ(config["lambda1"], "150");
  EXPECT_EQ(config["lambda2"], "2");
  EXPECT_EQ(config["kernel"], "cauchy");
  EXPECT_EQ(config["strategy"], "joint");
  EXPECT_EQ(report["options"]["bundle_adjustment"]["lambda2"], 2.0);
  EXPECT_EQ(report["scene"]["keyframes"], 8);

  // Measured (seed 42): ATE 30 -> 1.9 mm.
  const double before = report["before"]["errors"]["camera_ate_sim3_m"];
  const double after = report["after"]["errors"]["camera_ate_sim3_m"];
  EXPECT_LT(after, 0.5 * before);
  EXPECT_GT(report["after"]["samples"]["on_field"], 0);
  EXPECT_TRUE(report["after"]["cost_by_type"].contains("curve_reprojection"));
  EXPECT_FALSE(report["schedule"]["stop_reason"].get<std::string>().empty());
  EXPECT_EQ(report["schedule"]["rounds"].size(), 1u);
}

}  // namespace
}  // namespace curvesfm
