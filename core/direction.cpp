#include "core/direction.h"

#include <Eigen/Geometry>
#include <cmath>

#include "core/check.h"

namespace curvesfm {
namespace {
constexpr double kSmallAngle = 1e-8;
}  // namespace

Direction::Direction(const Eigen::Vector3d& v) {
  const double norm = v.norm();
  CURVESFM_CHECK(norm > 1e-12 && std::isfinite(norm)) << "Direction needs a finite non-zero vector";
  v_ = v / norm;
}

Matrix32d Direction::basis() const {
  // Cross with the axis least aligned with v: well conditioned wherever v points.
  Eigen::Index axis = 0;
  v_.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d b1 = v_.cross(Eigen::Vector3d::Unit(axis)).normalized();
  Matrix32d B;
  B.col(0) = b1;
  B.col(1) = v_.cross(b1);
  return B;
}

Direction Direction::retract(const Eigen::Vector2d& delta) const {
  const Eigen::Vector3d xi = basis() * delta;
  const double theta = xi.norm();
  // sin(theta)/theta -> 1 as theta -> 0.
  const double sinc = theta < kSmallAngle ? 1.0 - theta * theta / 6.0 : std::sin(theta) / theta;
  return Direction(std::cos(theta) * v_ + sinc * xi);
}

Eigen::Vector2d Direction::localCoordinates(const Direction& other) const {
  const Eigen::Vector3d& w = other.v_;
  const Eigen::Vector3d orthogonal = w - v_.dot(w) * v_;
  const double sin_theta = orthogonal.norm();
  const double theta = std::atan2(sin_theta, v_.dot(w));
  // theta / sin(theta) -> 1 as theta -> 0.
  // Switch on the angle, not on sin: near the antipode sin is tiny but theta / sin is not 1.
  const double scale = theta < kSmallAngle ? 1.0 : theta / sin_theta;
  return basis().transpose() * (scale * orthogonal);
}

double Direction::angleTo(const Direction& other) const {
  return std::atan2(v_.cross(other.v_).norm(), v_.dot(other.v_));
}

}  // namespace curvesfm
