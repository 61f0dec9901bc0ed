#include "factors/pose_prior_factor.h"

#include <gtest/gtest.h>

#include <random>

#include "core/so3.h"
#include "test/support/numerical_jacobian.h"
#include "test/support/random_geometry.h"

namespace curvesfm {
namespace {

using testing::randomPose;

TEST(PosePriorFactor, ZeroAtThePriorAndHandComputedOffset) {
  const Pose3 prior(so3::exp(Eigen::Vector3d(0.1, 0.2, -0.3)), Eigen::Vector3d(1, 2, 3));
  const PosePriorFactor factor(poseKey(0), prior, NoiseModel{});
  Values values;
  values.insert(poseKey(0), prior);
  EXPECT_LT(factor.unwhitenedError(values).norm(), 1e-12);
  Vector6d delta;
  delta << 0.01, -0.02, 0.03, 0.5, -0.25, 0.125;
  values.update(poseKey(0), prior.retract(delta));
  EXPECT_LT((factor.unwhitenedError(values) - delta).norm(), 1e-12);
}

TEST(PosePriorFactor, JacobianMatchesNumerical) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const PosePriorFactor factor(poseKey(0), randomPose(rng), NoiseModel{});
    Values values;
    values.insert(poseKey(0), randomPose(rng));
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
  }
}

TEST(CameraPriorFactor, MeasuresRotationAndCentreOffsetsInSigmas) {
  const Pose3 prior(so3::exp(Eigen::Vector3d(0.1, 0.2, -0.3)), Eigen::Vector3d(1, 2, 3));
  const CameraPriorFactor factor(poseKey(0), prior, 0.5, 2.0);
  Values values;
  values.insert(poseKey(0), prior);
  EXPECT_LT(factor.unwhitenedError(values).norm(), 1e-12);
  // Turned about its own centre by 0.05 rad: only the rotation rows, 0.05 / 0.5 each.
  const Eigen::Vector3d turn(0.05, 0, 0);
  const Eigen::Quaterniond turned = so3::exp(turn) * prior.rotation();
  const Pose3 rotated(turned, -(turned * prior.inverseTranslation()));
  values.update(poseKey(0), rotated);
  Vector6d expected;
  expected << 0.1, 0, 0, 0, 0, 0;
  EXPECT_LT((factor.unwhitenedError(values) - expected).norm(), 1e-12);
  // Moved by (1, -2, 4) in world without turning: only the centre rows, in units of 2.
  const Pose3 moved(prior.rotation(),
                    -(prior.rotation() * (prior.inverseTranslation() + Eigen::Vector3d(1, -2, 4))));
  values.update(poseKey(0), moved);
  expected << 0, 0, 0, 0.5, -1, 2;
  EXPECT_LT((factor.unwhitenedError(values) - expected).norm(), 1e-12);
  EXPECT_THROW(CameraPriorFactor(poseKey(0), prior, 0.0, 1.0), CheckError);
  EXPECT_THROW(CameraPriorFactor(poseKey(0), prior, 1.0, -1.0), CheckError);
}

TEST(CameraPriorFactor, JacobianMatchesNumerical) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    const CameraPriorFactor factor(poseKey(0), randomPose(rng), 0.3, 1.5);
    Values values;
    values.insert(poseKey(0), randomPose(rng));
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
  }
}

TEST(CameraDistanceFactor, MeasuresDistanceBetweenCentres) {
  // Centres at the origin and at (3, 4, 0): distance 5.
  const Pose3 a;
  const Pose3 b = Pose3(so3::exp(Eigen::Vector3d(0.2, 0.1, 0)), Eigen::Vector3d(3, 4, 0)).inverse();
  Values values;
  values.insert(poseKey(0), a);
  values.insert(poseKey(1), b);
  const CameraDistanceFactor factor(poseKey(0), poseKey(1), 4.5, NoiseModel{});
  EXPECT_NEAR(factor.unwhitenedError(values)[0], 0.5, 1e-12);
  EXPECT_THROW(CameraDistanceFactor(poseKey(0), poseKey(1), 0.0, NoiseModel{}), CheckError);
}

TEST(CameraDistanceFactor, JacobiansMatchNumerical) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 50; ++trial) {
    const CameraDistanceFactor factor(poseKey(0), poseKey(1), 1.0, NoiseModel{});
    Values values;
    values.insert(poseKey(0), randomPose(rng));
    values.insert(poseKey(1), randomPose(rng));
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
  }
}

TEST(CameraDistanceFactor, CoincidentCentresGiveFiniteErrorAndZeroJacobians) {
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(poseKey(1), Pose3(so3::exp(Eigen::Vector3d(0.3, 0, 0)), Eigen::Vector3d::Zero()));
  const Linearization linear =
      CameraDistanceFactor(poseKey(0), poseKey(1), 2.0, NoiseModel{}).linearize(values);
  EXPECT_DOUBLE_EQ(linear.error[0], -2.0);
  EXPECT_TRUE(linear.jacobians[0].isZero());
  EXPECT_TRUE(linear.jacobians[1].isZero());
}

}  // namespace
}  // namespace curvesfm
