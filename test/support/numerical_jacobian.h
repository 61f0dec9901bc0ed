#pragma once

// Central-difference Jacobians of factors through each variable's retract(), for tests.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <random>

#include "graph/factor.h"
#include "graph/values.h"

namespace curvesfm::testing {

/// Central differences at 0 of f: R^kIn -> R^3, one column per input coordinate.
template <int kIn, class F>
Eigen::Matrix<double, 3, kIn> numericalDerivative(F&& f, double step = 1e-6) {
  Eigen::Matrix<double, 3, kIn> jacobian;
  for (int k = 0; k < kIn; ++k) {
    const Eigen::Matrix<double, kIn, 1> delta = Eigen::Matrix<double, kIn, 1>::Unit(k) * step;
    jacobian.col(k) = (f(delta) - f(-delta)) / (2.0 * step);
  }
  return jacobian;
}

/// A uniformly random unit vector.
inline Eigen::Vector3d randomUnitVector(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  } while (v.norm() < 1e-3);
  return v.normalized();
}

/// d error / d delta at delta = 0, where the key's value is retract(value, delta).
inline Eigen::MatrixXd numericalJacobian(const Factor& factor, const Values& values, Key key,
                                         double step = 1e-6) {
  const int dim = tangentDim(values.type(key));
  Eigen::MatrixXd jacobian(factor.residualDimension(), dim);
  for (int k = 0; k < dim; ++k) {
    const Eigen::VectorXd delta = Eigen::VectorXd::Unit(dim, k) * step;
    jacobian.col(k) = (factor.unwhitenedError(values.retract(key, delta)) -
                       factor.unwhitenedError(values.retract(key, -delta))) /
                      (2.0 * step);
  }
  return jacobian;
}

/// Every analytic Jacobian of `factor` at `values` agrees with central differences of `step` to
/// `tolerance` relative to the Jacobian's scale (absolute below 1).
inline void expectJacobiansMatchNumerical(const Factor& factor, const Values& values,
                                          double tolerance = 1e-5, double step = 1e-6) {
  const Linearization linear = factor.linearize(values);
  ASSERT_EQ(linear.jacobians.size(), factor.keys().size());
  for (std::size_t i = 0; i < factor.keys().size(); ++i) {
    const Key key = factor.keys()[i];
    const Eigen::MatrixXd numerical = numericalJacobian(factor, values, key, step);
    const double scale = std::max(1.0, numerical.cwiseAbs().maxCoeff());
    EXPECT_LE((linear.jacobians[i] - numerical).cwiseAbs().maxCoeff(), tolerance * scale)
        << factor.typeName() << " w.r.t. " << key << "\nanalytic:\n"
        << linear.jacobians[i] << "\nnumerical:\n"
        << numerical;
  }
}

}  // namespace curvesfm::testing
