#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/point_observation.h"
#include "core/pose3.h"

namespace curvesfm {

/// A synthetic point bundle-adjustment scene: cameras on a circular arc looking at a cube of
/// random points, each point tracked over a run of consecutive cameras, with Gaussian pixel
/// noise, and a perturbed starting guess. Camera 0 and the scale (distance camera 0 - camera 1)
/// are left at their true values: they are the gauge that a solver holds fixed.
struct PointSceneOptions {
  int num_cameras = 50;        ///< Cameras along the arc; >= 2.
  int num_points = 5000;       ///< Points in the cube; >= 1.
  int track_length = 10;       ///< Consecutive cameras that observe each point; 1..num_cameras.
  double orbit_radius = 8.0;   ///< Distance of the cameras from the cube centre (m); > 0.
  double arc_degrees = 90.0;   ///< Angle spanned by the camera arc (deg); (0, 360].
  double cube_half_size = 2.0;   ///< Half edge of the point cube (m); (0, orbit_radius / 2).
  double pixel_noise = 0.5;      ///< Std dev of the pixel noise (px); >= 0.
  double pose_noise_translation = 0.05;  ///< Std dev of the start-guess translation error (m); >= 0.
  double pose_noise_rotation_deg = 0.5;  ///< Std dev of the start-guess rotation error (deg); >= 0.
  double point_noise = 0.05;   ///< Std dev of the start-guess point error (m); >= 0.
  unsigned seed = 42;          ///< Random seed; the same seed gives the same scene.
  /// 640x480 pinhole with mild barrel distortion, so the factors exercise the distortion model.
  CameraIntrinsics intrinsics{500.0, 500.0, 319.5, 239.5, -0.05, 0.01, 0.0, 0.0, 0.0, 640, 480};

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

struct PointScene {
  std::shared_ptr<const Camera> camera;
  std::vector<Pose3> true_cam_from_world;
  std::vector<Pose3> initial_cam_from_world;
  std::vector<Eigen::Vector3d> true_points;
  std::vector<Eigen::Vector3d> initial_points;
  std::vector<PointObservation> observations;  ///< Noisy pixels; only points inside the image.

  /// True distance between the centres of cameras 0 and 1: the scale gauge.
  double trueScaleDistance() const;
};

PointScene makePointScene(const PointSceneOptions& options);

/// Errors of an estimate against the scene's ground truth (no alignment: the gauge is fixed).
struct PointSceneErrors {
  double position_rmse = 0.0;         ///< RMS camera-centre error in the solver's gauge (m).
  /// RMS camera-centre error after a Sim(3) (Umeyama) alignment to the truth (m): the ATE,
  /// free of the drift that the gauge (camera 0 and one baseline) lets accumulate.
  double position_ate_sim3 = 0.0;
  double rotation_mean_deg = 0.0;     ///< Mean camera rotation error (deg).
  double point_rmse = 0.0;            ///< RMS point error (m).
  double reprojection_rmse_px = 0.0;  ///< RMS of |project - observed| over all observations (px).
};

PointSceneErrors evaluatePointScene(const PointScene& scene,
                                    const std::vector<Pose3>& cam_from_world,
                                    const std::vector<Eigen::Vector3d>& points);

}  // namespace curvesfm
