#include "factors/point_reprojection_factor.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <random>

#include "core/so3.h"
#include "graph/ceres_cost_function.h"
#include "graph/ceres_manifolds.h"
#include "test/support/ceres_checks.h"
#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

std::shared_ptr<const Camera> distortedCamera() {
  return std::make_shared<const Camera>(
      CameraIntrinsics{520.0, 515.0, 320.5, 240.5, -0.12, 0.05, 1e-3, -2e-3, 0.01, 640, 480});
}

// A pose and a point in front of it, at random.
Values randomConfiguration(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Pose3 cam_from_world(so3::exp(Eigen::Vector3d(n(rng), n(rng), n(rng))),
                             Eigen::Vector3d(n(rng), n(rng), n(rng)));
  const Eigen::Vector3d point_in_cam(0.3 * n(rng), 0.3 * n(rng), 2.0 + std::abs(n(rng)));
  Values values;
  values.insert(poseKey(0), cam_from_world);
  values.insert(pointKey(0), cam_from_world.inverse() * point_in_cam);
  return values;
}

PointReprojectionFactor factorAt(const Eigen::Vector2d& measured) {
  return PointReprojectionFactor(poseKey(0), pointKey(0), measured, distortedCamera(),
                                 NoiseModel{});
}

TEST(PointReprojectionFactor, ZeroErrorAtTheTrueProjection) {
  std::mt19937 rng(1);
  const Values values = randomConfiguration(rng);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(distortedCamera()->project(
      values.at<Pose3>(poseKey(0)) * values.at<Eigen::Vector3d>(pointKey(0)), &pixel));
  EXPECT_LT(factorAt(pixel).unwhitenedError(values).norm(), 1e-12);
}

TEST(PointReprojectionFactor, HandComputedValueWithoutDistortion) {
  // Identity pose, point (0.2, -0.1, 2): pixel = (fx * 0.1 + cx, fy * -0.05 + cy).
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(pointKey(0), Eigen::Vector3d(0.2, -0.1, 2.0));
  const auto pinhole =
      std::make_shared<const Camera>(CameraIntrinsics{500, 400, 320, 240, 0, 0, 0, 0, 0, 640, 480});
  const PointReprojectionFactor factor(poseKey(0), pointKey(0), Eigen::Vector2d(360, 225), pinhole,
                                       NoiseModel{});
  const Eigen::VectorXd error = factor.unwhitenedError(values);
  EXPECT_NEAR(error[0], (500 * 0.1 + 320) - 360, 1e-12);
  EXPECT_NEAR(error[1], (400 * -0.05 + 240) - 225, 1e-12);
}

TEST(PointReprojectionFactor, JacobiansMatchNumericalAtRandomConfigurations) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 100; ++trial) {
    const Values values = randomConfiguration(rng);
    testing::expectJacobiansMatchNumerical(factorAt(Eigen::Vector2d(300, 200)), values, 1e-5);
  }
}

TEST(PointReprojectionFactor, CeresAdapterPassesGradientChecker) {
  std::mt19937 rng(3);
  const auto factor = std::make_shared<const PointReprojectionFactor>(factorAt({310, 250}));
  FactorCostFunction cost(factor);
  const std::vector<const ceres::Manifold*> manifolds = {manifoldFor(VariableType::kPose3),
                                                         nullptr};
  ceres::NumericDiffOptions numeric_options;
  // Ridders starts at 1e-2 of each parameter by default: too coarse for a projection with
  // unit-quaternion inputs, it stops before it converges.
  numeric_options.ridders_relative_initial_step_size = 1e-3;
  ceres::GradientChecker checker(&cost, &manifolds, numeric_options);
  for (int trial = 0; trial < 20; ++trial) {
    testing::expectProbeAgrees(
        checker, testing::AmbientBlocks(*factor, randomConfiguration(rng)), 1e-6);
  }
}

