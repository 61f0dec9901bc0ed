#include "factors/tangent_alignment_factor.h"

#include <cmath>

namespace curvesfm {
namespace {

// Below this angle (rad) theta / sin(theta) and its derivative come from their Taylor series:
// the closed forms cancel catastrophically near 0. Both are accurate to ~1e-12 here.
constexpr double kSmallAngle = 1e-3;

// log_v(u) for unit u, v, and its Jacobians w.r.t. u and v in R^3 (3x3 each, optional).
Eigen::Vector3d sphereLog(const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                          Eigen::Matrix3d* d_log_d_u, Eigen::Matrix3d* d_log_d_v,
                          const Matrix32d& v_basis) {
  const double cos_angle = u.dot(v);
  const double sin_angle = u.cross(v).norm();
  const double angle = std::atan2(sin_angle, cos_angle);
  if (sin_angle < 1e-12 && cos_angle < 0.0) {
    // Opposite: every perpendicular is a geodesic; pick one and do not pull.
    if (d_log_d_u) d_log_d_u->setZero();
    if (d_log_d_v) d_log_d_v->setZero();
    return M_PI * v_basis.col(0);
  }
  // h(a) = theta / sin(theta) as a function of a = cos(theta), and dh/da.
  double h;
  double dh_da;
  if (angle < kSmallAngle) {
    const double angle2 = angle * angle;
    h = 1.0 + angle2 / 6.0;
    dh_da = -1.0 / 3.0 - 2.0 * angle2 / 15.0;
  } else {
    h = angle / sin_angle;
    dh_da = (h * cos_angle - 1.0) / (sin_angle * sin_angle);
  }
  const Eigen::Vector3d perpendicular = u - cos_angle * v;
  if (d_log_d_u) {
    *d_log_d_u = h * (Eigen::Matrix3d::Identity() - v * v.transpose()) +
                 dh_da * perpendicular * v.transpose();
  }
  if (d_log_d_v) {
    *d_log_d_v = -h * (v * u.transpose() + cos_angle * Eigen::Matrix3d::Identity()) +
                 dh_da * perpendicular * u.transpose();
  }
  return h * perpendicular;
}

}  // namespace

TangentAlignmentFactor::TangentAlignmentFactor(Key q0_key, Key q1_key, Key v0_key, Key v1_key,
                                               NoiseModel noise_model)
    : Base({q0_key, q1_key, v0_key, v1_key}, std::move(noise_model)) {}

TangentAlignmentFactor::Error TangentAlignmentFactor::evaluateError(
    const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, const Direction& v0,
    const Direction& v1, Jacobian<Eigen::Vector3d>* H_q0, Jacobian<Eigen::Vector3d>* H_q1,
    Jacobian<Direction>* H_v0, Jacobian<Direction>* H_v1) const {
  const Eigen::Vector3d chord = q1 - q0;
  const double length = chord.norm();
  if (!(length > 0.0)) {
    if (H_q0) H_q0->setZero();
    if (H_q1) H_q1->setZero();
    if (H_v0) H_v0->setZero();
    if (H_v1) H_v1->setZero();
    return Error::Zero();
  }
  const Eigen::Vector3d unit = chord / length;
  const bool wants_jacobians = H_q0 || H_q1 || H_v0 || H_v1;
  const Direction* tangents[2] = {&v0, &v1};
  Jacobian<Direction>* H_tangents[2] = {H_v0, H_v1};
  Eigen::Matrix<double, 6, 3> d_error_d_chord;
  Error error;
  for (int end = 0; end < 2; ++end) {
    const Matrix32d basis = tangents[end]->basis();
    Eigen::Matrix3d d_log_d_u;
    Eigen::Matrix3d d_log_d_v;
    error.segment<3>(3 * end) =
        sphereLog(unit, tangents[end]->vector(), wants_jacobians ? &d_log_d_u : nullptr,
                  H_tangents[end] ? &d_log_d_v : nullptr, basis);
    if (!wants_jacobians) continue;
    // d(c / |c|)/dc = (I - u u^T) / |c|.
    d_error_d_chord.middleRows<3>(3 * end) =
        d_log_d_u * (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / length;
    if (H_tangents[end]) {
      H_tangents[end]->setZero();
      H_tangents[end]->middleRows<3>(3 * end) = d_log_d_v * basis;
    }
  }
  if (H_q0) *H_q0 = -d_error_d_chord;
  if (H_q1) *H_q1 = d_error_d_chord;
  return error;
}

}  // namespace curvesfm
