#pragma once

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

// A synthetic scene for curve bundle adjustment: smooth 3D curves (lines, circular arcs,
// helices) in a room-sized box, keyframes on an orbit or a forward walk, per keyframe a rendered
// image with a blurred step edge along every projected curve, its Sobel gradients and Canny
// edges, the (curve, segment, keyframe) observations, and a perturbed starting guess.
//
// World frame: the room centre is the origin, y points down (the image y of an upright camera),
// z is the viewing direction of the middle orbit camera and of the walk. Units: metres, pixels
// (centres at integers, as Camera::project), 8-bit intensities. Everything is plain data.

/// Where the keyframes are.
enum class CameraPath {
  /// On a horizontal circular arc of radius camera_distance around the room centre, looking at
  /// it, with a gentle height wave (+-10% of the radius) so the cameras are not coplanar.
  kOrbit,
  /// Along a straight line towards the room (+z), looking ahead, with a slight lateral (+-0.1 m)
  /// and vertical (+-0.05 m) wiggle and a +-2 deg yaw/pitch wiggle. The last keyframe is
  /// camera_distance in front of the room centre, the first one walk_length further back.
  kForwardWalk,
  /// Along a straight line parallel to the room's x axis, walk_length long and centred on the
  /// room, camera_distance in front of its centre, looking across the line (+z) as a car's side
  /// camera, with the forward walk's wiggle (one period per 10 m of a longer walk). Each curve
  /// stays in view over a bounded stretch: the long-sequence case. Stretch the volume along x
  /// with the walk (e.g. half extents (walk_length / 2 + 2, 1.5, 1)).
  kSidewaysWalk,
};

/// The shape of the curves before they are fitted by poly-Béziers.
enum class CurveKind {
  kLine,   ///< A straight segment.
  kArc,    ///< A circular arc spanning 60-180 deg in a random plane.
  kHelix,  ///< Half a turn to a full turn of a helix with a 20-40 deg slope, radius >= 0.1 m.
  kMixed,  ///< Each curve picks one of the three kinds above at random (options only).
};

template <>
struct EnumNames<CameraPath> {
  static constexpr std::array<std::pair<CameraPath, const char*>, 3> kNames = {{
      {CameraPath::kOrbit, "orbit"},
      {CameraPath::kForwardWalk, "forward_walk"},
      {CameraPath::kSidewaysWalk, "sideways_walk"},
  }};
};
template <>
struct EnumNames<CurveKind> {
  static constexpr std::array<std::pair<CurveKind, const char*>, 4> kNames = {{
      {CurveKind::kLine, "line"},
      {CurveKind::kArc, "arc"},
      {CurveKind::kHelix, "helix"},
      {CurveKind::kMixed, "mixed"},
  }};
};

struct CurveSceneOptions {
  // --- cameras ---
  int num_keyframes = 12;                       ///< Keyframes (images); >= 2.
  CameraPath camera_path = CameraPath::kOrbit;  ///< See CameraPath.
  /// kOrbit: orbit radius; kForwardWalk: distance from the last keyframe to the room centre;
  /// kSidewaysWalk: distance of the line from the room centre (m); > 0.
  double camera_distance = 3.0;
  /// kOrbit: angle spanned by the keyframes (deg); (0, 360]. At 360 the keyframes are
  /// 360 / num_keyframes apart, so that the last does not repeat the first.
  double arc_degrees = 90.0;
  double walk_length = 2.0;   ///< The walks: distance first to last keyframe (m); > 0.
  /// 640x480 pinhole with mild barrel distortion, as PointSceneOptions: rendering and
  /// observations go through the distortion model.
  CameraIntrinsics intrinsics{500.0, 500.0, 319.5, 239.5, -0.05, 0.01, 0.0, 0.0, 0.0, 640, 480};

  // --- curves ---
  /// Curves; >= 1. Every keyframe sees the whole default volume, so hundreds of curves turn the
  /// images into a tangle of crossing edges; enlarge volume_half_extents around the cameras
  /// instead (e.g. (6, 1.5, 6) with a 360 deg orbit: each keyframe then sees about a third).
  int num_curves = 12;
  CurveKind curve_kind = CurveKind::kMixed;  ///< See CurveKind.
  int segments_per_curve = 3;                ///< Cubic segments per curve; in [1, 64].
  double min_curve_length = 0.5;             ///< Shortest curve (m); > 0.
  double max_curve_length = 1.5;             ///< Longest curve (m); >= min_curve_length.
  /// Half edge lengths of the box (centred at the origin) that contains every curve (m); each
  /// > 0, and max_curve_length <= 2 * the smallest one so that every kind fits.
  Eigen::Vector3d volume_half_extents = Eigen::Vector3d(1.25, 1.0, 1.0);
  /// Every curve point keeps at least this distance to every keyframe centre (m); >= 0.
  double min_camera_distance = 1.0;

