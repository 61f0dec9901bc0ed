#include "frontend/image/image_undistorter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/errors.h"
#include "frontend/image/edge_detector.h"

namespace curvesfm {
namespace {

// Strong barrel distortion with a tangential part, as a wide-angle webcam.
Camera distortedCamera() {
  // fx, fy, cx, cy, k1, k2, p1, p2, k3, width, height.
  return Camera(
      CameraIntrinsics{480.0, 470.0, 322.0, 236.5, -0.28, 0.09, 0.0012, -0.0009, -0.01, 640, 480});
}

// A Gaussian spot (sigma 1.5 px) centred on the sub-pixel position `centre`.
void renderSpot(const Eigen::Vector2d& centre, cv::Mat* image) {
  const int x0 = static_cast<int>(std::lround(centre.x()));
  const int y0 = static_cast<int>(std::lround(centre.y()));
  for (int r = y0 - 6; r <= y0 + 6; ++r) {
    for (int c = x0 - 6; c <= x0 + 6; ++c) {
      const double d2 = (Eigen::Vector2d(c, r) - centre).squaredNorm();
      image->at<float>(r, c) += static_cast<float>(200.0 * std::exp(-d2 / (2.0 * 1.5 * 1.5)));
    }
  }
}

// Intensity-weighted centroid in the 15 x 15 window around `guess`.
Eigen::Vector2d centroid(const cv::Mat& image, const Eigen::Vector2d& guess) {
  const int x0 = static_cast<int>(std::lround(guess.x()));
  const int y0 = static_cast<int>(std::lround(guess.y()));
  double sum = 0.0;
  Eigen::Vector2d weighted = Eigen::Vector2d::Zero();
  for (int r = y0 - 7; r <= y0 + 7; ++r) {
    for (int c = x0 - 7; c <= x0 + 7; ++c) {
      const double value = image.at<float>(r, c);
      sum += value;
      weighted += value * Eigen::Vector2d(c, r);
    }
  }
  return weighted / sum;
}

TEST(ImageUndistorter, MapsADistortedPointToItsPinholeProjection) {
  const ImageUndistorter undistorter(distortedCamera());
  const Camera& source = undistorter.sourceCamera();
  const Camera& pinhole = undistorter.camera();
  // Points whose pinhole projections spread from the centre to 20 px from the corners.
  std::vector<Eigen::Vector3d> points;
  for (const double u : {30.0, 180.0, 320.0, 470.0, 610.0}) {
    for (const double v : {25.0, 130.0, 240.0, 350.0, 455.0}) {
      points.push_back(pinhole.unproject(Eigen::Vector2d(u + 0.37, v - 0.21), 2.0));
    }
  }
  cv::Mat image(source.height(), source.width(), CV_32FC1, cv::Scalar(0));
  for (const Eigen::Vector3d& point : points) {
    Eigen::Vector2d distorted;
    ASSERT_TRUE(source.project(point, &distorted));
    ASSERT_TRUE(source.isInImage(distorted, 7.0));
    renderSpot(distorted, &image);
  }
  const cv::Mat undistorted = undistorter.undistort(image);
  for (const Eigen::Vector3d& point : points) {
    Eigen::Vector2d expected;
    ASSERT_TRUE(pinhole.project(point, &expected));
    EXPECT_LT((centroid(undistorted, expected) - expected).norm(), 0.5)
        << "at " << expected.transpose();
  }
}

TEST(ImageUndistorter, GivesThePinholeCameraAndMasksPixelsWithoutData) {
  const ImageUndistorter barrel(distortedCamera());
  EXPECT_FALSE(barrel.isIdentity());
  EXPECT_FALSE(barrel.camera().hasDistortion());
  EXPECT_TRUE(barrel.camera().K().isApprox(distortedCamera().K()));
  EXPECT_EQ(barrel.camera().width(), 640);
  EXPECT_EQ(barrel.camera().height(), 480);
  // Barrel distortion pulls every pinhole pixel inwards: the whole output has data (the rim of
  // the source is cropped instead).
  ASSERT_EQ(barrel.validMask().type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(barrel.validMask()), 640 * 480);

  CameraIntrinsics intrinsics = distortedCamera().intrinsics();
  intrinsics.k1 = 0.2;  // Pincushion: the corners of the pinhole image lie beyond the sensor.
  intrinsics.k2 = intrinsics.k3 = 0.0;
  const ImageUndistorter pincushion{Camera(intrinsics)};
  const cv::Mat& mask = pincushion.validMask();
  EXPECT_EQ(mask.at<std::uint8_t>(0, 0), 0);
  EXPECT_EQ(mask.at<std::uint8_t>(479, 639), 0);
  EXPECT_EQ(mask.at<std::uint8_t>(240, 320), 255);
}

TEST(ImageUndistorter, NoArtificialEdgesAlongTheBorderOfTheData) {
  CameraIntrinsics intrinsics = distortedCamera().intrinsics();
  intrinsics.k1 = 0.2;
  const ImageUndistorter undistorter{Camera(intrinsics)};
  ASSERT_LT(cv::countNonZero(undistorter.validMask()), 640 * 480);
  cv::Mat image(480, 640, CV_8UC3, cv::Scalar(40, 180, 90));
  const cv::Mat undistorted = undistorter.undistort(image);
  EXPECT_EQ(undistorted.type(), CV_8UC3);
  const EdgeImage edges = detectEdges(undistorted, EdgeDetectorOptions(), undistorter.validMask());
  EXPECT_EQ(cv::countNonZero(edges.edges), 0);
}

TEST(ImageUndistorter, IsTheIdentityWithoutDistortion) {
  const ImageUndistorter undistorter{Camera(CameraIntrinsics())};
  EXPECT_TRUE(undistorter.isIdentity());
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(7));
  const cv::Mat same = undistorter.undistort(image);
  EXPECT_EQ(same.data, image.data);
  EXPECT_EQ(cv::countNonZero(undistorter.validMask()), 640 * 480);
}

TEST(ImageUndistorter, BadOptionsAndImagesThrow) {
  ImageUndistorterOptions options;
  options.valid_margin_px = -1;
  EXPECT_THROW(ImageUndistorter(distortedCamera(), options), InvalidOptions);
  const ImageUndistorter undistorter(distortedCamera());
  EXPECT_THROW(undistorter.undistort(cv::Mat(480, 641, CV_8UC1)), CheckError);
}

}  // namespace
}  // namespace curvesfm
