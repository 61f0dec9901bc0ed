#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/pose3.h"
#include "core/similarity_alignment.h"

namespace curvesfm {

/// The Umeyama (least-squares, with scale) Sim(3) truth_from_estimated that maps the estimated
/// camera centres onto the true ones. Both trajectories are cam_from_world, index-aligned, and
/// must have the same size >= 2 (CheckError otherwise). With fewer than 3 non-collinear centres
/// (a straight walk) the rotation about their line is not determined; use alignCameraFrames.
Sim3 alignCameraCentres(const std::vector<Pose3>& true_cam_from_world,
                        const std::vector<Pose3>& estimated_cam_from_world);

/// Like alignCameraCentres, but every camera also contributes the tips of its three axes:
/// centre + axis_length * (x, y, z axis of the camera in the world) for the truth, and the same
/// with axis_length / s for the estimate, s being alignCameraCentres' scale (axis_length in m,
/// > 0). The rotation is then determined by the camera orientations even when all centres lie on
/// one line, and an exact similarity between the trajectories is recovered exactly. Use it to
/// carry structure (points, curves) into the true frame.
Sim3 alignCameraFrames(const std::vector<Pose3>& true_cam_from_world,
                       const std::vector<Pose3>& estimated_cam_from_world, double axis_length);

/// Pose errors of an estimated trajectory against the truth (same contract as above).
struct TrajectoryErrors {
  /// RMS camera-centre error in the solver's gauge, without alignment (m).
  double position_rmse = 0.0;
  /// RMS camera-centre error after alignCameraCentres (m): the absolute trajectory error (ATE),
  /// free of the drift that a gauge of one camera and one baseline lets accumulate.
  double position_ate_sim3 = 0.0;
  /// Mean angle of R_estimated * R_true^T over the cameras, without alignment (deg).
  double rotation_mean_deg = 0.0;
};

TrajectoryErrors evaluateTrajectory(const std::vector<Pose3>& true_cam_from_world,
                                    const std::vector<Pose3>& estimated_cam_from_world);

}  // namespace curvesfm
