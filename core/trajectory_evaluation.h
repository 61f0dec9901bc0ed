#pragma once

#include <string>
#include <vector>

#include "core/dataset_io.h"
#include "core/errors.h"
#include "core/pose3.h"
#include "core/similarity_alignment.h"
#include "core/timestamp_association.h"

namespace curvesfm {

// Trajectory evaluation as the TUM RGB-D tools and evo define it (DESIGN.md "Evaluation"):
// associate an estimated and a ground-truth trajectory by timestamp, align the estimate onto the
// ground truth by camera centres, then report
//   - ATE, the absolute trajectory error: |c_gt,k - T * c_est,k| per matched pose k, c being the
//     camera centre and T the alignment (Sim(3), SE(3) or none);
//   - RPE, the relative pose error over `rpe_delta` matched poses: with P_k the aligned estimate
//     and Q_k the ground truth (camera-to-world), E_k = (Q_k^-1 Q_k+d)^-1 (P_k^-1 P_k+d); its
//     translation norm (m) and rotation angle (deg). Relative motions ignore a rigid alignment,
//     but not a Sim(3) one: its scale multiplies the estimate's relative translations.

/// Options of compareTrajectories().
struct TrajectoryEvaluationOptions {
  /// Transform that maps the estimate onto the ground truth before the errors: kSim3 for
  /// monocular estimates (free scale), kSe3 for metric ones, kNone to compare as they are.
  AlignmentKind alignment = AlignmentKind::kSim3;
  /// Largest |t_estimate - t_ground_truth| of a matched pair (s); finite, >= 0. 0.02 s is the
  /// TUM tools' default (a 30 Hz camera against 100 Hz motion capture).
  double max_dt = 0.02;
  /// RPE frame distance d: motions between matched poses k and k + d (in time order); >= 1.
  int rpe_delta = 1;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// Summary statistics of a set of errors, as evo prints them.
struct ErrorStatistics {
  int count = 0;        ///< Number of errors; all figures below are 0 when it is 0.
  double rmse = 0.0;    ///< sqrt(mean of squares).
  double mean = 0.0;    ///< Arithmetic mean.
  double median = 0.0;  ///< Middle value; the mean of the middle two for an even count.
  double std = 0.0;     ///< Population standard deviation (divides by count, as numpy.std).
  double min = 0.0;     ///< Smallest error.
  double max = 0.0;     ///< Largest error.
};

/// Statistics of `errors` (any finite values; none gives the all-zero ErrorStatistics).
ErrorStatistics computeErrorStatistics(const std::vector<double>& errors);

/// A matched pose after alignment.
struct MatchedPose {
  TimestampMatch match;                 ///< Where the two poses come from.
  double estimate_timestamp = 0.0;      ///< s.
  double ground_truth_timestamp = 0.0;  ///< s.
  Pose3 ground_truth;                   ///< world_from_cam of the ground truth.
  Pose3 aligned_estimate;       ///< world_from_cam of the estimate carried into the ground truth's
                                ///< world by the alignment (Sim3::transformPose).
  double position_error = 0.0;  ///< ATE of this pose: distance between the camera centres (m).
};

/// The result of compareTrajectories().
struct TrajectoryEvaluation {
  TrajectoryEvaluationOptions options;  ///< The options it was computed with.
  int estimate_poses = 0;               ///< Poses in the estimated trajectory.
  int ground_truth_poses = 0;           ///< Poses in the ground-truth trajectory.
  std::vector<MatchedPose> matches;     ///< In the estimate's time order.
  /// The alignment applied to the estimate (the identity for AlignmentKind::kNone).
  Sim3 ground_truth_from_estimate;
  ErrorStatistics ate;                   ///< Of MatchedPose::position_error (m).
  std::vector<double> rpe_translation;   ///< |translation of E_k| per relative motion (m).
  std::vector<double> rpe_rotation_deg;  ///< Rotation angle of E_k per relative motion (deg).
  /// Of rpe_translation (m); count 0 when there are no more than rpe_delta matches.
  ErrorStatistics rpe_translation_stats;
  ErrorStatistics rpe_rotation_stats;  ///< Of rpe_rotation_deg (deg); count as above.
};

/// A pair of trajectories that cannot be compared: too few timestamps match, or the matched
/// estimated centres coincide so that no Sim(3) scale exists.
/// Message: "TrajectoryEvaluationError: <estimate> vs <ground truth>: <what went wrong>".
class TrajectoryEvaluationError : public Error {
 public:
  TrajectoryEvaluationError(const std::string& estimate_name, const std::string& ground_truth_name,
                            const std::string& problem);
};

/// Fewest matched poses an alignment needs: 3 for kSim3 and kSe3 (below that the rotation is not
/// determined), 1 for kNone.
int minimumMatches(AlignmentKind alignment);

/// Evaluates `estimate` against `ground_truth` (both camera-to-world, any order) as described at
/// the top of this file. `estimate_name` and `ground_truth_name` (e.g. the file paths) only
/// label error messages. Throws InvalidOptions for invalid `options`, and
/// TrajectoryEvaluationError when fewer than minimumMatches() poses match within max_dt (the
/// message gives both counts) or when Sim(3) alignment meets coinciding estimated centres.
TrajectoryEvaluation compareTrajectories(const std::vector<StampedPose>& estimate,
                                         const std::vector<StampedPose>& ground_truth,
                                         const TrajectoryEvaluationOptions& options,
                                         const std::string& estimate_name = "estimate",
                                         const std::string& ground_truth_name = "ground truth");

// ---------------------------------------------------------------------------------------------
// Index-aligned trajectories (synthetic scenes): both are cam_from_world with pose k of each the
// same frame.

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

/// Index-matched evaluation (synthetic scenes, where pose k of both trajectories is the same
/// frame): position_ate_sim3 is compareTrajectories()' ATE rmse, the figure `run` and `eval`
/// report, so every ATE in the project comes from one code. Needs >= 3 poses.
TrajectoryErrors evaluateTrajectory(const std::vector<Pose3>& true_cam_from_world,
                                    const std::vector<Pose3>& estimated_cam_from_world);

}  // namespace curvesfm
