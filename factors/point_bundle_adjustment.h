#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/point_observation.h"
#include "core/pose3.h"
#include "factors/pose_variables.h"
#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/robust_kernel.h"
#include "graph/values.h"

namespace curvesfm {

/// Weights and gauge of a classic point bundle adjustment.
struct PointBundleAdjustmentOptions {
  double pixel_sigma = 1.0;  ///< Std dev of a pixel measurement (px); > 0.
  RobustKernelType kernel = RobustKernelType::kHuber;  ///< Robust kernel on reprojection errors.
  double kernel_width = 1.0;   ///< Kernel width in sigmas (i.e. pixels at sigma 1); > 0.
  bool fix_first_pose = true;  ///< Hold camera 0 constant (6 of the 7 gauge DoF).
  /// Fix the scale through the distance between cameras 0 and 1 (a CameraDistanceFactor at
  /// PointBundleAdjustmentInput::scale_distance). Needs at least 2 cameras.
  bool fix_scale = true;
  double scale_sigma = 1e-4;  ///< Std dev of that distance constraint (scene units); > 0.
  /// Refine the camera's focal lengths by one factor shared by all images (focalScaleKey(), a
  /// FocalPointReprojectionFactor per observation; aspect ratio, principal point and distortion
  /// held), for a camera whose focal length is known only roughly. Off: the camera as given.
  bool refine_focal = false;

  void validate() const;
};

/// A point bundle adjustment as plain input data: one camera model shared by all images.
struct PointBundleAdjustmentInput {
  std::shared_ptr<const Camera> camera;
  std::vector<Pose3> cam_from_world;    ///< Starting guess per image.
  std::vector<Eigen::Vector3d> points;  ///< Starting guess per point, in world.
  std::vector<PointObservation> observations;
  /// Distance between the centres of cameras 0 and 1 that fixes the scale; <= 0 keeps the
  /// starting distance.
  double scale_distance = 0.0;
};

/// The graph, the starting values (poseKey(i), pointKey(p)) and what is held constant.
struct PointBundleAdjustmentProblem {
  FactorGraph graph;
  Values values;
  ProblemConfig config;
};

/// Builds one PointReprojectionFactor per observation (FocalPointReprojectionFactor with
/// options.refine_focal, the focal scale starting at 1) plus the gauge. Throws CheckError for an
/// observation whose camera or point index is out of range.
PointBundleAdjustmentProblem buildPointBundleAdjustment(
    const PointBundleAdjustmentInput& input, const PointBundleAdjustmentOptions& options);

/// The points of `values`, in input order (extractPoses gives the poses).
std::vector<Eigen::Vector3d> extractPoints(const Values& values, std::size_t num_points);

/// The factor on the camera's focal lengths in `values` (1 when the problem did not refine it).
double extractFocalScale(const Values& values);

/// How precisely `input`'s observations fix its camera centres: the rms centre error after a
/// Sim(3) alignment (the ATE's metric) that pixel noise of std dev `pixel_sigma` per coordinate
/// leaves at the optimum of a BA without robust kernel, to first order (the Cramér-Rao bound of
/// the centres): the information of every observation at `input`'s poses and points, the points
/// eliminated, the seven similarity directions that the alignment takes out projected away.
/// A lower bound on the ATE that such a BA reaches against the truth: it knows no bias, outlier
/// or camera error. Observations behind their camera do not count; points seen fewer than twice
/// carry nothing. Infinite when the observations leave more than the similarity free (cameras
/// that share no point, a camera seeing fewer than three points); 0 for fewer than three cameras
/// (a similarity fits two centres exactly). In input's length unit.
double predictedCentreAte(const PointBundleAdjustmentInput& input, double pixel_sigma);

/// The pixel noise (std dev per coordinate) that `input`'s residuals say: their sum of squares
/// over the observations in front of their cameras of the points seen at least twice, divided
/// by what the fit left free, 2 m - 3 P, less 6 n - 7 when the n poses were fitted too (a BA's
/// optimum). The plain rms understates the noise there: by 0.71 x on three-view tracks. NaN
/// when nothing is left free.
double estimatedPixelSigma(const PointBundleAdjustmentInput& input, bool poses_fitted);

}  // namespace curvesfm
