#include "core/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "core/errors.h"

namespace curvesfm {
namespace {

// TUM RGB-D freiburg1 calibration: strong, realistic radial-tangential distortion.
CameraIntrinsics tumFreiburg1() {
  CameraIntrinsics c;
  c.fx = 517.306408;
  c.fy = 516.469215;
  c.cx = 318.643040;
  c.cy = 255.313989;
  c.k1 = 0.262383;
  c.k2 = -0.953104;
  c.p1 = -0.005358;
  c.p2 = 0.002628;
  c.k3 = 1.163314;
  return c;
}

CameraIntrinsics randomIntrinsics(std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  CameraIntrinsics c;
  c.fx = 500.0 + 200.0 * unit(rng);
  c.fy = c.fx * (1.0 + 0.05 * unit(rng));
  c.cx = 319.5 + 20.0 * unit(rng);
  c.cy = 239.5 + 20.0 * unit(rng);
  c.k1 = 0.3 * unit(rng);
  c.k2 = 0.1 * unit(rng);
  c.p1 = 1e-3 * unit(rng);
  c.p2 = 1e-3 * unit(rng);
  c.k3 = 0.05 * unit(rng);
  return c;
}

// A point in front of the camera whose normalized coordinates are inside a typical image.
Eigen::Vector3d randomPointInView(std::mt19937& rng) {
  std::uniform_real_distribution<double> lateral(-0.5, 0.5);
  std::uniform_real_distribution<double> depth(0.5, 10.0);
  const double z = depth(rng);
  return Eigen::Vector3d(lateral(rng) * z, lateral(rng) * z, z);
}

template <class F>
std::string invalidOptionsMessage(F&& f) {
  try {
    f();
  } catch (const InvalidOptions& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InvalidOptions";
  return "";
}

TEST(Camera, ProjectsPointOnAxisToPrincipalPoint) {
  const Camera camera(tumFreiburg1());
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera.project(Eigen::Vector3d(0.0, 0.0, 3.0), &pixel));
  EXPECT_DOUBLE_EQ(pixel.x(), camera.cx());
  EXPECT_DOUBLE_EQ(pixel.y(), camera.cy());
}

TEST(Camera, ProjectMatchesHandComputedValueWithDistortion) {
  CameraIntrinsics c;
  c.fx = 500.0;
  c.fy = 400.0;
  c.cx = 320.0;
  c.cy = 240.0;
  c.k1 = 0.1;
  c.k2 = 0.01;
  c.p1 = 0.001;
  c.p2 = 0.002;
  c.k3 = 0.001;
  const Camera camera(c);
  // x = 0.2, y = 0.1, r^2 = 0.05, radial = 1.005025125,
  // xd = 0.201005025 + 0.00004 + 0.00026, yd = 0.1005025125 + 0.00007 + 0.00008.
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera.project(Eigen::Vector3d(0.4, 0.2, 2.0), &pixel));
  EXPECT_NEAR(pixel.x(), 420.6525125, 1e-9);
  EXPECT_NEAR(pixel.y(), 280.261005, 1e-9);
}

TEST(Camera, ProjectJacobianMatchesCentralDifferences) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Camera camera(randomIntrinsics(rng));
    for (int sample = 0; sample < 20; ++sample) {
      const Eigen::Vector3d point = randomPointInView(rng);
      Eigen::Vector2d pixel;
      Matrix23d H;
      ASSERT_TRUE(camera.project(point, &pixel, &H));
      Matrix23d numerical;
      const double h = 1e-6 * point.z();
      for (int i = 0; i < 3; ++i) {
        Eigen::Vector2d plus;
        Eigen::Vector2d minus;
        ASSERT_TRUE(camera.project(point + h * Eigen::Vector3d::Unit(i), &plus));
        ASSERT_TRUE(camera.project(point - h * Eigen::Vector3d::Unit(i), &minus));
        numerical.col(i) = (plus - minus) / (2.0 * h);
      }
      EXPECT_LE((H - numerical).cwiseAbs().maxCoeff(), 1e-5 * (1.0 + H.norm()))
          << "trial " << trial << " point " << point.transpose() << "\nanalytic\n"
          << H << "\nnumerical\n"
          << numerical;
    }
  }
}

TEST(Camera, DistortJacobianMatchesCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-0.6, 0.6);
  for (int trial = 0; trial < 200; ++trial) {
    const Camera camera(randomIntrinsics(rng));
    const Eigen::Vector2d xn(coordinate(rng), coordinate(rng));
    Eigen::Matrix2d H;
    camera.distortNormalized(xn, &H);
    Eigen::Matrix2d numerical;
    const double h = 1e-6;
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector2d step = h * Eigen::Vector2d::Unit(i);
      numerical.col(i) =
          (camera.distortNormalized(xn + step) - camera.distortNormalized(xn - step)) / (2.0 * h);
    }
    EXPECT_LE((H - numerical).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
  }
}

TEST(Camera, UndistortInvertsDistort) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> coordinate(-0.6, 0.6);
  for (int trial = 0; trial < 500; ++trial) {
    const Camera camera(randomIntrinsics(rng));
    const Eigen::Vector2d xn(coordinate(rng), coordinate(rng));
    const Eigen::Vector2d recovered = camera.undistortNormalized(camera.distortNormalized(xn));
    EXPECT_LE((recovered - xn).norm(), 1e-10) << "trial " << trial << " xn " << xn.transpose();
  }
}

TEST(Camera, PixelToNormalizedInvertsProjectionOverWholeImage) {
  const Camera camera(tumFreiburg1());
  for (int v = 0; v < camera.height(); v += 16) {
    for (int u = 0; u < camera.width(); u += 16) {
      const Eigen::Vector2d pixel(u, v);
      const Eigen::Vector2d xn = camera.pixelToNormalized(pixel);
      Eigen::Vector2d reprojected;
      ASSERT_TRUE(camera.project(Eigen::Vector3d(xn.x(), xn.y(), 1.0), &reprojected));
      EXPECT_LE((reprojected - pixel).norm(), 1e-7) << "pixel " << pixel.transpose();
    }
  }
}

TEST(Camera, UnprojectInvertsProject) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 500; ++trial) {
    const Camera camera(randomIntrinsics(rng));
    const Eigen::Vector3d point = randomPointInView(rng);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(camera.project(point, &pixel));
    const Eigen::Vector3d recovered = camera.unproject(pixel, point.z());
    EXPECT_DOUBLE_EQ(recovered.z(), point.z());
    EXPECT_LE((recovered - point).norm(), 1e-9 * point.z()) << "trial " << trial;
  }
}

TEST(Camera, UndistortPixelGivesIdealPinholePixel) {
  const Camera camera(tumFreiburg1());
  const Eigen::Vector3d point(0.3, -0.2, 1.0);
  Eigen::Vector2d distorted;
  ASSERT_TRUE(camera.project(point, &distorted));
  const Eigen::Vector3d ideal = camera.K() * point;
  EXPECT_LE((camera.undistortPixel(distorted) - ideal.head<2>()).norm(), 1e-7);

  const Camera pinhole{CameraIntrinsics()};
  const Eigen::Vector2d pixel(12.25, 400.5);
  EXPECT_EQ(pinhole.undistortPixel(pixel), pixel);
}

TEST(Camera, UndistortStaysFiniteWhereModelFolds) {
  CameraIntrinsics c;
  c.k1 = -0.5;  // radial(r) = r (1 - 0.5 r^2) peaks at r = 0.816 and folds back beyond it.
  const Camera camera(c);
  const Eigen::Vector2d far_outside(5.0, 5.0);
  EXPECT_TRUE(camera.undistortNormalized(far_outside).allFinite());
}

