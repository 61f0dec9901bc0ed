#include "core/so3.h"

#include <cmath>

namespace curvesfm::so3 {
namespace {
// Below this angle the closed forms lose precision; their Taylor series are exact to 1e-16.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return m;
}

Eigen::Quaterniond exp(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const double half = 0.5 * theta;
  // sin(theta/2)/theta, which tends to 1/2 as theta -> 0.
  const double k = theta < kSmallAngle ? 0.5 - theta * theta / 48.0 : std::sin(half) / theta;
  return Eigen::Quaterniond(std::cos(half), k * w.x(), k * w.y(), k * w.z());
}

Eigen::Vector3d log(const Eigen::Quaterniond& q_in) {
  // q and -q are the same rotation; pick w >= 0 so the angle lands in [0, pi].
  const Eigen::Quaterniond q = q_in.w() < 0.0 ? Eigen::Quaterniond(-q_in.coeffs()) : q_in;
  const double sin_half = q.vec().norm();
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  // theta / sin(theta/2) from atan(s/w) ~ s/w - s^3/(3 w^3) when s is tiny.
  const double k = sin_half < kSmallAngle
                       ? 2.0 / q.w() - 2.0 * sin_half * sin_half / (3.0 * q.w() * q.w() * q.w())
                       : theta / sin_half;
  return k * q.vec();
}

Eigen::Matrix3d leftJacobian(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = hat(w);
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  // (1 - cos) written as 2 sin^2(theta/2): no cancellation for small angles.
  const double half_sin = std::sin(0.5 * theta);
  return Eigen::Matrix3d::Identity() + 2.0 * half_sin * half_sin / t2 * W +
         (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix3d leftJacobianInverse(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = hat(w);
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
  const double t2 = theta * theta;
  // (1 + cos)/sin written as cot(theta/2): stays finite up to theta = pi.
  const double coeff = 1.0 / t2 - std::cos(0.5 * theta) / (2.0 * theta * std::sin(0.5 * theta));
  return Eigen::Matrix3d::Identity() - 0.5 * W + coeff * W * W;
}

Eigen::Matrix3d rightJacobianInverse(const Eigen::Vector3d& w) { return leftJacobianInverse(-w); }

}  // namespace curvesfm::so3
