#include "core/trajectory_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"

namespace curvesfm {
namespace {

TrajectoryEvaluation circleEvaluation() {
  std::vector<StampedPose> truth, estimate;
  for (int k = 0; k < 30; ++k) {
    const double angle = 0.2 * k;
    const Eigen::Vector3d centre(std::cos(angle), 0.01 * std::sin(3 * angle), std::sin(angle));
    truth.push_back({0.1 * k, Pose3(Eigen::Quaterniond::Identity(), centre)});
    estimate.push_back(
        {0.1 * k, Pose3(Eigen::Quaterniond::Identity(),
                        2.0 * centre + 0.02 * Eigen::Vector3d::UnitX() * std::cos(k))});
  }
  return compareTrajectories(estimate, truth, TrajectoryEvaluationOptions());
}

TEST(TopViewAxes, DropTheAxisOfLeastSpread) {
  const auto axes = [](const std::vector<Eigen::Vector3d>& points) {
    const TopViewAxes a = chooseTopViewAxes(points);
    return std::make_pair(a.horizontal, a.vertical);
  };
  EXPECT_EQ(axes({{0, 0, 0}, {5, 1, 3}}), std::make_pair(0, 2));  // x-z
  EXPECT_EQ(axes({{0, 0, 0}, {5, 3, 1}}), std::make_pair(0, 1));  // x-y
  EXPECT_EQ(axes({{0, 0, 0}, {1, 3, 5}}), std::make_pair(1, 2));  // y-z
  EXPECT_EQ(axes({}), std::make_pair(0, 2));                      // Ties: x-z.
  EXPECT_EQ(axes({{1, 1, 1}, {2, 2, 2}}), std::make_pair(0, 2));
}

TEST(TrajectoryPlot, RendersTwoPanelsOfTheRequestedSize) {
  TrajectoryPlotOptions options;
  options.panel_width = 500;
  options.panel_height = 400;
  const cv::Mat figure = renderTrajectoryEvaluation(circleEvaluation(), options);
  EXPECT_EQ(figure.cols, 1000);
  EXPECT_EQ(figure.rows, 400);
  EXPECT_EQ(figure.type(), CV_8UC3);
  // Both panels hold coloured (non-grey) data pixels.
  for (const cv::Rect half : {cv::Rect(0, 0, 500, 400), cv::Rect(500, 0, 500, 400)}) {
    cv::Mat hsv;
    cv::cvtColor(figure(half), hsv, cv::COLOR_BGR2HSV);
    std::vector<cv::Mat> channels;
    cv::split(hsv, channels);
    EXPECT_GT(cv::countNonZero(channels[1] > 100), 100);
  }
}

TEST(TrajectoryPlot, InvalidSizesAndUnwritablePathsAreReported) {
  TrajectoryPlotOptions options;
  options.panel_width = 10;
  EXPECT_THROW(options.validate(), InvalidOptions);
  const std::string path = "/nonexistent_dir_for_eval/plot.png";
  try {
    saveTrajectoryEvaluationPlot(path, circleEvaluation());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), testing::HasSubstr("IoError: " + path + ": "));
  }
}

}  // namespace
}  // namespace curvesfm
