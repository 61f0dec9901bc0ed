#include "core/so3.h"

#include <gtest/gtest.h>

#include "test/support/numerical_jacobian.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace curvesfm {
namespace {

using testing::numericalDerivative;
using testing::randomUnitVector;

constexpr double kPi = 3.14159265358979323846;

// Rotation vector with angle drawn uniformly from [min_angle, max_angle].
Eigen::Vector3d randomRotationVector(std::mt19937& rng, double min_angle, double max_angle) {
  std::uniform_real_distribution<double> angle(min_angle, max_angle);
  return angle(rng) * randomUnitVector(rng);
}

// Rotation vector with angle log-uniform in [10^min_exponent, 10^max_exponent].
Eigen::Vector3d randomTinyRotationVector(std::mt19937& rng, double min_exponent,
                                         double max_exponent) {
  std::uniform_real_distribution<double> exponent(min_exponent, max_exponent);
  return std::pow(10.0, exponent(rng)) * randomUnitVector(rng);
}

// Angles that stress every branch: zero, tiny, both sides of the small-angle switch, ordinary,
// and close to pi.
std::vector<Eigen::Vector3d> representativeRotationVectors(std::mt19937& rng) {
  std::vector<Eigen::Vector3d> result;
  result.push_back(Eigen::Vector3d::Zero());
  for (int i = 0; i < 20; ++i) result.push_back(randomTinyRotationVector(rng, -9.0, -4.0));
  for (const double angle :
       {1e-5 * (1.0 - 1e-6), 1e-5 * (1.0 + 1e-6), 2e-5 * (1.0 - 1e-6), 2e-5 * (1.0 + 1e-6)}) {
    result.push_back(angle * randomUnitVector(rng));
  }
  for (int i = 0; i < 30; ++i) result.push_back(randomRotationVector(rng, 1e-3, 3.0));
  for (const double angle : {3.0, 3.1, 3.14, kPi - 1e-6}) {
    result.push_back(angle * randomUnitVector(rng));
  }
  return result;
}

TEST(So3, HatMatchesCrossProduct) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(-5.0, 5.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d w(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d x(unit(rng), unit(rng), unit(rng));
    EXPECT_LE((so3::hat(w) * x - w.cross(x)).norm(), 1e-12) << "w = " << w.transpose();
    EXPECT_LE((so3::hat(w) + so3::hat(w).transpose()).norm(), 0.0);
  }
}

TEST(So3, ExpOfZeroIsIdentity) {
  const Eigen::Quaterniond q = so3::exp(Eigen::Vector3d::Zero());
  EXPECT_EQ(q.w(), 1.0);
  EXPECT_EQ(q.vec().norm(), 0.0);
  EXPECT_EQ(so3::log(Eigen::Quaterniond::Identity()).norm(), 0.0);
}

TEST(So3, ExpMatchesEigenAngleAxis) {
  std::mt19937 rng(2);
  for (const Eigen::Vector3d& w : representativeRotationVectors(rng)) {
    const double angle = w.norm();
    const Eigen::Vector3d axis =
        angle > 0.0 ? Eigen::Vector3d(w / angle) : Eigen::Vector3d::UnitX();
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    const Eigen::Quaterniond q = so3::exp(w);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15) << "w = " << w.transpose();
    EXPECT_LE((q.toRotationMatrix() - expected).cwiseAbs().maxCoeff(), 1e-14)
        << "w = " << w.transpose();
  }
}

TEST(So3, LogInvertsExpForRandomAngles) {
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d w = randomRotationVector(rng, 1e-4, kPi - 1e-3);
    EXPECT_LE((so3::log(so3::exp(w)) - w).norm(), 1e-13) << "w = " << w.transpose();
  }
}

TEST(So3, LogInvertsExpForTinyAngles) {
  std::mt19937 rng(4);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d w = randomTinyRotationVector(rng, -9.0, -4.0);
    // Relative: tiny rotation vectors must keep their full precision.
    EXPECT_LE((so3::log(so3::exp(w)) - w).norm(), 1e-13 * w.norm())
        << "w = " << w.transpose() << ", angle = " << w.norm();
  }
}

