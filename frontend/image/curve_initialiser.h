#pragma once

#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/pose3.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/epipolar_depth.h"

namespace curvesfm {

/// How CurveInitialiser turns a keyframe's chains with depth into poly-Bézier curves (paper §2.3,
/// DESIGN.md "The curve model").
///
/// Lengths are in the world's unit (metres for the defaults); the pipeline works in multiples of
/// its scene scale instead (PipelineOptions::scene_scale, defaultPipelineInitialiserOptions()).
/// min_chord is meant as a guard against collapsed segments, not as a size filter.
struct CurveInitialiserOptions {
  int pixels_per_segment = 12;  ///< Target lifted pixels per segment (chain pixels; the paper's
                                ///< "roughly the same number of pixels"): a run of n points gets
                                ///< max(1, round(n / this)) segments, fewer if one would hold
                                ///< fewer than 4 points. In [4, 10000].
  int min_segments = 1;  ///< Curves (maximal sequences of consecutive accepted segments) with
                         ///< fewer segments are dropped (count). In [1, 10000].
  int max_gap_px = 1;    ///< Gaps of up to this many consecutive pixels without a valid depth
                         ///< are bridged (the fit skips them); a longer gap ends the run (chain
                         ///< pixels). In [0, 100].
  double max_relative_depth_jump = 0.1;     ///< A run ends between consecutive lifted pixels whose
                                            ///< depths differ by more than this fraction of the
                                            ///< smaller one: an occlusion boundary or an outlier
                                            ///< (unitless). In (0, 100].
  double max_rms_residual_rel_chord = 0.1;  ///< A segment is rejected if the RMS distance of its
                                            ///< points to the cubic at their t_k exceeds this
                                            ///< fraction of its chord |P3 - P0|. Exact depths
                                            ///< on integer pixels give 3-5% at 12 px (mostly
                                            ///< the uniform t_k against 1 and 1.41 px steps)
                                            ///< (unitless). In (0, 100].
  double min_chord = 1e-4;        ///< Segments with a shorter chord |P3 - P0| are rejected: their
                                  ///< tangents are undefined (world length unit). In [0, 1e6].
  double max_arm_to_chord = 1.5;  ///< A segment is rejected as a loop or cusp if an arm
                                  ///< |P1 - P0| or |P3 - P2| is longer than this multiple of its
                                  ///< chord, or points against it; a circular arc of angle a has
                                  ///< arms of (2/3) tan(a/4) / sin(a/2) chords (0.33 straight,
                                  ///< 0.67 for a half circle) (unitless). In (0, 100].

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// The chain pixels one segment was fitted to: chain indices first..last (inclusive) of the
/// curve's chain; pixels without depth in between were skipped. Neighbouring segments of a curve
/// share their boundary pixel (last of one == first of the next).
struct PixelRange {
  int first = 0;  ///< Index into EdgeChain::pixels of the segment's first point.
  int last = 0;   ///< Index into EdgeChain::pixels of the segment's last point.
};

/// One initialised curve.
struct InitialCurve {
  PolyBezier curve;  ///< In the world frame, Q_0 at the chain's side of segment_pixels[0].first.
  int chain = -1;    ///< Index of the chain it was lifted from.
  /// segment_pixels[i]: the pixels segment i was fitted to; size curve.numSegments().
  std::vector<PixelRange> segment_pixels;
};

/// What initialisation did with the pixels, runs and segments it was given, for reports. Every
/// lifted pixel ends in one run or one too-short run; every fitted segment is accepted or
/// rejected for exactly one reason (checked in that order: chord, loop, fit).
struct CurveInitialisationCounts {
  int pixels = 0;                   ///< Chain pixels seen.
  int pixels_lifted = 0;            ///< ... of which had a valid, finite, positive depth.
  int depth_jumps = 0;              ///< Runs ended at a depth jump (max_relative_depth_jump).
  int runs = 0;                     ///< Runs of >= 4 lifted pixels, split into segments.
  int runs_too_short = 0;           ///< Runs of 1-3 lifted pixels, dropped: a cubic needs 4.
  int segments_accepted = 0;        ///< Fitted segments kept (before the min_segments filter).
  int segments_short_chord = 0;     ///< Rejected by min_chord.
  int segments_loop = 0;            ///< Rejected by max_arm_to_chord.
  int segments_bad_fit = 0;         ///< Rejected by max_rms_residual_rel_chord.
  int curves = 0;                   ///< Curves returned.
  int curves_too_few_segments = 0;  ///< Curves dropped by min_segments.

  int segmentsRejected() const { return segments_short_chord + segments_loop + segments_bad_fit; }
};

/// The curves of one keyframe and what happened on the way.
struct CurveInitialisation {
  std::vector<InitialCurve> curves;  ///< In chain order, then along each chain.
  CurveInitialisationCounts counts;
};

/// Initialises world-frame poly-Bézier curves from a keyframe's edge chains and their depths
/// (paper §2.3). Per chain:
///  1. Runs: the chain is cut into runs of pixels with a valid depth; gaps of at most
///     max_gap_px invalid pixels are bridged, longer gaps and depth jumps end a run. Closed
///     chains are treated as open at their first pixel (a PolyBezier has two ends).
///  2. Lifting (paper eq. 4): p_w = world_from_cam * camera.unproject(pixel, depth).
///  3. Splitting: a run of n points becomes k segments with boundaries at the points
///     round(j (n - 1) / k), j = 0..k, so neighbours share their boundary point and hold
///     roughly equal pixel counts (k, see pixels_per_segment).
///  4. Fitting: BezierFitter (t_k = k / (m - 1), linear least squares).
///  5. Rejection: short chord, loop or cusp, bad fit (see the options). A rejected segment cuts
///     the run; each maximal sequence of accepted segments is one curve.
///  6. Linking: linkSegments (shared Q, averaged unit tangents, arm lengths from the fit);
///     curves with fewer than min_segments segments are dropped.
/// Immutable after construction; initialise() may be called concurrently.
class CurveInitialiser {
 public:
  /// Throws InvalidOptions on bad options.
  explicit CurveInitialiser(const CurveInitialiserOptions& options = {});

  const CurveInitialiserOptions& options() const { return options_; }

  /// `camera`: the camera the chains were extracted in (ImageUndistorter::camera()); pixels are
  /// lifted with Camera::unproject, depths are z in that camera (PixelDepth::depth).
  /// `cam_from_world`: the keyframe's pose. `depths.chains[c][i]` belongs to
  /// `chains[c].pixels[i]` (estimateChainDepths). A valid depth that is not finite and positive
  /// is treated as invalid. Throws CheckError if the depths do not match the chains.
  CurveInitialisation initialise(const Camera& camera, const Pose3& cam_from_world,
                                 const std::vector<EdgeChain>& chains,
                                 const ChainDepths& depths) const;

 private:
  CurveInitialiserOptions options_;
};

}  // namespace curvesfm
