#include "factors/tangent_alignment_factor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

const Key kQ0 = curvePointKey(2, 0);
const Key kQ1 = curvePointKey(2, 1);
const Key kV0 = directionKey(2, 0);
const Key kV1 = directionKey(2, 1);

Values segment(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Eigen::Vector3d& v0,
               const Eigen::Vector3d& v1) {
  Values values;
  values.insert(kQ0, q0);
  values.insert(kQ1, q1);
  values.insert(kV0, Direction(v0));
  values.insert(kV1, Direction(v1));
  return values;
}

const TangentAlignmentFactor kFactor(kQ0, kQ1, kV0, kV1, NoiseModel{});

TEST(TangentAlignmentFactor, ErrorNormsAreTheAnglesToTheChord) {
  // Chord along +x; v0 30 degrees off in the xy-plane, v1 100 degrees off in the xz-plane.
  const double a0 = 30.0 * M_PI / 180.0;
  const double a1 = 100.0 * M_PI / 180.0;
  const Eigen::VectorXd error = kFactor.unwhitenedError(
      segment(Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(3, 1, 1),
              Eigen::Vector3d(std::cos(a0), std::sin(a0), 0),
              Eigen::Vector3d(std::cos(a1), 0, std::sin(a1))));
  EXPECT_NEAR(error.head<3>().norm(), a0, 1e-12);
  EXPECT_NEAR(error.tail<3>().norm(), a1, 1e-12);
  // Each part lies in the tangent plane of its direction and points towards the chord.
  EXPECT_NEAR(error.head<3>().dot(Eigen::Vector3d(std::cos(a0), std::sin(a0), 0)), 0.0, 1e-12);
  EXPECT_GT(error[0], 0.0);
}

TEST(TangentAlignmentFactor, ZeroForAStraightSegment) {
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, -1).normalized();
  const Values values = segment(Eigen::Vector3d::Zero(), 0.7 * dir, dir, dir);
  EXPECT_LT(kFactor.unwhitenedError(values).norm(), 1e-12);
}

TEST(TangentAlignmentFactor, JacobiansMatchNumericalFromLargeToTinyAngles) {
  std::mt19937 rng(13);
  for (const double spread : {1.0, 0.1, 1e-3, 1e-5}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Vector3d q0 = testing::randomUnitVector(rng);
      const Eigen::Vector3d chord = 0.5 * testing::randomUnitVector(rng);
      const Values values =
          segment(q0, q0 + chord, chord.normalized() + spread * testing::randomUnitVector(rng),
                  chord.normalized() + spread * testing::randomUnitVector(rng));
      SCOPED_TRACE(spread);
      testing::expectJacobiansMatchNumerical(kFactor, values, 1e-6);
    }
  }
}

TEST(TangentAlignmentFactor, DegenerateCasesStayFinite) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  for (const Values& values :
       {segment(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), x, x),   // zero chord
        segment(Eigen::Vector3d::Zero(), x, -x, x)}) {                    // opposite tangent
    const Linearization linear = kFactor.linearize(values);
    EXPECT_TRUE(linear.error.allFinite());
    for (const auto& jacobian : linear.jacobians) EXPECT_TRUE(jacobian.allFinite());
  }
  const Eigen::VectorXd opposite =
      kFactor.unwhitenedError(segment(Eigen::Vector3d::Zero(), x, -x, x));
  EXPECT_NEAR(opposite.head<3>().norm(), M_PI, 1e-12);
}

}  // namespace
}  // namespace curvesfm
