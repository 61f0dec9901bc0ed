#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"
#include "factors/point_bundle_adjustment.h"
#include "frontend/image/absolute_pose.h"
#include "frontend/image/feature_tracks.h"
#include "frontend/image/image_undistorter.h"
#include "frontend/image/two_view_geometry.h"
#include "graph/optimizer.h"

namespace curvesfm {

// The point-based initialiser (issue 13): initial camera poses and a sparse point map from a
// calibrated image sequence alone, so that the curve pipeline needs nothing but the images. It is
// an incremental structure from motion in the manner of COLMAP, on the frontend's tracks
// (feature_tracks.h) and our own point bundle adjustment (factors/point_bundle_adjustment.h);
// every decision is anchored in ../shared/reviews/initialiser_anchors.md A.5:
//  1. Tracks: KLT between consecutive frames plus descriptor matches between matching frames.
//  2. Initial pair: among pairs (i, j) with i in the first pair_search_frames frames (of the
//     frames no model holds yet) and 0 < j - i <= max_pair_gap (j stepped by their median flow,
//     see pair_flow_step), estimateTwoViewGeometry on their
//     shared tracks, with the median triangulation angle gated at min_pair_median_parallax_deg;
//     the accepted pair with the highest inliers x min(median angle, pair_parallax_cap_deg) wins
//     (OpenMVG's and COLMAP's preference for wide, well-supported pairs, not the first that
//     works). Two-view BA follows, then the gauge: the first frame of the pair is the world
//     frame, and the scale makes the median depth of its points 1 (so the map's unit is "median
//     scene depth at the start", written in the report).
//  3. Registration: the unregistered frame that sees the most map points next; PnP in RANSAC and
//     refinement (absolute_pose.h); up to max_registration_trials candidates per step, tried
//     again with fallback_min_inliers when none passes.
//  4. Triangulation of every track the new frame shares with registered frames and no point yet:
//     from the new frame and the registered observation of widest angle, gated by angle
//     (min_triangulation_angle_deg), cheirality and reprojection (max_reprojection_error_px);
//     the track's other registered observations join when they reproject within the same bound.
//  5. Local BA over the new frame and the local_ba_frames - 1 frames registered just before it
//     (the points they see free, the other frames that see those points held); global BA when
//     the model has grown by global_ba_growth since the last one, and at the end. After each
//     global BA, observations beyond max_reprojection_error_px are dropped, points below the
//     angle gate removed, and tracks re-triangulated.
//  6. Recovery: when no frame registers, the model is closed and a new one starts from the best
//     pair among the frames no model holds (at most max_models). Models are merged into the
//     first by the Sim(3) fitted (Umeyama, with an inlier pass) on the tracks both triangulated,
//     or, with too few of those, by the poses of a frame both registered (scale: the ratio of
//     the median depths of the points each sees in it); a model that shares neither is reported
//     apart and its frames count as unregistered.
//  7. Loop matches (LoopMatchOptions): pairs of matching frames that the merged model says see
//     the same scene but that share few tracks are matched, and their matches merge tracks where
//     one point explains both, with global BA after each round: what ties a trajectory's return
//     to its start, which the matching window alone leaves to drift.
//
// Pixels: the images may be distorted; they are undistorted once (ImageUndistorter), and every
// pixel of the result (point observations) is an undistorted pixel of undistortedCamera().

/// Loop matches, once the models are built and merged: a trajectory that returns to a place it
/// saw long before shares no track with its earlier frames (the matching window pairs only
/// nearby frames), so nothing holds its scale and position to theirs. Pairs of matching frames
/// that the reconstruction says see the same scene but share few tracks are matched (SIFT,
/// F/H verification), and each verified match merges the two tracks it joins only where one
/// point reprojects within max_merge_error_px into every registered frame of both (COLMAP's
/// track merging): a wrong match that a fitted F lets through joins two scene points at
/// different depths and fails this test. Global BA follows every round of merges, and the
/// matches not merged yet are tried again on its poses.
struct LoopMatchOptions {
  /// Whether loop matches are searched.
  bool enabled = true;
  /// A pair of registered matching frames is a candidate when at least this fraction of the
  /// points seen in the earlier frame project into the later one's image, in front of it
  /// (unitless). In (0, 1].
  double min_covisible_fraction = 0.3;
  /// A point counts as seen by both only when their rays to it differ by at most this (deg):
  /// a point projects into a camera on the other side of the scene too, but its appearance
  /// changes beyond matching. Pavilion orbits its chair: without the limit 954 pairs are
  /// candidates and 75 of them have verified matches (5.9 s of matching); 60 deg keeps 294 with
  /// all 75 (2.4 s), 40 deg 184 with 69 and a worse fountain-P11 (2.52 against 2.43 mm;
  /// docs/benchmarks.md, session 49). In (0, 180].
  double max_view_angle_deg = 60.0;
  /// ...and at most this fraction of those projecting points are already seen in the later
  /// frame (unitless): the two frames see the same scene but their tracks do not say so.
  /// In [0, 1].
  double max_shared_fraction = 0.5;
  /// A merged point must reproject within this distance into every registered frame of both
  /// tracks (px; COLMAP's merge bound 4). Finite, > 0.
  double max_merge_error_px = 8.0;
  /// Most rounds of merges and global BA (count). >= 1.
  int max_rounds = 3;
  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// Thresholds of the incremental reconstruction (defaults: COLMAP's and ORB-SLAM's, see above).
struct PointInitialiserOptions {
  ImageUndistorterOptions undistort;
  PointTrackerOptions klt;           ///< KLT between consecutive frames.
  FeatureMatchingOptions features;   ///< Descriptors between matching frames.
  FeatureTrackOptions tracks;        ///< When descriptors are matched and joined to KLT.
  TwoViewOptions two_view;           ///< The initial pair's geometry and acceptance.
  AbsolutePoseOptions registration;  ///< PnP registration of the next frames.
  /// Objective of every BA (pixel sigma, robust kernel). Its refine_focal applies to global BA
  /// only: local BA sees too few images to tell the focal length from the depths.
  PointBundleAdjustmentOptions ba;
  /// Solvers of local and global BA: our own Schur complement (graph_schur), as the curve BAs
  /// of `run`. Ceres' sparse_schur on two threads sums in an order the threads decide, so its
  /// poses differ in the 13th digit from run to run, enough to flip the curve pipeline's discrete
  /// decisions downstream; graph_schur gives the same bits for a given thread count, and the
  /// initialiser's BAs ran 1.1-3x faster on the six real sets (docs/benchmarks.md, session 29).
  OptimizerOptions local_ba = defaultLocalSolver();
  OptimizerOptions global_ba = defaultGlobalSolver();
  /// The initial pair's first frame is searched among this many frames (count). >= 1.
  int pair_search_frames = 20;
  /// Most frames between the initial pair's two frames (count): slow video needs a wide gap
  /// for parallax (7-Scenes moves about 7 mm a frame at 1-3 m). >= 1.
  int max_pair_gap = 60;
  /// Pairs whose shared tracks move by less than this median distance are not tried (px): they
  /// cannot have parallax, and skipping them keeps the search fast on video. Finite, >= 0.
  double min_pair_flow_px = 10.0;
  /// For one first frame, a second frame is tried only when its median flow exceeds the last
  /// tried one's by this factor (unitless): the pairs of a slow sequence differ little from
  /// one frame to the next, and this bounds the fits per first frame to a few. >= 1 (1: all).
  double pair_flow_step = 1.25;
  /// Smallest median triangulation angle of the initial pair (deg; COLMAP 16, too strict for
  /// hand-held video per the anchors, which suggest 4-8). In [0, 90).
  double min_pair_median_parallax_deg = 4.0;
  /// The pair score counts the median angle up to this (deg): beyond it, more inliers win.
  /// In (0, 90].
  double pair_parallax_cap_deg = 20.0;
  /// Largest reprojection error of an observation kept in the map (px; COLMAP 4). Finite, > 0.
  double max_reprojection_error_px = 4.0;
  /// At given poses (finishAtPoses), each point is refined by least squares over its views
  /// within the gate, the poses held (refinePointAtPoses; COLMAP's point_triangulator runs a BA
  /// with the poses held), instead of kept where the two views farthest apart put it: a
  /// two-view point carries those two views' errors into every other view's residual. Off by
  /// default, measured (docs/benchmarks.md, "Points at given poses refined", session 52): the
  /// six real sets' truth starts drift less on five (KITTI 06 15.8 -> 13.0 mm) and their noise
  /// starts end level (geometric mean 0.785 against 0.780 x), but the planar noise starts ended
  /// further on 39 of 45, because the start model read the start against these points and tied
  /// it tighter. It now reads the two-view points (StartModelOptions::two_view_points), and 34
  /// of 45 planar runs end at or below 0.5 x against the default's 36 (session 53): level, not
  /// better.
  bool refine_at_given_poses = false;
  /// At given poses, with refine_at_given_poses, the gate follows the residuals: this times the
  /// median reprojection error of the tracks triangulated within given_poses_max_gate_px, bounded
  /// by max_reprojection_error_px below and given_poses_max_gate_px above (unitless; 0: the
  /// fixed max_reprojection_error_px). A start the images agree with has a median near the
  /// tracks' noise (0.2-0.5 px on five real sets, 1.7 px on 7-Scenes' ground truth) and keeps the
  /// fixed gate; a start off by pixels per pose (medians 1.4-5 px) would otherwise keep only the
  /// tracks that agree with its errors (docs/benchmarks.md, "Points at a start"). The median of a
  /// 2D Gaussian residual's norm is 1.18 sigma, so 3 gates at 3.5 sigma. Off by default: it serves
  /// the hybrid graph (--ba-points), which is off. >= 0.
  double given_poses_gate_scale = 0.0;
  /// The widest gate at given poses, and the one the median is measured within (px).
  /// >= max_reprojection_error_px.
  double given_poses_max_gate_px = 12.0;
  /// Smallest angle between the rays of a triangulated point (deg; COLMAP 1.5). In [0, 90).
  double min_triangulation_angle_deg = 1.5;
  /// Frames refined by local BA: the new frame and those registered just before it (count).
  /// >= 1.
  int local_ba_frames = 6;
  /// Global BA runs when the registered frames have grown by this factor since the last one
  /// (unitless; COLMAP 1.1, here 1.2 to halve the solves on long video), and at the end. > 1.
  double global_ba_growth = 1.2;
  /// Candidates tried per registration step before the model is declared stuck (count). >= 1.
  int max_registration_trials = 5;
  /// When no candidate registers with registration.min_inliers, the candidates are tried once
  /// more accepting this many inliers (count; above registration.min_inliers: no second try).
  /// Pavilion's frames 53-58 turn towards distant background and see 27-36 triangulated points
  /// where the chair left the view; templeSparseRing's stills 23 deg apart see 25-30. >= 4.
  int fallback_min_inliers = 20;
  /// Most sub-models started (the first included) before giving up on the rest (count). >= 1.
  int max_models = 5;
  /// Fewest tracks two models must both have triangulated to be merged by them, and fewest
  /// points each must see in a shared frame to be merged by its poses instead (count). >= 3.
  int min_merge_points = 20;
  LoopMatchOptions loops;  ///< Loop matches after the models are merged.
  /// OpenCV threads while the tracks are built (count; 0: OpenCV's default, every core). One by
  /// default: issue 13 budgets tracking per core, and two threads gain about a quarter of the
  /// wall time of SIFT detection for half again its processor time. The command's --threads sets
  /// it too unless --points-tracking-threads is given. cv::setNumThreads is process-wide: other
  /// OpenCV work in the process while the tracks are built runs with this count. >= 0.
  int tracking_threads = 1;
  /// The result's centre precision (ReprojectionSummary::precision) is computed up to this
  /// many posed frames (count; 0: never). Its eigen-decomposition grows with the cube of the
  /// frames: 0.3 s at 100 frames (Pavilion, the kitchen), several seconds at 300. >= 0.
  int precision_max_frames = 200;
  /// Throws InvalidOptions naming the first field outside its range (also of the nested ones).
  void validate() const;

