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
  const Eigen::Vector3d transformed = R * point + translation_;
  if (H_pose) {
    // d(exp(w) x + u)/d[w; u] at 0 with x = R p + t: [-[x]x, I].
    H_pose->leftCols<3>() = -so3::hat(transformed);
    H_pose->rightCols<3>().setIdentity();
  }
  if (H_point) *H_point = R;
  return transformed;
}

Eigen::Vector3d Pose3::inverseTranslation(Matrix36d* H_pose) const {
  const Eigen::Matrix3d Rt = rotationMatrix().transpose();
  if (H_pose) {
    // c' = -R^T exp(-w) (exp(w) t + u) = c - R^T exp(-w) u: the rotation leaves c in place.
    H_pose->leftCols<3>().setZero();
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
  const Eigen::Quaterniond turn = so3::exp(delta.head<3>());
  return Pose3(turn * rotation_, turn * translation_ + delta.tail<3>());
}

Vector6d Pose3::localCoordinates(const Pose3& other, Matrix6d* H_this, Matrix6d* H_other) const {
  // The left motion P = other * this^-1 = (R_p, t_p); delta = [log(R_p); t_p].
  const Eigen::Quaterniond rotation = other.rotation_ * rotation_.conjugate();
  const Eigen::Vector3d shift = other.translation_ - rotation * translation_;
  Vector6d delta;
  const Eigen::Vector3d w = so3::log(rotation);
  delta << w, shift;
  if (H_this) {
    // this -> (exp(d), e) this turns P into P (exp(d), e)^-1 ~= (R_p exp(-d), t_p - R_p e), and
    // log(R_p exp(-d)) ~= w - JrInv(w) d.
    H_this->setZero();
    H_this->topLeftCorner<3, 3>() = -so3::rightJacobianInverse(w);
    H_this->bottomRightCorner<3, 3>() = -rotation.toRotationMatrix();
  }
  if (H_other) {
    // other -> (exp(d), e) other turns P into (exp(d) R_p, exp(d) t_p + e), and
    // log(exp(d) R_p) ~= w + JlInv(w) d, exp(d) t_p ~= t_p - [t_p]x d.
    H_other->setZero();
    H_other->topLeftCorner<3, 3>() = so3::leftJacobianInverse(w);
    H_other->bottomLeftCorner<3, 3>() = -so3::hat(shift);
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

Pose3 perturbCamera(const Pose3& world_from_cam, const Vector6d& delta) {
  return Pose3(so3::exp(delta.head<3>()) * world_from_cam.rotation(),
               world_from_cam.translation() + delta.tail<3>());
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
