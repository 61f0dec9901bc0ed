#pragma once

#include "core/pose3.h"
#include "graph/factor.h"

namespace curvesfm {

/// Ties the motion between two keyframes to a measured one, e.g. the initial trajectory's:
/// odometry is locally accurate even where it has drifted, and the edges of a scene with few
/// edge directions leave some pose directions weakly constrained (docs/benchmarks.md).
///   rel = cam_j_from_world * cam_i_from_world^-1        (cam_j_from_cam_i)
///   e   = W * measured.localCoordinates(rel),  W = diag(1/sigma_R (x3), 1/sigma_t (x3))
/// so e = [log(R_rel R_meas^T) / sigma_R; (t_rel - R_rel R_meas^T t_meas) / sigma_t], whose
/// translation part is -R_rel times the shift of camera j's centre seen from camera i, is already
/// whitened (dimensionless): give it a NoiseModel of sigma 1, with a kernel if wanted. sigma_R =
/// rotation_sigma (rad) and sigma_t = translation_sigma (scene units), both per axis.
/// Keys: two Pose3 (cam_from_world). Jacobians 6x6 each, w.r.t. the pose tangents.
class RelativePoseFactor : public NoiseModelFactorN<6, Pose3, Pose3> {
  using Base = NoiseModelFactorN<6, Pose3, Pose3>;

 public:
  /// Throws CheckError unless both sigmas are > 0 and finite.
  RelativePoseFactor(Key pose_i, Key pose_j, const Pose3& cam_j_from_cam_i, double rotation_sigma,
                     double translation_sigma, NoiseModel noise_model = {});

  Error evaluateError(const Pose3& cam_i_from_world, const Pose3& cam_j_from_world,
                      Jacobian<Pose3>* H_i, Jacobian<Pose3>* H_j) const override;
  const char* typeName() const override { return "relative_pose"; }
  const Pose3& measured() const { return measured_; }

 private:
  Pose3 measured_;
  Vector6d whitening_;
};

}  // namespace curvesfm
