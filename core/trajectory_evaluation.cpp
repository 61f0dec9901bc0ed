#include "core/trajectory_evaluation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <tuple>

#include "core/angles.h"
#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

// The camera centres (world_from_cam translations) of the matched poses of one trajectory, as
// columns; `side` picks the index into `poses` from a match.
Eigen::Matrix3Xd matchedCentres(const std::vector<StampedPose>& poses,
                                const std::vector<TimestampMatch>& matches,
                                int TimestampMatch::*side) {
  Eigen::Matrix3Xd centres(3, static_cast<Eigen::Index>(matches.size()));
  for (std::size_t k = 0; k < matches.size(); ++k) {
    centres.col(static_cast<Eigen::Index>(k)) =
        poses[matches[k].*side].world_from_cam.translation();
  }
  return centres;
}

std::vector<MatchedPose> alignedPoses(const std::vector<StampedPose>& estimate,
                                      const std::vector<StampedPose>& ground_truth,
                                      const std::vector<TimestampMatch>& matches,
                                      const Sim3& ground_truth_from_estimate) {
  std::vector<MatchedPose> poses;
  poses.reserve(matches.size());
  for (const TimestampMatch& match : matches) {
    const StampedPose& e = estimate[match.estimate_index];
    const StampedPose& g = ground_truth[match.ground_truth_index];
    const Pose3 aligned = ground_truth_from_estimate.transformPose(e.world_from_cam);
    const double error = (aligned.translation() - g.world_from_cam.translation()).norm();
    poses.push_back({match, e.timestamp, g.timestamp, g.world_from_cam, aligned, error});
  }
  return poses;
}

// Throws TrajectoryEvaluationError when the matches cannot carry the requested alignment.
void checkAlignable(const TrajectoryEvaluation& evaluation,
                    const Eigen::Matrix3Xd& estimated_centres, const std::string& estimate_name,
                    const std::string& ground_truth_name) {
  const TrajectoryEvaluationOptions& options = evaluation.options;
  const int matched = static_cast<int>(estimated_centres.cols());
  if (matched < minimumMatches(options.alignment)) {
    throw TrajectoryEvaluationError(
        estimate_name, ground_truth_name,
        "matched " + std::to_string(matched) + " of " + std::to_string(evaluation.estimate_poses) +
            " estimated poses (" + std::to_string(evaluation.ground_truth_poses) +
            " ground-truth) within max_dt " + formatOptionValue(options.max_dt) + " s; " +
            toString(options.alignment) + " alignment needs at least " +
            std::to_string(minimumMatches(options.alignment)));
  }
  if (options.alignment == AlignmentKind::kSim3 && !hasSpreadForScale(estimated_centres)) {
    throw TrajectoryEvaluationError(
        estimate_name, ground_truth_name,
        "the " + std::to_string(matched) +
            " matched estimated camera centres coincide, so sim3 alignment has no scale to "
            "estimate; use se3 or none");
  }
}

void computeRelativeErrors(TrajectoryEvaluation* evaluation) {
  const std::vector<MatchedPose>& m = evaluation->matches;
  const std::size_t delta = static_cast<std::size_t>(evaluation->options.rpe_delta);
  for (std::size_t k = 0; k + delta < m.size(); ++k) {
    const Pose3 true_motion = m[k].ground_truth.inverse() * m[k + delta].ground_truth;
    const Pose3 motion = m[k].aligned_estimate.inverse() * m[k + delta].aligned_estimate;
    const Pose3 error = true_motion.inverse() * motion;
    evaluation->rpe_translation.push_back(error.translation().norm());
    evaluation->rpe_rotation_deg.push_back(so3::log(error.rotation()).norm() * kRadToDeg);
  }
  evaluation->rpe_translation_stats = computeErrorStatistics(evaluation->rpe_translation);
  evaluation->rpe_rotation_stats = computeErrorStatistics(evaluation->rpe_rotation_deg);
}

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

// Pose k stamped with time k, camera-to-world as StampedPose holds it.
std::vector<StampedPose> stampedByIndex(const std::vector<Pose3>& cam_from_world) {
  std::vector<StampedPose> poses(cam_from_world.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    poses[k] = {static_cast<double>(k), cam_from_world[k].inverse()};
  }
  return poses;
}

}  // namespace

