#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/pose3.h"

namespace curvesfm {

// Extending an existing curve with a new one (paper §3.3: "The segment is added to an existing
// curve if the seed group of pixels is smoothly connected to the pixels of an already existing
// curve"). A new keyframe's unexplained edge runs begin where the projection of a registered
// curve stops explaining the chain, a few pixels past its end; when the curve lifted from such a
// run continues that end smoothly in the image and at the same depth, its segments are appended
// to the existing curve instead of starting a new one, so an edge seen piece by piece as the
// camera moves becomes one curve, with one continuous tangent, rather than a row of fragments.

/// When a new curve counts as smoothly connected to an existing curve's end. Pixel tolerances
/// are in the new keyframe; the gap is measured between the projected end points.
struct CurveExtensionOptions {
  /// Extend existing curves at all; false starts every new curve on its own.
  bool enabled = true;
  /// Largest distance between the projections of the two end points (px). The unexplained run
  /// starts about PipelineOptions::explained_radius_px + 1 px past the existing curve's
  /// projected end, plus any leading pixels without depth. Finite, > 0.
  double max_gap_px = 8.0;
  /// Largest offset of the new end point across the existing end's image tangent, and the
  /// farthest it may lie behind the existing end (px): a parallel edge (the other side of a thin
  /// line) or an overlapping duplicate is no continuation. Finite, >= 0.
  double max_lateral_px = 2.0;
  /// Largest angle between the two curves' directions in the image at the join (deg): the
  /// existing end's and the new curve's, each from the last tenth of its end segment. Measured
  /// in the image, where edge pixels are precise, not in 3D, where a new curve's tangent carries
  /// the noise of depths lifted over a short baseline. In (0, 180].
  double max_angle_deg = 30.0;
  /// Largest 3D distance between the two end points, as a fraction of the existing end's depth
  /// in the keyframe (unitless): the same edge, not one that passes in front of another. The
  /// default is the curve initialiser's max_relative_depth_jump, which ends a run of lifted
  /// pixels at an occlusion boundary the same way. Finite, > 0.
  double max_relative_depth_gap = 0.1;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// An end of a map curve as a keyframe sees it: where a new curve may attach.
struct OpenEnd {
  int curve = -1;                                   ///< Map curve id.
  CurveEnd end = CurveEnd::kBack;                   ///< Which of its ends.
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< The end point (world).
  double depth = 0.0;                               ///< Depth z of `point` in the keyframe.
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< Projection of `point`.
  Eigen::Vector2d pixel_outward = Eigen::Vector2d::UnitX();  ///< Unit image direction in which
                                                             ///< the projection leaves the curve.
};

/// The end `end` of map curve `id` seen from `cam_from_world`, or nothing when the last tenth of
/// the end segment does not project in front of the camera to two distinct pixels.
std::optional<OpenEnd> openEnd(int id, const PolyBezier& curve, CurveEnd end,
                               const Pose3& cam_from_world, const Camera& camera);

/// A new curve found to continue an open end.
struct CurveJoin {
  int open_end = -1;                    ///< Index into the `ends` given to findJoin.
  CurveEnd new_end = CurveEnd::kFront;  ///< The new curve's end that touches it.
  double gap_px = 0.0;                  ///< Distance between the projected end points.
};

/// The open end that `candidate` (a new curve in the world frame) continues smoothly, by the
/// checks of CurveExtensionOptions at either of its ends; the smallest pixel gap wins. An end
/// that projects behind the camera is not tried. Nothing when no end passes.
std::optional<CurveJoin> findJoin(const PolyBezier& candidate, const std::vector<OpenEnd>& ends,
                                  const Pose3& cam_from_world, const Camera& camera,
                                  const CurveExtensionOptions& options);

/// An existing curve continued by a new one.
struct ExtendedCurve {
  PolyBezier curve;
  /// added_segments[i]: the index in `curve` of the addition's segment i.
  std::vector<int> added_segments;
};

/// `existing` continued at `existing_end` by `addition`, whose end `addition_end` touches it.
/// The existing curve's points, tangents and arm lengths stay exactly as they are (its segment
/// indices shift by the addition's count when it grows at the front); the addition's touching
/// end moves onto the existing end point and tangent, its other points and lengths stay.
ExtendedCurve extendCurve(const PolyBezier& existing, CurveEnd existing_end,
                          const PolyBezier& addition, CurveEnd addition_end);

}  // namespace curvesfm
