#include "factors/point_bundle_adjustment.h"

#include <cmath>

#include "core/check.h"
#include "core/errors.h"
#include "factors/point_reprojection_factor.h"

namespace curvesfm {

void PointBundleAdjustmentOptions::validate() const {
  const OptionCheck require("PointBundleAdjustmentOptions");
  require.positive("pixel_sigma", pixel_sigma);
  require.positive("kernel_width", kernel_width);
  require.positive("scale_sigma", scale_sigma);
}

PointBundleAdjustmentProblem buildPointBundleAdjustment(
    const PointBundleAdjustmentInput& input, const PointBundleAdjustmentOptions& options) {
  options.validate();
  CURVESFM_CHECK(input.camera != nullptr) << "point bundle adjustment needs a camera";
  PointBundleAdjustmentProblem problem;
  for (std::size_t i = 0; i < input.cam_from_world.size(); ++i) {
    problem.values.insert(poseKey(i), input.cam_from_world[i]);
  }
  for (std::size_t p = 0; p < input.points.size(); ++p) {
    problem.values.insert(pointKey(p), input.points[p]);
  }
  if (options.refine_focal) problem.values.insert(focalScaleKey(), 1.0);

  const NoiseModel pixel_noise{options.pixel_sigma,
                               RobustKernel(options.kernel, options.kernel_width)};
  const int num_cameras = static_cast<int>(input.cam_from_world.size());
  const int num_points = static_cast<int>(input.points.size());
  for (const PointObservation& obs : input.observations) {
    CURVESFM_CHECK(obs.camera_index >= 0 && obs.camera_index < num_cameras &&
                   obs.point_index >= 0 && obs.point_index < num_points)
        << "observation of point " << obs.point_index << " in camera " << obs.camera_index
        << " is out of range (" << num_points << " points, " << num_cameras << " cameras)";
    if (options.refine_focal) {
      problem.graph.emplace<FocalPointReprojectionFactor>(
          poseKey(obs.camera_index), pointKey(obs.point_index), focalScaleKey(), obs.pixel,
          input.camera, pixel_noise);
    } else {
      problem.graph.emplace<PointReprojectionFactor>(poseKey(obs.camera_index),
                                                     pointKey(obs.point_index), obs.pixel,
                                                     input.camera, pixel_noise);
    }
  }

  if (options.fix_first_pose && num_cameras > 0) problem.config.setConstant(poseKey(0));
  if (options.fix_scale) {
    addScaleGauge(input.cam_from_world, input.scale_distance, options.scale_sigma, &problem.graph);
  }
  return problem;
}

std::vector<Eigen::Vector3d> extractPoints(const Values& values, std::size_t num_points) {
  std::vector<Eigen::Vector3d> points;
  for (std::size_t p = 0; p < num_points; ++p) {
    points.push_back(values.at<Eigen::Vector3d>(pointKey(p)));
  }
  return points;
}

double extractFocalScale(const Values& values) {
  return values.exists(focalScaleKey()) ? values.at<double>(focalScaleKey()) : 1.0;
}

}  // namespace curvesfm