  // --- rendering ---
  /// Gaussian blur of the step edges (px); in [0.3, 5]. The band drawn on each side of a curve
  /// is the erf step out to 3 sigma, then a linear return to the background over
  /// edge_return_length_px, slow enough for this scene's Canny thresholds to ignore.
  double edge_blur_sigma_px = 1.0;
  /// Length of that return (px); 0 = max(8 sigma, 8 px), else in [1, 200]. Its slope,
  /// contrast / (2 * length) grey levels per px, must stay below the low threshold of whatever
  /// detector reads the images, or each curve shows a second, parallel edge a few pixels away:
  /// `curvesfm run`'s automatic thresholds fall to 0.8 grey levels / px on noise-free images
  /// (EdgeDetectorOptions::auto_min_high_threshold x auto_low_ratio), 5 for the defaults here.
  /// A given length also fades each curve's ends out over it inside the curve, so that the fade
  /// draws no edge across the end nor continues the edge past it.
  double edge_return_length_px = 0.0;
  /// Intensity step across an edge (8-bit units): the bright side is background + contrast / 2,
  /// the dark side background - contrast / 2 (background 128); in (0, 255]. The peak L2 Sobel
  /// magnitude of a straight edge is about 4 * contrast * erf(1 / (sqrt(2) sigma)), 218 for the
  /// defaults; the return to the background stays below 4 * contrast / max(8 sigma, 8 px) = 40.
  double step_contrast = 80.0;
  double pixel_noise = 0.0;  ///< Std dev of Gaussian intensity noise (8-bit units); >= 0.
  /// Canny's lower hysteresis threshold on the L2 magnitude of the 3x3 Sobel gradient (cv::Canny
  /// with L2gradient = true on grad_x, grad_y); > 0. Scale both thresholds with the step's peak
  /// magnitude (see step_contrast) when changing the contrast or the blur.
  double canny_low_threshold = 60.0;
  /// Canny's upper hysteresis threshold (same unit); >= canny_low_threshold.
  double canny_high_threshold = 120.0;
  /// Random 2D curves (40-200 px, same step profile) drawn in each image but belonging to no 3D
  /// curve; >= 0.
  int num_clutter_edges = 0;
  /// Probability that, in an observed (curve, keyframe) pair, a contiguous 30-50% of the curve
  /// (its parameter range) at one end is not drawn; the curve's segments stay observed, with
  /// CurveObservation::hidden_fraction telling how much of each is hidden; in [0, 1].
  double occlusion_fraction = 0.0;

  // --- observations ---
  /// A segment is observed in a keyframe if at least this fraction of its 17 samples
  /// (t = k / 16) project at positive depth inside the image shrunk by visibility_margin_px;
  /// in (0, 1].
  double min_visible_fraction = 0.8;
  double visibility_margin_px = 3.0;  ///< See min_visible_fraction (px); >= 0.
  /// ... and if its projected polyline through those samples is at least this long (px), so
  /// that a segment seen end-on is not observed; >= 0.
  double min_projected_length_px = 5.0;

  // --- starting guess (keyframe 0 and the 0-1 distance are kept: the gauge) ---
  double pose_noise_translation = 0.02;  ///< Std dev per axis of the camera-centre error (m); >= 0.
  /// Std dev per axis of the rotation-vector error, applied in the camera frame (deg); >= 0.
  double pose_noise_rotation_deg = 1.0;
  double curve_point_noise = 0.02;  ///< Std dev per axis of the error of every Q_i (m); >= 0.
  /// Std dev per tangent-plane component of the error of every v_i, applied by
  /// Direction::retract, so the rms angle is sqrt(2) times this (deg); in [0, 30].
  double curve_tangent_noise_deg = 2.0;
  /// Std dev of the log of the factor that multiplies every d1_i, d2_i (about the relative
  /// error; lengths stay positive); in [0, 1].
  double curve_length_noise = 0.05;

  unsigned seed = 42;  ///< Random seed; the same options give a bit-identical scene.

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// A contiguous part of a curve that is not drawn in a keyframe, in the curve parameter
/// g = segment index + t, g in [0, numSegments()].
struct HiddenCurvePart {
  int curve_index = 0;
  double begin = 0.0;  ///< First hidden parameter.
  double end = 0.0;    ///< Last hidden parameter; > begin.
};

/// The rendered data of one keyframe. Images are width x height of the intrinsics.
struct CurveKeyframe {
  cv::Mat image;   ///< CV_8UC1 rendering (background 128, step edges, clutter, noise).
  cv::Mat edges;   ///< CV_8UC1 Canny edges of `image`: 255 on an edge pixel, 0 elsewhere.
  cv::Mat grad_x;  ///< CV_16SC1 3x3 Sobel d/dx of `image` (what cv::Canny uses internally).
  cv::Mat grad_y;  ///< CV_16SC1 3x3 Sobel d/dy of `image`.
  std::vector<HiddenCurvePart> hidden_parts;  ///< Occluded parts of curves in this keyframe.
};

/// Segment `segment_index` of curve `curve_index` is seen in keyframe `keyframe_index` (see
/// CurveSceneOptions::min_visible_fraction).
struct CurveObservation {
  int curve_index = 0;
  int segment_index = 0;
  int keyframe_index = 0;
  /// Fraction of the segment's parameter range [0, 1] that is occluded (not drawn) in this
  /// keyframe; 0 for a fully drawn segment, up to 1 for a segment whose edges are all missing.
  double hidden_fraction = 0.0;

