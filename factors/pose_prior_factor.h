#pragma once

#include "core/pose3.h"
#include "graph/factor.h"

namespace curvesfm {

/// A prior on a pose, e.g. to anchor the gauge softly or to tie a pose to an external estimate:
///   e = prior.localCoordinates(pose) = [log(R R_prior^T); t - R R_prior^T t_prior]
/// (rad; scene units); for cam_from_world the translation part is -R (c - c_prior), c = -R^T t.
/// Key: one Pose3. Jacobian 6x6 w.r.t. the pose tangent. Put per-axis scaling of rotation vs
/// translation into the noise model's sigma by choosing units; sigma is isotropic.
class PosePriorFactor : public NoiseModelFactorN<6, Pose3> {
  using Base = NoiseModelFactorN<6, Pose3>;

 public:
  PosePriorFactor(Key pose_key, const Pose3& prior, NoiseModel noise_model);

  Error evaluateError(const Pose3& pose, Jacobian<Pose3>* H_pose) const override;
  const char* typeName() const override { return "pose_prior"; }
  const Pose3& prior() const { return prior_; }

 private:
  Pose3 prior_;
};

/// A prior on a camera's orientation and centre in world, each with its own std dev, e.g. a start
/// whose poses are known to within a rotation and a shift per axis:
///   e = [log(R R_prior^T) / rotation_sigma; (c - c_prior) / centre_sigma],  c = -R^T t,
/// already whitened (dimensionless; give it a NoiseModel of sigma 1). Unlike PosePriorFactor its
/// centre error is in world axes, so it can be weighted per world axis later.
/// Key: one Pose3 (cam_from_world). Jacobian 6x6 w.r.t. the pose tangent.
class CameraPriorFactor : public NoiseModelFactorN<6, Pose3> {
  using Base = NoiseModelFactorN<6, Pose3>;

 public:
  /// Throws CheckError unless both sigmas are > 0 and finite.
  CameraPriorFactor(Key pose_key, const Pose3& prior_cam_from_world, double rotation_sigma,
                    double centre_sigma, NoiseModel noise_model = {});

  Error evaluateError(const Pose3& cam_from_world, Jacobian<Pose3>* H_pose) const override;
  const char* typeName() const override { return "camera_prior"; }

 private:
  Eigen::Quaterniond prior_rotation_;
  Eigen::Vector3d prior_centre_;
  double rotation_weight_;
  double centre_weight_;
};

/// Fixes the monocular scale gauge: the distance between two camera centres,
///   e = |c_j - c_i| - distance,   c = -R^T t for each cam_from_world pose.
/// Keys: two Pose3 (cam_from_world). Jacobians 1x6 each. When the centres coincide the
/// direction is undefined: the error is -distance and the Jacobians are zero.
class CameraDistanceFactor : public NoiseModelFactorN<1, Pose3, Pose3> {
  using Base = NoiseModelFactorN<1, Pose3, Pose3>;

 public:
  CameraDistanceFactor(Key pose_i, Key pose_j, double distance, NoiseModel noise_model);

  Error evaluateError(const Pose3& cam_i_from_world, const Pose3& cam_j_from_world,
                      Jacobian<Pose3>* H_i, Jacobian<Pose3>* H_j) const override;
  const char* typeName() const override { return "camera_distance"; }
  double distance() const { return distance_; }

 private:
  double distance_;
};

}  // namespace curvesfm
