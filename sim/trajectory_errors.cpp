#include "sim/trajectory_errors.h"

#include <cmath>

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

void checkSameSize(const std::vector<Pose3>& truth, const std::vector<Pose3>& estimate) {
  CURVESFM_CHECK(truth.size() == estimate.size())
      << "trajectories differ in length: " << truth.size() << " true vs " << estimate.size()
      << " estimated poses";
  CURVESFM_CHECK(truth.size() >= 2) << "an alignment needs at least 2 poses, got " << truth.size();
}

// Centre, then (optionally) the three axis tips of every camera, as the columns of a matrix.
Eigen::Matrix3Xd cameraFramePoints(const std::vector<Pose3>& cam_from_world, double axis_length) {
  const int per_camera = axis_length > 0.0 ? 4 : 1;
  Eigen::Matrix3Xd points(3, per_camera * static_cast<Eigen::Index>(cam_from_world.size()));
  for (std::size_t i = 0; i < cam_from_world.size(); ++i) {
    const Eigen::Vector3d centre = cam_from_world[i].inverseTranslation();
    const Eigen::Index column = per_camera * static_cast<Eigen::Index>(i);
    points.col(column) = centre;
    if (per_camera == 1) continue;
    // The rows of R (cam_from_world) are the camera axes in the world.
    const Eigen::Matrix3d axes = cam_from_world[i].rotationMatrix().transpose();
    for (int a = 0; a < 3; ++a) points.col(column + 1 + a) = centre + axis_length * axes.col(a);
  }
  return points;
}

}  // namespace

Sim3 alignCameraCentres(const std::vector<Pose3>& true_cam_from_world,
                        const std::vector<Pose3>& estimated_cam_from_world) {
  checkSameSize(true_cam_from_world, estimated_cam_from_world);
  return alignPointSets(cameraFramePoints(estimated_cam_from_world, 0.0),
                        cameraFramePoints(true_cam_from_world, 0.0), AlignmentKind::kSim3);
}

Sim3 alignCameraFrames(const std::vector<Pose3>& true_cam_from_world,
                       const std::vector<Pose3>& estimated_cam_from_world, double axis_length) {
  checkSameSize(true_cam_from_world, estimated_cam_from_world);
  CURVESFM_CHECK(axis_length > 0.0) << "axis_length must be > 0, got " << axis_length;
  // The estimate's axes are drawn at the length that the centres' scale maps to axis_length,
  // so that an exact similarity between the trajectories is recovered exactly.
  const double scale = alignCameraCentres(true_cam_from_world, estimated_cam_from_world).scale;
  return alignPointSets(cameraFramePoints(estimated_cam_from_world, axis_length / scale),
                        cameraFramePoints(true_cam_from_world, axis_length), AlignmentKind::kSim3);
}

TrajectoryErrors evaluateTrajectory(const std::vector<Pose3>& true_cam_from_world,
                                    const std::vector<Pose3>& estimated_cam_from_world) {
  checkSameSize(true_cam_from_world, estimated_cam_from_world);
  const std::size_t num_cameras = true_cam_from_world.size();
  TrajectoryErrors errors;
  const Sim3 truth_from_estimated =
      alignCameraCentres(true_cam_from_world, estimated_cam_from_world);
  for (std::size_t i = 0; i < num_cameras; ++i) {
    const Pose3& truth = true_cam_from_world[i];
    const Pose3& estimate = estimated_cam_from_world[i];
    const Eigen::Vector3d true_centre = truth.inverseTranslation();
    const Eigen::Vector3d centre = estimate.inverseTranslation();
    errors.position_rmse += (centre - true_centre).squaredNorm();
    errors.position_ate_sim3 += (truth_from_estimated * centre - true_centre).squaredNorm();
    errors.rotation_mean_deg +=
        so3::log(estimate.rotation() * truth.rotation().conjugate()).norm() * kRadToDeg;
  }
  errors.position_rmse = std::sqrt(errors.position_rmse / num_cameras);
  errors.position_ate_sim3 = std::sqrt(errors.position_ate_sim3 / num_cameras);
  errors.rotation_mean_deg /= num_cameras;
  return errors;
}

}  // namespace curvesfm
