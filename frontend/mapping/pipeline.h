#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/bezier.h"
#include "core/camera.h"
#include "core/pose3.h"
#include "factors/curve_bundle_adjustment.h"
#include "factors/curve_precision.h"
#include "factors/curve_statistics.h"
#include "frontend/image/correspondence_checks.h"
#include "frontend/image/curve_extension.h"
#include "frontend/image/curve_initialiser.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/edge_detector.h"
#include "frontend/image/epipolar_depth.h"
#include "frontend/image/image_undistorter.h"
#include "frontend/image/keyframe_image.h"
#include "frontend/mapping/curve_map.h"
#include "frontend/mapping/sanity_checks.h"
#include "graph/scheduler.h"

namespace curvesfm {

/// The solver of every pipeline BA (local, global, pose tracking): our own Schur complement
/// (LinearSolver::kGraphSchur), 1.9-2.4x faster than Ceres' sparse Schur on the real sets'
/// global BA with the same figures within their run-to-run variation (docs/benchmarks.md, "Our
/// own Schur complement").
OptimizerOptions defaultPipelineOptimizerOptions();
/// The defaults of PipelineOptions::local_ba: alternating, local scope, a window of 5 keyframes.
SchedulerOptions defaultLocalBundleAdjustmentOptions();
/// The defaults of PipelineOptions::global_ba: joint, global scope.
SchedulerOptions defaultGlobalBundleAdjustmentOptions();

/// The scene scale at which the pipeline's relative defaults equal the stages' metric defaults:
/// the distance between consecutive true camera centres of the default `curvesfm synth planar`
/// (30 frames on a 0.25 m orbit's 90 deg arc: 2 * 0.25 m * sin(45/29 deg) = 13.5 mm), so that
/// the README's run and the planar bench keep their metric behaviour. One exception: the depth
/// range starts at 10 scene scales, not 14.8 (0.2 m), so that sparser sequences still see the
/// plane (10 frames: 0.57-0.73 m at 13-17 baselines of 43.6 mm). Where the point initialiser
/// gave the poses, each keyframe's depth range comes from its points instead
/// (PipelineOptions::point_depth_range).
constexpr double kPlanarReferenceSceneScale = 0.0135396923381;

// The defaults of the stages whose options hold lengths, in multiples of the scene scale
// (PipelineOptions::scene_scale): the stages' metric defaults divided by
// kPlanarReferenceSceneScale, rounded to two digits.
/// min_depth 10, max_depth 1500 (was 0.2 m, 20 m).
EpipolarDepthOptions defaultPipelineDepthOptions();
/// min_chord 7.4e-3 (was 1e-4 m).
CurveInitialiserOptions defaultPipelineInitialiserOptions();
/// min_depth 0.74 (was 0.01 m).
CorrespondenceOptions defaultPipelineCorrespondenceOptions();
/// min_keyframe_translation 0.74 (was 0.01 m).
CurveMapOptions defaultPipelineMapOptions();
/// lambda1 0.018 px^2 per squared scene scale (was 100 px^2/m^2), scale_sigma 7.4e-3 scene scales
/// (was 1e-4 m), and a Cauchy kernel (width 2) on the edge residuals instead of Huber's: it
/// redescends, so a sample within the field's reach of a neighbouring edge pulls less the
/// farther it lies, where Huber's pull stays constant. Re-association adds many such samples in
/// views far from those that lifted a curve: started at the truth, Pavilion drifts 3.08 mm
/// instead of 4.87 and templeRing 0.38 instead of 0.84. A start far off loses some basin: from
/// the point initialiser the kernels are even over six real sets (Pavilion, 41 mm off, 0.66 ->
/// 0.74 x; KITTI 0.72 -> 0.68 x), and the factor layer's synthetic protocol (2 cm / 1 deg, tens
/// of pixels) keeps Huber (docs/benchmarks.md, "A redescending kernel", session 17).
CurveBundleAdjustmentOptions defaultPipelineBundleAdjustmentOptions();

/// Every tunable of the incremental pipeline (paper §2.3, §3.3-3.4), one struct per stage.
///
/// Monocular poses have an arbitrary unit, so no option is in metres: every length (depth range,
/// minimum depths and chords, keyframe translation, the BA's length weight and scale sigma) is a
/// multiple of the scene scale (scene_scale), and the pipeline works internally in that unit (it
/// divides the initial poses' translations by it and multiplies the results back), so a start in
/// millimetres or in COLMAP's arbitrary unit reconstructs the same as one in metres.
struct PipelineOptions {
  /// The unit of every length option (pose units). 0 derives it: the distance between the
  /// initial camera centres of the first frame and of the first later frame whose centre differs
  /// from it (normally frame 1, which becomes keyframe 1 when min_keyframe_translation < 1, so the
  /// scale is also the BA's scale gauge, the initial baseline of keyframes 0 and 1). Known from
  /// the second frame on, before anything needs it; until a frame moves, no curve starts. The
  /// value used is PipelineResult::scene_scale. Finite, >= 0.
  double scene_scale = 0.0;
  /// With points (setPoints), a keyframe that sees at least 10 of them searches depths in
  /// [5th percentile / point_depth_margin, 95th percentile x point_depth_margin] of their depths
  /// instead of depth.min_depth..max_depth: a baseline is a poor yardstick for depth on real
  /// sequences (KITTI moves a metre a frame and sees 5-80 m).
  bool point_depth_range = true;
  /// Factor that widens the points' depth range on both sides (unitless). Finite, >= 1.
  double point_depth_margin = 2.0;
  ImageUndistorterOptions undistort;
  EdgeDetectorOptions edges;
  EdgeChainOptions chains;
  NearestEdgeFieldOptions field;
  EpipolarDepthOptions depth = defaultPipelineDepthOptions();  ///< Lengths in scene scales.
  CurveInitialiserOptions initialiser = defaultPipelineInitialiserOptions();  ///< Ditto.
  /// When a new curve continues an existing one instead of starting on its own.
  CurveExtensionOptions extension;
  CorrespondenceOptions correspondence = defaultPipelineCorrespondenceOptions();  ///< Ditto.
  /// Promotion, disabling, keyframe selection (translation in scene scales).
  CurveMapOptions map = defaultPipelineMapOptions();
  /// The objective of local and global BA (lengths in scene scales).
  CurveBundleAdjustmentOptions ba = defaultPipelineBundleAdjustmentOptions();
  /// After each keyframe (alternating, local scope, window 5).
  SchedulerOptions local_ba = defaultLocalBundleAdjustmentOptions();
  /// Let local BA move the window's poses (the paper's local BA) or hold every pose at its
  /// current value and refine the curves alone; global BA refines poses either way. Off by
  /// default: on a start that drifts like odometry (locally accurate, globally off) the young
  /// curves, lifted over short baselines, are too far off to correct the poses, and local BA
  /// moving them makes the trajectory worse in every failing case of the planar bench (e.g.
  /// LinuxLogo 0 % with a 0.1 deg / 2 mm motion prior: 3.24 -> 6.91 mm moving poses, 2.45 mm
  /// holding them; docs/benchmarks.md).
  bool local_ba_refines_poses = false;
  /// Local BA refines each curve segment from at most this many of its keyframes: those in the
  /// window and the rest spread evenly over its older ones (thinLocalObservations). Bounds a
  /// keyframe's local BA on long sequences, whose curves stay in view over hundreds of
  /// keyframes; global BA uses every observation. 0: every keyframe; else > local_ba's window.
  /// 20 leaves the temples' runs unchanged (their tracks are shorter) and took 41 % off the local
  /// BA of the 300-frame 7-Scenes kitchen, whose curves stay in view over a hundred keyframes,
  /// with a 10 % lower ATE there and 2-5 % higher on Pavilion and the planar demo
  /// (docs/benchmarks.md, "The 300-frame kitchen beside COLMAP").
  int local_ba_max_curve_keyframes = 20;
  SchedulerOptions global_ba = defaultGlobalBundleAdjustmentOptions();  ///< Once at the end.
  bool run_global_ba = true;   ///< Run global BA in finish().
  /// After global BA, rounds of re-association, each followed by global BA again: every
  /// promoted curve's segments are checked (registerSegment) in every keyframe that has no
  /// observation of them, at the refined poses and curves. Tracks then span the baselines that
  /// fix depth, which the incremental registration misses while the map is still off (a curve
  /// lifted over a short, noisy baseline projects too far from its edges a few keyframes on).
  /// Stops early when a round adds no observation. >= 0; 0 turns it off.
  int reassociation_rounds = 3;
  /// Most Levenberg-Marquardt iterations of each global BA that a re-association round follows
  /// (the first global BA and every round's but the last); the last global BA runs to
  /// global_ba's own limits. The poses a round re-associates at need not be converged: the
  /// next round's BA takes them on, and the later rounds then keep correcting where after
  /// converged solves they hardly moved the poses (docs/benchmarks.md, "A budget for
  /// re-association's global BAs": with the stall test 2.6x fewer global BA iterations on the
  /// six real sets, 20 of 30 runs closer to the truth, 9 further). >= 0; 0: no budget, every
  /// global BA runs to its limits.
  int reassociation_interim_iterations = 8;
  /// Kernel width of the global BA that ends the run, after the last re-association round
  /// (sigmas, as ba.kernel_width; 0: ba.kernel_width). Narrower, the final solve lets go of the
  /// wrong nearest edges that pull a good start away, and also of the observations a far start
  /// still has several pixels off: at 1 the truth starts of five of the six real sets drift 2-21 %
  /// less and Pavilion's five noise starts, tied to their poses by the start model, end at
  /// 0.38-0.47 x instead of 0.46-0.53, while Pavilion's initialiser start ends at 0.590 x
  /// instead of 0.562 and the planar drift protocol is unchanged within its spread (45 of 45
  /// cases refined; docs/benchmarks.md, "A narrower kernel for the last global BA" and "The
  /// narrow last kernel by default"). Finite and > 0, or 0.
  double last_global_ba_kernel_width = 1.0;
  /// After the last global BA, how precisely the curves fix the camera centres
  /// (factors/curve_precision.h: the ATE the edge noise alone would leave), for runs of at most
  /// this many keyframes: it linearises every edge factor once and eliminates each curve, a few
  /// per cent of a run (templeRing 1 s, fountain-P11's 39,000 observations 5 s of 187 s), and
  /// inverts 6 x keyframes rows. >= 0; 0: never.
  int curve_precision_max_keyframes = 200;
  /// Re-association leaves a keyframe's edges to the curves already observed there: a segment
  /// whose projection lies mostly (over half its samples) within explained_radius_px of the
  /// projection of a segment observed in that keyframe is not registered there, nor are two
  /// re-associated segments on one edge. Off by default: on real scenes it lowered the drift of
  /// a start at the truth (Pavilion 4.41 -> 3.47 mm; 4.87 -> 3.99 on session 16's code, where
  /// blocking only nearer curves gave 4.71 and a random third of the re-associations 3.84: it
  /// helps by adding fewer, not by choosing), but on the planar bench, where the curve a
  /// re-associated segment would meet is mostly its own duplicate, started after the segment's
  /// curve was lost, it kept tracks short and 5 of 6 cases ended 20-50 % worse (LinuxLogo 1.53
  /// -> 2.31 mm; docs/benchmarks.md). reassociation_skip_occluded tells an occluder (nearer)
  /// from a duplicate (as near).
  bool reassociation_skip_explained = false;
  /// Re-association leaves a segment hidden behind a nearer curve: one whose projection lies
  /// mostly (over half its samples) within explained_radius_px of the projection of a segment
  /// observed in that keyframe, or re-associated there before it, whose depth at that pixel is
  /// below reassociation_occluder_depth_ratio times the sample's own. Unlike
  /// reassociation_skip_explained it lets a curve take an edge that a duplicate at its own depth
  /// explains, so on a plane it blocks little (the demo under session 16's Huber kernel: 45
  /// segments a round, ATE 0.343 -> 0.341 mm). Off by default: on the real sets its results stay
  /// within the noise seeds' spread (docs/benchmarks.md, session 16).
  bool reassociation_skip_occluded = false;
  /// A curve occludes a sample where its depth is below this fraction of the sample's depth
  /// (unitless, in (0, 1]): the margin keeps two curves on one surface, whose depths differ by
  /// their lifting errors, from hiding each other.
  double reassociation_occluder_depth_ratio = 0.9;
  /// Largest mean edge distance of a re-associated segment (px; see
  /// CorrespondenceOptions::max_mean_edge_distance_px); 0 takes correspondence's.
  double reassociation_max_edge_distance_px = 0.0;
  /// Largest angle between a re-associated view and the mean of the segment's earlier viewing
  /// directions (deg; see CorrespondenceOptions::max_viewing_angle_deg); 0 takes
  /// correspondence's.
  double reassociation_max_viewing_angle_deg = 0.0;
  /// Reference keyframes considered for the depth of a new keyframe's edges (the most recent
  /// ones, ranked by rankReferenceFrames). >= 1.
  int depth_reference_candidates = 4;
  /// Before registration, refine a new keyframe's starting pose alone against the projections of
  /// the global curves (curves constant; temporary ones were never refined), so that
  /// registration can succeed when the initial pose puts projections farther than
  /// correspondence.max_mean_edge_distance_px off. A starting value only. Off by default: on the
  /// planar orbit it made the trajectory worse (30 frames, drifting start, no re-association,
  /// before the motion prior and curves-only local BA: ATE 2.0 -> 5.8 mm against 1.45 mm
  /// untracked), since the incremental map, lifted over short baselines with the given poses, is
  /// off by centimetres in depth until re-association and global BA fix it.
  bool track_keyframe_pose = false;
  /// Solver of that pose refinement (max_iterations per keyframe).
  OptimizerOptions tracking = defaultPipelineOptimizerOptions();
  /// Threads that try the map's segments in a keyframe, during the incremental registration and
  /// re-association (count, in [1, 64]; the result does not depend on it: every attempt only
  /// reads the map, and the map takes the registrations in the serial order). Re-association
  /// with reassociation_skip_explained or reassociation_skip_occluded stays on one thread: each
  /// registration there changes the masks the next attempt reads.
  int registration_threads = 1;
  /// Chain pixels within this distance of the projection of a segment registered in the
  /// keyframe count as explained by it; only runs of unexplained pixels (at least
  /// chains.min_length_px long) seed new curves (px). Finite, >= 0.
  double explained_radius_px = 3.0;
  /// Which curves are implausible (dropped before every global BA and from the result) and when
  /// the run gets a verdict (PipelineResult::sanity).
  SanityOptions sanity;

