#pragma once

#include <array>
#include <cstddef>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"
#include "factors/curve_statistics.h"
#include "frontend/image/colour_map.h"
#include "frontend/image/curve_overlay.h"

namespace curvesfm {

// The images `run --overlays` writes (issue 14's diagnosis): every keyframe with the final curves
// coloured by one of their statistics (factors/curve_statistics.h) and a legend, and the worst
// curves one by one. The statistics become colours here, so that frontend/image draws plain
// colours and never sees the solver's statistics.

/// Which statistic colours the curves of the overlays. The ranges are fixed, so that overlays of
/// different runs compare; values beyond them take the end colours.
enum class CurveColouring {
  kNone,      ///< Every curve in CurveOverlayOptions::colour, no legend.
  kResidual,  ///< residual_rms_px, linear from 0 to kResidualColourMaxPx.
  kTrack,     ///< keyframes (track length), linear from kTrackColourMin to kTrackColourMax.
  kPull,      ///< pose_pull_share, log10 from kPullShareColourMin to kPullShareColourMax.
};

template <>
struct EnumNames<CurveColouring> {
  static constexpr std::array<std::pair<CurveColouring, const char*>, 4> kNames = {
      {{CurveColouring::kNone, "none"},
       {CurveColouring::kResidual, "residual"},
       {CurveColouring::kTrack, "track"},
       {CurveColouring::kPull, "pull"}}};
};

/// Residuals from 0 to this (px): about three times a good BA's, so the good curves are blue.
constexpr double kResidualColourMaxPx = 3.0;
/// Track lengths (keyframes): a curve needs 2 keyframes; 20 is a long track for a keyframe
/// sequence.
constexpr int kTrackColourMin = 2;
constexpr int kTrackColourMax = 20;
/// Pull shares (fractions of all curves' pull): three decades around 1/N for N from 10 to 10000
/// curves, so a curve pulling ten times its fair share shows at any map size.
constexpr double kPullShareColourMin = 1e-4;
constexpr double kPullShareColourMax = 1e-1;

/// How `run --overlays` colours the curves beyond drawing them (CurveOverlayOptions).
struct OverlayColouringOptions {
  /// The statistic that colours each curve of overlays/NNNNNN.png through colourMapBgr over its
  /// fixed range, with a legend. Default residual: curves that sit off their edges stand out,
  /// whatever the size of the map.
  CurveColouring colour_by = CurveColouring::kResidual;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// Where curve `s` falls in the range of `colouring`: 0 at the low end, 1 at the high end,
/// clipped to [0, 1]; 0 for kNone. A pull share of 0 is at the low end.
double colourFraction(CurveColouring colouring, const CurveStatistics& s);
/// The legend of `colouring` (kNone has none: CheckError): its statistic, unit and range.
ColourLegend colourLegend(CurveColouring colouring);
/// One colour per curve: colourMapBgr(colourFraction(...)), or `plain` for every curve with
/// kNone.
std::vector<cv::Scalar> curveColours(CurveColouring colouring,
                                     const std::vector<CurveStatistics>& stats,
                                     const cv::Scalar& plain);

/// The rankings of the worst curves, in report.json's curve_statistics ("highest_residual",
/// "most_pull") and in worst_curves/.
enum class CurveRanking {
  kResidual,  ///< By residual_rms_px.
  kPull,      ///< By pose_pull_share.
};

template <>
struct EnumNames<CurveRanking> {
  static constexpr std::array<std::pair<CurveRanking, const char*>, 2> kNames = {
      {{CurveRanking::kResidual, "residual"}, {CurveRanking::kPull, "pull"}}};
};

/// How many curves each ranking lists.
constexpr std::size_t kWorstCurvesListed = 10;

/// Indices of the `count` curves of `stats` ranked highest, highest first; equal values keep the
/// index order.
std::vector<std::size_t> worstCurves(const std::vector<CurveStatistics>& stats,
                                     CurveRanking ranking, std::size_t count);

/// The final map as the overlays draw it: plain data, so that tests need no pipeline.
struct OverlayScene {
  Camera camera;                               ///< Of the keyframe images (undistorted).
  std::vector<cv::Mat> keyframe_images;        ///< CV_8UC3 of the camera's size, one per keyframe.
  std::vector<Pose3> keyframe_cam_from_world;  ///< One per keyframe image.
  std::vector<PolyBezier> curves;              ///< World frame.
  /// One per curve, in order; empty draws every curve as CurveColouring::kNone.
  std::vector<CurveStatistics> statistics;
};

/// Writes `dir`/NNNNNN.png for keyframe NNNNNN: its image with every curve, coloured by
/// `colouring`, and the legend in the top-left corner. Creates `dir`; IoError when an image
/// cannot be written. Returns the number of images.
int writeOverlays(const std::string& dir, const OverlayScene& scene,
                  const CurveOverlayOptions& drawing, CurveColouring colouring);

/// Writes, for each ranking, the worst kWorstCurvesListed curves one image each:
/// `dir`/<ranking>_<rank>_curve_<curve>_kf_<keyframe>.png (e.g. residual_01_curve_0042_kf_0007.png;
/// rank from 01, curve its index into curves.obj and curves.csv, 4 digits or more) on the keyframe
/// where its residual is largest (CurveStatistics::worst_keyframe), the curve thick in magenta and
/// the others faint in drawing.colour; and `dir`/worst_curves.md, the index: per ranking a table
/// of the curves with their statistics and image. Curves with no observing keyframe get no image.
/// Creates `dir`; IoError when a file cannot be written. Returns the number of images.
int writeWorstCurves(const std::string& dir, const OverlayScene& scene,
                     const CurveOverlayOptions& drawing);

}  // namespace curvesfm
