#include "graph/ceres_manifolds.h"

#include <ceres/manifold_test_utils.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "core/so3.h"

namespace curvesfm {
namespace {

Eigen::VectorXd randomPose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd x(7);
  Pose3(so3::exp(Eigen::Vector3d(n(rng), n(rng), n(rng))),
        Eigen::Vector3d(n(rng), n(rng), n(rng)))
      .toAmbient(x.data());
  return x;
}

Eigen::VectorXd randomDirection(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::VectorXd x(3);
  Direction(Eigen::Vector3d(n(rng), n(rng), n(rng))).toAmbient(x.data());
  return x;
}

Eigen::VectorXd smallDelta(std::mt19937& rng, int size) {
  std::normal_distribution<double> n(0.0, 0.3);
  Eigen::VectorXd delta(size);
  for (int i = 0; i < size; ++i) delta[i] = n(rng);
  return delta;
}

TEST(PoseManifold, SatisfiesCeresInvariants) {
  std::mt19937 rng(1);
  const PoseManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd x = randomPose(rng);
    const Eigen::VectorXd y = randomPose(rng);
    const Eigen::VectorXd delta = smallDelta(rng, 6);
    using namespace ceres;  // the Ceres macro names its matchers unqualified
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-8);
  }
}

TEST(DirectionManifold, SatisfiesCeresInvariants) {
  std::mt19937 rng(2);
  const DirectionManifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::VectorXd x = randomDirection(rng);
    // Minus is only an inverse of Plus within pi of x: keep y in the same hemisphere.
    Eigen::VectorXd y = randomDirection(rng);
    if (x.dot(y) < 0) y = -y;
    const Eigen::VectorXd delta = smallDelta(rng, 2);
    using namespace ceres;  // the Ceres macro names its matchers unqualified
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-8);
  }
}

TEST(PoseManifold, PlusIsPose3Retract) {
  std::mt19937 rng(3);
  const Eigen::VectorXd x = randomPose(rng);
  const Eigen::VectorXd delta = smallDelta(rng, 6);
  Eigen::VectorXd plus(7);
  PoseManifold().Plus(x.data(), delta.data(), plus.data());
  const Pose3 expected = Pose3::fromAmbient(x.data()).retract(delta);
  EXPECT_TRUE(Pose3::fromAmbient(plus.data()).translation().isApprox(expected.translation()));
  EXPECT_TRUE(Pose3::fromAmbient(plus.data()).rotation().isApprox(expected.rotation()));
}

TEST(LiftToAmbient, TimesPlusJacobianGivesTheTangentJacobian) {
  std::mt19937 rng(4);
  const int rows = 5;
  for (VariableType type : {VariableType::kPose3, VariableType::kDirection,
                            VariableType::kPoint3, VariableType::kScalar}) {
    const int n = ambientDim(type), k = tangentDim(type);
    Eigen::VectorXd x = type == VariableType::kPose3        ? randomPose(rng)
                        : type == VariableType::kDirection  ? randomDirection(rng)
                                                            : smallDelta(rng, n);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const RowMajor tangent = RowMajor::Random(rows, k);
    RowMajor ambient(rows, n);
    liftToAmbient(type, x.data(), tangent.data(), rows, ambient.data());
    RowMajor plus_jacobian = RowMajor::Identity(n, k);
    if (const ceres::Manifold* manifold = manifoldFor(type)) {
      manifold->PlusJacobian(x.data(), plus_jacobian.data());
    }
    EXPECT_LT((ambient * plus_jacobian - tangent).cwiseAbs().maxCoeff(), 1e-12)
        << toString(type);
  }
}

}  // namespace
}  // namespace curvesfm
