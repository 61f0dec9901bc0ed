#pragma once

#include <vector>

#include "factors/curve_bundle_adjustment.h"

namespace curvesfm {

// What each curve of a curve bundle adjustment contributes (issue 14's diagnosis: which curves
// pull the poses where). Read at the BA input's values, usually after the last global BA:
//  - residual RMS over its samples in every keyframe that observes it (px; a capped sample, one
//    beyond the field's reach or off the image, counts at the cap);
//  - its track (observations and distinct keyframes), length, the median distance from the
//    observing cameras to its middle and the widest angle between their rays there (a curve seen
//    from nearly one direction has a poorly constrained depth);
//  - its pull on the poses: the norm of its edge factors' part of the cost gradient with respect
//    to each observing pose, J_pose^T rho'(s) r / sigma^2 with the robust kernel's weight,
//    summed over the poses free to move (whitened px per tangent unit: rotation and translation
//    mixed, so a ranking, not a physical quantity), and that as a share of all curves' pull. At a
//    converged BA the whole gradient is near zero, but each curve's part of it is what the other
//    terms hold back: a few curves with most of the pull are the ones moving the trajectory.
struct CurveStatistics {
  int observations = 0;  ///< (segment, keyframe) observations.
  int keyframes = 0;     ///< Distinct keyframes observing it (its track length).
  /// The first keyframe observing it (the pipeline reports the keyframe that started it).
  int first_keyframe = -1;
  int last_keyframe = -1;  ///< The last keyframe observing it.
  /// The observing keyframe where its residual RMS is largest (the first of equals; -1 when no
  /// sample was evaluated): where an overlay shows it worst.
  int worst_keyframe = -1;
  double residual_rms_px = 0.0;          ///< RMS of its sample residuals (px).
  double length = 0.0;                   ///< Arc length (the input's length unit).
  /// Its chords' sum over their references' (CurveBundleAdjustmentInput::
  /// segment_reference_lengths; 1 without them): below 1 the curve has shrunk since it was made,
  /// near 0 it has collapsed onto a point of an edge, which fits every view.
  double chord_ratio = 1.0;
  double median_camera_distance = 0.0;   ///< Observing camera centres to its middle (length unit).
  double triangulation_angle_deg = 0.0;  ///< Widest angle between observing rays at its middle.
  /// How far the curve runs out of the epipolar planes of its views (deg): per sample, the widest
  /// angle over pairs of observing centres between its tangent and the plane through the sample
  /// and the pair; the median over its samples. Near 0 the curve runs along every epipolar line
  /// it is seen on, so its depth along itself is not observed: the edge residuals hold it
  /// equally well tilted in depth (a sideways walk past a horizontal edge, an orbit past a
  /// horizontal ledge), and 0 when its observing centres all coincide (no baseline). 90 when
  /// fewer than two keyframes observe it: nothing to judge.
  double epipolar_angle_deg = 90.0;
  double pose_pull = 0.0;                ///< See above.
  double pose_pull_share = 0.0;  ///< pose_pull over the sum of all curves' (0 when none pull).
};

/// One entry per input curve, in input order. Builds the curve BA's graph
/// (buildCurveBundleAdjustment) to evaluate its edge factors; the other terms are not counted.
std::vector<CurveStatistics> curveStatistics(const CurveBundleAdjustmentInput& input,
                                             const CurveBundleAdjustmentOptions& options);

}  // namespace curvesfm
