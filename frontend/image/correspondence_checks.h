#pragma once

#include <Eigen/Core>
#include <limits>
#include <opencv2/core.hpp>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/enum_names.h"
#include "core/nearest_edge_field.h"
#include "core/pose3.h"
#include "core/segment_observation.h"

namespace curvesfm {

// The four checks that decide whether a map segment is registered in a new keyframe (paper
// §3.4, DESIGN.md "Correspondences and maps"). Segments are BezierSegmentParams in the world
// frame; a keyframe is its pose cam_from_world, camera, nearest-edge field and BGR image. All
// functions are pure and never throw on geometry (a segment behind the camera or outside the
// image gives a failing result, not an exception); they throw InvalidOptions on bad options and
// CheckError on a malformed image.

/// Thresholds and sampling of the correspondence checks.
struct CorrespondenceOptions {
  /// Samples B(t_k), t_k = k / (m - 1), k = 0..m-1, taken along the segment by the depth, edge
  /// distance and appearance checks (count). In [2, 65].
  int samples_per_segment = 10;
  /// Minimum depth z of every sample in the new camera (length unit of the poses, along the
  /// principal axis; the pipeline's is in multiples of its scene scale, see
  /// defaultPipelineCorrespondenceOptions()). Finite and >= Camera::kMinDepth; the default only
  /// keeps projections finite, it is no near plane.
  double min_depth = 0.01;
  /// Largest accepted mean distance between the projected samples and their nearest edge pixel
  /// (px; see checkEdgeDistance). A sample outside the image or beyond the field's reach counts as
  /// the reach. Finite, > 0.
  double max_mean_edge_distance_px = 3.0;
  /// Half width w of the appearance region across the projected curve (px): at every sample the
  /// pixels at offsets -w..w (1 px apart) along the curve's image normal are averaged, i.e. a
  /// band 2w + 1 px wide covering both sides of the edge. In [0, 50].
  int appearance_half_width_px = 4;
  /// Weight lambda of the hue term of the appearance error (unitless). Finite, >= 0.
  double hue_weight = 1.0;
  /// Largest accepted appearance error lambda (S1 + S2) / 2 |H1 - H2| + |V1 - V2| (unitless,
  /// hue difference in half turns, S and V in [0, 1]; see appearanceError). Finite, > 0.
  double max_appearance_error = 0.2;
  /// Largest accepted angle between the new viewing direction and the mean of the earlier ones
  /// (deg). In (0, 180].
  double max_viewing_angle_deg = 60.0;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// Mean HSV colour of the region around one projected segment (paper §3.4). Hue in degrees
/// [0, 360), saturation and value in [0, 1] (OpenCV's floating-point HSV convention; 8-bit
/// OpenCV hue is half of it). The hue is the circular mean of the pixels' hues weighted by their
/// saturation, since the hue of a grey pixel is arbitrary; it is 0 when no pixel is saturated.
struct HsvAppearance {
  double hue_deg = 0.0;     ///< Mean hue (deg), [0, 360).
  double saturation = 0.0;  ///< Mean saturation, [0, 1].
  double value = 0.0;       ///< Mean value (brightness), [0, 1].
  int num_pixels = 0;       ///< Pixels averaged; 0 means the region was not seen at all.

  bool valid() const { return num_pixels > 0; }
};

/// A verified observation as the pipeline keeps it: the appearance and viewing direction
/// measured there serve as references when the segment is looked for in later keyframes.
struct ObservedSegmentAppearance {
  SegmentObservation observation;
  HsvAppearance appearance;
  Eigen::Vector3d viewing_direction_in_world = Eigen::Vector3d::UnitZ();  ///< Unit vector.
};

/// The outcome of one check: whether it passed and the measured quantity, for reports.
struct CheckResult {
  bool passed = false;
  double value = 0.0;  ///< Unit given by the function that returned it.
};

/// Depth check: every sample has depth z >= options.min_depth in cam_from_world.
/// value: the smallest sample depth (length unit of the poses; negative behind the camera).
CheckResult checkPositiveDepth(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                               const CorrespondenceOptions& options);

/// Spatial check: the mean distance (px) from the projected samples to their nearest edge pixel
/// in `field`, each capped at field.maxDistance() (samples behind the camera, outside the image
/// or beyond reach count as the cap), is at most options.max_mean_edge_distance_px.
/// value: that mean (px). The distance to an edge pixel is to the piece of edge it stands for: the
/// segment through its sub-pixel position, across its normal, sqrt(2)/2 px to either side. So a
/// sample beside a straight edge measures its distance across it, without the up to 0.5 px of
/// along-edge quantisation, while a sample past the end of an edge still measures its gap.
CheckResult checkEdgeDistance(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                              const Camera& camera, const NearestEdgeField& field,
                              const CorrespondenceOptions& options);

/// The unit viewing direction of an observation: from the camera centre to the segment centre
/// B(0.5), in the world frame (paper §3.4). Zero if the two points coincide.
Eigen::Vector3d viewingDirection(const BezierSegmentParams& segment,
                                 const Eigen::Vector3d& camera_centre_in_world);

/// The running mean of a segment's earlier viewing directions (unit vectors, world frame).
class ViewingDirectionMean {
 public:
  /// Adds one unit viewing direction (a zero vector is ignored).
  void add(const Eigen::Vector3d& direction_in_world);
  int count() const { return count_; }
  /// The normalised mean direction; zero if there is none or the directions cancel.
  Eigen::Vector3d mean() const;

