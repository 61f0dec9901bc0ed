#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace curvesfm::so3 {

/// Skew-symmetric matrix with hat(w) * x == w.cross(x).
Eigen::Matrix3d hat(const Eigen::Vector3d& w);

/// Rotation by the rotation vector `w` (axis * angle, radians); exact near w = 0.
Eigen::Quaterniond exp(const Eigen::Vector3d& w);

/// Rotation vector of `q`, angle in [0, pi]; inverse of exp().
Eigen::Vector3d log(const Eigen::Quaterniond& q);

/// Left Jacobian Jl(w): exp(w + dw) ~= exp(Jl(w) dw) * exp(w).
Eigen::Matrix3d leftJacobian(const Eigen::Vector3d& w);

/// Inverse of the left Jacobian: log(exp(d) * exp(w)) ~= w + JlInv(w) d.
Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& w);

/// Inverse of the right Jacobian: log(exp(w) * exp(d)) ~= w + JrInv(w) d; JrInv(w) = JlInv(-w).
Eigen::Matrix3d rightJacobianInverse(const Eigen::Vector3d& w);

}  // namespace curvesfm::so3
