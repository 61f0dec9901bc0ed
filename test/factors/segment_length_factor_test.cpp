#include "factors/segment_length_factor.h"

#include <gtest/gtest.h>

#include <random>

#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

Values chord(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1) {
  Values values;
  values.insert(curvePointKey(0, 0), q0);
  values.insert(curvePointKey(0, 1), q1);
  return values;
}

SegmentLengthFactor factorWithInitialLength(double length) {
  return SegmentLengthFactor(curvePointKey(0, 0), curvePointKey(0, 1), length, NoiseModel{});
}

TEST(SegmentLengthFactor, ErrorIsTheChangeOfChordLength) {
  const Values values = chord(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1, 2, 3.5));
  EXPECT_NEAR(factorWithInitialLength(0.5).unwhitenedError(values)[0], 0.0, 1e-15);
  EXPECT_NEAR(factorWithInitialLength(0.75).unwhitenedError(values)[0], -0.25, 1e-15);
}

TEST(SegmentLengthFactor, JacobiansMatchNumerical) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d q0 = testing::randomUnitVector(rng);
    const Values values = chord(q0, q0 + 0.3 * testing::randomUnitVector(rng));
    testing::expectJacobiansMatchNumerical(factorWithInitialLength(0.2), values, 1e-7);
  }
}

TEST(SegmentLengthFactor, CollapsedChordHasFiniteErrorAndZeroJacobians) {
  const Linearization linear =
      factorWithInitialLength(0.4).linearize(chord(Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones()));
  EXPECT_DOUBLE_EQ(linear.error[0], -0.4);
  EXPECT_TRUE(linear.jacobians[0].isZero());
  EXPECT_TRUE(linear.jacobians[1].isZero());
}

TEST(SegmentLengthFactor, RejectsNegativeOrNonFiniteInitialLength) {
  EXPECT_THROW(factorWithInitialLength(-1.0), CheckError);
  EXPECT_THROW(factorWithInitialLength(std::nan("")), CheckError);
}

}  // namespace
}  // namespace curvesfm
