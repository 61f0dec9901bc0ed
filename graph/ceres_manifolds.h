#pragma once

#include <ceres/manifold.h>

#include "graph/variable_traits.h"

namespace curvesfm {

/// Pose3's chart as a Ceres manifold. Ambient [qx qy qz qw tx ty tz], tangent [w; u]:
/// Plus(x, d) = (exp(w) * q, exp(w) * t + u), exactly Pose3::retract.
class PoseManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

/// Direction's chart as a Ceres manifold: ambient the unit 3-vector, tangent 2-D, Plus is
/// Direction::retract (great-circle step along Direction::basis()).
class DirectionManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 3; }
  int TangentSize() const override { return 2; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

/// The shared manifold for a variable type, or nullptr for Euclidean types (points, scalars).
const ceres::Manifold* manifoldFor(VariableType type);

/// Turns a tangent-space Jacobian J_t (rows x tangentDim, row-major) into the ambient-space
/// Jacobian Ceres expects (rows x ambientDim, row-major), such that J_a * PlusJacobian(x) = J_t.
/// We use J_a = J_t * MinusJacobian(x): both manifolds have MinusJacobian * PlusJacobian = I.
void liftToAmbient(VariableType type, const double* x, const double* tangent_jacobian, int rows,
                   double* ambient_jacobian);

/// Anchored charts, for variables that share one solver block (CeresProblem's curve blocks).
/// Such a block holds no manifold: it holds the tangent offsets delta of its variables from
/// anchors fixed for the whole solve, x = retract(anchor, delta), so Ceres adds steps to it as to
/// a vector and never multiplies a wide block's Jacobian by a PlusJacobian. Points, directions
/// and scalars only (poses keep their own block and PoseManifold).

/// x = retract(anchor, delta), ambient in and out. Throws CheckError for a pose.
void retractAnchored(VariableType type, const double* anchor, const double* delta, double* x);
/// Turns the factor's tangent Jacobian J_t at x = retract(anchor, delta) (ambient, as
/// retractAnchored gave it; rows x n, row-major, n = tangentDim) into d error / d delta = J_t * C,
/// C = d localCoordinates(x, retract(anchor, delta + e)) / de at e = 0, written into columns
/// [column, column + n) of `block_jacobian` (rows x block_size, row-major). C is the identity but
/// for directions, whose exponential map bends away from the anchor's tangent plane.
void writeAnchoredJacobian(VariableType type, const double* anchor, const double* delta,
                           const double* x, const double* tangent_jacobian, int rows,
                           double* block_jacobian, int block_size, int column);

}  // namespace curvesfm
