#include "graph/ceres_manifolds.h"

#include <Eigen/Core>
#include <cmath>

#include "core/check.h"
#include "core/direction.h"
#include "core/pose3.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// d(exp(w) * q)/dw at w = 0, in Eigen's coefficient order (x, y, z, w):
// 0.5 * [qw I - [qv]x ; -qv^T]. Its columns are orthogonal with norm 1/2, so 4 P^T is the
// left inverse used as MinusJacobian.
Eigen::Matrix<double, 4, 3> quaternionPlusJacobian(const double* q) {
  const Eigen::Vector3d qv(q[0], q[1], q[2]);
  Eigen::Matrix<double, 4, 3> P;
  P.topRows<3>() = 0.5 * (q[3] * Eigen::Matrix3d::Identity() - so3::hat(qv));
  P.row(3) = -0.5 * qv.transpose();
  return P;
}

}  // namespace

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Pose3::fromAmbient(x).retract(Vector6d::Map(delta)).toAmbient(x_plus_delta);
  return true;
}

bool PoseManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topLeftCorner<4, 3>() = quaternionPlusJacobian(x);
  // t' = exp(w) t + u.
  J.bottomLeftCorner<3, 3>() = -so3::hat(Eigen::Vector3d(x[4], x[5], x[6]));
  J.bottomRightCorner<3, 3>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Vector6d::Map(y_minus_x) = Pose3::fromAmbient(x).localCoordinates(Pose3::fromAmbient(y));
  return true;
}

bool PoseManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topLeftCorner<3, 4>() = 4.0 * quaternionPlusJacobian(x).transpose();
  // u = t_y - exp(w) t_x ~= dt + [t]x w: the left inverse of PlusJacobian.
  J.bottomLeftCorner<3, 4>() =
      so3::hat(Eigen::Vector3d(x[4], x[5], x[6])) * J.topLeftCorner<3, 4>();
  J.bottomRightCorner<3, 3>().setIdentity();
  return true;
}

bool DirectionManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Direction::fromAmbient(x).retract(Eigen::Vector2d::Map(delta)).toAmbient(x_plus_delta);
  return true;
}

bool DirectionManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 3, 2, Eigen::RowMajor>> J(jacobian);
  J = Direction::fromAmbient(x).basis();
  return true;
}

bool DirectionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Vector2d::Map(y_minus_x) =
      Direction::fromAmbient(x).localCoordinates(Direction::fromAmbient(y));
  return true;
}

bool DirectionManifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> J(jacobian);
  J = Direction::fromAmbient(x).basis().transpose();
  return true;
}

const ceres::Manifold* manifoldFor(VariableType type) {
  static const PoseManifold pose_manifold;
  static const DirectionManifold direction_manifold;
  switch (type) {
    case VariableType::kPose3:
      return &pose_manifold;
    case VariableType::kDirection:
      return &direction_manifold;
    case VariableType::kPoint3:
    case VariableType::kScalar:
      return nullptr;
  }
  return nullptr;
}

void liftToAmbient(VariableType type, const double* x, const double* tangent_jacobian, int rows,
                   double* ambient_jacobian) {
  switch (type) {
    case VariableType::kPose3: {
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> Jt(
          tangent_jacobian, rows, 6);
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> Ja(ambient_jacobian,
                                                                               rows, 7);
      // Ja = Jt * MinusJacobian(x), so that Ja * PlusJacobian(x) == Jt.
      const Eigen::Matrix<double, 3, 4> dw_dq = 4.0 * quaternionPlusJacobian(x).transpose();
      const Eigen::Matrix3d t_hat = so3::hat(Eigen::Vector3d(x[4], x[5], x[6]));
      Ja.leftCols<4>().noalias() = (Jt.leftCols<3>() + Jt.rightCols<3>() * t_hat) * dw_dq;
      Ja.rightCols<3>() = Jt.rightCols<3>();
      return;
    }
    case VariableType::kDirection: {
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>> Jt(
          tangent_jacobian, rows, 2);
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> Ja(ambient_jacobian,
                                                                               rows, 3);
      Ja.noalias() = Jt * Direction::fromAmbient(x).basis().transpose();
      return;
    }
    case VariableType::kPoint3:
    case VariableType::kScalar:
      std::copy(tangent_jacobian, tangent_jacobian + rows * tangentDim(type), ambient_jacobian);
      return;
  }
}

namespace {

// C = B(x)^T * d(retract(anchor, delta))/d delta for x = retract(anchor, delta). With xi = B0
// delta and theta = |xi|, retract = cos(theta) v0 + sinc(theta) xi, whose derivative in xi is
// sinc I - sinc v0 xi^T + k xi xi^T, k = (theta cos(theta) - sin(theta)) / theta^3.
Eigen::Matrix2d directionChartJacobian(const Direction& anchor, const Eigen::Vector2d& delta,
                                       const Direction& x) {
  const Matrix32d B0 = anchor.basis();
  const Eigen::Vector3d xi = B0 * delta;
  const double theta = xi.norm();
  // Series below 0.01, where k's closed form loses digits to cancellation.
  const double t2 = theta * theta;
  double sinc = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
  double k = -1.0 / 3.0 + t2 / 30.0 - t2 * t2 / 840.0;
  if (theta >= 1e-2) {
    sinc = std::sin(theta) / theta;
    k = (theta * std::cos(theta) - std::sin(theta)) / (theta * theta * theta);
  }
  const Eigen::Matrix3d d_retract = sinc * Eigen::Matrix3d::Identity() -
                                    sinc * anchor.vector() * xi.transpose() +
                                    k * xi * xi.transpose();
  return x.basis().transpose() * d_retract * B0;
}

}  // namespace

void retractAnchored(VariableType type, const double* anchor, const double* delta, double* x) {
  CURVESFM_CHECK(type != VariableType::kPose3) << "retractAnchored: poses have no anchored chart";
  retractAmbient(type, anchor, delta, x);
}

void writeAnchoredJacobian(VariableType type, const double* anchor, const double* delta,
                           const double* x, const double* tangent_jacobian, int rows,
                           double* block_jacobian, int block_size, int column) {
  const int n = tangentDim(type);
  using Out = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>, 0,
                         Eigen::OuterStride<>>;
  Out out(block_jacobian + column, rows, n, Eigen::OuterStride<>(block_size));
  Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Jt(
      tangent_jacobian, rows, n);
  if (type != VariableType::kDirection) {
    out = Jt;
    return;
  }
  out.noalias() =
      Jt * directionChartJacobian(Direction::fromAmbient(anchor), Eigen::Vector2d::Map(delta),
                                  Direction::fromAmbient(x));
}

}  // namespace curvesfm
