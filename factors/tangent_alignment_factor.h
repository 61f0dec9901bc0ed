#pragma once

#include <Eigen/Core>

#include "core/direction.h"
#include "graph/factor.h"

namespace curvesfm {

/// The tangent regulariser E_s2 (paper §3.1, eq. 8): the angles between a segment's chord
/// c = Q_{i+1} - Q_i and its two end tangents v_i, v_{i+1} should be small, which keeps a
/// segment from bulging or looping where edges give no support.
///
/// Error (6 rows, radians): [log_{v_i}(c/|c|); log_{v_{i+1}}(c/|c|)], where
///   log_v(u) = theta / sin(theta) * (u - (v.u) v),   theta = angle(u, v),
/// is the sphere's log map written in R^3 (a vector orthogonal to v of norm theta). Its squared
/// norm is exactly theta_i^2 + theta_{i+1}^2, the paper's squared angles, yet unlike theta itself
/// it is smooth at theta = 0, where the optimum lies.
/// Keys: Q_i, Q_{i+1} (points), v_i, v_{i+1} (Direction). Jacobians 6x3, 6x3, 6x2, 6x2.
/// Weight lambda2 enters as the noise model: sigma = 1 / sqrt(lambda2).
/// Degenerate cases give zero Jacobians for the affected rows: a zero chord (error 0), and a
/// tangent opposite to the chord (error of norm pi along an arbitrary perpendicular).
class TangentAlignmentFactor
    : public NoiseModelFactorN<6, Eigen::Vector3d, Eigen::Vector3d, Direction, Direction> {
  using Base = NoiseModelFactorN<6, Eigen::Vector3d, Eigen::Vector3d, Direction, Direction>;

 public:
  TangentAlignmentFactor(Key q0_key, Key q1_key, Key v0_key, Key v1_key, NoiseModel noise_model);

  Error evaluateError(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Direction& v0,
                      const Direction& v1, Jacobian<Eigen::Vector3d>* H_q0,
                      Jacobian<Eigen::Vector3d>* H_q1, Jacobian<Direction>* H_v0,
                      Jacobian<Direction>* H_v1) const override;
  const char* typeName() const override { return "tangent_alignment"; }
};

}  // namespace curvesfm
