// `curvesfm eval` end to end: the real executable, its output, messages and exit codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "apps/cli/report_json.h"
#include "test/support/run_executable.h"

namespace curvesfm {
namespace {

using testing::CommandResult;
using testing::runCurvesfm;

class EvalCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("eval_command_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string path(const std::string& name) const { return (folder_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  // A wavy circle of `count` poses, 10 per second, scaled by `scale`.
  std::string writeCircle(const std::string& name, int count, double scale) const {
    std::string text = "# timestamp tx ty tz qx qy qz qw\n";
    for (int k = 0; k < count; ++k) {
      const double a = 0.1 * k;
      char line[256];
      std::snprintf(line, sizeof(line), "%.6f %.6f %.6f %.6f 0 0 0 1\n", 10.0 + 0.1 * k,
                    scale * (std::cos(a) + 1.0), scale * 0.05 * std::sin(3 * a),
                    scale * std::sin(a));
      text += line;
    }
    return write(name, text);
  }

  std::filesystem::path folder_;
};

TEST_F(EvalCommandTest, PrintsMatchesAteAndRpeAndWritesJsonAndPlot) {
  const std::string gt = writeCircle("gt.txt", 40, 1.0);
  const std::string est = writeCircle("est.txt", 40, 0.5);
  const CommandResult result = runCurvesfm("eval --est " + est + " --gt " + gt + " --json " +
                                           path("eval.json") + " --plot " + path("eval.png"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output,
              ::testing::HasSubstr("matched 40 of 40 estimated poses (40 ground-truth) within "
                                   "0.02 s"));
  EXPECT_THAT(result.output, ::testing::HasSubstr("alignment sim3"));
  EXPECT_THAT(result.output, ::testing::HasSubstr("rmse"));
  EXPECT_THAT(result.output, ::testing::HasSubstr("RPE rot (deg)"));

  std::ifstream json_file(path("eval.json"));
  const nlohmann::json report = nlohmann::json::parse(json_file);
  EXPECT_EQ(report["matched"], 40);
  EXPECT_EQ(report["options"]["alignment"], "sim3");
  EXPECT_EQ(report["curvesfm"], versionJson());
  EXPECT_NEAR(report["alignment"]["scale"].get<double>(), 2.0, 1e-4);
  EXPECT_LT(report["ate_m"]["rmse"].get<double>(), 1e-4);
  EXPECT_EQ(report["ate_m"]["count"], 40);
  EXPECT_EQ(report["rpe_translation_m"]["count"], 39);
  EXPECT_EQ(report["per_pose"]["ate_m"].size(), 40u);
  // The figure draws the aligned positions as they are: scale 2 maps the half-size circle onto
  // the ground truth.
  ASSERT_EQ(report["per_pose"]["aligned_position"].size(), 40u);
  ASSERT_EQ(report["per_pose"]["ground_truth_position"].size(), 40u);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(report["per_pose"]["aligned_position"][7][axis].get<double>(),
                report["per_pose"]["ground_truth_position"][7][axis].get<double>(), 1e-4);
  }
  EXPECT_EQ(report["config"]["max-dt"], "0.02");

  // Drawn by python3 -m curvesfm_plots eval from the JSON: two 8 x 6 inch panels at 100 dpi.
  const cv::Mat plot = cv::imread(path("eval.png"));
  EXPECT_EQ(plot.cols, 1600);
  EXPECT_EQ(plot.rows, 600);
}

TEST_F(EvalCommandTest, AlignedOutCarriesEveryEstimatedPoseOntoTheGroundTruth) {
  const std::string gt = writeCircle("gt.txt", 40, 1.0);
  // Five poses past the ground truth's end: unmatched, yet written, so that the file can stand
  // in for the estimate.
  const std::string est = writeCircle("est.txt", 45, 0.5);
  const CommandResult result =
      runCurvesfm("eval --est " + est + " --gt " + gt + " --aligned-out " + path("aligned.txt"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, ::testing::HasSubstr("aligned estimate: " + path("aligned.txt")));

  const CommandResult again = runCurvesfm("eval --est " + path("aligned.txt") + " --gt " + gt +
                                          " --align none --json " + path("again.json"));
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_THAT(again.output, ::testing::HasSubstr("matched 40 of 45 estimated poses"));
  std::ifstream json_file(path("again.json"));
  const nlohmann::json report = nlohmann::json::parse(json_file);
  EXPECT_LT(report["ate_m"]["max"].get<double>(), 1e-4);
  EXPECT_LT(report["rpe_rotation_deg"]["max"].get<double>(), 1e-3);
}

TEST_F(EvalCommandTest, AlignedOutInAMissingFolderExitsWithOneLineNamingIt) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  const std::string target = path("missing/aligned.txt");
  const CommandResult result =
      runCurvesfm("eval --est " + gt + " --gt " + gt + " --aligned-out " + target);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output,
              ::testing::EndsWith("IoError: " + target + ": cannot open for writing\n"));
}

TEST_F(EvalCommandTest, PlotWithoutJsonWritesAPdf) {
  const std::string gt = writeCircle("gt.txt", 20, 1.0);
  const CommandResult result =
      runCurvesfm("eval --est " + gt + " --gt " + gt + " --plot " + path("eval.pdf"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, ::testing::HasSubstr("plot: " + path("eval.pdf")));
  EXPECT_THAT(result.output, ::testing::Not(::testing::HasSubstr("json:")));
  std::ifstream pdf(path("eval.pdf"));
  std::string magic(4, ' ');
  pdf.read(magic.data(), 4);
  EXPECT_EQ(magic, "%PDF");
}

TEST_F(EvalCommandTest, PlotOtherThanPngOrPdfIsAUsageErrorBeforeAnyWork) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  // The estimate does not exist: the extension is refused before any file is read.
  const CommandResult result = runCurvesfm("eval --est " + path("missing.txt") + " --gt " + gt +
                                           " --plot " + path("eval.jpg"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, ::testing::HasSubstr("--plot"));
  EXPECT_THAT(result.output, ::testing::HasSubstr("expected a file name ending in .png or .pdf"));
  EXPECT_FALSE(std::filesystem::exists(path("eval.jpg")));
}

TEST_F(EvalCommandTest, MissingFileExitsWithOneNamingIt) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  const CommandResult result = runCurvesfm("eval --est " + path("missing.txt") + " --gt " + gt);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "IoError: " + path("missing.txt") + ": cannot open for reading\n");
}

