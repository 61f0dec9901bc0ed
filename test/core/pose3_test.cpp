#include "core/pose3.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/errors.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kConfigurations = 100;

// Central differences of f: R^N -> R^M at 0, one column per tangent coordinate.
template <int N, class F>
Eigen::MatrixXd numericalDerivative(F&& f, double step = 1e-6) {
  using Tangent = Eigen::Matrix<double, N, 1>;
  const Eigen::VectorXd f0 = f(Tangent::Zero());
  Eigen::MatrixXd jacobian(f0.size(), N);
  for (int k = 0; k < N; ++k) {
    const Tangent delta = Tangent::Unit(k) * step;
    jacobian.col(k) = (f(delta) - f(-delta)) / (2.0 * step);
  }
  return jacobian;
}

// Largest entry of |analytic - numerical|, relative to the Jacobian's scale (absolute below 1).
double jacobianError(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numerical) {
  const double scale = std::max(1.0, numerical.cwiseAbs().maxCoeff());
  return (analytic - numerical).cwiseAbs().maxCoeff() / scale;
}

Eigen::Quaterniond randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
}

Eigen::Vector3d randomVector(std::mt19937& rng, double half_width) {
  std::uniform_real_distribution<double> unit(-half_width, half_width);
  return Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
}

Pose3 randomPose(std::mt19937& rng) { return Pose3(randomRotation(rng), randomVector(rng, 5.0)); }

// Tangent vector with rotation angle uniform in [0, max_angle] and translation in a cube.
Vector6d randomTangent(std::mt19937& rng, double max_angle, double half_width) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, max_angle);
  Vector6d xi;
  xi.head<3>() = angle(rng) * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  xi.tail<3>() = randomVector(rng, half_width);
  return xi;
}

void expectPoseNear(const Pose3& actual, const Pose3& expected, double tolerance) {
  EXPECT_LE(actual.rotation().angularDistance(expected.rotation()), tolerance)
      << "rotation " << actual.rotation().coeffs().transpose() << " vs "
      << expected.rotation().coeffs().transpose();
  EXPECT_LE((actual.translation() - expected.translation()).norm(), tolerance)
      << "translation " << actual.translation().transpose() << " vs "
      << expected.translation().transpose();
}

TEST(Pose3, DefaultIsIdentity) {
  const Pose3 identity;
  const Eigen::Vector3d p(1.0, -2.0, 3.0);
  EXPECT_EQ(identity.transformPoint(p), p);
  EXPECT_EQ(identity.rotationMatrix(), Eigen::Matrix3d::Identity());
  EXPECT_EQ(identity.translation(), Eigen::Vector3d::Zero());
}

TEST(Pose3, ConstructorNormalisesQuaternionWithNonNegativeW) {
  const Pose3 pose(Eigen::Quaterniond(-2.0, 1.0, -1.0, 0.5), Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_NEAR(pose.rotation().norm(), 1.0, 1e-15);
  EXPECT_GE(pose.rotation().w(), 0.0);
  const Eigen::Quaterniond expected = Eigen::Quaterniond(2.0, -1.0, 1.0, -0.5).normalized();
  EXPECT_LE((pose.rotation().coeffs() - expected.coeffs()).norm(), 1e-15);
}

TEST(Pose3, ZeroQuaternionThrowsCheckError) {
  EXPECT_THROW(Pose3(Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0), Eigen::Vector3d::Zero()), CheckError);
  const double ambient[7] = {0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0};
  EXPECT_THROW(Pose3::fromAmbient(ambient), CheckError);
}

TEST(Pose3, MatrixConstructorAgreesWithQuaternionConstructor) {
  std::mt19937 rng(1);
  for (int i = 0; i < kConfigurations; ++i) {
    const Eigen::Quaterniond q = randomRotation(rng);
    const Eigen::Vector3d t = randomVector(rng, 5.0);
    expectPoseNear(Pose3(q.toRotationMatrix(), t), Pose3(q, t), 1e-14);
  }
}

TEST(Pose3, TransformPointMatchesRotationThenTranslation) {
  std::mt19937 rng(2);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    const Eigen::Vector3d p = randomVector(rng, 10.0);
    const Eigen::Vector3d expected = pose.rotationMatrix() * p + pose.translation();
    EXPECT_LE((pose.transformPoint(p) - expected).norm(), 1e-13);
    EXPECT_LE((pose * p - expected).norm(), 1e-13);
  }
}

