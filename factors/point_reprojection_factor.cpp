#include "factors/point_reprojection_factor.h"

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {

PointReprojectionFactor::PointReprojectionFactor(Key pose_key, Key point_key,
                                                 const Eigen::Vector2d& measured,
                                                 std::shared_ptr<const Camera> camera,
                                                 NoiseModel noise_model)
    : Base({pose_key, point_key}, std::move(noise_model)),
      measured_(measured),
      camera_(std::move(camera)) {
  CURVESFM_CHECK(camera_ != nullptr) << "PointReprojectionFactor needs a camera";
}

PointReprojectionFactor::Error PointReprojectionFactor::evaluateError(
    const Pose3& cam_from_world, const Eigen::Vector3d& point_in_world, Jacobian<Pose3>* H_pose,
    Jacobian<Eigen::Vector3d>* H_point) const {
  const Eigen::Matrix3d R = cam_from_world.rotationMatrix();
  const Eigen::Vector3d point_in_cam = R * point_in_world + cam_from_world.translation();
  Eigen::Vector2d pixel;
  Matrix23d d_pixel_d_cam;
  const bool wants_jacobians = H_pose || H_point;
  if (!camera_->project(point_in_cam, &pixel, wants_jacobians ? &d_pixel_d_cam : nullptr)) {
    if (H_pose) H_pose->setZero();
    if (H_point) H_point->setZero();
    return Error::Constant(kBehindCameraError);
  }
  if (H_pose) {
    // d(exp(w) x + u)/d[w; u] = [-[x]x, I] for x = R p + t.
    H_pose->leftCols<3>().noalias() = -d_pixel_d_cam * so3::hat(point_in_cam);
    H_pose->rightCols<3>() = d_pixel_d_cam;
  }
  if (H_point) H_point->noalias() = d_pixel_d_cam * R;
  return pixel - measured_;
}

}  // namespace curvesfm