 private:
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  int count_ = 0;
};

/// Viewing-direction check: the angle between viewingDirection(segment, camera centre) and
/// `mean_direction_in_world` (the mean of the earlier observations' directions; any length) is
/// at most options.max_viewing_angle_deg. A zero mean (no earlier observation) passes with angle
/// 0. value: the angle (deg).
CheckResult checkViewingDirection(const BezierSegmentParams& segment,
                                  const Eigen::Vector3d& camera_centre_in_world,
                                  const Eigen::Vector3d& mean_direction_in_world,
                                  const CorrespondenceOptions& options);

/// The mean HSV colour of the enlarged region around the segment's projection into `image_bgr`
/// (CV_8UC3, BGR, the size of the camera's image; CheckError otherwise).
///
/// Region: at each of the options.samples_per_segment samples, the pixels (nearest pixel) at
/// offsets -w..w px (w = appearance_half_width_px) along the image normal of the curve there,
/// i.e. a band of width 2w + 1 px centred on the curve. If `field` is given, each band is
/// centred on the sample's nearest edge pixel (sub-pixel position) and oriented by its gradient
/// instead (the paper compares colours at "the closest pixel retrieved via the nearest neighbor
/// field", which forgives a small pose error); samples without an edge within reach fall back to
/// the projection. Samples behind the camera or out of the image, and band pixels out of the
/// image, are skipped; num_pixels counts what was averaged.
HsvAppearance appearanceOf(const BezierSegmentParams& segment, const Pose3& cam_from_world,
                           const Camera& camera, const cv::Mat& image_bgr,
                           const CorrespondenceOptions& options,
                           const NearestEdgeField* field = nullptr);

/// The appearance error of paper §3.4, DESIGN.md:
///   E = lambda (S1 + S2) / 2 dH + |V1 - V2|,  dH = min(|H1 - H2|, 360 - |H1 - H2|) / 180
/// so dH in [0, 1] (half turns) and E in [0, lambda + 1]. The saturation factor silences the
/// hue of grey regions, where it is undefined.
double appearanceError(const HsvAppearance& a, const HsvAppearance& b, double hue_weight);

/// Appearance check: both descriptors are valid and appearanceError(reference, candidate,
/// options.hue_weight) <= options.max_appearance_error. value: the error (+infinity if either
/// descriptor is invalid).
CheckResult checkAppearance(const HsvAppearance& reference, const HsvAppearance& candidate,
                            const CorrespondenceOptions& options);

/// The checks, in the order registerSegment runs them (cheapest first).
enum class CorrespondenceCheck { kNone, kDepth, kEdgeDistance, kViewingDirection, kAppearance };

template <>
struct EnumNames<CorrespondenceCheck> {
  static constexpr std::array<std::pair<CorrespondenceCheck, const char*>, 5> kNames = {{
      {CorrespondenceCheck::kNone, "none"},
      {CorrespondenceCheck::kDepth, "depth"},
      {CorrespondenceCheck::kEdgeDistance, "edge_distance"},
      {CorrespondenceCheck::kViewingDirection, "viewing_direction"},
      {CorrespondenceCheck::kAppearance, "appearance"},
  }};
};

/// The new keyframe as the checks see it. References: the caller keeps the objects alive.
struct KeyframeView {
  const Pose3& cam_from_world;
  const Camera& camera;
  const NearestEdgeField& field;
  const cv::Mat& image_bgr;  ///< CV_8UC3, BGR.
};

/// What is known about the segment from its earlier observations.
struct SegmentHistory {
  HsvAppearance reference_appearance;  ///< From the first (or previous) observation.
  /// Mean of the earlier viewing directions (ViewingDirectionMean::mean()); zero if none.
  Eigen::Vector3d mean_viewing_direction_in_world = Eigen::Vector3d::Zero();
};

/// The outcome of registerSegment. Measurements of checks that did not run are NaN.
struct CorrespondenceVerdict {
  static constexpr double kNotRun = std::numeric_limits<double>::quiet_NaN();

  bool registered = false;
  /// The first check that failed; kNone if registered.
  CorrespondenceCheck failed_check = CorrespondenceCheck::kNone;
  double min_depth = kNotRun;              ///< checkPositiveDepth's value (pose units).
  double mean_edge_distance_px = kNotRun;  ///< checkEdgeDistance's value (px).
  double viewing_angle_deg = kNotRun;      ///< checkViewingDirection's value (deg).
  double appearance_error = kNotRun;       ///< checkAppearance's value (unitless).
  /// Measured in the new keyframe (for the pipeline to store once registered); meaningful only
  /// once the corresponding check ran.
  HsvAppearance appearance;
  Eigen::Vector3d viewing_direction_in_world = Eigen::Vector3d::Zero();
};

/// Runs the four checks of paper §3.4 in the order depth, edge distance, viewing direction,
/// appearance (cheapest first) and stops at the first failure. The appearance is measured with
/// the keyframe's nearest-edge field (see appearanceOf). Throws InvalidOptions on bad options.
CorrespondenceVerdict registerSegment(const BezierSegmentParams& segment, const KeyframeView& view,
                                      const SegmentHistory& history,
                                      const CorrespondenceOptions& options);

}  // namespace curvesfm
