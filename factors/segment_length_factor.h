#pragma once

#include <Eigen/Core>

#include "graph/factor.h"

namespace curvesfm {

/// The segment-length regulariser E_s1 (paper §3.1, eq. 7): keeps a segment's chord at its
/// initial length so that curves do not shrink onto the parts of edges they happen to see,
///   e = |Q_{i+1} - Q_i| - initial_length      (scene length unit).
/// Keys: Q_i and Q_{i+1} (points). Jacobians 1x3 each: -u^T and u^T with u the unit chord.
/// Weight lambda1 enters as the noise model: sigma = 1 / sqrt(lambda1).
/// A zero chord has no direction: the error is -initial_length with zero Jacobians.
class SegmentLengthFactor : public NoiseModelFactorN<1, Eigen::Vector3d, Eigen::Vector3d> {
  using Base = NoiseModelFactorN<1, Eigen::Vector3d, Eigen::Vector3d>;

 public:
  /// `initial_length` >= 0 (CheckError otherwise).
  SegmentLengthFactor(Key q0_key, Key q1_key, double initial_length, NoiseModel noise_model);

  Error evaluateError(const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                      Jacobian<Eigen::Vector3d>* H_q0,
                      Jacobian<Eigen::Vector3d>* H_q1) const override;
  const char* typeName() const override { return "segment_length"; }
  double initialLength() const { return initial_length_; }

 private:
  double initial_length_;
};

}  // namespace curvesfm