TEST(Camera, ProjectRejectsPointsBehindOrOnCameraPlane) {
  const Camera camera(tumFreiburg1());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double z : {-1.0, 0.0, Camera::kMinDepth, nan}) {
    Eigen::Vector2d pixel(7.0, 7.0);
    Matrix23d H = Matrix23d::Constant(7.0);
    EXPECT_FALSE(camera.project(Eigen::Vector3d(0.1, 0.1, z), &pixel, &H)) << "z = " << z;
    EXPECT_TRUE(pixel.isZero()) << "z = " << z;
    EXPECT_TRUE(H.isZero()) << "z = " << z;
  }
  Eigen::Vector2d pixel;
  EXPECT_TRUE(camera.project(Eigen::Vector3d(0.0, 0.0, 2.0 * Camera::kMinDepth), &pixel));
}

TEST(Camera, IsInImageAcceptsPixelCentresFromZeroToSizeMinusOne) {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  const Camera camera(c);
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(0.0, 0.0)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(639.0, 479.0)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(-1e-9, 0.0)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(0.0, -1e-9)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(639.0 + 1e-9, 0.0)));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(0.0, 479.0 + 1e-9)));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(2.0, 2.0), 2.0));
  EXPECT_TRUE(camera.isInImage(Eigen::Vector2d(637.0, 477.0), 2.0));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(1.99, 2.0), 2.0));
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(637.01, 2.0), 2.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(camera.isInImage(Eigen::Vector2d(nan, 10.0)));
}

TEST(Camera, KAndDistortionFlagReflectIntrinsics) {
  const Camera camera(tumFreiburg1());
  Eigen::Matrix3d expected;
  expected << camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(), camera.cy(), 0.0, 0.0, 1.0;
  EXPECT_EQ(camera.K(), expected);
  EXPECT_TRUE(camera.hasDistortion());
  EXPECT_FALSE(Camera(CameraIntrinsics()).hasDistortion());
  CameraIntrinsics only_p2;
  only_p2.p2 = 1e-4;
  EXPECT_TRUE(Camera(only_p2).hasDistortion());
}

TEST(Camera, WithFocalScaleScalesTheFocalLengthsOnly) {
  const Camera camera(tumFreiburg1());
  const Camera scaled = camera.withFocalScale(1.05);
  EXPECT_DOUBLE_EQ(scaled.fx(), 1.05 * camera.fx());
  EXPECT_DOUBLE_EQ(scaled.fy(), 1.05 * camera.fy());
  EXPECT_EQ(scaled.cx(), camera.cx());
  EXPECT_EQ(scaled.cy(), camera.cy());
  EXPECT_EQ(scaled.intrinsics().k1, camera.intrinsics().k1);
  EXPECT_EQ(scaled.width(), camera.width());
}

TEST(Camera, InvalidIntrinsicsThrowInvalidOptionsNamingField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const auto messageFor = [](auto mutate) {
    CameraIntrinsics c;
    mutate(c);
    return invalidOptionsMessage([&] { Camera camera(c); });
  };
  EXPECT_EQ(messageFor([](CameraIntrinsics& c) { c.fx = 0.0; }),
            "InvalidOptions: CameraIntrinsics.fx = 0: must be > 0 and finite");
  EXPECT_NE(messageFor([](CameraIntrinsics& c) { c.fy = -2.0; }).find("CameraIntrinsics.fy = -2"),
            std::string::npos);
  EXPECT_NE(messageFor([&](CameraIntrinsics& c) { c.fx = inf; }).find("CameraIntrinsics.fx = inf"),
            std::string::npos);
  EXPECT_NE(messageFor([&](CameraIntrinsics& c) { c.cx = nan; }).find("CameraIntrinsics.cx = nan"),
            std::string::npos);
  EXPECT_NE(messageFor([&](CameraIntrinsics& c) { c.k3 = inf; }).find("CameraIntrinsics.k3 = inf"),
            std::string::npos);
  EXPECT_EQ(messageFor([](CameraIntrinsics& c) { c.width = 0; }),
            "InvalidOptions: CameraIntrinsics.width = 0: must be > 0");
  EXPECT_NE(messageFor([](CameraIntrinsics& c) { c.height = -3; }).find("CameraIntrinsics.height"),
            std::string::npos);
}

}  // namespace
}  // namespace curvesfm