  bool partlyHidden() const { return hidden_fraction > 0.0; }
};

struct CurveScene {
  std::shared_ptr<const Camera> camera;
  std::vector<Pose3> true_cam_from_world;  ///< One per keyframe.
  /// The starting guess: keyframe 0 is exactly true, keyframe 1's centre is at its true distance
  /// from keyframe 0's (the gauge a solver holds fixed); all others are perturbed.
  std::vector<Pose3> initial_cam_from_world;
  /// Ground truth: poly-Béziers fitted to dense samples of the generated shapes, so the curve
  /// model represents them exactly.
  std::vector<PolyBezier> true_curves;
  std::vector<PolyBezier> initial_curves;  ///< Perturbed copies of true_curves (every variable).
  std::vector<CurveKind> curve_kinds;      ///< The shape each true curve was fitted to.
  std::vector<CurveKeyframe> keyframes;    ///< Rendered data, index-aligned with the poses.
  /// Sorted by keyframe, then curve, then segment.
  std::vector<CurveObservation> observations;

  /// True distance between the centres of keyframes 0 and 1: the scale gauge.
  double trueScaleDistance() const;
};

/// Builds the scene. Deterministic: the same options give bit-identical results. Throws
/// InvalidOptions for invalid options, and names min_camera_distance if no curve can be placed
/// in the volume at that distance from every keyframe.
CurveScene makeCurveScene(const CurveSceneOptions& options);

/// Writes the scene as a dataset in the TUM RGB-D layout (sim/synthetic_dataset.h: rgb.txt,
/// rgb/, camera.yaml with the distortion, groundtruth.txt, init_poses.txt unless
/// `with_initial_poses` is false), keyframe k at timestamp k / 30 s, and `dir`/gt_curves.obj, the
/// true curves as polylines (64 samples per segment) for `curvesfm eval-map --gt-curves`. Throws
/// IoError naming the path that cannot be created or written.
void writeCurveDataset(const std::string& dir, const CurveScene& scene,
                       bool with_initial_poses = true);

/// Errors of an estimate (cam_from_world per keyframe, one curve per true curve, matched by
/// index; a curve may have any number of segments).
struct CurveSceneErrors {
  double position_rmse = 0.0;      ///< RMS camera-centre error in the solver's gauge (m).
  double position_ate_sim3 = 0.0;  ///< RMS camera-centre error after a Sim(3) Umeyama (m).
  double rotation_mean_deg = 0.0;  ///< Mean camera rotation error in the gauge (deg).
  /// Mean over the estimated curves' samples (16 per segment) of the distance to the true curve
  /// (its polyline with 64 samples per segment) in the solver's gauge (m). One-sided: it measures
  /// where the estimate is, not whether it covers the whole true curve. 0 for the truth.
  double curve_mean_error = 0.0;
  double curve_max_error = 0.0;  ///< Largest of those distances (m).
  /// curve_mean_error after mapping the estimate through the Sim(3) that aligns the camera
  /// frames (alignCameraFrames with 1 m axes), which stays determined on a straight walk (m).
  double curve_mean_error_aligned = 0.0;
};

/// Throws CheckError if the sizes do not match the scene.
CurveSceneErrors evaluateCurveScene(const CurveScene& scene,
                                    const std::vector<Pose3>& cam_from_world,
                                    const std::vector<PolyBezier>& curves);

/// How well a keyframe's Canny edges agree with its projected true curves (drawn parts only).
struct EdgeAgreement {
  /// Mean over the projected true-curve samples (about 3 px apart, at least 2 px inside the
  /// image) of the distance to the nearest edge pixel centre, each capped at max_distance_px.
  double mean_curve_to_edge_px = 0.0;
  /// Fraction of those samples with an edge pixel within 1 px.
  double curve_samples_on_edges = 0.0;
  /// Fraction of the edge pixels within max_distance_px of a projected true curve.
  double edge_pixels_near_curves = 0.0;
  int num_curve_samples = 0;
  int num_edge_pixels = 0;
};

/// Image-space consistency check for tests and diagnostics; keyframe in [0, num keyframes)
/// (CheckError otherwise), max_distance_px > 0.
EdgeAgreement measureEdgeAgreement(const CurveScene& scene, int keyframe,
                                   double max_distance_px = 2.0);

}  // namespace curvesfm
