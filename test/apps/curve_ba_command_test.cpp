#include "apps/curve_ba_command.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "apps/cli/report_json.h"
#include "test/apps/curve_ba_command_fixture.h"

namespace curvesfm {
namespace {

using testing::CurveBaCommandTest;

TEST_F(CurveBaCommandTest, ConfigFileSetsEnumsAndBoolsAndFlagsWin) {
  const std::string config = write("curve-ba.yaml",
                                   "strategy: alternating\n"
                                   "camera-path: forward_walk\n"
                                   "subpixel-edges: false\n"
                                   "kernel: cauchy\n"
                                   "lambda1: 7\n"
                                   "keyframes: 3\n"
                                   "curves: 2\n"
                                   "max-iterations: 2\n"
                                   "max-rounds: 1\n");
  const nlohmann::json report = runWithReport({"--config", config, "--lambda1", "9"});
  const nlohmann::json& options = report["options"];
  EXPECT_EQ(options["scheduler"]["strategy"], "alternating");
  EXPECT_EQ(options["scene"]["camera_path"], "forward_walk");
  EXPECT_EQ(options["bundle_adjustment"]["use_subpixel_edges"], false);
  EXPECT_EQ(options["bundle_adjustment"]["kernel"], "cauchy");
  EXPECT_EQ(options["bundle_adjustment"]["lambda1"], 9.0);  // the flag beats the file
  EXPECT_EQ(options["scene"]["num_keyframes"], 3);
  EXPECT_EQ(report["config"]["lambda1"], "9");
  EXPECT_EQ(report["config"]["subpixel-edges"], "false");
  EXPECT_EQ(report["curvesfm"], versionJson());
  // Every field of the objective, the motion prior's included, and the derived gauge switch.
  EXPECT_EQ(options["bundle_adjustment"]["motion_prior_rotation_sigma_deg"], 0.02);
  EXPECT_EQ(options["scheduler"]["fix_first_pose"], true);
  EXPECT_EQ(options["scene"]["intrinsics"]["width"], 640);
}

TEST_F(CurveBaCommandTest, UnknownEnumValueNamesTheFlagAndTheAcceptedNames) {
  const std::string flag = messageOf({"--strategy", "joinnt"});
  EXPECT_NE(flag.find("--strategy"), std::string::npos) << flag;
  EXPECT_NE(flag.find("\"joinnt\""), std::string::npos) << flag;
  EXPECT_NE(flag.find("joint, alternating, inner_iterations"), std::string::npos) << flag;

  const std::string file = messageOf({"--config", write("bad.yaml", "curve-kind: spiral\n")});
  EXPECT_NE(file.find("--curve-kind"), std::string::npos) << file;
  EXPECT_NE(file.find("line, arc, helix, mixed"), std::string::npos) << file;
}

TEST_F(CurveBaCommandTest, BadBoolAndOutOfRangeValuesAreRejected) {
  const std::string boolean = messageOf({"--fix-scale", "maybe"});
  EXPECT_NE(boolean.find("--fix-scale"), std::string::npos) << boolean;
  EXPECT_NE(boolean.find("'maybe'"), std::string::npos) << boolean;
  const std::string range = messageOf({"--lambda2", "-1"});
  EXPECT_EQ(range.rfind("InvalidOptions: ", 0), 0u) << range;
  EXPECT_NE(range.find("lambda2"), std::string::npos) << range;
}

}  // namespace
}  // namespace curvesfm
