#include "core/direction.h"

#include <gtest/gtest.h>

#include "test/support/numerical_jacobian.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

using testing::numericalDerivative;
using testing::randomUnitVector;

constexpr double kPi = 3.14159265358979323846;

// Tangent vector with norm uniform in [0, max_norm].
Eigen::Vector2d randomTangent(std::mt19937& rng, double max_norm) {
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  std::uniform_real_distribution<double> norm(0.0, max_norm);
  const double phi = angle(rng);
  return norm(rng) * Eigen::Vector2d(std::cos(phi), std::sin(phi));
}

// Random directions plus the axis-aligned ones, near-axis ones and ties between axes, where the
// choice of the helper axis in basis() switches.
std::vector<Direction> testDirections(std::mt19937& rng) {
  std::vector<Direction> result;
  for (int axis = 0; axis < 3; ++axis) {
    result.emplace_back(Eigen::Vector3d::Unit(axis));
    result.emplace_back(-Eigen::Vector3d::Unit(axis));
    result.emplace_back(Eigen::Vector3d::Unit(axis) + 1e-9 * Eigen::Vector3d::Ones());
  }
  result.emplace_back(Eigen::Vector3d(1.0, 1.0, 1.0));
  result.emplace_back(Eigen::Vector3d(-1.0, 1.0, -1.0));
  result.emplace_back(Eigen::Vector3d(1.0, 1.0, 0.0));
  result.emplace_back(Eigen::Vector3d(0.0, -1.0, 1.0));
  for (int i = 0; i < 50; ++i) result.emplace_back(randomUnitVector(rng));
  return result;
}

TEST(Direction, DefaultIsPlusZ) { EXPECT_EQ(Direction().vector(), Eigen::Vector3d::UnitZ()); }

TEST(Direction, ConstructorNormalises) {
  const Direction d(Eigen::Vector3d(3.0, 0.0, -4.0));
  EXPECT_NEAR(d.vector().norm(), 1.0, 1e-15);
  EXPECT_LE((d.vector() - Eigen::Vector3d(0.6, 0.0, -0.8)).norm(), 1e-15);
  const Direction tiny(Eigen::Vector3d(1e-10, 2e-10, -2e-10));
  EXPECT_LE((tiny.vector() - Eigen::Vector3d(1.0, 2.0, -2.0) / 3.0).norm(), 1e-15);
}

TEST(Direction, ZeroOrNonFiniteVectorThrowsCheckError) {
  EXPECT_THROW(Direction(Eigen::Vector3d::Zero()), CheckError);
  EXPECT_THROW(Direction(Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 1.0)),
               CheckError);
  EXPECT_THROW(Direction(Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0.0, 1.0)),
               CheckError);
  const double ambient[3] = {0.0, 0.0, 0.0};
  EXPECT_THROW(Direction::fromAmbient(ambient), CheckError);
}

TEST(Direction, BasisIsOrthonormalAndOrthogonalToVector) {
  std::mt19937 rng(1);
  for (const Direction& d : testDirections(rng)) {
    const Matrix32d B = d.basis();
    EXPECT_LE((B.transpose() * B - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff(), 1e-15)
        << "v = " << d.vector().transpose();
    EXPECT_LE((B.transpose() * d.vector()).cwiseAbs().maxCoeff(), 1e-15)
        << "v = " << d.vector().transpose();
  }
}

TEST(Direction, RetractOfZeroIsIdentity) {
  std::mt19937 rng(3);
  for (const Direction& d : testDirections(rng)) {
    // Only the renormalisation of an already unit vector separates the two.
    EXPECT_LE((d.retract(Eigen::Vector2d::Zero()).vector() - d.vector()).norm(), 1e-15);
  }
}

TEST(Direction, RetractStaysUnitAndMovesByTangentNorm) {
  std::mt19937 rng(4);
  for (const Direction& d : testDirections(rng)) {
    for (int i = 0; i < 10; ++i) {
      const Eigen::Vector2d delta = randomTangent(rng, kPi - 1e-6);
      const Direction moved = d.retract(delta);
      EXPECT_NEAR(moved.vector().norm(), 1.0, 1e-15);
      EXPECT_NEAR(d.angleTo(moved), delta.norm(), 1e-12) << "delta = " << delta.transpose();
      // Along the great circle through v in direction basis() * delta.
      const Eigen::Vector3d xi = d.basis() * delta;
      const Eigen::Vector3d expected =
          std::cos(delta.norm()) * d.vector() + std::sin(delta.norm()) * xi.normalized();
      EXPECT_LE((moved.vector() - expected).norm(), 1e-14) << "delta = " << delta.transpose();
    }
  }
}

TEST(Direction, RetractMovesByTinyTangentNorm) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> exponent(-12.0, -4.0);
  for (const Direction& d : testDirections(rng)) {
    const Eigen::Vector2d delta = std::pow(10.0, exponent(rng)) * randomTangent(rng, 1.0);
    const Eigen::Vector3d expected = std::cos(delta.norm()) * d.vector() +
                                     std::sin(delta.norm()) * (d.basis() * delta).normalized();
    EXPECT_LE((d.retract(delta).vector() - expected).norm(), 1e-15)
        << "delta = " << delta.transpose();
  }
}

