#pragma once

#include <Eigen/Core>

#include "core/eigen_types.h"

namespace curvesfm {

/// A unit vector in R^3 (2 degrees of freedom), e.g. a curve tangent.
///
/// Tangent space: delta in R^2 lives in the plane orthogonal to v, spanned by the orthonormal
/// columns of basis() (3x2). retract() follows the great circle (exponential map on the sphere):
///   xi = basis() * delta,  retract(delta) = cos|xi| v + sin|xi| xi / |xi|.
/// This is the minimal update the paper writes as v = R0 v(theta) with R0 re-anchored at every
/// step. A Jacobian H_v (m x 3) w.r.t. the vector becomes H_v * basis() (m x 2) in the tangent.
/// Ambient storage for solvers: the 3 coordinates of v.
class Direction {
 public:
  static constexpr int kTangentDim = 2;
  static constexpr int kAmbientDim = 3;

  /// +z.
  Direction() : v_(Eigen::Vector3d::UnitZ()) {}
  /// Normalises `v`; `v` must be non-zero and finite.
  explicit Direction(const Eigen::Vector3d& v);

  const Eigen::Vector3d& vector() const { return v_; }

  /// Orthonormal tangent basis at v (3x2), a fixed function of v.
  Matrix32d basis() const;

  Direction retract(const Eigen::Vector2d& delta) const;
  /// Inverse of retract for directions less than pi apart.
  Eigen::Vector2d localCoordinates(const Direction& other) const;

  /// Angle to `other` in radians, in [0, pi].
  double angleTo(const Direction& other) const;

  void toAmbient(double* out) const { Eigen::Vector3d::Map(out) = v_; }
  static Direction fromAmbient(const double* in) {
    return Direction(Eigen::Vector3d(in[0], in[1], in[2]));
  }

 private:
  Eigen::Vector3d v_;
};

}  // namespace curvesfm
