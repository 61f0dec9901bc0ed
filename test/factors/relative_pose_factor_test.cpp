#include "factors/relative_pose_factor.h"

#include <gtest/gtest.h>

#include <random>

#include "core/check.h"
#include "core/so3.h"
#include "test/support/numerical_jacobian.h"
#include "test/support/random_geometry.h"

namespace curvesfm {
namespace {

using testing::randomPose;

TEST(RelativePoseFactor, ZeroAtTheMeasuredMotionWhereverThePairIs) {
  std::mt19937 rng(3);
  const Pose3 cam_j_from_cam_i = randomPose(rng);
  const RelativePoseFactor factor(poseKey(0), poseKey(1), cam_j_from_cam_i, 0.01, 0.002);
  for (int trial = 0; trial < 5; ++trial) {
    // Moving both poses by the same world transform keeps their relative motion.
    const Pose3 cam_i_from_world = randomPose(rng);
    Values values;
    values.insert(poseKey(0), cam_i_from_world);
    values.insert(poseKey(1), cam_j_from_cam_i * cam_i_from_world);
    EXPECT_LT(factor.unwhitenedError(values).norm(), 1e-9);
  }
}

TEST(RelativePoseFactor, WhitensRotationAndTranslationBySeparateSigmas) {
  const Pose3 measured(so3::exp(Eigen::Vector3d(0.1, -0.2, 0.05)), Eigen::Vector3d(0.3, 0, 0));
  Vector6d delta;
  delta << 0.002, -0.001, 0.003, 0.01, -0.02, 0.005;
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(poseKey(1), measured.retract(delta));
  const RelativePoseFactor factor(poseKey(0), poseKey(1), measured, 0.001, 0.01);
  Vector6d expected;
  expected << 2.0, -1.0, 3.0, 1.0, -2.0, 0.5;
  EXPECT_LT((factor.unwhitenedError(values) - expected).norm(), 1e-9);
}

TEST(RelativePoseFactor, JacobiansMatchNumerical) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    const RelativePoseFactor factor(poseKey(0), poseKey(1), randomPose(rng), 0.5, 2.0);
    Values values;
    values.insert(poseKey(0), randomPose(rng));
    values.insert(poseKey(1), randomPose(rng));
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
  }
}

TEST(RelativePoseFactor, RejectsNonPositiveSigmas) {
  EXPECT_THROW(RelativePoseFactor(poseKey(0), poseKey(1), Pose3(), 0.0, 1.0), CheckError);
  EXPECT_THROW(RelativePoseFactor(poseKey(0), poseKey(1), Pose3(), 1.0, -1.0), CheckError);
}

}  // namespace
}  // namespace curvesfm
