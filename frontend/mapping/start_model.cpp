#include "frontend/mapping/start_model.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/errors.h"
#include "core/pose3.h"
#include "core/so3.h"
#include "frontend/image/absolute_pose.h"

namespace curvesfm {

void StartModelOptions::validate() const {
  const OptionCheck require("StartModelOptions");
  require(min_points >= 6, "min_points", min_points, ">= 6");
  require(min_frames >= 3, "min_frames", min_frames, ">= 3");
  require.positive("min_rotation_deg", min_rotation_deg);
  require.positive("min_rotation_to_measurement", min_rotation_to_measurement);
  require(max_variogram_lag >= 2 && max_variogram_lag <= 100, "max_variogram_lag",
          max_variogram_lag, "in [2, 100]");
  require.positive("max_variogram_growth", max_variogram_growth);
  require(prior_sigma_scale > 0.0 && prior_sigma_scale <= 10.0, "prior_sigma_scale",
          prior_sigma_scale, "in (0, 10]");
  require(rotation_prior_sigma_scale > 0.0 && rotation_prior_sigma_scale <= 100.0,
          "rotation_prior_sigma_scale", rotation_prior_sigma_scale, "in (0, 100]");
  require.positive("max_reprojection_error_px", max_reprojection_error_px);
  require(relift_passes >= 0 && relift_passes <= 100, "relift_passes", relift_passes,
          "in [0, 100]");
  require(reassociation_rounds >= -1 && reassociation_rounds <= 100, "reassociation_rounds",
          reassociation_rounds, "-1 or in [0, 100]");
}

namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;

// How one frame moves from its given pose to the pose its points give it.
struct FrameMove {
  int frame = -1;
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  // Rotation vector, camera frame (rad).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();    // World frame, pose units.
  // The PnP rotation's own variance, summed over its three axes (rad^2): what the move would be
  // for a start without error.
  double rotation_variance = 0.0;
};

// The points and pixels of every frame, by frame.
struct FrameCorrespondences {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
};

std::vector<FrameCorrespondences> correspondencesByFrame(const PointInitialisation& init,
                                                         bool two_view_points) {
  const std::vector<InitialisedPoint>& points =
      two_view_points && !init.two_view_points.empty() ? init.two_view_points : init.points;
  std::vector<FrameCorrespondences> by_frame(init.frames.size());
  for (const InitialisedPoint& point : points) {
    for (const TrackObservation& o : point.observations) {
      by_frame[o.frame].points.push_back(point.position);
      by_frame[o.frame].pixels.push_back(o.pixel);
    }
  }
  return by_frame;
}

// The variance of a PnP pose's rotation, summed over its axes (rad^2): sigma^2 (J^T J)^-1 of the
// reprojection residuals of its inliers, sigma from their own scatter. Only the pixels' noise:
// the points' errors, shared between frames, are what the moves measure.
double pnpRotationVariance(const Camera& camera, const FrameCorrespondences& c,
                           const AbsolutePose& pose) {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  double squared_residuals = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (!pose.inliers[i]) continue;
    const Eigen::Vector3d x = pose.cam_from_world * c.points[i];
    Eigen::Vector2d pixel;
    Matrix23d d_pixel_d_cam;
    if (!camera.project(x, &pixel, &d_pixel_d_cam)) continue;
    // d(exp(w) x + u) / d[w; u] = [-[x]x, I].
    Eigen::Matrix<double, 2, 6> J;
    J.leftCols<3>() = -d_pixel_d_cam * so3::hat(x);
    J.rightCols<3>() = d_pixel_d_cam;
    H.noalias() += J.transpose() * J;
    squared_residuals += (pixel - c.pixels[i]).squaredNorm();
    ++count;
  }
  if (count <= 6) return 0.0;
  const double sigma2 = squared_residuals / (2.0 * count - 6.0);
  const Eigen::Matrix<double, 6, 6> covariance = sigma2 * H.inverse();
  return covariance.topLeftCorner<3, 3>().trace();
}

