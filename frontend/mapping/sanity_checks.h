#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/bezier.h"
#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

// The sanity of a run (issue 14): a curve that cannot belong to the scene (one that leaves the
// region the cameras and points span, or is longer than that region) is dropped from the map, and
// a run whose map or trajectory is implausible says so. Monocular poses have an arbitrary unit, so
// nothing here is in metres: the extent comes from the scene itself and pose moves are counted in
// keyframe spacings.

/// The sanity checks of the pipeline (PipelineOptions::sanity): which curves are implausible and
/// when a run gets a verdict.
struct SanityOptions {
  /// Drop every curve that leaves the scene's extent (sceneExtent) or is longer than its diagonal
  /// from the map: from the global BAs that follow and from the result. Off, such curves are only
  /// listed (checked once, on the final map).
  bool drop_implausible_curves = true;
  /// The extent spans the points between this percentile and 100 minus it on each axis (%), so
  /// that a few stray points (or, without points, a few runaway curves) do not widen it. In
  /// [0, 25].
  double extent_percentile = 2.0;
  /// Every face of that box moves out by this fraction of its diagonal (unitless): 1 adds the
  /// whole diagonal on every side (a cube's diagonal grows 4.5 times). Covers the background
  /// beyond the points and a curve's ends past them: on Pavilion the curves beyond the points'
  /// box thin out continuously to 0.67 diagonals (one at 1.1), and 0.5 dropped 20 of that tail
  /// (refined ATE 30.4 mm against 28.8 mm keeping them), while a runaway curve lies tens to
  /// thousands of diagonals out. Finite, >= 0.
  double extent_margin = 1.0;
  /// Samples per curve segment tested against the extent and summed into the curve's length
  /// (count). In [1, 1000].
  int samples_per_segment = 8;
  /// After each global BA, a curve whose residual RMS over all its observations exceeds this
  /// (px) is implausible too (dropped with drop_implausible_curves): a curve lifted from a wrong
  /// match, or an occluding contour, fits no set of poses, and left in the map it pulls them
  /// towards its own error. A capped sample counts at the cap (CurveStatistics). >= 0; 0 off.
  double max_curve_residual_px = 0.0;
  /// After each global BA, a curve whose chords sum to less than this fraction of their lengths
  /// at creation (CurveStatistics::chord_ratio) is implausible too. In [0, 1); 0 off.
  double min_chord_ratio = 0.0;
  /// Before the first global BA and after each, a curve whose median sample runs within this
  /// angle of the epipolar planes of its views (CurveStatistics::epipolar_angle_deg) is
  /// implausible too (deg): its depth along itself is unobserved, so the BA keeps it wherever it
  /// was lifted, often tilted in depth. Off by default: such curves still hold the poses across
  /// their edges, and dropping them made Pavilion's trajectories worse (docs/benchmarks.md,
  /// "Curves along their epipolar planes"). In [0, 90); 0 off.
  double min_epipolar_angle_deg = 0.0;
  /// Verdict when more than this fraction of the curves that reached the global map were
  /// implausible (unitless). In [0, 1].
  double max_implausible_fraction = 0.5;
  /// Verdict when a refined keyframe centre lies more than this many keyframe spacings (the median
  /// distance between consecutive initial keyframe centres) from its initial centre, after the
  /// Sim(3) alignment of the refined centres onto the initial ones (largestPoseMove). Global BA
  /// corrects a start by a fraction of a spacing (README demo 0.06, templeRing 0.009; the motion
  /// prior's sigma is 0.03 spacings a step); a whole spacing is far beyond the start's
  /// uncertainty. Finite, > 0.
  double max_pose_move_spacings = 1.0;
  /// Verdict when the run has fewer keyframes (count). >= 0.
  int min_keyframes = 3;
  /// Verdict when the final map has fewer curves (count). >= 0.
  int min_curves = 10;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// An axis-aligned box of the scene, world frame; empty (min > max) when nothing spans it.
struct SceneExtent {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(1.0);
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-1.0);
  /// Where the box came from besides the cameras: "points", "curves" or "" (cameras alone).
  std::string source;

  /// True when the box is not empty and its diagonal is positive and finite.
  bool valid() const;
  /// |max - min|; 0 when empty.
  double diagonal() const;
  bool contains(const Eigen::Vector3d& point) const;
  /// The box with every length multiplied by `factor` (> 0), e.g. back to pose units.
  SceneExtent scaled(double factor) const;
};

/// The scene's extent: the box of every camera centre and of `points` between the percentiles
/// (SanityOptions::extent_percentile, per axis), enlarged on every side by extent_margin times
/// its diagonal. `source` names what `points` are ("points" or "curves"; "" when empty). Invalid
/// (SceneExtent::valid) when the box has no positive diagonal, e.g. one camera and no points.
SceneExtent sceneExtent(const std::vector<Eigen::Vector3d>& camera_centres,
                        const std::vector<Eigen::Vector3d>& points, const std::string& source,
                        const SanityOptions& options);

