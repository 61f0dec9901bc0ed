#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

// Registration of a new frame against the map: its pose from 2D-3D correspondences by PnP inside
// RANSAC, then a Levenberg-Marquardt refinement on the inliers (COLMAP's image registration:
// ../shared/reviews/initialiser_anchors.md A.5 item 6; OpenCV's solvePnPRansac and
// solvePnPRefineLM). Accepted only with enough inliers, absolutely and as a fraction, so that a
// frame the map barely sees is reported as unregistered rather than placed by a few points.
//
// Frames and units: pixels are undistorted pinhole pixels of `camera` (distortion removed),
// points in the world frame, the pose cam_from_world in the points' unit. Deterministic: OpenCV's
// RANSAC draws from its own generator, re-seeded by every call.

/// Why a frame was not registered.
enum class AbsolutePoseRejection {
  kNone,            ///< Accepted.
  kTooFewMatches,   ///< Fewer 2D-3D correspondences than min_inliers.
  kNoModel,         ///< RANSAC found no pose.
  kTooFewInliers,   ///< Fewer than min_inliers.
  kLowInlierRatio,  ///< Inliers below min_inlier_ratio of the correspondences.
};

template <>
struct EnumNames<AbsolutePoseRejection> {
  static constexpr std::array<std::pair<AbsolutePoseRejection, const char*>, 5> kNames = {
      {{AbsolutePoseRejection::kNone, "none"},
       {AbsolutePoseRejection::kTooFewMatches, "too_few_matches"},
       {AbsolutePoseRejection::kNoModel, "no_model"},
       {AbsolutePoseRejection::kTooFewInliers, "too_few_inliers"},
       {AbsolutePoseRejection::kLowInlierRatio, "low_inlier_ratio"}}};
};

/// Thresholds of PnP registration (defaults: COLMAP's abs_pose_* and ORB-SLAM's relocalisation).
struct AbsolutePoseOptions {
  /// RANSAC inlier threshold on the reprojection error (px; COLMAP 12 at its image sizes, ORB-SLAM
  /// ~2.4 sigma). Finite, > 0.
  double max_reprojection_error_px = 4.0;
  /// RANSAC confidence (probability of one all-inlier sample). In (0, 1).
  double confidence = 0.9999;
  /// Most RANSAC iterations (count). >= 1.
  int max_iterations = 1000;
  /// Fewest inliers to accept the pose (count; COLMAP 30). >= 4.
  int min_inliers = 30;
  /// Fewest inliers as a fraction of the correspondences (unitless; COLMAP 0.25). In [0, 1].
  double min_inlier_ratio = 0.25;
  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// What estimateAbsolutePose found; inliers and the pose are filled as far as the steps went.
struct AbsolutePose {
  bool accepted = false;
  AbsolutePoseRejection rejection = AbsolutePoseRejection::kNone;
  Pose3 cam_from_world;               ///< The refined pose (identity when no model).
  std::vector<std::uint8_t> inliers;  ///< Per correspondence, 1 if within the threshold.
  int num_inliers = 0;
};

/// The pose of a frame of `camera` from points[i] (world) seen at pixels[i]: AP3P inside RANSAC,
/// then Levenberg-Marquardt on RANSAC's inliers, inliers counted again at the refined pose. Never
/// throws on degenerate data: it rejects with a reason. Throws InvalidOptions for bad options and
/// CheckError when the two lists differ in size.
AbsolutePose estimateAbsolutePose(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const AbsolutePoseOptions& options);

}  // namespace curvesfm