TEST(PointReprojectionFactor, PointBehindCameraGivesCappedErrorAndZeroJacobians) {
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(pointKey(0), Eigen::Vector3d(0.1, 0.2, -1.0));
  const Linearization linear = factorAt({320, 240}).linearize(values);
  EXPECT_TRUE(linear.error.allFinite());
  EXPECT_DOUBLE_EQ(linear.error[0], PointReprojectionFactor::kBehindCameraError);
  EXPECT_TRUE(linear.jacobians[0].isZero());
  EXPECT_TRUE(linear.jacobians[1].isZero());
  // On the camera plane: finite too.
  values.update(pointKey(0), Eigen::Vector3d(0.1, 0.2, 0.0));
  EXPECT_TRUE(factorAt({320, 240}).linearize(values).error.allFinite());
}

FocalPointReprojectionFactor focalFactorAt(const Eigen::Vector2d& measured) {
  return FocalPointReprojectionFactor(poseKey(0), pointKey(0), focalScaleKey(), measured,
                                      distortedCamera(), NoiseModel{});
}

Values withFocalScale(Values values, double scale) {
  values.insert(focalScaleKey(), scale);
  return values;
}

TEST(FocalPointReprojectionFactor, AtScaleOneIsThePlainFactor) {
  std::mt19937 rng(4);
  const Values values = randomConfiguration(rng);
  const Eigen::VectorXd plain = factorAt({300, 200}).unwhitenedError(values);
  const Eigen::VectorXd focal =
      focalFactorAt({300, 200}).unwhitenedError(withFocalScale(values, 1.0));
  EXPECT_LT((plain - focal).norm(), 1e-12);
}

TEST(FocalPointReprojectionFactor, IsTheCameraWithScaledFocalLengths) {
  std::mt19937 rng(5);
  const Values values = randomConfiguration(rng);
  CameraIntrinsics scaled = distortedCamera()->intrinsics();
  scaled.fx *= 1.07;
  scaled.fy *= 1.07;
  const PointReprojectionFactor reference(poseKey(0), pointKey(0), {300, 200},
                                          std::make_shared<const Camera>(scaled), NoiseModel{});
  const Eigen::VectorXd expected = reference.unwhitenedError(values);
  const Eigen::VectorXd focal =
      focalFactorAt({300, 200}).unwhitenedError(withFocalScale(values, 1.07));
  EXPECT_LT((expected - focal).norm(), 1e-9);
}

TEST(FocalPointReprojectionFactor, JacobiansMatchNumericalAtRandomConfigurations) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> scale(0.8, 1.2);
  for (int trial = 0; trial < 100; ++trial) {
    const Values values = withFocalScale(randomConfiguration(rng), scale(rng));
    testing::expectJacobiansMatchNumerical(focalFactorAt({300, 200}), values, 1e-5);
  }
}

TEST(FocalPointReprojectionFactor, CeresAdapterPassesGradientChecker) {
  std::mt19937 rng(7);
  const auto factor =
      std::make_shared<const FocalPointReprojectionFactor>(focalFactorAt({310, 250}));
  FactorCostFunction cost(factor);
  const std::vector<const ceres::Manifold*> manifolds = {manifoldFor(VariableType::kPose3), nullptr,
                                                         nullptr};
  ceres::NumericDiffOptions numeric_options;
  numeric_options.ridders_relative_initial_step_size = 1e-3;  // As the plain factor's check.
  ceres::GradientChecker checker(&cost, &manifolds, numeric_options);
  for (int trial = 0; trial < 20; ++trial) {
    testing::expectProbeAgrees(
        checker, testing::AmbientBlocks(*factor, withFocalScale(randomConfiguration(rng), 1.04)),
        1e-6);
  }
}

TEST(FocalPointReprojectionFactor, PointBehindCameraGivesCappedErrorAndZeroJacobians) {
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(pointKey(0), Eigen::Vector3d(0.1, 0.2, -1.0));
  const Linearization linear = focalFactorAt({320, 240}).linearize(withFocalScale(values, 1.1));
  EXPECT_DOUBLE_EQ(linear.error[0], PointReprojectionFactor::kBehindCameraError);
  for (const Eigen::MatrixXd& jacobian : linear.jacobians) EXPECT_TRUE(jacobian.isZero());
}

}  // namespace
}  // namespace curvesfm
