#include "factors/relative_pose_factor.h"

#include <cmath>

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {

RelativePoseFactor::RelativePoseFactor(Key pose_i, Key pose_j, const Pose3& cam_j_from_cam_i,
                                       double rotation_sigma, double translation_sigma,
                                       NoiseModel noise_model)
    : Base({pose_i, pose_j}, std::move(noise_model)), measured_(cam_j_from_cam_i) {
  CURVESFM_CHECK(std::isfinite(rotation_sigma) && rotation_sigma > 0.0 &&
                 std::isfinite(translation_sigma) && translation_sigma > 0.0)
      << "RelativePoseFactor sigmas must be > 0, got rotation " << rotation_sigma
      << ", translation " << translation_sigma;
  whitening_ << Eigen::Vector3d::Constant(1.0 / rotation_sigma),
      Eigen::Vector3d::Constant(1.0 / translation_sigma);
}

RelativePoseFactor::Error RelativePoseFactor::evaluateError(const Pose3& cam_i_from_world,
                                                            const Pose3& cam_j_from_world,
                                                            Jacobian<Pose3>* H_i,
                                                            Jacobian<Pose3>* H_j) const {
  const Pose3 relative = cam_j_from_world * cam_i_from_world.inverse();
  if (!H_i && !H_j) return whitening_.asDiagonal() * measured_.localCoordinates(relative);
  Matrix6d d_error_d_relative;
  const Vector6d error = measured_.localCoordinates(relative, nullptr, &d_error_d_relative);
  // relative = P_j cam_j_from_world cam_i_from_world^-1 P_i^-1 for the poses' left motions
  // P = (exp(w), u); as a left motion of relative:
  //   from P_j: [w_j; u_j] itself;
  //   from P_i: [-R_rel w_i; -[t_rel]x R_rel w_i - R_rel u_i].
  const Eigen::Matrix3d R_rel = relative.rotationMatrix();
  const Eigen::DiagonalMatrix<double, 6> whitening(whitening_);
  if (H_j) *H_j = whitening * d_error_d_relative;
  if (H_i) {
    Matrix6d d_relative = Matrix6d::Zero();
    d_relative.topLeftCorner<3, 3>() = -R_rel;
    d_relative.bottomLeftCorner<3, 3>() = -so3::hat(relative.translation()) * R_rel;
    d_relative.bottomRightCorner<3, 3>() = -R_rel;
    *H_i = whitening * d_error_d_relative * d_relative;
  }
  return whitening * error;
}

}  // namespace curvesfm
