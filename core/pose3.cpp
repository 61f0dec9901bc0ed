#include "core/pose3.h"

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {

Pose3::Pose3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
    : rotation_(rotation), translation_(translation) {
  const double norm = rotation_.norm();
  CURVESFM_CHECK(norm > 1e-12) << "Pose3 needs a non-zero quaternion";
  // q and -q are one rotation; keeping qw >= 0 makes the ambient form unique.
  rotation_.coeffs() /= rotation_.w() < 0.0 ? -norm : norm;
}

Pose3::Pose3(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : Pose3(Eigen::Quaterniond(rotation), translation) {}

Pose3 Pose3::operator*(const Pose3& other) const {
  return Pose3(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_);
}

Pose3 Pose3::inverse() const {
  const Eigen::Quaterniond r_inv = rotation_.conjugate();
  return Pose3(r_inv, -(r_inv * translation_));
}

Eigen::Vector3d Pose3::transformPoint(const Eigen::Vector3d& point, Matrix36d* H_pose,
                                      Eigen::Matrix3d* H_point) const {
  const Eigen::Matrix3d R = rotationMatrix();
  const Eigen::Vector3d rotated = R * point;
  if (H_pose) {
    // d(exp(w) R p)/dw at w = 0 is -[R p]x; the translation enters with identity.
    H_pose->leftCols<3>() = -so3::hat(rotated);
    H_pose->rightCols<3>().setIdentity();
  }
  if (H_point) *H_point = R;
  return rotated + translation_;
}

Eigen::Vector3d Pose3::inverseTranslation(Matrix36d* H_pose) const {
  const Eigen::Matrix3d Rt = rotationMatrix().transpose();
  if (H_pose) {
    // c = -R^T t; with R -> exp(w) R, R^T -> R^T (I - [w]x), so dc/dw = -R^T [t]x.
    H_pose->leftCols<3>() = -Rt * so3::hat(translation_);
    H_pose->rightCols<3>() = -Rt;
  }
  return -(Rt * translation_);
}

Pose3 Pose3::exp(const Vector6d& xi) {
  const Eigen::Vector3d w = xi.head<3>();
  return Pose3(so3::exp(w), so3::leftJacobian(w) * xi.tail<3>());
}

Vector6d Pose3::log() const {
  Vector6d xi;
  const Eigen::Vector3d w = so3::log(rotation_);
  xi.head<3>() = w;
  xi.tail<3>() = so3::leftJacobianInverse(w) * translation_;
  return xi;
}

Pose3 Pose3::retract(const Vector6d& delta) const {
  return Pose3(so3::exp(delta.head<3>()) * rotation_, translation_ + delta.tail<3>());
}

Vector6d Pose3::localCoordinates(const Pose3& other, Matrix6d* H_this, Matrix6d* H_other) const {
  Vector6d delta;
  const Eigen::Vector3d w = so3::log(other.rotation_ * rotation_.conjugate());
  delta.head<3>() = w;
  delta.tail<3>() = other.translation_ - translation_;
  if (H_this) {
    // log(R_o R^T exp(-d)) ~= w - JrInv(w) d.
    H_this->setZero();
    H_this->topLeftCorner<3, 3>() = -so3::rightJacobianInverse(w);
    H_this->bottomRightCorner<3, 3>() = -Eigen::Matrix3d::Identity();
  }
  if (H_other) {
    // log(exp(d) R_o R^T) ~= w + JlInv(w) d.
    H_other->setZero();
    H_other->topLeftCorner<3, 3>() = so3::leftJacobianInverse(w);
    H_other->bottomRightCorner<3, 3>().setIdentity();
  }
  return delta;
}

void Pose3::toAmbient(double* out) const {
  Eigen::Vector4d::Map(out) = rotation_.coeffs();
  Eigen::Vector3d::Map(out + 4) = translation_;
}

Pose3 Pose3::fromAmbient(const double* in) {
  return Pose3(Eigen::Quaterniond(in[3], in[0], in[1], in[2]), Eigen::Vector3d(in[4], in[5], in[6]));
}

double cameraCentreDistance(const Pose3& a_cam_from_world, const Pose3& b_cam_from_world) {
  return (a_cam_from_world.inverseTranslation() - b_cam_from_world.inverseTranslation()).norm();
}

double meanCameraStep(const std::vector<Pose3>& cam_from_world) {
  if (cam_from_world.size() < 2) return 0.0;
  double sum = 0.0;
  for (std::size_t i = 1; i < cam_from_world.size(); ++i) {
    sum += cameraCentreDistance(cam_from_world[i], cam_from_world[i - 1]);
  }
  return sum / static_cast<double>(cam_from_world.size() - 1);
}

}  // namespace curvesfm