void TrajectoryEvaluationOptions::validate() const {
  const OptionCheck require("TrajectoryEvaluationOptions");
  require(std::isfinite(max_dt) && max_dt >= 0.0, "max_dt", max_dt,
          "must be finite and >= 0 (seconds)");
  require(rpe_delta >= 1, "rpe_delta", rpe_delta, "must be >= 1 (frames)");
}

ErrorStatistics computeErrorStatistics(const std::vector<double>& errors) {
  ErrorStatistics stats;
  if (errors.empty()) return stats;
  const double n = static_cast<double>(errors.size());
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0, sum_squares = 0.0;
  for (double e : sorted) {
    sum += e;
    sum_squares += e * e;
  }
  stats.count = static_cast<int>(errors.size());
  stats.mean = sum / n;
  stats.rmse = std::sqrt(sum_squares / n);
  double deviation = 0.0;
  for (double e : sorted) deviation += (e - stats.mean) * (e - stats.mean);
  // Two passes rather than rmse^2 - mean^2, which cancels badly when all errors are alike.
  stats.std = std::sqrt(deviation / n);
  const std::size_t middle = sorted.size() / 2;
  stats.median =
      sorted.size() % 2 == 1 ? sorted[middle] : 0.5 * (sorted[middle - 1] + sorted[middle]);
  stats.min = sorted.front();
  stats.max = sorted.back();
  return stats;
}

TrajectoryEvaluationError::TrajectoryEvaluationError(const std::string& estimate_name,
                                                     const std::string& ground_truth_name,
                                                     const std::string& problem)
    : Error("TrajectoryEvaluationError: " + estimate_name + " vs " + ground_truth_name + ": " +
            problem) {}

int minimumMatches(AlignmentKind alignment) { return alignment == AlignmentKind::kNone ? 1 : 3; }

TrajectoryEvaluation compareTrajectories(const std::vector<StampedPose>& estimate,
                                         const std::vector<StampedPose>& ground_truth,
                                         const TrajectoryEvaluationOptions& options,
                                         const std::string& estimate_name,
                                         const std::string& ground_truth_name) {
  options.validate();
  TrajectoryEvaluation evaluation;
  evaluation.options = options;
  evaluation.estimate_poses = static_cast<int>(estimate.size());
  evaluation.ground_truth_poses = static_cast<int>(ground_truth.size());
  const std::vector<TimestampMatch> matches =
      associateByTimestamp(estimate, ground_truth, options.max_dt);
  const Eigen::Matrix3Xd estimated_centres =
      matchedCentres(estimate, matches, &TimestampMatch::estimate_index);
  checkAlignable(evaluation, estimated_centres, estimate_name, ground_truth_name);
  evaluation.ground_truth_from_estimate = alignPointSets(
      estimated_centres, matchedCentres(ground_truth, matches, &TimestampMatch::ground_truth_index),
      options.alignment);
  evaluation.matches =
      alignedPoses(estimate, ground_truth, matches, evaluation.ground_truth_from_estimate);

  std::vector<double> position_errors;
  for (const MatchedPose& m : evaluation.matches) position_errors.push_back(m.position_error);
  evaluation.ate = computeErrorStatistics(position_errors);
  computeRelativeErrors(&evaluation);
  return evaluation;
}

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
  TrajectoryEvaluationOptions by_index;
  by_index.max_dt = 0.0;  // Pose k is stamped k on both sides, so only k matches k.
  const TrajectoryEvaluation ate =
      compareTrajectories(stampedByIndex(estimated_cam_from_world),
                          stampedByIndex(true_cam_from_world), by_index, "estimated", "true");
  TrajectoryErrors errors;
  errors.position_ate_sim3 = ate.ate.rmse;
  const std::size_t num_cameras = true_cam_from_world.size();
  for (std::size_t i = 0; i < num_cameras; ++i) {
    const Pose3& truth = true_cam_from_world[i];
    const Pose3& estimate = estimated_cam_from_world[i];
    errors.position_rmse +=
        (estimate.inverseTranslation() - truth.inverseTranslation()).squaredNorm();
    errors.rotation_mean_deg +=
        so3::log(estimate.rotation() * truth.rotation().conjugate()).norm() * kRadToDeg;
  }
  errors.position_rmse = std::sqrt(errors.position_rmse / num_cameras);
  errors.rotation_mean_deg /= num_cameras;
  return errors;
}

}  // namespace curvesfm
