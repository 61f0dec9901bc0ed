#pragma once

#include <Eigen/Core>
#include <cmath>

#include "factors/curve_bundle_adjustment.h"

namespace curvesfm {

/// How precisely the curves of a curve bundle adjustment fix the camera centres (issue 14: do the
/// curves carry what a target asks, or is the target below what the images hold?). The curves'
/// counterpart of predictedCentreAte for points: the rms centre error after a Sim(3) alignment
/// that noise on the edge residuals alone would leave at the optimum, to first order, from the
/// information of the curve observations (the edge factors with the robust kernel's weight at
/// `values`, the length and tangent terms on the structure), every curve eliminated. Priors on
/// the poses, the gauge and the hybrid graph's points do not count.
///
/// A lower bound under its noise model, and two models are given, since a segment's samples are
/// not independent (neighbouring samples meet neighbouring edge pixels, and the curve's own shape
/// error is smooth):
///  - independent samples;
///  - errors along each observation's samples correlated as AR(1) with the lag-1 correlation of
///    the residuals (consecutive live samples, pooled over the observations within 3 sigmas).
/// Both know no bias, no wrong association and no error of the camera.
struct CurveCentrePrecision {
  int observations = 0;  ///< Edge observations with at least one live sample.
  int samples = 0;       ///< Live samples (within the field's reach, not capped).
  /// Std dev of a live sample's residual (px), robust: 1.4826 x the median absolute residual.
  double pixel_sigma = 0.0;
  /// Lag-1 correlation of consecutive live samples' residuals within an observation.
  double sample_correlation = 0.0;
  /// Predicted centre ATE, independent samples / AR(1) samples (the poses' length unit); infinite
  /// where the curves leave more than the similarity free; NaN before it was computed.
  double predicted_centre_ate = std::nan("");
  double predicted_centre_ate_correlated = std::nan("");
  double seconds = 0.0;  ///< Wall time of computing it.
};

/// The curves' information on the poses (6 rows per keyframe, Pose3's tangent) that
/// curveCentrePrecision inverts, for edge noise of std dev `pixel_sigma` (px) per live sample,
/// AR(1) with `correlation` (|.| < 1) along each observation's samples. Observations in keyframes
/// >= `keyframes` do not count.
Eigen::MatrixXd curvePoseInformation(const CurveBundleAdjustmentProblem& problem, int keyframes,
                                     double pixel_sigma, double correlation);

/// The figure above for the first `keyframes` poses (poseKey(0 .. keyframes - 1)) of `problem`,
/// at its values.
CurveCentrePrecision curveCentrePrecision(const CurveBundleAdjustmentProblem& problem,
                                          int keyframes);

}  // namespace curvesfm
