#include "factors/pose_variables.h"

#include "core/check.h"
#include "factors/pose_prior_factor.h"

namespace curvesfm {

void addScaleGauge(const std::vector<Pose3>& cam_from_world, double distance, double sigma,
                   FactorGraph* graph) {
  CURVESFM_CHECK(cam_from_world.size() >= 2) << "fixing the scale needs two poses";
  const double fixed =
      distance > 0.0 ? distance : cameraCentreDistance(cam_from_world[1], cam_from_world[0]);
  graph->emplace<CameraDistanceFactor>(poseKey(0), poseKey(1), fixed, NoiseModel{sigma, {}});
}

std::vector<Pose3> extractPoses(const Values& values, std::size_t num_poses) {
  std::vector<Pose3> poses;
  poses.reserve(num_poses);
  for (std::size_t i = 0; i < num_poses; ++i) poses.push_back(values.at<Pose3>(poseKey(i)));
  return poses;
}

}  // namespace curvesfm
