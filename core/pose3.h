#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "core/eigen_types.h"

namespace curvesfm {

/// A rigid transform target_from_source in SE(3): x_target = R * x_source + t.
/// Name variables after the frames they map, e.g. `cam_from_world`, `world_from_cam`.
///
/// Tangent space (the chart used by the optimiser and all Jacobians), delta = [w; u]:
///   retract(delta) = (exp(w), u) * (R, t) = (exp(w) * R, exp(w) * t + u)
/// i.e. a rigid motion of the target frame applied on the left. For `cam_from_world` the rotation
/// turns the camera about its own centre and u shifts it in its own frame, so a tangent step
/// moves the camera the same way whatever the source (world) frame: a start moved rigidly takes
/// the same pose steps (g2o's and Sophus' left update).
/// Ambient storage for solvers: 7 doubles [qx, qy, qz, qw, tx, ty, tz] (Eigen's order), qw >= 0.
class Pose3 {
 public:
  static constexpr int kTangentDim = 6;
  static constexpr int kAmbientDim = 7;

  /// The identity transform.
  Pose3() : rotation_(Eigen::Quaterniond::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  /// `rotation` is normalised (and its sign chosen so that qw >= 0); it must not be zero.
  Pose3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);
  Pose3(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);

  const Eigen::Quaterniond& rotation() const { return rotation_; }
  Eigen::Matrix3d rotationMatrix() const { return rotation_.toRotationMatrix(); }
  const Eigen::Vector3d& translation() const { return translation_; }

  /// Composition: (a_from_b * b_from_c) == a_from_c.
  Pose3 operator*(const Pose3& other) const;
  Pose3 inverse() const;

  /// x_target = R x_source + t. Optional Jacobians: H_pose (3x6, tangent), H_point (3x3).
  Eigen::Vector3d transformPoint(const Eigen::Vector3d& point, Matrix36d* H_pose = nullptr,
                                 Eigen::Matrix3d* H_point = nullptr) const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const { return transformPoint(point); }

  /// Position of the target frame's origin in the source frame, i.e. for `cam_from_world` the
  /// camera centre in world: -R^T t. Optional H_pose (3x6; 0 in w: the chart turns about it).
  Eigen::Vector3d inverseTranslation(Matrix36d* H_pose = nullptr) const;

  /// SE(3) group exponential of xi = [w; v] (rotation vector, translational velocity).
  static Pose3 exp(const Vector6d& xi);
  /// SE(3) group logarithm; inverse of exp() for rotation angles below pi.
  Vector6d log() const;

  /// The optimiser's chart (see class comment).
  Pose3 retract(const Vector6d& delta) const;
  /// Inverse of retract: this->retract(localCoordinates(other)) == other.
  /// Optional Jacobians w.r.t. this pose's and the other pose's tangent (6x6 each).
  Vector6d localCoordinates(const Pose3& other, Matrix6d* H_this = nullptr,
                            Matrix6d* H_other = nullptr) const;

  /// Ambient storage (see class comment).
  void toAmbient(double* out) const;
  static Pose3 fromAmbient(const double* in);

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
};

/// `world_from_cam` turned by exp(w) about its own centre and its centre shifted by u, both in
/// world axes, delta = [w; u]: (exp(w) R, t + u). The perturbed starts of the benches.
Pose3 perturbCamera(const Pose3& world_from_cam, const Vector6d& delta);

/// Distance between the camera centres of two cam_from_world poses (their unit).
double cameraCentreDistance(const Pose3& a_cam_from_world, const Pose3& b_cam_from_world);

/// Mean distance between the camera centres of consecutive poses of a trajectory; 0 for fewer
/// than two poses.
double meanCameraStep(const std::vector<Pose3>& cam_from_world);

}  // namespace curvesfm