TEST_F(EvalCommandTest, MalformedLineGivesPathAndLine) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  const std::string est = write("est.txt",
                                "# header\n"
                                "1.0 0 0 0 0 0 0 1\n"
                                "1.1 0 0 0 0 0 1\n");
  const CommandResult result = runCurvesfm("eval --est " + est + " --gt " + gt);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "ParseError: " + est +
                               ":3: expected 8 fields \"timestamp tx ty tz qx qy qz qw\", "
                               "found 7\n");
}

TEST_F(EvalCommandTest, TooFewMatchesNameBothFiles) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  const std::string est = write("est.txt", "500.0 0 0 0 0 0 0 1\n500.1 1 0 0 0 0 0 1\n");
  const CommandResult result = runCurvesfm("eval --est " + est + " --gt " + gt + " --align se3");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "TrajectoryEvaluationError: " + est + " vs " + gt +
                               ": matched 0 of 2 estimated poses (10 ground-truth) within max_dt "
                               "0.02 s; se3 alignment needs at least 3\n");
}

TEST_F(EvalCommandTest, BadOptionsAreUsageErrors) {
  const std::string gt = writeCircle("gt.txt", 10, 1.0);
  CommandResult result = runCurvesfm("eval --est " + gt + " --gt " + gt + " --align sim2");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output,
              ::testing::HasSubstr("--align: \"sim2\": expected one of sim3, se3, none"));
  result = runCurvesfm("eval --gt " + gt);
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, ::testing::HasSubstr("--est is required"));
  result = runCurvesfm("eval --est " + gt + " --gt " + gt + " --max-dt -1");
  EXPECT_EQ(result.exit_code, 2);
  // A range error names the flag first, then the field it sets.
  EXPECT_THAT(result.output,
              ::testing::StartsWith("InvalidOptions: --max-dt = -1: must be finite and >= 0 "
                                    "(seconds) (TrajectoryEvaluationOptions.max_dt)"));
}

}  // namespace
}  // namespace curvesfm