  static OptimizerOptions defaultLocalSolver();
  static OptimizerOptions defaultGlobalSolver();
};

/// Why a frame is not in the reconstruction.
enum class FrameRegistration {
  kRegistered,         ///< Has a pose.
  kNoCorrespondences,  ///< No model point is seen in it (tracks lost).
  kRejected,           ///< PnP tried and rejected it (see the rejection).
  kNotTried,           ///< The models stopped before this frame came up (too many failures).
  kNoModel,            ///< No model could be started at all (no initial pair; see the failure).
  kUnmergedModel,      ///< Registered in a sub-model that could not be merged with the first.
};

template <>
struct EnumNames<FrameRegistration> {
  static constexpr std::array<std::pair<FrameRegistration, const char*>, 6> kNames = {
      {{FrameRegistration::kRegistered, "registered"},
       {FrameRegistration::kNoCorrespondences, "no_correspondences"},
       {FrameRegistration::kRejected, "rejected"},
       {FrameRegistration::kNotTried, "not_tried"},
       {FrameRegistration::kNoModel, "no_model"},
       {FrameRegistration::kUnmergedModel, "unmerged_model"}}};
};

/// One frame of the result.
struct InitialisedFrame {
  FrameRegistration status = FrameRegistration::kNotTried;
  /// For kRejected: PnP's last rejection of it.
  AbsolutePoseRejection rejection = AbsolutePoseRejection::kNone;
  int model = -1;           ///< The sub-model that registered it (0 = the first), or -1.
  int correspondences = 0;  ///< 2D-3D correspondences at its (last) registration attempt.
  int inliers = 0;          ///< PnP inliers of that attempt.
  std::optional<Pose3> cam_from_world;  ///< Set when registered.
};

/// One point of the map.
struct InitialisedPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< World, in the map's unit.
  cv::Vec3b colour_bgr = cv::Vec3b(0, 0, 0);           ///< Where it was first seen.
  /// Its observations in registered frames (undistorted pixels), by frame.
  std::vector<TrackObservation> observations;
};

/// How precisely a map's points fix its posed frames' centres, from their own residuals.
struct CentrePrecision {
  /// The pixel noise the residuals say, per coordinate, net of what was fitted to them
  /// (estimatedPixelSigma; px); > 0.
  double pixel_sigma = 0.0;
  /// The ATE (after Sim(3) alignment, in the poses' unit) that this noise alone would leave the
  /// centres at a point BA's optimum, to first order (predictedCentreAte): the floor of what
  /// the points can tell. Far below the ATE against a ground truth, it says that the ground
  /// truth, the camera or a bias of the points, not the noise, makes the difference. Meaningful
  /// at poses the images agree with (the initialiser's own, or an exact truth): at poses off by
  /// pixels the residuals, and so the floor, carry their error too. Infinite when the
  /// observations do not fix every centre.
  double predicted_ate = 0.0;
};

/// How a map's points reproject into the frames that observe them: residual = observed pixel -
/// projected pixel (undistorted pixels). At the initialiser's own poses it is what BA left; at
/// given poses it says how well those poses and the camera agree with the images (a start off by
/// a few pixels per view more than doubles the rms; docs/benchmarks.md, session 50). The mean
/// stays near zero even where every view is off by one shift: the points triangulated at the
/// poses absorb most of it.
struct ReprojectionSummary {
  int observations = 0;                               ///< In front of their cameras.
  Eigen::Vector2d mean_px = Eigen::Vector2d::Zero();  ///< Mean residual (px).
  double rms_px = 0.0;                                ///< Root mean square of its length (px).
  /// How precisely these observations fix the posed frames' centres (centrePrecision). Unset
  /// when not computed (fewer than three or more than PointInitialiserOptions::
  /// precision_max_frames posed frames) or when the residuals tell no noise.
  std::optional<CentrePrecision> precision;
};

/// One bundle adjustment the initialiser ran.
struct InitialiserBundleAdjustment {
  std::string scope;  ///< "two_view", "local" or "global".
  int model = 0;
  int frames = 0, points = 0, observations = 0;
  OptimizationSummary summary;
};

/// Wall time of each stage (s).
struct InitialiserTimes {
  double undistort = 0.0, klt = 0.0, matching = 0.0, pair_search = 0.0, registration = 0.0,
         triangulation = 0.0, local_ba = 0.0, global_ba = 0.0, merge = 0.0, total = 0.0;
  /// Loop matches: finding and matching the candidate pairs and merging tracks (the global BA and
  /// re-triangulation after each round count in global_ba and triangulation).
  double loops = 0.0;
  /// The centres' precision (ReprojectionSummary::precision), an eigen-decomposition.
  double precision = 0.0;
  /// Undistortion and tracks per frame, scaled to a 640x480 frame by the pixel count (ms): the
  /// tracking budget of issue 13 (50 ms on one core, tracking_threads 1) in any image size.
  double tracksMsPerVgaFrame(int frames, int width, int height) const;
};

/// What the loop matches did.
struct LoopMatchStats {
  int candidate_pairs = 0;  ///< Pairs of matching frames matched as loop candidates.
  int verified_pairs = 0;   ///< Of those, pairs whose matches passed the F/H verification.
  /// Verified matches with a track at one end at least and not the same track at both (a pair
  /// of tracks may be joined by several).
  int matches = 0;
  int merges = 0;           ///< Of those, merged (over all rounds).
  int rounds = 0;           ///< Rounds of merges and global BA run.
};

/// What the initialiser made of the sequence.
struct PointInitialisation {
  std::vector<InitialisedFrame> frames;  ///< One per frame given, in order.
  std::vector<InitialisedPoint> points;  ///< The merged map.
  /// finishAtPoses with refine_at_given_poses: the points as they are triangulated without it
  /// (two views each, observations within max_reprojection_error_px), which the start model
  /// reads the start against (StartModelOptions::two_view_points); empty otherwise, when
  /// `points` are those.
  std::vector<InitialisedPoint> two_view_points;
  int num_tracks = 0;                    ///< Tracks of at least two frames.
  int models = 0;                        ///< Sub-models started.
  int merged_models = 0;                 ///< Of those, merged into the first (itself included).
  std::pair<int, int> initial_pair = {-1, -1};  ///< Frames of the first model's pair.
  TwoViewGeometry initial_geometry;             ///< Its two-view geometry.
  int pairs_tried = 0;                          ///< Pair candidates evaluated, all models.
  LoopMatchStats loops;                         ///< Loop matches (LoopMatchOptions).
  /// The gauge: map unit = median depth of the initial pair's points in its first frame.
  std::string scale_convention = "median depth of the initial pair's points = 1";
  /// The factor global BA applied to the camera's focal lengths (unitless; 1 unless
  /// ba.refine_focal): undistortedCamera() and the poses and points hold the refined camera.
  double focal_scale = 1.0;
  std::vector<InitialiserBundleAdjustment> bundle_adjustments;
  std::vector<FeatureTrackFrameStats> track_stats;  ///< Per frame.
  /// finishAtPoses: the reprojection gate applied (px) and, where it follows the residuals
  /// (given_poses_gate_scale), their median within given_poses_max_gate_px (px); 0 otherwise.
  double given_poses_gate_px = 0.0;
  double given_poses_median_error_px = 0.0;
  /// The points' residuals in the registered frames, at the poses returned.
  ReprojectionSummary reprojection;
  InitialiserTimes seconds;
  int registeredFrames() const;
  /// Why nothing could be reconstructed; empty when a model exists.
  std::string failure;
};

/// The residuals of `result`'s points in its posed frames, projected by `camera` (the undistorted
/// camera the pixels refer to).
ReprojectionSummary reprojectionSummary(const Camera& camera, const PointInitialisation& result);

/// The CentrePrecision of `result`'s points in its posed frames, projected by `camera`; with
/// `poses_fitted` the poses were refined with the points (the initialiser's own), else given.
/// None when the residuals tell no noise: none left free by the fit, or all zero.
std::optional<CentrePrecision> centrePrecision(const Camera& camera,
                                               const PointInitialisation& result,
                                               bool poses_fitted);

/// Runs the initialiser over a sequence: feed every frame in order, then finish(). Not
/// thread-safe.
class PointInitialiser {
 public:
  /// `camera` is the dataset's (possibly distorted) camera. Throws InvalidOptions for bad options.
  PointInitialiser(const Camera& camera, const PointInitialiserOptions& options);
  ~PointInitialiser();
  /// Tracks the frame (8-bit BGR or grey, the camera's size; CheckError otherwise).
  void addFrame(const cv::Mat& image);
  /// Reconstructs from the tracks. Never throws on hard data: failure and per-frame reasons say
  /// what could not be done.
  PointInitialisation finish();
  /// Triangulates the tracks at known poses instead (cam_from_world per frame given, in the
  /// poses' unit; a frame without one is left out), with the angle gate of finish(), each point
  /// refined over its views with the poses held (refine_at_given_poses) and gated by
  /// max_reprojection_error_px or by the residuals (given_poses_gate_scale): the points of a run
  /// that brings its own poses, for the keyframes' depth ranges, the start model and the hybrid
  /// graph (COLMAP's point_triangulator does the same for a known model). Every posed frame is
  /// "registered" with its pose unchanged. Call instead of finish(), once.
  PointInitialisation finishAtPoses(const std::vector<std::optional<Pose3>>& cam_from_world);
  /// The pinhole camera of the undistorted images, which every result pixel refers to (after
  /// finish(), with the focal lengths global BA refined under ba.refine_focal).
  const Camera& undistortedCamera() const;
  /// Called by finish() after every registered frame with (model, frames registered in it,
  /// frames given, live points in it): a long reconstruction shows its progress.
  using Progress = std::function<void(int model, int registered, int frames, int points)>;
  void setProgress(Progress progress);
  /// Called by finish() once the loop candidates are matched (round 0) and after each round of
  /// merges and its global BA (round 1, 2, ...), with the counts so far: on long video the loop
  /// matches take a while (the kitchen's 300 frames: about 30 s).
  using LoopProgress = std::function<void(int round, const LoopMatchStats& so_far)>;
  void setLoopProgress(LoopProgress progress);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace curvesfm
