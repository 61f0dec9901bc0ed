#pragma once

#include <memory>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/nearest_edge_field.h"
#include "core/point_observation.h"
#include "core/pose3.h"
#include "core/segment_observation.h"
#include "factors/curve_reprojection_factor.h"
#include "factors/pose_variables.h"
#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/robust_kernel.h"
#include "graph/values.h"

namespace curvesfm {

/// The paper's objective E = E_geo + lambda1 E_s1 + lambda2 E_s2 (§3.1) as graph weights.
/// E_geo residuals are pixels, E_s1 residuals scene length units (the unit of the poses and
/// curves given: metres in curve-ba's scenes, multiples of the scene scale in the pipeline, which
/// works in that unit; see defaultPipelineBundleAdjustmentOptions()), E_s2 residuals radians, so
/// the lambdas carry units: lambda1 is px^2 per squared length unit of length change, lambda2
/// px^2 per rad^2. Each term becomes a noise model with sigma = 1 / sqrt(lambda).
struct CurveBundleAdjustmentOptions {
  /// s: each (segment, keyframe) pair gives s + 1 residuals at t_k = k / s. 1..64.
  int samples_per_segment = 10;
  /// Measure against the nearest edge pixel's sub-pixel position (true) or its pixel centre.
  bool use_subpixel_edges = true;
  /// Match a sample only to an edge whose normal lies within this angle (deg) of the projected
  /// curve's normal (CurveSampling::max_normal_angle_deg); (0, 90], 90 accepts every match.
  /// Lower values remove most of the bias of partly hidden curves but cap more samples of a
  /// poor start (docs/benchmarks.md, "Curve bundle adjustment").
  double max_normal_angle_deg = 90.0;
  /// Blend the residuals to the nearest edges of the four pixel centres around each sample, so
  /// that the residual does not jump as a sample crosses a pixel boundary
  /// (CurveSampling::blending).
  bool interpolate_edges = false;
  /// The blend treats two edge pixels as one edge if each lies within this distance (px) of the
  /// other's line; >= 0. Flat rather than an EdgeBlending member, so that the options table
  /// names each field; the defaults are EdgeBlending's (0.5 px).
  double interpolate_max_line_offset_px = EdgeBlending{}.max_line_offset_px;
  /// ...and their normals are within this angle (deg), either sign; [0, 90] (45 deg).
  double interpolate_max_normal_angle_deg = EdgeBlending{}.max_normal_angle_deg;
  /// Measure a sample that projects outside the image but within this distance (px) of it
  /// against the edge line at the closest image pixel, instead of capping it
  /// (CurveSampling::border_margin_px); >= 0, 0 caps.
  double border_margin_px = 0.0;
  double pixel_sigma = 1.0;                            ///< Std dev of an edge residual (px); > 0.
  RobustKernelType kernel = RobustKernelType::kHuber;  ///< Kernel on edge residuals.
  double kernel_width = 2.0;  ///< Kernel width in sigmas (px at sigma 1); > 0.
  double lambda1 =
      100.0;  ///< Weight of E_s1, segment length (px^2 / length unit^2); >= 0, 0 drops it.
  /// E_s1's reference: each segment's length when it was created, where the input gives it
  /// (CurveBundleAdjustmentInput::segment_reference_lengths; the paper's "original value after
  /// initialization"), instead of its chord at the start of this BA. Off by default: the chord at
  /// each BA's start lets a segment shrink BA after BA, but with it Pavilion's noise starts ended
  /// worse (median of 5 seeds 1.24 -> 1.46 x the start; docs/benchmarks.md, "Curves shrink onto
  /// points").
  bool length_from_creation = false;
  /// E_s1 relative to each segment's own length instead: the std dev of its chord is this
  /// fraction of its reference length (unitless; lambda1 is then unused). A straight segment's
  /// length is invisible to the edge residuals (they measure across the edge), so without a
  /// prior of its own size a segment drifts along its edge, in practice shrinking onto a point
  /// that fits any view. >= 0; 0 uses lambda1.
  double length_sigma_rel = 0.0;
  double lambda2 = 1.0;  ///< Weight of E_s2, tangent alignment (px^2 / rad^2); >= 0, 0 drops it.
  bool fix_first_pose = true;  ///< Hold keyframe 0 constant (6 of the 7 gauge DoF).
  /// Fix the scale through the distance between keyframes 0 and 1 (a CameraDistanceFactor at
  /// CurveBundleAdjustmentInput::scale_distance). Needs at least 2 keyframes.
  bool fix_scale = true;
  double scale_sigma = 1e-4;  ///< Std dev of that distance constraint (length unit); > 0.
  /// Tie the motion between consecutive keyframes to that of
  /// CurveBundleAdjustmentInput::motion_prior_cam_from_world (a RelativePoseFactor per pair):
  /// odometry drifts but is locally accurate, and it holds the pose directions that a scene
  /// with edges in few directions leaves weakly constrained.
  bool motion_prior = true;
  /// Std dev of each pair's motion per axis: rotation (deg), and translation as a fraction of
  /// the mean distance between consecutive camera centres of the prior trajectory, so that it
  /// does not depend on the unit of the initial poses (a monocular start has none); > 0. The
  /// defaults are `synth planar`'s drift per frame (0.05 deg, 1 mm of a 13.5 mm step) over 2.5:
  /// the s + 1 samples of a segment share its error, so the edge term counts each segment
  /// several times over, and a prior at the true sigma loses to wrong young curves (planar
  /// bench: WindowsLogo 20 % ends at 3.5 mm from 2.2 mm with it, 1.9 mm with these;
  /// docs/benchmarks.md).
  double motion_prior_rotation_sigma_deg = 0.02;
  double motion_prior_translation_sigma_rel = 0.03;
  /// Tie each keyframe's orientation and centre to its pose in
  /// CurveBundleAdjustmentInput::motion_prior_cam_from_world (a CameraPriorFactor per keyframe):
  /// for a start whose poses are each known to within a rotation and a shift, independent per
  /// pose (a noisy start, GNSS/INS), normally with motion_prior off, since such a start's
  /// consecutive motions are off by 1.4 x its noise (planar protocol, 0.1 deg per pose: refined /
  /// start ATE median 3.15 x with the motion prior, 0.65 x with this prior alone;
  /// docs/benchmarks.md, session 23). Off by default: a start that drifts (odometry, the point
  /// initialiser) is off by more than its local accuracy, and this prior would hold that drift.
  bool start_prior = false;
  /// Std dev per axis of that orientation (deg), and of that centre as a fraction of the prior
  /// trajectory's mean distance between consecutive camera centres; > 0.
  double start_prior_rotation_sigma_deg = 0.1;
  double start_prior_centre_sigma_rel = 0.01;
  /// The hybrid graph (issue 13): the point initialiser's points stay in the graph, one
  /// PointReprojectionFactor per observation in a keyframe beside the curve factors, with their
  /// own noise and kernel. Only when the input has points.
  bool points = false;
  /// Std dev of a point's reprojection residual (px); > 0. Its square against pixel_sigma's is
  /// the weight of a point observation against one curve sample.
  double point_pixel_sigma = 1.0;
  /// Std dev of the residual of a point observed as a descriptor keypoint (px; 0: point_pixel_
  /// sigma). A keypoint is detected in its image alone, so its error is its own, where a KLT
  /// observation inherits the drift of the frames it was followed through. >= 0.
  double keypoint_pixel_sigma = 0.0;
  /// Keypoints larger than this diameter (px; 0: every keypoint alike) get a sigma grown with
  /// their size: keypoint sigma x size / keypoint_reference_size, as ORB-SLAM weighs a keypoint
  /// by its pyramid level. A keypoint found at a coarser scale is localised less precisely: SIFT
  /// matches under the true poses of templeRing lie 0.07 px from their epipolar lines at 2 px,
  /// 0.18 at 5, 0.43 at 11 and 0.68 at 22 (docs/benchmarks.md, session 55). The sizes are SIFT
  /// diameters; ORB's are its 31 px patch at each level, so it needs a reference of its own. >= 0.
  double keypoint_reference_size = 0.0;
  RobustKernelType point_kernel = RobustKernelType::kHuber;  ///< Kernel on point residuals.
  double point_kernel_width = 2.0;                           ///< Kernel width in point sigmas; > 0.

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// A curve bundle adjustment as plain input data: one camera model shared by all keyframes.
struct CurveBundleAdjustmentInput {
  std::shared_ptr<const Camera> camera;
  std::vector<Pose3> cam_from_world;                            ///< Starting guess per keyframe.
  std::vector<std::shared_ptr<const NearestEdgeField>> fields;  ///< One per keyframe.
  std::vector<PolyBezier> curves;  ///< Starting guess per curve, in world.
  /// Each segment's chord when it was created, per curve and segment (paper §3.1: "consistent
  /// with its original value after initialization"): E_s1's reference with
  /// CurveBundleAdjustmentOptions::length_from_creation, and what CurveStatistics::chord_ratio
  /// compares with. Empty: the chords of `curves`.
  std::vector<std::vector<double>> segment_reference_lengths;
  std::vector<SegmentObservation> observations;
  /// Distance between the centres of keyframes 0 and 1 that fixes the scale; <= 0 keeps the
  /// starting distance.
  double scale_distance = 0.0;
  /// The trajectory whose consecutive motions CurveBundleAdjustmentOptions::motion_prior keeps
  /// (usually the initial poses); empty for none, else one pose per keyframe.
  std::vector<Pose3> motion_prior_cam_from_world;
  /// Points in world (pointKey(p)) and their observations in the keyframes (camera_index = the
  /// keyframe, pixels of `camera`): the hybrid graph's, used when options.points.
  std::vector<Eigen::Vector3d> points;
  std::vector<PointObservation> point_observations;
};

/// The graph, the starting values and what is held constant. Keys: poseKey(j) per keyframe,
/// segmentKeys(c, i) per curve segment, pointKey(p) per point of the hybrid graph.
struct CurveBundleAdjustmentProblem {
  FactorGraph graph;
  Values values;
  ProblemConfig config;
};

/// One CurveReprojectionFactor per observation, one SegmentLengthFactor and one
/// TangentAlignmentFactor per segment (when their lambda is > 0), the gauge, and a
/// RelativePoseFactor per consecutive keyframe pair when the motion prior is on and given, and
/// with options.points a PointReprojectionFactor per point observation. Curve
/// variables no observation touches stay in the values but get no factor. Throws CheckError for an
/// observation out of range, a missing field, or fields that differ from the camera's size.
CurveBundleAdjustmentProblem buildCurveBundleAdjustment(
    const CurveBundleAdjustmentInput& input, const CurveBundleAdjustmentOptions& options);

/// The curves of `values`, with the segment counts of `layout` (usually the input curves).
/// Lengths the optimiser drove to zero or below are floored at 1e-9 so that the result is a
/// valid PolyBezier.
std::vector<PolyBezier> extractCurves(const Values& values, const std::vector<PolyBezier>& layout);

/// Where the samples of every curve reprojection factor of `graph` fall at `values`.
CurveSampleCounts countCurveSamples(const FactorGraph& graph, const Values& values);

}  // namespace curvesfm