std::vector<FrameMove> measureFrameMoves(const Camera& camera, const PointInitialisation& init,
                                         const StartModelOptions& options) {
  AbsolutePoseOptions pnp;
  pnp.max_reprojection_error_px = options.max_reprojection_error_px;
  pnp.min_inliers = options.min_points;
  const std::vector<FrameCorrespondences> by_frame =
      correspondencesByFrame(init, options.two_view_points);
  std::vector<FrameMove> moves;
  for (std::size_t f = 0; f < init.frames.size(); ++f) {
    const std::optional<Pose3>& given = init.frames[f].cam_from_world;
    if (!given || static_cast<int>(by_frame[f].points.size()) < options.min_points) continue;
    const AbsolutePose pose =
        estimateAbsolutePose(camera, by_frame[f].points, by_frame[f].pixels, pnp);
    if (!pose.accepted) continue;
    moves.push_back({static_cast<int>(f),
                     so3::log(pose.cam_from_world.rotation() * given->rotation().inverse()),
                     pose.cam_from_world.inverseTranslation() - given->inverseTranslation(),
                     pnpRotationVariance(camera, by_frame[f], pose)});
  }
  return moves;
}

// The mean distance between consecutive posed frames' camera centres (pose units).
double meanPosedStep(const PointInitialisation& init) {
  std::vector<Pose3> posed;
  for (const InitialisedFrame& frame : init.frames) {
    if (frame.cam_from_world) posed.push_back(*frame.cam_from_world);
  }
  return meanCameraStep(posed);
}

// Mean squared difference of the rotation moves of frames `lag` apart (rad^2); none without such
// a pair.
std::optional<double> rotationVariogram(const std::vector<FrameMove>& moves, int lag) {
  double sum = 0.0;
  int pairs = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    while (j < moves.size() && moves[j].frame < moves[i].frame + lag) ++j;
    if (j == moves.size()) break;
    if (moves[j].frame != moves[i].frame + lag) continue;
    sum += (moves[j].rotation - moves[i].rotation).squaredNorm();
    ++pairs;
  }
  if (pairs == 0) return std::nullopt;
  return sum / pairs;
}

}  // namespace

StartModelEstimate estimateStartModel(const Camera& camera, const PointInitialisation& points,
                                      const StartModelOptions& options) {
  options.validate();
  StartModelEstimate estimate;
  const std::vector<FrameMove> moves = measureFrameMoves(camera, points, options);
  estimate.frames_measured = static_cast<int>(moves.size());
  if (moves.empty()) return estimate;

  double rotation_sq = 0.0, centre_sq = 0.0, measurement_sq = 0.0;
  for (const FrameMove& move : moves) {
    rotation_sq += move.rotation.squaredNorm();
    centre_sq += move.centre.squaredNorm();
    measurement_sq += move.rotation_variance;
  }
  estimate.rotation_to_measurement =
      measurement_sq > 0.0 ? std::sqrt(rotation_sq / measurement_sq) : 0.0;
  const double per_axis = 3.0 * static_cast<double>(moves.size());
  estimate.rotation_rms_deg = std::sqrt(rotation_sq / per_axis) * kDegreesPerRadian;
  estimate.centre_rms = std::sqrt(centre_sq / per_axis);
  const double spacing = meanPosedStep(points);
  estimate.centre_rms_spacings = spacing > 0.0 ? estimate.centre_rms / spacing : 0.0;
  estimate.variogram_lag = std::clamp(estimate.frames_measured / 3, 2, options.max_variogram_lag);
  const std::optional<double> v1 = rotationVariogram(moves, 1);
  const std::optional<double> vk = rotationVariogram(moves, estimate.variogram_lag);
  if (v1 && vk && *v1 > 0.0) estimate.variogram_growth = *vk / *v1;

  // Without enough frames, or without frames 1 and k apart, the moves say nothing of the kind.
  if (estimate.frames_measured < options.min_frames || !v1 || !vk) return estimate;
  if (estimate.rotation_rms_deg < options.min_rotation_deg ||
      estimate.rotation_to_measurement < options.min_rotation_to_measurement) {
    estimate.model = StartModel::kConsistent;
  } else if (estimate.variogram_growth > options.max_variogram_growth) {
    estimate.model = StartModel::kDrifting;
  } else {
    estimate.model = StartModel::kPerPose;
  }
  return estimate;
}

bool tiesEachPose(const StartModelEstimate& estimate, const StartModelOptions& options) {
  return estimate.model == StartModel::kPerPose ||
         (estimate.model == StartModel::kDrifting && options.tie_drifting_per_pose);
}

}  // namespace curvesfm