  /// Throws InvalidOptions naming the stage struct, the field, its value and the constraint.
  void validate() const;
};

/// One input image with its starting pose (from an initial trajectory).
/// One point of the hybrid graph seen in a frame (Pipeline::setPoints).
struct PointSighting {
  int point = -1;                                   ///< Index into the points given.
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  ///< Undistorted pixel (undistortedCamera()).
  bool keypoint = false;  ///< A descriptor keypoint's pixel, not KLT's (TrackObservation).
  double keypoint_size = 0.0;  ///< The keypoint's diameter (px); 0 for KLT.
};

struct PipelineFrame {
  double timestamp = 0.0;
  /// Colour image as loaded (distorted), CV_8UC3. May stay empty when `image` is given, or on a
  /// frame that selectKeyframes says is no keyframe.
  cv::Mat image_bgr;
  Pose3 initial_cam_from_world;  ///< Starting guess.
  /// The points of setPoints() this frame sees; used when it becomes a keyframe and
  /// ba.points is on.
  std::vector<PointSighting> points = {};
  /// Diagnosis only (issue 14): the pose at which the frontend lifts and registers curves for
  /// this frame instead of the starting guess; global BA still starts from
  /// initial_cam_from_world. With the truth here and a perturbed start, a run separates a map
  /// built at the start's errors from an optimiser that cannot leave them.
  std::optional<Pose3> frontend_cam_from_world = std::nullopt;
  /// The image stage of image_bgr (Pipeline::prepareImage), when the caller ran it ahead, e.g.
  /// on another thread while the previous keyframe's BA ran; else addFrame runs it.
  std::shared_ptr<const KeyframeImage> image = nullptr;
};

/// What happened to one frame (a progress line and a report.json entry).
struct KeyframeStats {
  int frame_index = 0;      ///< Index of the frame in the input sequence.
  int keyframe_index = -1;  ///< -1 if the frame was not made a keyframe.
  double timestamp = 0.0;
  // Per-stage wall time (s); the frontend budget covers all but local_ba_seconds.
  double undistort_seconds = 0.0;
  double edges_seconds = 0.0;  ///< detectEdges + extractEdgeChains.
  double field_seconds = 0.0;
  double depth_seconds = 0.0;
  double correspondence_seconds = 0.0;  ///< Pose tracking, projection and the four checks.
  double initialise_seconds = 0.0;      ///< New curves from unregistered chains.
  double local_ba_seconds = 0.0;        ///< Building the window's graph, solving, writing back.
  // Counts.
  int edge_pixels = 0;
  /// Canny hysteresis thresholds applied to this keyframe (grey levels / px), automatic or given.
  double canny_high_threshold = 0.0;
  double canny_low_threshold = 0.0;
  int chains = 0;
  int valid_depths = 0;
  int registered_segments = 0;  ///< Map segments registered in this keyframe.
  /// Map segments projected here and not registered, by reason: skipped as duplicates of edges
  /// a higher tier explained, or the first failed check (rejectedSegments() is their sum).
  int rejected_duplicate = 0;
  int rejected_depth = 0;
  int rejected_edge_distance = 0;
  int rejected_viewing_direction = 0;
  int rejected_appearance = 0;
  int new_curves = 0;       ///< Curves started from unregistered edges.
  int extended_curves = 0;  ///< New curves appended to an existing curve's end instead.
  int global_curves = 0;    ///< Curves in the global map after this keyframe.
  int temporary_curves = 0;
  double local_ba_initial_cost = 0.0;
  double local_ba_final_cost = 0.0;
  int local_ba_iterations = 0;  ///< Levenberg-Marquardt iterations over its solves.

