#include "core/trajectory_evaluation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <tuple>

#include "core/check.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

struct Candidate {
  double dt;
  int estimate_index;
  int ground_truth_index;
};

// Every (estimate, ground truth) pair within max_dt, found by a binary search in the
// ground-truth stamps so that long trajectories do not cost |estimate| * |ground truth|.
std::vector<Candidate> candidatePairs(const std::vector<StampedPose>& estimate,
                                      const std::vector<StampedPose>& ground_truth, double max_dt) {
  std::vector<int> by_time(ground_truth.size());
  std::iota(by_time.begin(), by_time.end(), 0);
  const auto earlier = [&](int a, int b) {
    return ground_truth[a].timestamp < ground_truth[b].timestamp;
  };
  std::stable_sort(by_time.begin(), by_time.end(), earlier);
  std::vector<Candidate> candidates;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const double t = estimate[i].timestamp;
    auto it =
        std::lower_bound(by_time.begin(), by_time.end(), t - max_dt,
                         [&](int g, double value) { return ground_truth[g].timestamp < value; });
    for (; it != by_time.end() && ground_truth[*it].timestamp <= t + max_dt; ++it) {
      const double dt = std::abs(ground_truth[*it].timestamp - t);
      if (dt <= max_dt) candidates.push_back({dt, static_cast<int>(i), *it});
    }
  }
  return candidates;
}

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
            " ground-truth) within max_dt " + formatNumber(options.max_dt) + " s; " +
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

}  // namespace

void TrajectoryEvaluationOptions::validate() const {
  if (!(std::isfinite(max_dt) && max_dt >= 0.0)) {
    throw InvalidOptions("TrajectoryEvaluationOptions", "max_dt", formatNumber(max_dt),
                         "must be finite and >= 0 (seconds)");
  }
  if (rpe_delta < 1) {
    throw InvalidOptions("TrajectoryEvaluationOptions", "rpe_delta", std::to_string(rpe_delta),
                         "must be >= 1 (frames)");
  }
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

std::vector<TimestampMatch> associateByTimestamp(const std::vector<StampedPose>& estimate,
                                                 const std::vector<StampedPose>& ground_truth,
                                                 double max_dt) {
  CURVESFM_CHECK(std::isfinite(max_dt) && max_dt >= 0.0) << "max_dt = " << max_dt;
  std::vector<Candidate> candidates = candidatePairs(estimate, ground_truth, max_dt);
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.dt, a.estimate_index, a.ground_truth_index) <
           std::tie(b.dt, b.estimate_index, b.ground_truth_index);
  });
  std::vector<bool> estimate_used(estimate.size(), false);
  std::vector<bool> ground_truth_used(ground_truth.size(), false);
  std::vector<TimestampMatch> matches;
  for (const Candidate& c : candidates) {
    if (estimate_used[c.estimate_index] || ground_truth_used[c.ground_truth_index]) continue;
    estimate_used[c.estimate_index] = true;
    ground_truth_used[c.ground_truth_index] = true;
    matches.push_back({c.estimate_index, c.ground_truth_index});
  }
  std::sort(matches.begin(), matches.end(), [&](const TimestampMatch& a, const TimestampMatch& b) {
    return std::make_pair(estimate[a.estimate_index].timestamp, a.estimate_index) <
           std::make_pair(estimate[b.estimate_index].timestamp, b.estimate_index);
  });
  return matches;
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

}  // namespace curvesfm