TEST(Pose3, CompositionMatchesSuccessiveTransforms) {
  std::mt19937 rng(3);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 a_from_b = randomPose(rng);
    const Pose3 b_from_c = randomPose(rng);
    const Eigen::Vector3d p_c = randomVector(rng, 10.0);
    EXPECT_LE(((a_from_b * b_from_c) * p_c - a_from_b * (b_from_c * p_c)).norm(), 1e-12);
  }
}

TEST(Pose3, CompositionIsAssociative) {
  std::mt19937 rng(4);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 a = randomPose(rng);
    const Pose3 b = randomPose(rng);
    const Pose3 c = randomPose(rng);
    expectPoseNear((a * b) * c, a * (b * c), 1e-13);
  }
}

TEST(Pose3, InverseComposesToIdentity) {
  std::mt19937 rng(5);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    expectPoseNear(pose * pose.inverse(), Pose3(), 1e-14);
    expectPoseNear(pose.inverse() * pose, Pose3(), 1e-14);
    expectPoseNear(pose.inverse().inverse(), pose, 1e-14);
    const Eigen::Vector3d p = randomVector(rng, 10.0);
    EXPECT_LE((pose.inverse() * (pose * p) - p).norm(), 1e-13);
  }
}

TEST(Pose3, InverseOfProductIsReversedProductOfInverses) {
  std::mt19937 rng(6);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 a = randomPose(rng);
    const Pose3 b = randomPose(rng);
    expectPoseNear((a * b).inverse(), b.inverse() * a.inverse(), 1e-13);
  }
}

TEST(Pose3, InverseTranslationIsTranslationOfInverse) {
  std::mt19937 rng(7);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 cam_from_world = randomPose(rng);
    const Eigen::Vector3d centre = cam_from_world.inverseTranslation();
    EXPECT_LE((centre - cam_from_world.inverse().translation()).norm(), 1e-13);
    // The camera centre maps to the camera's origin.
    EXPECT_LE((cam_from_world * centre).norm(), 1e-13);
  }
}

TEST(Pose3, ExpOfPureTranslationIsThatTranslation) {
  Vector6d xi;
  xi << 0.0, 0.0, 0.0, 1.0, -2.0, 3.0;
  expectPoseNear(Pose3::exp(xi), Pose3(Eigen::Quaterniond::Identity(), xi.tail<3>()), 0.0);
}

TEST(Pose3, ExpMatchesEigenAngleAxisForRotation) {
  std::mt19937 rng(8);
  for (int i = 0; i < kConfigurations; ++i) {
    const Vector6d xi = randomTangent(rng, kPi, 5.0);
    const Eigen::Vector3d w = xi.head<3>();
    const Eigen::Quaterniond expected(Eigen::AngleAxisd(w.norm(), w.normalized()));
    EXPECT_LE(Pose3::exp(xi).rotation().angularDistance(expected), 1e-14);
  }
}

TEST(Pose3, LogInvertsExp) {
  std::mt19937 rng(9);
  for (int i = 0; i < kConfigurations; ++i) {
    const Vector6d xi = randomTangent(rng, kPi - 1e-3, 5.0);
    EXPECT_LE((Pose3::exp(xi).log() - xi).norm(), 1e-12) << "xi = " << xi.transpose();
  }
}

TEST(Pose3, LogInvertsExpForSmallAngles) {
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> exponent(-9.0, -3.0);
  for (int i = 0; i < kConfigurations; ++i) {
    Vector6d xi = randomTangent(rng, 1.0, 5.0);
    xi.head<3>() = xi.head<3>().normalized() * std::pow(10.0, exponent(rng));
    const Vector6d recovered = Pose3::exp(xi).log();
    EXPECT_LE((recovered.head<3>() - xi.head<3>()).norm(), 1e-10 * xi.head<3>().norm())
        << "xi = " << xi.transpose();
    EXPECT_LE((recovered.tail<3>() - xi.tail<3>()).norm(), 1e-13) << "xi = " << xi.transpose();
  }
}

TEST(Pose3, ExpInvertsLog) {
  std::mt19937 rng(11);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    expectPoseNear(Pose3::exp(pose.log()), pose, 1e-12);
  }
}

TEST(Pose3, RetractOfZeroIsIdentityMap) {
  std::mt19937 rng(12);
  const Pose3 pose = randomPose(rng);
  expectPoseNear(pose.retract(Vector6d::Zero()), pose, 0.0);
  EXPECT_EQ(pose.localCoordinates(pose), Vector6d::Zero());
}