/// Why a curve is implausible.
enum class CurveImplausibility {
  kNone,              ///< Plausible.
  kOutsideExtent,     ///< A sample lies outside the scene's extent.
  kLongerThanExtent,  ///< Inside, but longer than the extent's diagonal.
  /// Its residual RMS over its observations exceeds SanityOptions::max_curve_residual_px after a
  /// global BA: it does not fit its own views.
  kHighResidual,
  /// Its chords sum to less than SanityOptions::min_chord_ratio of their lengths at creation
  /// after a global BA: it has collapsed towards a point of an edge, which fits any view.
  kCollapsed,
  /// It runs within SanityOptions::min_epipolar_angle_deg of its views' epipolar planes: its
  /// depth along itself is unobserved.
  kAlongEpipolar,
};

template <>
struct EnumNames<CurveImplausibility> {
  static constexpr std::array<std::pair<CurveImplausibility, const char*>, 6> kNames = {{
      {CurveImplausibility::kNone, "none"},
      {CurveImplausibility::kOutsideExtent, "outside_extent"},
      {CurveImplausibility::kLongerThanExtent, "longer_than_extent"},
      {CurveImplausibility::kHighResidual, "high_residual"},
      {CurveImplausibility::kCollapsed, "collapsed"},
      {CurveImplausibility::kAlongEpipolar, "along_epipolar"},
  }};
};

/// One curve judged against the extent.
struct CurveCheck {
  CurveImplausibility reason = CurveImplausibility::kNone;
  /// Length of the sampled polyline (the curve's unit): a lower bound of the arc length.
  double length = 0.0;
};

/// Samples `curve` (samples_per_segment per segment, PolyBezier::sample) and judges it: outside
/// when a sample lies outside `extent`, else too long when its length exceeds the extent's
/// diagonal. A non-finite sample counts as outside. Plausible when `extent` is not valid.
CurveCheck checkCurve(const PolyBezier& curve, const SceneExtent& extent, int samples_per_segment);

/// A curve the sanity checks found implausible (PipelineResult::sanity).
struct ImplausibleCurve {
  int id = -1;        ///< Its id in the curve map (CurveMap), not its index in the result.
  int segments = 0;   ///< Segment count.
  double length = 0;  ///< Sampled length, in the unit of the poses given.
  CurveImplausibility reason = CurveImplausibility::kNone;
  /// Global BAs that had run when it was found (0: before the first, or no global BA).
  int after_global_bas = 0;
  bool dropped = false;  ///< Dropped from the map (SanityOptions::drop_implausible_curves).
};

/// The largest move of a refined keyframe away from its initial pose (largestPoseMove).
struct PoseMove {
  int keyframe = -1;      ///< Keyframe index; -1 when not measured (fewer than 3 keyframes...).
  double distance = 0.0;  ///< Camera-centre distance after alignment, the initial poses' unit.
  double spacing = 0.0;   ///< Median distance of consecutive initial keyframe centres, same unit.
  /// distance / spacing; 0 when not measured.
  double spacings() const { return spacing > 0.0 ? distance / spacing : 0.0; }
};

/// Aligns the refined camera centres onto the initial ones by the least-squares Sim(3) (a
/// monocular refinement may rescale, rotate and shift the whole trajectory, which is no move),
/// and returns the keyframe whose aligned centre lies farthest from its initial centre. Not
/// measured (keyframe -1) with fewer than 3 keyframes, centres without spread, or a zero median
/// spacing. Both vectors are cam_from_world and of equal size (CheckError otherwise).
PoseMove largestPoseMove(const std::vector<Pose3>& initial_cam_from_world,
                         const std::vector<Pose3>& refined_cam_from_world);

/// What makes a run implausible.
enum class RunVerdictKind {
  kFewKeyframes,           ///< Fewer than min_keyframes keyframes.
  kFewCurves,              ///< Fewer than min_curves curves in the final map.
  kMostCurvesImplausible,  ///< More than max_implausible_fraction of the curves implausible.
  kPosesMovedFar,          ///< A keyframe moved more than max_pose_move_spacings.
};

template <>
struct EnumNames<RunVerdictKind> {
  static constexpr std::array<std::pair<RunVerdictKind, const char*>, 4> kNames = {{
      {RunVerdictKind::kFewKeyframes, "few_keyframes"},
      {RunVerdictKind::kFewCurves, "few_curves"},
      {RunVerdictKind::kMostCurvesImplausible, "most_curves_implausible"},
      {RunVerdictKind::kPosesMovedFar, "poses_moved_far"},
  }};
};

/// One verdict: its kind and one line that says what is wrong, with the figures.
struct RunVerdict {
  RunVerdictKind kind = RunVerdictKind::kFewKeyframes;
  std::string message;
};

/// The sanity of a run: the extent, the implausible curves, the largest pose move, the verdicts.
struct RunSanity {
  SceneExtent extent;      ///< The last extent the curves were checked against, pose units.
  int checked_curves = 0;  ///< Curves that reached the global map (each judged).
  std::vector<ImplausibleCurve> implausible_curves;
  PoseMove pose_move;
  std::vector<RunVerdict> verdicts;  ///< Empty for a plausible run.

  int droppedCurves() const;
};

/// The verdicts on a run of `keyframes` keyframes whose final map holds `curves` curves, where
/// `implausible` of the `checked` curves that reached the global map were implausible and the
/// largest pose move was `move`; empty when nothing is wrong.
std::vector<RunVerdict> judgeRun(int keyframes, int curves, int checked, int implausible,
                                 const PoseMove& move, const SanityOptions& options);

}  // namespace curvesfm