TEST(So3, LogIsAccurateJustBelowItsSmallAngleSwitch) {
  // log switches to a series where |q.vec()| = sin(angle/2) < 1e-5, i.e. angle < 2e-5.
  // theta / sin(theta/2) = 2 + theta^2/12 + O(theta^4), whereas 2 / cos(theta/2) = 2 + theta^2/4:
  // the relative error of that branch is theta^2/12, 3.3e-11 at theta = 2e-5.
  const Eigen::Vector3d w(1.9e-5, 0.0, 0.0);
  const Eigen::Vector3d recovered = so3::log(so3::exp(w));
  EXPECT_NEAR(recovered.x() / w.x() - 1.0, 0.0, 1e-14) << "log(exp(w)).x() = " << recovered.x();
}

TEST(So3, LogReturnsAngleInZeroToPiNearPi) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> exponent(-9.0, -1.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d axis = randomUnitVector(rng);
    const double offset = std::pow(10.0, exponent(rng));
    // Just below pi: log recovers w itself.
    const Eigen::Vector3d below = (kPi - offset) * axis;
    const Eigen::Vector3d log_below = so3::log(so3::exp(below));
    EXPECT_LE(log_below.norm(), kPi);
    EXPECT_LE((log_below - below).norm(), 1e-12) << "angle = pi - " << offset;
    // Just above pi: the same rotation is reached by the short way round, angle 2 pi - |w|.
    const Eigen::Vector3d above = (kPi + offset) * axis;
    const Eigen::Vector3d log_above = so3::log(so3::exp(above));
    EXPECT_LE(log_above.norm(), kPi);
    EXPECT_LE((log_above - (-(kPi - offset) * axis)).norm(), 1e-12) << "angle = pi + " << offset;
    EXPECT_LE(so3::exp(log_above).angularDistance(so3::exp(above)), 1e-12);
  }
}

TEST(So3, LogOfNegatedQuaternionIsUnchanged) {
  std::mt19937 rng(6);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Quaterniond q = so3::exp(randomRotationVector(rng, 0.0, kPi - 1e-3));
    const Eigen::Quaterniond minus_q(-q.coeffs());
    EXPECT_LE((so3::log(minus_q) - so3::log(q)).norm(), 1e-14);
  }
}

TEST(So3, ExpInvertsLogForRandomRotations) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d w = so3::log(q);
    EXPECT_LE(w.norm(), kPi);
    EXPECT_LE(so3::exp(w).angularDistance(q), 1e-13);
  }
}

TEST(So3, LeftJacobianMatchesCentralDifferences) {
  // exp(w + dw) ~= exp(Jl(w) dw) exp(w)  <=>  Jl(w) = d log(exp(w + dw) exp(w)^-1) / d dw at 0.
  std::mt19937 rng(8);
  for (const Eigen::Vector3d& w : representativeRotationVectors(rng)) {
    const Eigen::Quaterniond exp_w_inv = so3::exp(w).conjugate();
    const Eigen::Matrix3d numerical = numericalDerivative<3>(
        [&](const Eigen::Vector3d& dw) { return so3::log(so3::exp(w + dw) * exp_w_inv); });
    EXPECT_LE((so3::leftJacobian(w) - numerical).cwiseAbs().maxCoeff(), 1e-6)
        << "w = " << w.transpose() << ", angle = " << w.norm() << "\nanalytic:\n"
        << so3::leftJacobian(w) << "\nnumerical:\n"
        << numerical;
  }
}

