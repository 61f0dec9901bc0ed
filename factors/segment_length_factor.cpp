#include "factors/segment_length_factor.h"

#include <cmath>

#include "core/check.h"

namespace curvesfm {

SegmentLengthFactor::SegmentLengthFactor(Key q0_key, Key q1_key, double initial_length,
                                         NoiseModel noise_model)
    : Base({q0_key, q1_key}, std::move(noise_model)), initial_length_(initial_length) {
  CURVESFM_CHECK(std::isfinite(initial_length) && initial_length >= 0.0)
      << "SegmentLengthFactor: initial length " << initial_length << " must be finite and >= 0";
}

SegmentLengthFactor::Error SegmentLengthFactor::evaluateError(
    const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, Jacobian<Eigen::Vector3d>* H_q0,
    Jacobian<Eigen::Vector3d>* H_q1) const {
  const Eigen::Vector3d chord = q1 - q0;
  const double length = chord.norm();
  const Eigen::RowVector3d unit =
      length > 0.0 ? Eigen::RowVector3d(chord.transpose() / length) : Eigen::RowVector3d::Zero();
  if (H_q0) *H_q0 = -unit;
  if (H_q1) *H_q1 = unit;
  return Error::Constant(length - initial_length_);
}

}  // namespace curvesfm
