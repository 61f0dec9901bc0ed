#include "factors/pose_prior_factor.h"

#include <cmath>

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {

PosePriorFactor::PosePriorFactor(Key pose_key, const Pose3& prior, NoiseModel noise_model)
    : Base({pose_key}, std::move(noise_model)), prior_(prior) {}

PosePriorFactor::Error PosePriorFactor::evaluateError(const Pose3& pose,
                                                      Jacobian<Pose3>* H_pose) const {
  if (!H_pose) return prior_.localCoordinates(pose);
  Matrix6d H;
  const Vector6d error = prior_.localCoordinates(pose, nullptr, &H);
  *H_pose = H;
  return error;
}

CameraPriorFactor::CameraPriorFactor(Key pose_key, const Pose3& prior_cam_from_world,
                                     double rotation_sigma, double centre_sigma,
                                     NoiseModel noise_model)
    : Base({pose_key}, std::move(noise_model)),
      prior_rotation_(prior_cam_from_world.rotation()),
      prior_centre_(prior_cam_from_world.inverseTranslation()) {
  CURVESFM_CHECK(std::isfinite(rotation_sigma) && rotation_sigma > 0.0 &&
                 std::isfinite(centre_sigma) && centre_sigma > 0.0)
      << "CameraPriorFactor sigmas must be > 0, got rotation " << rotation_sigma << ", centre "
      << centre_sigma;
  rotation_weight_ = 1.0 / rotation_sigma;
  centre_weight_ = 1.0 / centre_sigma;
}

CameraPriorFactor::Error CameraPriorFactor::evaluateError(const Pose3& cam_from_world,
                                                          Jacobian<Pose3>* H_pose) const {
  Matrix36d d_centre;
  const Eigen::Vector3d centre = cam_from_world.inverseTranslation(H_pose ? &d_centre : nullptr);
  const Eigen::Vector3d rotation_error =
      so3::log(cam_from_world.rotation() * prior_rotation_.conjugate());
  Error error;
  error << rotation_weight_ * rotation_error, centre_weight_ * (centre - prior_centre_);
  if (H_pose) {
    // The tangent turns R on the left: log(exp(w) R R_prior^T) ~= e + JlInv(e) w.
    H_pose->setZero();
    H_pose->topLeftCorner<3, 3>() = rotation_weight_ * so3::leftJacobianInverse(rotation_error);
    H_pose->bottomRows<3>() = centre_weight_ * d_centre;
  }
  return error;
}

CameraDistanceFactor::CameraDistanceFactor(Key pose_i, Key pose_j, double distance,
                                           NoiseModel noise_model)
    : Base({pose_i, pose_j}, std::move(noise_model)), distance_(distance) {
  CURVESFM_CHECK(std::isfinite(distance) && distance > 0.0)
      << "CameraDistanceFactor distance must be > 0, got " << distance;
}

CameraDistanceFactor::Error CameraDistanceFactor::evaluateError(const Pose3& cam_i_from_world,
                                                                const Pose3& cam_j_from_world,
                                                                Jacobian<Pose3>* H_i,
                                                                Jacobian<Pose3>* H_j) const {
  Matrix36d d_ci, d_cj;
  const Eigen::Vector3d baseline =
      cam_j_from_world.inverseTranslation(H_j ? &d_cj : nullptr) -
      cam_i_from_world.inverseTranslation(H_i ? &d_ci : nullptr);
  const double length = baseline.norm();
  const bool degenerate = length < 1e-12;
  const Eigen::RowVector3d unit =
      degenerate ? Eigen::RowVector3d::Zero() : Eigen::RowVector3d(baseline.transpose() / length);
  if (H_i) *H_i = -unit * d_ci;
  if (H_j) *H_j = unit * d_cj;
  return Error::Constant(length - distance_);
}

}  // namespace curvesfm