TEST(Direction, LocalCoordinatesInvertsRetract) {
  std::mt19937 rng(6);
  for (const Direction& d : testDirections(rng)) {
    for (int i = 0; i < 10; ++i) {
      const Eigen::Vector2d delta = randomTangent(rng, kPi - 1e-3);
      EXPECT_LE((d.localCoordinates(d.retract(delta)) - delta).norm(), 1e-12)
          << "v = " << d.vector().transpose() << ", delta = " << delta.transpose();
    }
  }
}

TEST(Direction, LocalCoordinatesInvertsRetractForTinySteps) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> exponent(-12.0, -4.0);
  for (const Direction& d : testDirections(rng)) {
    const Eigen::Vector2d delta = std::pow(10.0, exponent(rng)) * randomTangent(rng, 1.0);
    // v is unit only to rounding, so the recovered step carries ~1e-16 absolute noise.
    EXPECT_LE((d.localCoordinates(d.retract(delta)) - delta).norm(), 1e-15 + 1e-9 * delta.norm())
        << "delta = " << delta.transpose();
  }
}

TEST(Direction, LocalCoordinatesInvertsRetractNearlyAntipodal) {
  // Documented for directions less than pi apart: pi - 1e-9 qualifies. The recovered step is
  // ill-conditioned only to ~1e-7 here (sin(angle) ~ 1e-9 is known to ~1e-16 absolute).
  std::mt19937 rng(8);
  for (const Direction& d : testDirections(rng)) {
    const Eigen::Vector2d delta = (kPi - 1e-9) * randomTangent(rng, 1.0).normalized();
    const Eigen::Vector2d recovered = d.localCoordinates(d.retract(delta));
    EXPECT_LE((recovered - delta).norm(), 1e-5)
        << "v = " << d.vector().transpose() << ", delta = " << delta.transpose()
        << ", localCoordinates = " << recovered.transpose();
  }
}

TEST(Direction, RetractInvertsLocalCoordinates) {
  std::mt19937 rng(9);
  for (const Direction& d : testDirections(rng)) {
    const Direction other(randomUnitVector(rng));
    EXPECT_LE((d.retract(d.localCoordinates(other)).vector() - other.vector()).norm(), 1e-12);
  }
}

TEST(Direction, LocalCoordinatesOfItselfIsZero) {
  std::mt19937 rng(10);
  for (const Direction& d : testDirections(rng)) {
    EXPECT_LE(d.localCoordinates(d).norm(), 1e-16);
  }
}

TEST(Direction, AngleToMatchesHandComputedValues) {
  const Direction x(Eigen::Vector3d::UnitX());
  EXPECT_EQ(x.angleTo(x), 0.0);
  EXPECT_NEAR(x.angleTo(Direction(Eigen::Vector3d::UnitY())), kPi / 2.0, 1e-15);
  EXPECT_NEAR(x.angleTo(Direction(-Eigen::Vector3d::UnitX())), kPi, 1e-15);
  EXPECT_NEAR(x.angleTo(Direction(Eigen::Vector3d(1.0, 1.0, 0.0))), kPi / 4.0, 1e-15);
  EXPECT_NEAR(x.angleTo(Direction(Eigen::Vector3d(-1.0, 0.0, 1.0))), 3.0 * kPi / 4.0, 1e-15);
  // atan2 keeps tiny angles accurate where acos(dot) would round to 0.
  EXPECT_NEAR(x.angleTo(Direction(Eigen::Vector3d(1.0, 1e-10, 0.0))), 1e-10, 1e-24);
}

TEST(Direction, AngleToIsSymmetricAndMatchesAcos) {
  std::mt19937 rng(11);
  for (int i = 0; i < 200; ++i) {
    const Direction a(randomUnitVector(rng));
    const Direction b(randomUnitVector(rng));
    const double angle = a.angleTo(b);
    EXPECT_EQ(angle, b.angleTo(a));
    EXPECT_GE(angle, 0.0);
    EXPECT_LE(angle, kPi);
    EXPECT_NEAR(angle, std::acos(a.vector().dot(b.vector())), 1e-7);
  }
}

TEST(Direction, RetractDerivativeAtZeroIsBasis) {
  std::mt19937 rng(12);
  for (const Direction& d : testDirections(rng)) {
    const Matrix32d numerical = numericalDerivative<2>(
        [&](const Eigen::Vector2d& delta) -> Eigen::Vector3d { return d.retract(delta).vector(); });
    EXPECT_LE((numerical - d.basis()).cwiseAbs().maxCoeff(), 1e-6)
        << "v = " << d.vector().transpose() << "\nnumerical:\n"
        << numerical << "\nbasis:\n"
        << d.basis();
  }
}

TEST(Direction, AmbientRoundTrip) {
  std::mt19937 rng(13);
  for (const Direction& d : testDirections(rng)) {
    double ambient[Direction::kAmbientDim];
    d.toAmbient(ambient);
    EXPECT_EQ(Eigen::Vector3d(ambient[0], ambient[1], ambient[2]), d.vector());
    // fromAmbient renormalises, which may move the last bit.
    EXPECT_LE((Direction::fromAmbient(ambient).vector() - d.vector()).norm(), 1e-15);
  }
}

}  // namespace
}  // namespace curvesfm