  int rejectedSegments() const {
    return rejected_duplicate + rejected_depth + rejected_edge_distance +
           rejected_viewing_direction + rejected_appearance;
  }
  /// The image stage (prepareKeyframeImage), which may run ahead on its own thread.
  double imageStageSeconds() const { return undistort_seconds + edges_seconds + field_seconds; }
  double frontendSeconds() const {
    return imageStageSeconds() + depth_seconds + correspondence_seconds + initialise_seconds;
  }
};

/// Which frames Pipeline::addFrame will make keyframes, given every frame's initial pose in
/// order: the choice depends on these poses and the options alone (the scene scale and the
/// keyframe thresholds), so a caller can load and prepare only the keyframes' images, and ahead.
/// Throws InvalidOptions on bad options.
std::vector<bool> selectKeyframes(const std::vector<Pose3>& initial_cam_from_world,
                                  const PipelineOptions& options);

/// Per-stage time of the keyframes of a run: means per keyframe (ms), and the slowest
/// keyframe's frontend time (the frontend budget is per keyframe; local BA is reported apart).
struct KeyframeTimes {
  int keyframes = 0;
  double undistort_ms = 0.0;
  double edges_ms = 0.0;
  double field_ms = 0.0;
  double depth_ms = 0.0;
  double correspondence_ms = 0.0;
  double initialise_ms = 0.0;
  double frontend_ms = 0.0;     ///< Sum of the six above.
  double image_stage_ms = 0.0;  ///< Of which undistort, edges and field (imageStageSeconds).
  double local_ba_ms = 0.0;
  double slowest_frontend_ms = 0.0;
};

/// The times of the keyframes among `frames` (frames that did not become keyframes are skipped);
/// all zero without keyframes.
KeyframeTimes keyframeTimes(const std::vector<KeyframeStats>& frames);

/// One round of re-association after global BA (PipelineOptions::reassociation_rounds).
struct ReassociationRound {
  int added_observations = 0;  ///< (segment, keyframe) registrations the round added.
  /// Segments left to curves already observed in a keyframe, unchecked: on their explained
  /// edges (reassociation_skip_explained) or behind them (reassociation_skip_occluded).
  int left_to_other_curves = 0;
  ScheduleReport global_ba;    ///< The global BA that followed.
};

/// The keyframe poses after one stage of the run (issue 14's diagnosis: which stage moves them).
struct PoseStage {
  /// "incremental" (after the last keyframe's local BA), "global_ba", "reassociation_N".
  std::string name;
  std::vector<Pose3> keyframe_cam_from_world;  ///< Pose units, as keyframe_cam_from_world.
};

/// The result of a run: the refined keyframe trajectory and the global curve map.

struct PipelineResult {
  std::vector<double> keyframe_timestamps;
  std::vector<Pose3> keyframe_cam_from_world;          ///< Refined.
  std::vector<Pose3> keyframe_initial_cam_from_world;  ///< As given.
  std::vector<PolyBezier> curves;                      ///< Global map, world frame.
  std::vector<KeyframeStats> frames;                   ///< One per input frame.
  ScheduleReport global_ba;                            ///< The first global BA; empty if not run.
  std::vector<ReassociationRound> reassociation;       ///< In order; empty if none ran.
  CurveSampleCounts final_samples;                     ///< Where curve samples fall at the end.
  /// The scene scale the run used (PipelineOptions::scene_scale, given or derived; pose units);
  /// 0 if it was to be derived and no frame moved.
  double scene_scale = 0.0;
  /// The hybrid graph's points after the last BA, world frame, pose units; empty unless
  /// ba.points and setPoints().
  std::vector<Eigen::Vector3d> points;
  /// The keyframe poses after each stage, in order; the last is keyframe_cam_from_world.
  std::vector<PoseStage> pose_stages;
  /// Per curve of `curves`, in order, at the final poses (factors/curve_statistics.h; lengths in
  /// pose units; first_keyframe is the keyframe whose depth started the curve).
  std::vector<CurveStatistics> curve_statistics;
  /// The scene's extent, the implausible curves (those dropped are not in `curves`), the largest
  /// pose move and the verdicts; lengths in pose units.
  RunSanity sanity;
  /// How precisely the final map's curves fix the centres (PipelineOptions::
  /// curve_precision_max_keyframes), its ATEs in pose units; empty when not computed.
  std::optional<CurveCentrePrecision> curve_precision;

