#include "frontend/image/curve_overlay.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "core/errors.h"
#include "test/support/cameras.h"

namespace curvesfm {
namespace {

// Principal point (79.5, 59.5).
Camera smallCamera() { return testing::centredPinhole(100.0, 160, 120); }

// A straight one-segment curve from a to b (arms of a third: uniform speed).
PolyBezier line(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Direction v(b - a);
  const double arm = (b - a).norm() / 3.0;
  return PolyBezier({a, b}, {v, v}, {SegmentLengths{arm, arm}});
}

int greenPixels(const cv::Mat& image) {
  int count = 0;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) count += image.at<cv::Vec3b>(r, c)[1] > 0;
  }
  return count;
}

TEST(CurveOverlay, DrawsAHorizontalLineWhereItProjects) {
  const Camera camera = smallCamera();
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(0, 0, 0));
  // At depth 2 m, x in [-0.5, 0.5] m projects to columns 54.5..104.5 on row 59.5.
  const CurveOverlayCounts counts =
      drawCurves(&image, {line({-0.5, 0, 2}, {0.5, 0, 2})}, camera, Pose3(), {});
  EXPECT_EQ(counts.drawn_samples, 17);
  EXPECT_EQ(counts.behind_camera, 0);
  EXPECT_GT(image.at<cv::Vec3b>(59, 80)[1] + image.at<cv::Vec3b>(60, 80)[1], 0);
  EXPECT_EQ(image.at<cv::Vec3b>(20, 80), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(image.at<cv::Vec3b>(59, 20), cv::Vec3b(0, 0, 0));
}

TEST(CurveOverlay, SkipsSamplesBehindTheCameraWithoutDrawingAcrossTheImage) {
  const Camera camera = smallCamera();
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(0, 0, 0));
  CurveOverlayOptions options;
  options.point_radius_px = 0;
  // From 2 m in front to 2 m behind, off-axis: the front half draws a short ray towards the
  // vanishing point; the rear half must not appear.
  const CurveOverlayCounts counts =
      drawCurves(&image, {line({0.2, 0.1, 2}, {0.2, 0.1, -2})}, camera, Pose3(), options);
  EXPECT_GT(counts.behind_camera, 0);
  EXPECT_GT(counts.drawn_samples, 0);
  EXPECT_EQ(counts.drawn_samples + counts.behind_camera + counts.far_outside, 17);
  EXPECT_GT(greenPixels(image), 0);
  // Nothing left of or above the principal point: the visible part lies right of and below it.
  EXPECT_EQ(greenPixels(image(cv::Rect(0, 0, 79, 120))), 0);
  EXPECT_EQ(greenPixels(image(cv::Rect(0, 0, 160, 59))), 0);
}

TEST(CurveOverlay, DrawsEachCurveInItsOwnColour) {
  const Camera camera = smallCamera();
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(0, 0, 0));
  CurveOverlayOptions options;
  options.point_radius_px = 0;
  // Rows 39.5 and 79.5 at depth 2 m; options.colour (green) must not appear.
  const std::vector<PolyBezier> curves = {line({-0.5, -0.4, 2}, {0.5, -0.4, 2}),
                                          line({-0.5, 0.4, 2}, {0.5, 0.4, 2})};
  drawCurves(&image, curves, {cv::Scalar(0, 0, 255), cv::Scalar(255, 0, 0)}, camera, Pose3(),
             options);
  const cv::Vec3b upper = image.at<cv::Vec3b>(39, 80) + image.at<cv::Vec3b>(40, 80);
  const cv::Vec3b lower = image.at<cv::Vec3b>(79, 80) + image.at<cv::Vec3b>(80, 80);
  EXPECT_GT(upper[2], 0);
  EXPECT_EQ(upper[0], 0);
  EXPECT_GT(lower[0], 0);
  EXPECT_EQ(lower[2], 0);
  EXPECT_EQ(greenPixels(image), 0);
  EXPECT_THROW(drawCurves(&image, curves, {cv::Scalar(0, 0, 255)}, camera, Pose3()), CheckError);
}

TEST(CurveOverlay, RejectsBadOptionsAndImages) {
  const Camera camera = smallCamera();
  cv::Mat image(120, 160, CV_8UC3);
  CurveOverlayOptions options;
  options.samples_per_segment = 0;
  EXPECT_THROW(drawCurves(&image, {}, camera, Pose3(), options), InvalidOptions);
  cv::Mat grey(120, 160, CV_8UC1);
  EXPECT_THROW(drawCurves(&grey, {}, camera, Pose3()), CheckError);
  cv::Mat small(60, 80, CV_8UC3);
  EXPECT_THROW(drawCurves(&small, {}, camera, Pose3()), CheckError);
}

}  // namespace
}  // namespace curvesfm