TEST(Pose3, RetractAppliesARigidMotionOfTheTargetFrameOnTheLeft) {
  std::mt19937 rng(13);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    const Vector6d delta = randomTangent(rng, 1.0, 1.0);
    expectPoseNear(pose.retract(delta),
                   Pose3(so3::exp(delta.head<3>()), Eigen::Vector3d(delta.tail<3>())) * pose,
                   1e-14);
  }
}

// The optimiser's steps must not depend on where the world's origin lies: the same step taken
// from a pose expressed in a world moved rigidly is the same camera motion.
TEST(Pose3, RetractDoesNotDependOnTheSourceFrame) {
  std::mt19937 rng(16);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 cam_from_world = randomPose(rng);
    Pose3 world_from_moved = randomPose(rng);
    world_from_moved = Pose3(world_from_moved.rotation(), 100.0 * world_from_moved.translation());
    const Vector6d delta = randomTangent(rng, 1.0, 1.0);
    expectPoseNear((cam_from_world * world_from_moved).retract(delta),
                   cam_from_world.retract(delta) * world_from_moved, 1e-11);
  }
}

TEST(Pose3, RetractTurnsACameraAboutItsOwnCentre) {
  std::mt19937 rng(17);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 cam_from_world = randomPose(rng);
    const Vector6d turn =
        (Vector6d() << randomTangent(rng, 1.0, 0.0).head<3>(), 0, 0, 0).finished();
    EXPECT_LE(
        (cam_from_world.retract(turn).inverseTranslation() - cam_from_world.inverseTranslation())
            .norm(),
        1e-12);
  }
}

TEST(Pose3, RetractInvertsLocalCoordinates) {
  std::mt19937 rng(14);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 a = randomPose(rng);
    const Pose3 b = randomPose(rng);
    expectPoseNear(a.retract(a.localCoordinates(b)), b, 1e-12);
  }
}

TEST(Pose3, LocalCoordinatesInvertsRetract) {
  std::mt19937 rng(15);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    const Vector6d delta = randomTangent(rng, 2.5, 3.0);
    EXPECT_LE((pose.localCoordinates(pose.retract(delta)) - delta).norm(), 1e-12)
        << "delta = " << delta.transpose();
  }
}

TEST(Pose3, TransformPointJacobiansMatchCentralDifferences) {
  std::mt19937 rng(16);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    const Eigen::Vector3d p = randomVector(rng, 10.0);
    Matrix36d H_pose;
    Eigen::Matrix3d H_point;
    pose.transformPoint(p, &H_pose, &H_point);
    const Eigen::MatrixXd numerical_pose = numericalDerivative<6>(
        [&](const Vector6d& d) -> Eigen::VectorXd { return pose.retract(d).transformPoint(p); });
    const Eigen::MatrixXd numerical_point = numericalDerivative<3>(
        [&](const Eigen::Vector3d& d) -> Eigen::VectorXd { return pose.transformPoint(p + d); });
    EXPECT_LE(jacobianError(H_pose, numerical_pose), 1e-6) << "analytic:\n"
                                                           << H_pose << "\nnumerical:\n"
                                                           << numerical_pose;
    EXPECT_LE(jacobianError(H_point, numerical_point), 1e-6);
  }
}

TEST(Pose3, TransformPointJacobianArgumentsAreOptional) {
  const Pose3 pose(Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2), Eigen::Vector3d(1.0, 2.0, 3.0));
  const Eigen::Vector3d p(0.5, -1.0, 4.0);
  Matrix36d H_pose;
  Eigen::Matrix3d H_point;
  const Eigen::Vector3d expected = pose.transformPoint(p);
  EXPECT_EQ(pose.transformPoint(p, &H_pose, nullptr), expected);
  EXPECT_EQ(pose.transformPoint(p, nullptr, &H_point), expected);
  EXPECT_EQ(H_point, pose.rotationMatrix());
}

TEST(Pose3, InverseTranslationJacobianMatchesCentralDifferences) {
  std::mt19937 rng(17);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    Matrix36d H_pose;
    const Eigen::Vector3d centre = pose.inverseTranslation(&H_pose);
    EXPECT_LE((centre - pose.inverseTranslation()).norm(), 0.0);
    const Eigen::MatrixXd numerical = numericalDerivative<6>(
        [&](const Vector6d& d) -> Eigen::VectorXd { return pose.retract(d).inverseTranslation(); });
    EXPECT_LE(jacobianError(H_pose, numerical), 1e-6) << "analytic:\n"
                                                      << H_pose << "\nnumerical:\n"
                                                      << numerical;
  }
}