  /// Wall time of the first global BA and of the re-association rounds' (s).
  double globalBaSeconds() const;
};

/// The incremental curve SfM pipeline: feed frames in order, then call finish(). Frames are
/// undistorted once (ImageUndistorter) and all later stages use its pinhole camera.
///
/// Per keyframe (KeyframeSelector on the initial poses): edges, chains and the nearest-edge
/// field; optionally pose tracking (track_keyframe_pose); registration of the map's segments
/// with the four checks of registerSegment, global curves first, then temporary ones, then
/// disabled ones (a segment of a later tier whose projection lies mostly on edges an earlier
/// registration explained is skipped as a duplicate); depth of the unexplained chain runs
/// against the best of the previous depth_reference_candidates keyframes, so keyframe 0 only
/// stores its data and curves start at keyframe 1; new temporary curves, observed in this
/// keyframe and, if the checks pass there, in the reference keyframe their depth came from;
/// promotion and disabling (CurveMap::endKeyframe); local BA over the global map (poses of
/// keyframe 0 fixed, scale fixed by the initial distance between keyframes 0 and 1). A new run
/// that smoothly continues the end of a curve registered in this keyframe extends that curve
/// (CurveExtensionOptions); the others start new curves. The length regulariser E_s1 of every BA is
/// relative to the curve's length when that BA starts, not at its initialisation
/// (buildCurveBundleAdjustment takes the input curves as the reference). finish() runs global BA
/// over every curve that reached the global map, then the re-association rounds. Before every
/// global BA and after the last one, the curves that reached the global map are checked against
/// the scene's extent (sceneExtent: the keyframe centres and the points of setPoints(), or
/// without points the curves' own points, robustly); implausible ones are dropped for good
/// (SanityOptions). One that only the last global BA made implausible leaves the result but was
/// in that BA. finish() then judges the run (judgeRun).
class Pipeline {
 public:
  /// Throws InvalidOptions (options) or CheckError (camera).
  Pipeline(const Camera& camera, const PipelineOptions& options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Processes one frame: decides whether it becomes a keyframe and, if so, runs the frontend
  /// stages and local BA. Returns the frame's stats. A keyframe needs its image or its image
  /// stage (CheckError otherwise).
  KeyframeStats addFrame(const PipelineFrame& frame);

  /// The image stage of a frame with this pipeline's camera and options (prepareKeyframeImage).
  /// Reads nothing that addFrame or finish write: safe to call on another thread meanwhile.
  KeyframeImage prepareImage(const cv::Mat& image_bgr) const;

  /// The point map of the hybrid graph (world frame, the unit of the initial poses), e.g. the
  /// point initialiser's; frames name what they see in PipelineFrame::points. With
  /// options.ba.points, every BA keeps the points that its keyframes see beside the curves.
  /// Call before the first frame.
  void setPoints(std::vector<Eigen::Vector3d> points_in_world);

  /// Global BA and re-association (if enabled) and the final map. Call once, after the last
  /// frame.
  PipelineResult finish();

  /// The pinhole camera of the undistorted images (for overlays of the result).
  const Camera& undistortedCamera() const;
  /// The undistorted colour image of keyframe k (for overlays).
  const cv::Mat& keyframeImage(int k) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace curvesfm
