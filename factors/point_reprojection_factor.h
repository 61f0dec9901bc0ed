#pragma once

#include <Eigen/Core>
#include <memory>

#include "core/camera.h"
#include "core/pose3.h"
#include "graph/factor.h"

namespace curvesfm {

/// Classic point reprojection (pixels):
///   e = project(cam_from_world * point_in_world) - measured
/// Keys: the pose (Pose3, cam_from_world) and the point (Eigen::Vector3d, world).
/// Jacobians: H_pose 2x6 (Pose3 tangent [w; u]), H_point 2x3.
/// A point at depth <= Camera::kMinDepth gives the constant error (kBehindCameraError,
/// kBehindCameraError) with zero Jacobians: it neither pulls nor produces NaN.
class PointReprojectionFactor : public NoiseModelFactorN<2, Pose3, Eigen::Vector3d> {
  using Base = NoiseModelFactorN<2, Pose3, Eigen::Vector3d>;

 public:
  /// Error per coordinate (pixels) of a point behind the camera.
  static constexpr double kBehindCameraError = 1e3;

  PointReprojectionFactor(Key pose_key, Key point_key, const Eigen::Vector2d& measured,
                          std::shared_ptr<const Camera> camera, NoiseModel noise_model);

  Error evaluateError(const Pose3& cam_from_world, const Eigen::Vector3d& point_in_world,
                      Jacobian<Pose3>* H_pose,
                      Jacobian<Eigen::Vector3d>* H_point) const override;

  const char* typeName() const override { return "point_reprojection"; }
  const Eigen::Vector2d& measured() const { return measured_; }
  const Camera& camera() const { return *camera_; }

 private:
  Eigen::Vector2d measured_;
  std::shared_ptr<const Camera> camera_;
};

/// The same reprojection with the focal lengths scaled by a shared factor s (unitless):
///   e = c + s (project(cam_from_world * point_in_world) - c) - measured,   c = (cx, cy),
/// i.e. the camera with fx, fy multiplied by s and the principal point held (distortion, where
/// the camera has any, stays in its normalized coordinates). One s for every image refines a
/// focal length given only roughly (self-calibration, as COLMAP's bundle adjustment refines
/// its focal length), keeping the aspect ratio.
/// Keys: the pose, the point and focalScaleKey() (double, 1 = the camera as given).
/// Jacobians: H_pose 2x6, H_point 2x3 as PointReprojectionFactor's times s, H_scale 2x1.
/// Behind the camera: PointReprojectionFactor's constant error and zero Jacobians.
class FocalPointReprojectionFactor : public NoiseModelFactorN<2, Pose3, Eigen::Vector3d, double> {
  using Base = NoiseModelFactorN<2, Pose3, Eigen::Vector3d, double>;

 public:
  FocalPointReprojectionFactor(Key pose_key, Key point_key, Key scale_key,
                               const Eigen::Vector2d& measured,
                               std::shared_ptr<const Camera> camera, NoiseModel noise_model);

  Error evaluateError(const Pose3& cam_from_world, const Eigen::Vector3d& point_in_world,
                      const double& focal_scale, Jacobian<Pose3>* H_pose,
                      Jacobian<Eigen::Vector3d>* H_point, Jacobian<double>* H_scale) const override;

  const char* typeName() const override { return "point_reprojection"; }

 private:
  Eigen::Vector2d measured_;
  std::shared_ptr<const Camera> camera_;
};

}  // namespace curvesfm
