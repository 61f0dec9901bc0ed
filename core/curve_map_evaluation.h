#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/curve_map_io.h"

namespace curvesfm {

// Curve-map evaluation, as EMAP and NEF define it: precision, recall and F-score of an estimated
// curve map against the ground-truth curves at distance thresholds tau. Both maps are polylines
// in the ground truth's frame and unit (the caller aligns the estimate first, e.g. by the Sim(3)
// of its trajectory: apps/eval_map_command.h). Both are sampled densely along their length and
//   precision(tau) = fraction of the estimate within tau of the ground-truth polylines,
//   recall(tau)    = fraction of the ground truth within tau of the estimated polylines,
//   F(tau)         = 2 P R / (P + R)   (0 when P + R = 0).
// Distances are exact point-to-segment distances (a uniform grid of cell size max tau finds the
// candidates), so only the sampling discretises. Each sample is the midpoint of an equal part of
// one segment, no longer than the spacing, and stands for that part's length: the fractions are
// fractions of curve length, whatever the lengths of the input segments (Pavilion's edges run
// from under a millimetre to 24 m). Counts of samples are reported beside them.
//
// Cropping: a ground truth that covers only part of the scene (Pavilion's cropped region) says
// nothing about estimated curves elsewhere, so precision counts only estimated samples inside the
// ground truth's bounding box enlarged by crop_margin. Recall is measured against the whole
// estimate: with a margin of at least the largest tau, cropping cannot change it anyway.

/// Options of evaluateCurveMap().
struct CurveMapEvaluationOptions {
  /// Distance thresholds tau (ground-truth units, e.g. Pavilion's metre-like Blender units);
  /// at least one, each > 0 and finite, strictly increasing. 1, 2 and 5 cm: the figures.
  std::vector<double> taus = {0.01, 0.02, 0.05};
  /// Longest arc one sample stands for (ground-truth units); >= 0 and finite; 0 takes a tenth of
  /// the smallest tau, so that the sampling moves a fraction by well under a per cent.
  double sample_spacing = 0.0;
  /// Count only estimated samples inside the ground truth's bounding box (grown by crop_margin)
  /// in precision; false counts them all (a ground truth that covers the whole scene).
  bool crop = true;
  /// Growth of that bounding box on every side (ground-truth units); >= 0 and finite. The default
  /// equals the largest default tau, so that an estimate within tau of the ground truth is never
  /// cropped.
  double crop_margin = 0.05;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// The figures at one threshold.
struct CurveMapScore {
  double tau = 0.0;                 ///< Ground-truth units.
  double precision = 0.0;           ///< In [0, 1]; 0 when no estimated sample is inside the crop.
  double recall = 0.0;              ///< In [0, 1]; 0 when the ground truth has no length.
  double f_score = 0.0;             ///< 2PR/(P+R), 0 when both are 0.
  int estimate_samples_within = 0;  ///< Estimated samples inside the crop within tau.
  int ground_truth_samples_within = 0;  ///< Ground-truth samples within tau of the estimate.
};

/// The result of evaluateCurveMap().
struct CurveMapEvaluation {
  CurveMapEvaluationOptions options;  ///< The options it was computed with.
  double sample_spacing = 0.0;        ///< The spacing in force (ground-truth units).
  /// The crop box (the ground truth's bounding box grown by crop_margin), ground-truth frame.
  Eigen::Vector3d crop_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d crop_max = Eigen::Vector3d::Zero();
  int estimate_polylines = 0;
  int estimate_samples = 0;             ///< All samples of the estimate.
  int estimate_samples_inside = 0;      ///< Those inside the crop (all when crop is false).
  double estimate_length = 0.0;         ///< Total length of the estimate (ground-truth units).
  double estimate_length_inside = 0.0;  ///< Its length inside the crop.
  int ground_truth_polylines = 0;
  int ground_truth_samples = 0;
  double ground_truth_length = 0.0;
  std::vector<CurveMapScore> scores;  ///< One per options.taus, in the same order.
};

/// Evaluates `estimate` against `ground_truth` as described at the top of this file; both in the
/// ground truth's frame. Throws InvalidOptions for invalid options. Empty maps are not errors:
/// their fractions are 0 (the counts say why).
CurveMapEvaluation evaluateCurveMap(const Polylines3& estimate, const Polylines3& ground_truth,
                                    const CurveMapEvaluationOptions& options);

}  // namespace curvesfm
