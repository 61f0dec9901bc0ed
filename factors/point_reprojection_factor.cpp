#include "factors/point_reprojection_factor.h"

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {

namespace {

// The pixel of a world point and its Jacobians (H_pose 2x6, H_point 2x3, each optional); false
// behind the camera.
template <class PoseJacobian, class PointJacobian>
bool projectWorldPoint(const Camera& camera, const Pose3& cam_from_world,
                       const Eigen::Vector3d& point_in_world, Eigen::Vector2d* pixel,
                       PoseJacobian* H_pose, PointJacobian* H_point) {
  const Eigen::Matrix3d R = cam_from_world.rotationMatrix();
  const Eigen::Vector3d point_in_cam = R * point_in_world + cam_from_world.translation();
  Matrix23d d_pixel_d_cam;
  const bool wants_jacobians = H_pose || H_point;
  if (!camera.project(point_in_cam, pixel, wants_jacobians ? &d_pixel_d_cam : nullptr)) {
    if (H_pose) H_pose->setZero();
    if (H_point) H_point->setZero();
    return false;
  }
  if (H_pose) {
    // d(exp(w) x + u)/d[w; u] = [-[x]x, I] for x = R p + t.
    H_pose->template leftCols<3>().noalias() = -d_pixel_d_cam * so3::hat(point_in_cam);
    H_pose->template rightCols<3>() = d_pixel_d_cam;
  }
  if (H_point) H_point->noalias() = d_pixel_d_cam * R;
  return true;
}

}  // namespace

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
  Eigen::Vector2d pixel;
  if (!projectWorldPoint(*camera_, cam_from_world, point_in_world, &pixel, H_pose, H_point)) {
    return Error::Constant(kBehindCameraError);
  }
  return pixel - measured_;
}

FocalPointReprojectionFactor::FocalPointReprojectionFactor(Key pose_key, Key point_key,
                                                           Key scale_key,
                                                           const Eigen::Vector2d& measured,
                                                           std::shared_ptr<const Camera> camera,
                                                           NoiseModel noise_model)
    : Base({pose_key, point_key, scale_key}, std::move(noise_model)),
      measured_(measured),
      camera_(std::move(camera)) {
  CURVESFM_CHECK(camera_ != nullptr) << "FocalPointReprojectionFactor needs a camera";
}

FocalPointReprojectionFactor::Error FocalPointReprojectionFactor::evaluateError(
    const Pose3& cam_from_world, const Eigen::Vector3d& point_in_world, const double& focal_scale,
    Jacobian<Pose3>* H_pose, Jacobian<Eigen::Vector3d>* H_point, Jacobian<double>* H_scale) const {
  Eigen::Vector2d pixel;
  if (!projectWorldPoint(*camera_, cam_from_world, point_in_world, &pixel, H_pose, H_point)) {
    if (H_scale) H_scale->setZero();
    return Error::Constant(PointReprojectionFactor::kBehindCameraError);
  }
  const Eigen::Vector2d centre(camera_->cx(), camera_->cy());
  const Eigen::Vector2d from_centre = pixel - centre;
  if (H_pose) *H_pose *= focal_scale;
  if (H_point) *H_point *= focal_scale;
  if (H_scale) *H_scale = from_centre;
  return centre + focal_scale * from_centre - measured_;
}

}  // namespace curvesfm