TEST(So3, LeftJacobianIsIdentityAtZero) {
  EXPECT_EQ(so3::leftJacobian(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  EXPECT_EQ(so3::leftJacobianInverse(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
  EXPECT_EQ(so3::rightJacobianInverse(Eigen::Vector3d::Zero()), Eigen::Matrix3d::Identity());
}

TEST(So3, JacobiansAreContinuousAcrossTheSmallAngleSwitch) {
  std::mt19937 rng(9);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d axis = randomUnitVector(rng);
    const Eigen::Vector3d below = 1e-5 * (1.0 - 1e-9) * axis;
    const Eigen::Vector3d above = 1e-5 * (1.0 + 1e-9) * axis;
    EXPECT_LE((so3::leftJacobian(below) - so3::leftJacobian(above)).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE(
        (so3::leftJacobianInverse(below) - so3::leftJacobianInverse(above)).cwiseAbs().maxCoeff(),
        1e-12);
  }
}

TEST(So3, LeftJacobianInverseInvertsLeftJacobian) {
  std::mt19937 rng(10);
  std::vector<Eigen::Vector3d> samples = representativeRotationVectors(rng);
  for (const double angle : {1e-12, 1e-9, 1e-7, 1e-4, 3.1, kPi - 1e-9, kPi}) {
    samples.push_back(angle * randomUnitVector(rng));
  }
  for (const Eigen::Vector3d& w : samples) {
    const Eigen::Matrix3d product = so3::leftJacobianInverse(w) * so3::leftJacobian(w);
    EXPECT_LE((product - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-13)
        << "w = " << w.transpose() << ", angle = " << w.norm();
    const Eigen::Matrix3d product_right = so3::leftJacobian(w) * so3::leftJacobianInverse(w);
    EXPECT_LE((product_right - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-13)
        << "w = " << w.transpose() << ", angle = " << w.norm();
  }
}

TEST(So3, LeftJacobianInverseMatchesCentralDifferences) {
  // log(exp(d) exp(w)) ~= w + JlInv(w) d.
  std::mt19937 rng(11);
  for (const Eigen::Vector3d& w : representativeRotationVectors(rng)) {
    // A step across pi would make log wrap to the other side.
    if (w.norm() > kPi - 1e-3) continue;
    const Eigen::Quaterniond exp_w = so3::exp(w);
    const Eigen::Matrix3d numerical = numericalDerivative<3>(
        [&](const Eigen::Vector3d& d) { return so3::log(so3::exp(d) * exp_w); });
    const double scale = std::max(1.0, numerical.cwiseAbs().maxCoeff());
    EXPECT_LE((so3::leftJacobianInverse(w) - numerical).cwiseAbs().maxCoeff(), 1e-6 * scale)
        << "w = " << w.transpose() << ", angle = " << w.norm();
  }
}

TEST(So3, RightJacobianInverseMatchesCentralDifferences) {
  // log(exp(w) exp(d)) ~= w + JrInv(w) d.
  std::mt19937 rng(12);
  for (const Eigen::Vector3d& w : representativeRotationVectors(rng)) {
    // A step across pi would make log wrap to the other side.
    if (w.norm() > kPi - 1e-3) continue;
    const Eigen::Quaterniond exp_w = so3::exp(w);
    const Eigen::Matrix3d numerical = numericalDerivative<3>(
        [&](const Eigen::Vector3d& d) { return so3::log(exp_w * so3::exp(d)); });
    const double scale = std::max(1.0, numerical.cwiseAbs().maxCoeff());
    EXPECT_LE((so3::rightJacobianInverse(w) - numerical).cwiseAbs().maxCoeff(), 1e-6 * scale)
        << "w = " << w.transpose() << ", angle = " << w.norm();
  }
}

TEST(So3, RightJacobianInverseIsLeftJacobianInverseOfNegatedVector) {
  std::mt19937 rng(13);
  for (const Eigen::Vector3d& w : representativeRotationVectors(rng)) {
    EXPECT_LE((so3::rightJacobianInverse(w) - so3::leftJacobianInverse(w).transpose())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-14)
        << "w = " << w.transpose();
  }
}

}  // namespace
}  // namespace curvesfm