TEST(Pose3, LocalCoordinatesJacobiansMatchCentralDifferences) {
  std::mt19937 rng(18);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 a = randomPose(rng);
    // Relative rotations up to 3 rad; a step must not carry the angle across pi.
    const Pose3 b = a.retract(randomTangent(rng, 3.0, 5.0));
    Matrix6d H_this;
    Matrix6d H_other;
    const Vector6d value = a.localCoordinates(b, &H_this, &H_other);
    EXPECT_EQ(value, a.localCoordinates(b));
    const Eigen::MatrixXd numerical_this = numericalDerivative<6>(
        [&](const Vector6d& d) -> Eigen::VectorXd { return a.retract(d).localCoordinates(b); });
    const Eigen::MatrixXd numerical_other = numericalDerivative<6>(
        [&](const Vector6d& d) -> Eigen::VectorXd { return a.localCoordinates(b.retract(d)); });
    EXPECT_LE(jacobianError(H_this, numerical_this), 1e-6) << "analytic:\n"
                                                           << H_this << "\nnumerical:\n"
                                                           << numerical_this;
    EXPECT_LE(jacobianError(H_other, numerical_other), 1e-6) << "analytic:\n"
                                                             << H_other << "\nnumerical:\n"
                                                             << numerical_other;
  }
}

TEST(Pose3, LocalCoordinatesJacobiansAtCoincidentPoses) {
  std::mt19937 rng(19);
  const Pose3 pose = randomPose(rng);
  Matrix6d H_this;
  Matrix6d H_other;
  pose.localCoordinates(pose, &H_this, &H_other);
  EXPECT_LE((H_this + Matrix6d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((H_other - Matrix6d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Pose3, AmbientRoundTrip) {
  std::mt19937 rng(20);
  for (int i = 0; i < kConfigurations; ++i) {
    const Pose3 pose = randomPose(rng);
    double ambient[Pose3::kAmbientDim];
    pose.toAmbient(ambient);
    EXPECT_EQ(ambient[0], pose.rotation().x());
    EXPECT_EQ(ambient[1], pose.rotation().y());
    EXPECT_EQ(ambient[2], pose.rotation().z());
    EXPECT_EQ(ambient[3], pose.rotation().w());
    EXPECT_GE(ambient[3], 0.0);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(ambient[4 + k], pose.translation()[k]);
    expectPoseNear(Pose3::fromAmbient(ambient), pose, 1e-15);
  }
}

TEST(Pose3, AmbientFormIsUniqueForNegatedQuaternion) {
  std::mt19937 rng(21);
  for (int i = 0; i < kConfigurations; ++i) {
    const Eigen::Quaterniond q = randomRotation(rng);
    const Eigen::Vector3d t = randomVector(rng, 5.0);
    double plus[Pose3::kAmbientDim];
    double minus[Pose3::kAmbientDim];
    Pose3(q, t).toAmbient(plus);
    Pose3(Eigen::Quaterniond(-q.coeffs()), t).toAmbient(minus);
    for (int k = 0; k < Pose3::kAmbientDim; ++k) EXPECT_EQ(plus[k], minus[k]) << "k = " << k;
  }
}

TEST(Pose3, FromAmbientNormalisesQuaternion) {
  const double ambient[Pose3::kAmbientDim] = {0.0, 0.0, 2.0, 2.0, 1.0, 2.0, 3.0};
  const Pose3 pose = Pose3::fromAmbient(ambient);
  const Eigen::Quaterniond expected(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()));
  EXPECT_LE(pose.rotation().angularDistance(expected), 1e-15);
  EXPECT_NEAR(pose.rotation().norm(), 1.0, 1e-15);
}

// Camera centres are -R^T t: a camera turned away still has its centre where it stands.
TEST(Pose3, CameraCentreDistanceAndMeanStepUseTheCentres) {
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitY()));
  const auto at = [&](const Eigen::Vector3d& centre) {
    return Pose3(turned, -(turned.inverse() * centre));
  };
  const std::vector<Pose3> path = {at({0.0, 0.0, 0.0}), at({3.0, 4.0, 0.0}), at({3.0, 4.0, 1.0})};
  EXPECT_NEAR(cameraCentreDistance(path[1], path[0]), 5.0, 1e-12);
  EXPECT_NEAR(cameraCentreDistance(path[0], path[1]), 5.0, 1e-12);
  EXPECT_NEAR(meanCameraStep(path), 3.0, 1e-12);
  EXPECT_EQ(meanCameraStep({path[0]}), 0.0);
  EXPECT_EQ(meanCameraStep({}), 0.0);
}

}  // namespace
}  // namespace curvesfm
