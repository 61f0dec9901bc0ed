#include "frontend/image/edge_coverage.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// A 200 x 100 view, identity pose, f = 100 px: a point (x, y, 1) projects to (100 + 100 x,
// 50 + 100 y). The image is dark left of column 100 and bright from it on: one vertical edge.
Camera camera() {
  CameraIntrinsics intrinsics;
  intrinsics.fx = intrinsics.fy = 100.0;
  intrinsics.cx = 100.0;
  intrinsics.cy = 50.0;
  intrinsics.width = 200;
  intrinsics.height = 100;
  return Camera(intrinsics);
}

cv::Mat stepImage() {
  cv::Mat image(100, 200, CV_8UC1, cv::Scalar(40));
  image.colRange(100, 200).setTo(200);
  return image;
}

TEST(EdgeCoverage, CountsViewsOnAnEdgeOfTheCurvesDirection) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitY(), across = Eigen::Vector3d::UnitX();
  const std::vector<Eigen::Vector3d> points = {
      {-0.005, 0.1, 1.0},  // On the edge (column 99.5), the curve along it: shown.
      {-0.005, 0.1, 1.0},  // The same point of a curve across the edge: the wrong direction.
      {0.5, 0.1, 1.0},     // In the bright half, 50 px from the edge.
      {0.0, 0.0, -1.0},    // Behind the camera.
      {2.0, 0.0, 1.0}};    // Right of the image.
  const std::vector<Eigen::Vector3d> directions = {up, across, up, up, up};
  EdgeCoverageCounter counter(points, directions, {});
  counter.addView(stepImage(), Pose3(), camera());
  // From the second view on, a curve along the edge: near the points on it, 50 px from the third.
  counter.setNearbyCurves({{{-0.005, -0.3, 1.0}, {-0.005, 0.3, 1.0}}});
  counter.addView(stepImage(), Pose3(), camera());
  ASSERT_EQ(counter.numViews(), 2);
  const std::vector<PointViews>& views = counter.views();
  EXPECT_EQ(views[0].in_image, 2);
  EXPECT_EQ(views[0].on_edge, 2);
  EXPECT_EQ(views[0].near_curve, 1);
  EXPECT_EQ(views[1].near_curve, 1);
  EXPECT_EQ(views[2].near_curve, 0);
  EXPECT_EQ(views[1].in_image, 2);
  EXPECT_EQ(views[1].on_edge, 0);
  EXPECT_EQ(views[2].in_image, 2);
  EXPECT_EQ(views[2].on_edge, 0);
  EXPECT_EQ(views[3].in_image, 0);
  EXPECT_EQ(views[4].in_image, 0);
}

TEST(EdgeCoverage, RefusesBadOptionsAndAnImageOfAnotherSize) {
  EdgeCoverageOptions options;
  options.max_edge_distance_px = 0.0;
  EXPECT_THROW(EdgeCoverageCounter({}, {}, options), InvalidOptions);
  options = {};
  options.max_normal_angle_deg = 120.0;
  EXPECT_THROW(EdgeCoverageCounter({}, {}, options), InvalidOptions);
  EXPECT_THROW(EdgeCoverageCounter({Eigen::Vector3d::Zero()}, {}, {}), CheckError);
  EdgeCoverageCounter counter({}, {}, {});
  EXPECT_THROW(counter.addView(cv::Mat(50, 200, CV_8UC1, cv::Scalar(0)), Pose3(), camera()),
               CheckError);
}

}  // namespace
}  // namespace curvesfm
