// `curvesfm eval-map` end to end: the real executable, its output, JSON, messages and exit codes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test/support/run_executable.h"
#include "test/support/temp_folder.h"

namespace curvesfm {
namespace {

using testing::CommandResult;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::runCurvesfm;

// The estimate's frame: x_est = kScale * R^T (x_gt - t), so that aligning its trajectory recovers
// the Sim(3) gt_from_est of scale 1 / kScale that maps its curves back onto the ground truth.
constexpr double kScale = 0.5;

class EvalMapCommandTest : public testing::TempFolderTest {
 protected:
  static Eigen::Matrix3d rotation() {
    return Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  }
  static Eigen::Vector3d toEstimate(const Eigen::Vector3d& gt) {
    return kScale * (rotation().transpose() * (gt - Eigen::Vector3d(0.3, -1.0, 2.0)));
  }
  // The ground-truth curves: a circle of radius 1 in the plane z = 0 as 100 edges of a curve
  // graph (Pavilion's format).
  static std::vector<Eigen::Vector3d> circle() {
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < 100; ++k) {
      const double a = 2.0 * M_PI * k / 100;
      points.emplace_back(std::cos(a), std::sin(a), 0.0);
    }
    return points;
  }
  void writeGroundTruthCurves() const {
    std::string points, edges;
    for (const Eigen::Vector3d& p : circle()) points += xyz(p) + "\n";
    for (int k = 0; k < 100; ++k) {
      edges += std::to_string(k + 1) + ".0E+00\n" + std::to_string((k + 1) % 100 + 1) + "\n";
    }
    write("gt/gt-points.txt", points);
    write("gt/gt-edges.txt", edges);
  }
  // The estimated curves as `curvesfm run` writes them: the circle, closed, moved by `offset` in
  // the ground truth's frame, then carried into the estimate's frame when `in_estimate_frame`.
  void writeEstimatedCurves(const std::string& name, const Eigen::Vector3d& offset,
                            bool in_estimate_frame) const {
    std::string text = "o curve_0\n";
    for (const Eigen::Vector3d& p : circle()) {
      text += "v " + xyz(in_estimate_frame ? toEstimate(p + offset) : p + offset) + "\n";
    }
    text += "l";
    for (int k = 0; k <= 100; ++k) text += " " + std::to_string(k % 100 + 1);
    write(name, text + "\n");
  }
  // 20 cameras 1 s apart, TUM camera-to-world: a wavy orbit around the circle, or a straight
  // walk past it, each camera turned a little about its own axes.
  void writeTrajectory(const std::string& name, bool in_estimate_frame,
                       bool straight = false) const {
    std::string text;
    for (int k = 0; k < 20; ++k) {
      const double a = 0.3 * k;
      const Eigen::Vector3d c = straight ? Eigen::Vector3d(-2.0 + 0.2 * k, -3.0, 0.5)
                                         : Eigen::Vector3d(3.0 * std::cos(a), 3.0 * std::sin(a),
                                                           1.0 + 0.2 * std::sin(3 * a));
      Eigen::Matrix3d world_from_cam =
          Eigen::AngleAxisd(0.1 * std::sin(a), Eigen::Vector3d(0.3, 1.0, 0.2).normalized())
              .matrix();
      if (in_estimate_frame) world_from_cam = rotation().transpose() * world_from_cam;
      const Eigen::Quaterniond q(world_from_cam);
      text += std::to_string(k) + " " + xyz(in_estimate_frame ? toEstimate(c) : c) + " " +
              xyz(q.vec()) + " " + std::to_string(q.w()) + "\n";
    }
    write(name, text);
  }
  static std::string xyz(const Eigen::Vector3d& p) {
    char text[128];
    std::snprintf(text, sizeof(text), "%.12f %.12f %.12f", p.x(), p.y(), p.z());
    return text;
  }
  nlohmann::json readJson(const std::string& name) const {
    std::ifstream in(path(name));
    return nlohmann::json::parse(in);
  }
};

TEST_F(EvalMapCommandTest, AlignsTheRunByItsTrajectoryAndScoresTheGroundTruthAsOne) {
  writeGroundTruthCurves();
  writeEstimatedCurves("run/curves.obj", Eigen::Vector3d::Zero(), true);
  writeTrajectory("run/trajectory.txt", true);
  writeTrajectory("gt.txt", false);
  const CommandResult result =
      runCurvesfm("eval-map --run " + path("run") + " --gt-trajectory " + path("gt.txt") +
                  " --gt-curves " + path("gt") + " --json " + path("map.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("alignment sim3"));
  EXPECT_THAT(result.output, HasSubstr("20 matched poses"));
  EXPECT_THAT(result.output, HasSubstr("(curve_graph): 100 polylines"));
  EXPECT_THAT(result.output, HasSubstr("estimated samples inside"));
  EXPECT_THAT(result.output, HasSubstr("precision"));

  const nlohmann::json report = readJson("map.json");
  EXPECT_EQ(report["command"], "eval-map");
  EXPECT_NEAR(report["alignment"]["scale"].get<double>(), 1.0 / kScale, 1e-9);
  EXPECT_EQ(report["alignment"]["matched"], 20);
  ASSERT_EQ(report["scores"].size(), 3u);
  for (const nlohmann::json& score : report["scores"]) {
    EXPECT_DOUBLE_EQ(score["precision"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(score["recall"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(score["f_score"].get<double>(), 1.0);
  }
  EXPECT_EQ(report["options"]["curve_map"]["taus"], "0.01,0.02,0.05");
  EXPECT_EQ(report["options"]["alignment"]["alignment"], "sim3");
  EXPECT_EQ(report["inputs"]["ground_truth_format"], "curve_graph");
  EXPECT_EQ(report["estimate"]["samples"], report["ground_truth"]["samples"]);
}

// Camera centres on one line leave the rotation about it free: fitted to the centres alone the
// curves land anywhere around the line, fitted to the camera frames (the default) on the truth.
TEST_F(EvalMapCommandTest, AStraightTrajectoryIsAlignedByItsCameraFrames) {
  writeGroundTruthCurves();
  writeEstimatedCurves("run/curves.obj", Eigen::Vector3d::Zero(), true);
  writeTrajectory("run/trajectory.txt", true, /*straight=*/true);
  writeTrajectory("gt.txt", false, /*straight=*/true);
  auto precisionAt1cm = [&](const std::string& flags) {
    const CommandResult result =
        runCurvesfm("eval-map --run " + path("run") + " --gt-trajectory " + path("gt.txt") +
                    " --gt-curves " + path("gt") + " --json " + path("map.json") + flags);
    EXPECT_EQ(result.exit_code, 0) << result.output;
    return readJson("map.json")["scores"][0]["precision"].get<double>();
  };
  EXPECT_LT(precisionAt1cm(" --align-frames false"), 0.5);
  EXPECT_DOUBLE_EQ(precisionAt1cm(""), 1.0);
  EXPECT_GT(readJson("map.json")["alignment"]["frames_axis_length"].get<double>(), 1.0);
}

TEST_F(EvalMapCommandTest, AlignNoneTakesTheCurvesAsTheyAreAndConfigSetsTheTaus) {
  writeGroundTruthCurves();
  // 3 cm above the ground truth's plane: within 5 cm, not within 2 cm.
  writeEstimatedCurves("up.obj", Eigen::Vector3d(0, 0, 0.03), false);
  write("map.yaml", "tau: 0.02,0.05\nalign: none\n");
  const CommandResult result =
      runCurvesfm("eval-map --config " + path("map.yaml") + " --curves " + path("up.obj") +
                  " --gt-curves " + path("gt") + " --json " + path("map.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("alignment none"));
  const nlohmann::json report = readJson("map.json");
  ASSERT_EQ(report["scores"].size(), 2u);
  EXPECT_EQ(report["scores"][0]["precision"], 0.0);
  EXPECT_EQ(report["scores"][0]["recall"], 0.0);
  EXPECT_EQ(report["scores"][1]["precision"], 1.0);
  EXPECT_EQ(report["scores"][1]["recall"], 1.0);
  EXPECT_TRUE(report["alignment"].is_null());
}

TEST_F(EvalMapCommandTest, MissingInputsAndBadOptionsAreUsageErrors) {
  writeGroundTruthCurves();
  CommandResult result = runCurvesfm("eval-map --gt-curves " + path("gt"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("give --run RUN_DIR or --curves FILE"));
  result = runCurvesfm("eval-map --curves " + path("missing.obj") + " --gt-curves " + path("gt"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("needs the estimated trajectory"));
  result = runCurvesfm("eval-map --run " + path("run") + " --gt-curves " + path("gt"));
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("needs the ground-truth trajectory"));
  result = runCurvesfm("eval-map --align none --curves " + path("x.obj") + " --gt-curves " +
                       path("gt") + " --tau 0.05,0.01");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("InvalidOptions: --tau = 0.01: must be strictly increasing "
                                       "(CurveMapEvaluationOptions.taus)"));
  result = runCurvesfm("eval-map --align none --curves " + path("x.obj") + " --gt-curves " +
                       path("gt") + " --tau 0.01,x");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("expected comma-separated numbers"));
  result = runCurvesfm("eval-map --align none --curves " + path("x.obj") + " --gt-curves " +
                       path("gt") + " --edge-coverage true");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("--edge-coverage needs the images"));
  result = runCurvesfm("eval-map --align none --curves " + path("x.obj") + " --gt-curves " +
                       path("gt") + " --edge-coverage-normal-angle 100");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.output, HasSubstr("max_normal_angle_deg"));
}

// The rendered curves of `synth curves`, scored against themselves: all of them lie in the
// images, most on an edge of their direction, and whatever the split the recall is 1.
TEST_F(EvalMapCommandTest, EdgeCoverageSplitsTheGroundTruthByWhatTheImagesShow) {
  const std::string data = path("synth");
  ASSERT_EQ(
      runCurvesfm("synth curves --out " + data + " --keyframes 8 --curves 10 --seed 3").exit_code,
      0);
  const std::string curves = data + "/gt_curves.obj";
  const CommandResult result =
      runCurvesfm("eval-map --curves " + curves + " --gt-curves " + curves + " --dataset " + data +
                  " --align none --edge-coverage true --json " + path("map.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("edge coverage (8 images of"));
  EXPECT_THAT(result.output, HasSubstr("on the part shown as an edge: 1.000 / 1.000 / 1.000"));
  const nlohmann::json coverage = readJson("map.json")["edge_coverage"];
  EXPECT_EQ(coverage["images"], 8);
  EXPECT_EQ(coverage["min_views"], 2);
  const double in_views = coverage["share_in_min_views"].get<double>();
  const double on_edge = coverage["share_on_edge_in_min_views"].get<double>();
  const double shown = coverage["share_shown"].get<double>();
  EXPECT_LE(in_views, 1.0);
  EXPECT_LE(on_edge, in_views);
  EXPECT_LE(shown, on_edge);
  EXPECT_GT(shown, 0.3);
  // The map is the ground truth: wherever the images show it, the map has a curve there.
  EXPECT_DOUBLE_EQ(coverage["share_shown_with_a_curve_in_the_images"].get<double>(), shown);
}

TEST_F(EvalMapCommandTest, BadFilesExitWithOneLineNamingFileAndLine) {
  writeGroundTruthCurves();
  write("gt/gt-edges.txt", "1\n2\n3\n");
  writeEstimatedCurves("est.obj", Eigen::Vector3d::Zero(), false);
  CommandResult result = runCurvesfm("eval-map --align none --curves " + path("est.obj") +
                                     " --gt-curves " + path("gt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_EQ(result.output, "ParseError: " + path("gt/gt-edges.txt") +
                               ":3: expected an even number of point indices (pairs), found an "
                               "odd number\n");
  result = runCurvesfm("eval-map --align none --curves " + path("missing.obj") + " --gt-curves " +
                       path("gt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("IoError: " + path("missing.obj") + ": does not exist"));
  // A run folder whose trajectory does not match the ground truth's times.
  writeGroundTruthCurves();
  write("run/curves.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
  write("run/trajectory.txt", "500 0 0 0 0 0 0 1\n");
  writeTrajectory("gt.txt", false);
  result = runCurvesfm("eval-map --run " + path("run") + " --gt-trajectory " + path("gt.txt") +
                       " --gt-curves " + path("gt"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("TrajectoryEvaluationError: "));
  // Edge coverage over a dataset without ground-truth poses to project with, before any work.
  const std::string data = path("synth");
  ASSERT_EQ(runCurvesfm("synth curves --out " + data + " --keyframes 4 --curves 5").exit_code, 0);
  std::filesystem::remove(data + "/groundtruth.txt");
  result =
      runCurvesfm("eval-map --align none --curves " + path("run/curves.obj") + " --gt-curves " +
                  path("gt") + " --dataset " + data + " --edge-coverage true");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("has no ground-truth trajectory to project the "
                                       "ground-truth curves with (--edge-coverage)"));
  EXPECT_THAT(result.output, Not(HasSubstr("precision")));
}

}  // namespace
}  // namespace curvesfm
