#include "frontend/mapping/pipeline.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "core/check.h"
#include "core/clock.h"
#include "core/errors.h"
#include "core/nearest_edge_field.h"
#include "core/parallel.h"
#include "factors/point_bundle_adjustment.h"
#include "factors/pose_variables.h"
#include "frontend/mapping/keyframe_selector.h"
#include "frontend/mapping/local_ba_observations.h"
#include "frontend/mapping/nearest_curve_depths.h"

namespace curvesfm {
namespace {

// One keyframe as the later keyframes and bundle adjustment need it.
struct Keyframe {
  int frame_index = 0;
  double timestamp = 0.0;
  Pose3 given_cam_from_world;    // As given, in pose units (for the result).
  Pose3 initial_cam_from_world;  // In the scene scale, as every pose below.
  Pose3 cam_from_world;          // Current estimate.
  // PipelineFrame::frontend_cam_from_world, in pose units, when given.
  std::optional<Pose3> given_frontend_cam_from_world;
  cv::Mat image_bgr;  // Undistorted.
  // The depth search's image: undistorted grey after the edge detector's blur, CV_32FC1
  // (KeyframeImage::grey_float); released once no later keyframe can take it as a depth reference.
  cv::Mat grey_float;
  std::shared_ptr<const NearestEdgeField> field;
  std::vector<PointSighting> points;  // The hybrid graph's points it sees.
};

KeyframeView viewOf(const Keyframe& keyframe, const Camera& camera) {
  return {keyframe.cam_from_world, camera, *keyframe.field, keyframe.image_bgr};
}

// The appearance and viewing direction of a segment seen in `keyframe`, as the map stores them.
ObservedSegmentAppearance measureSegment(const BezierSegmentParams& segment, int keyframe_index,
                                         const Keyframe& keyframe, const Camera& camera,
                                         const CorrespondenceOptions& options) {
  ObservedSegmentAppearance o;
  o.observation.keyframe = keyframe_index;
  o.appearance = appearanceOf(segment, keyframe.cam_from_world, camera, keyframe.image_bgr, options,
                              keyframe.field.get());
  o.viewing_direction_in_world =
      viewingDirection(segment, keyframe.cam_from_world.inverseTranslation());
  return o;
}

// What the map stores of a registration of segment `segment` of curve `id` in `keyframe`.
ObservedSegmentAppearance registration(int id, int segment, int keyframe,
                                       const CorrespondenceVerdict& verdict) {
  return {{id, segment, keyframe}, verdict.appearance, verdict.viewing_direction_in_world};
}

// The projection of a segment as a polyline, or empty if part of it is behind the camera; with
// `depths`, also each vertex's depth (z in the camera).
std::vector<cv::Point> projectSegment(const BezierSegmentParams& segment,
                                      const Pose3& cam_from_world, const Camera& camera,
                                      int samples, std::vector<double>* depths = nullptr) {
  const CubicBezier cubic = segment.toCubic();
  std::vector<cv::Point> polyline;
  if (depths) depths->clear();
  for (int k = 0; k < samples; ++k) {
    Eigen::Vector2d pixel;
    const double t = static_cast<double>(k) / (samples - 1);
    const Eigen::Vector3d in_camera = cam_from_world * cubic.evaluate(t);
    if (!camera.project(in_camera, &pixel)) {
      if (depths) depths->clear();
      return {};
    }
    polyline.emplace_back(static_cast<int>(std::lround(pixel.x())),
                          static_cast<int>(std::lround(pixel.y())));
    if (depths) depths->push_back(in_camera.z());
  }
  return polyline;
}

// Fraction of the polyline's vertices that fall on non-zero pixels of `mask`.
double fractionOnMask(const std::vector<cv::Point>& polyline, const cv::Mat& mask) {
  if (polyline.empty()) return 0.0;
  int on = 0;
  for (const cv::Point& p : polyline) {
    on += p.x >= 0 && p.y >= 0 && p.x < mask.cols && p.y < mask.rows && mask.at<uchar>(p) != 0;
  }
  return static_cast<double>(on) / polyline.size();
}

// The runs of chain pixels that no registered segment explains, as chains of their own.
std::vector<EdgeChain> unexplainedRuns(const std::vector<EdgeChain>& chains,
                                       const cv::Mat& explained, int min_length) {
  std::vector<EdgeChain> runs;
  for (const EdgeChain& chain : chains) {
    EdgeChain run;
    const auto flush = [&]() {
      if (static_cast<int>(run.pixels.size()) >= min_length) runs.push_back(run);
      run = EdgeChain();
    };
    for (std::size_t i = 0; i < chain.pixels.size(); ++i) {
      const Eigen::Vector2i& p = chain.pixels[i];
      if (explained.at<uchar>(p.y(), p.x()) != 0) {
        flush();
        continue;
      }
      run.pixels.push_back(p);
      run.normals.push_back(chain.normals[i]);
    }
    flush();
  }
  return runs;
}

// The reference view that served most valid pixels in [first, last] of a chain; -1 if none.
int dominantReference(const std::vector<PixelDepth>& depths, const PixelRange& range) {
  std::map<int, int> votes;
  for (int i = range.first; i <= range.last; ++i) {
    if (depths[i].valid()) ++votes[depths[i].reference];
  }
  int best = -1;
  int best_votes = 0;
  for (const auto& [reference, count] : votes) {
    if (count > best_votes) {
      best = reference;
      best_votes = count;
    }
  }
  return best;
}

// `cam_from_world` with the world's lengths multiplied by `factor`.
Pose3 scaledPose(const Pose3& cam_from_world, double factor) {
  return Pose3(cam_from_world.rotation(), cam_from_world.translation() * factor);
}

// `cam_from_world` in pose units moved to the scene scale `scale`, its translation rounded to a
// grid of 2^-32 scene scales (2.3e-10, far below any pose's accuracy). The same poses given in
// another unit (millimetres instead of metres) differ from these by rounding in their last bits,
// and the pipeline amplifies such differences: a projection landing on the other side of a pixel
// boundary of a nearest-edge field changes a residual, a registration, a curve. On the grid both
// become the same numbers, so they reconstruct the same scene.
Pose3 toSceneScale(const Pose3& cam_from_world, double scale) {
  constexpr double kGrid = 4294967296.0;  // 2^32
  Eigen::Vector3d t = cam_from_world.translation() / scale;
  for (int i = 0; i < 3; ++i) t[i] = std::round(t[i] * kGrid) / kGrid;
  return Pose3(cam_from_world.rotation(), t);
}

// `curve` with its points and arm lengths multiplied by `factor` (> 0).
PolyBezier scaledCurve(const PolyBezier& curve, double factor) {
  std::vector<Eigen::Vector3d> points = curve.points();
  for (Eigen::Vector3d& p : points) p *= factor;
  std::vector<SegmentLengths> lengths = curve.lengths();
  for (SegmentLengths& l : lengths) {
    l.d1 *= factor;
    l.d2 *= factor;
  }
  return PolyBezier(std::move(points), curve.directions(), std::move(lengths));
}

// The keyframe choice of addFrame, shared with selectKeyframes: the scene scale (given, or learnt
// from the first frame whose initial centre left frame 0's) and the selector on the initial
// poses in that unit.
class KeyframeGate {
 public:
  explicit KeyframeGate(const PipelineOptions& options)
      : selector_(options.map), scene_scale_(options.scene_scale) {}

  bool admit(const Pose3& initial_cam_from_world) {
    learnSceneScale(initial_cam_from_world.inverseTranslation());
    return selector_.isKeyframe(initial_cam_from_world, unit());
  }
  /// Pose units; 0 until known.
  double sceneScale() const { return scene_scale_; }
  /// The unit the pipeline works in: the scene scale, or the poses' own unit while it is unknown.
  double unit() const { return scene_scale_ > 0.0 ? scene_scale_ : 1.0; }

 private:
  void learnSceneScale(const Eigen::Vector3d& centre) {
    if (scene_scale_ > 0.0) return;
    if (!first_centre_) {
      first_centre_ = centre;
      return;
    }
    const double distance = (centre - *first_centre_).norm();
    if (distance > 0.0 && std::isfinite(distance)) scene_scale_ = distance;
  }

  KeyframeSelector selector_;
  double scene_scale_;
  std::optional<Eigen::Vector3d> first_centre_;  // Initial centre of frame 0.
};

void countRejection(CorrespondenceCheck failed, KeyframeStats* stats) {
  switch (failed) {
    case CorrespondenceCheck::kDepth:
      ++stats->rejected_depth;
      break;
    case CorrespondenceCheck::kEdgeDistance:
      ++stats->rejected_edge_distance;
      break;
    case CorrespondenceCheck::kViewingDirection:
      ++stats->rejected_viewing_direction;
      break;
    case CorrespondenceCheck::kAppearance:
      ++stats->rejected_appearance;
      break;
    case CorrespondenceCheck::kNone:
      break;
  }
}

}  // namespace

OptimizerOptions defaultPipelineOptimizerOptions() {
  OptimizerOptions options;
  options.linear_solver = LinearSolver::kGraphSchur;
  return options;
}

SchedulerOptions defaultLocalBundleAdjustmentOptions() {
  SchedulerOptions options;
  options.optimizer = defaultPipelineOptimizerOptions();
  options.strategy = Strategy::kAlternating;
  options.scope = Scope::kLocal;
  options.local_window = 5;
  // With every pose held, Ceres' first radius (1e4) makes the first steps of every solve nearly
  // undamped and rejected, and 1e-6 runs a tail of tiny steps against the nearest-edge cost's
  // jumps: on the six real sets these two take 31 -> 17 iterations a keyframe at the same ATEs
  // (docs/benchmarks.md, "Fewer local BA iterations").
  options.optimizer.initial_trust_region_radius = 10.0;
  options.optimizer.function_tolerance = 1e-4;
  return options;
}

SchedulerOptions defaultGlobalBundleAdjustmentOptions() {
  SchedulerOptions options;
  options.optimizer = defaultPipelineOptimizerOptions();
  // Near its minimum the nearest-edge cost's jumps keep Levenberg-Marquardt alternating rejected
  // steps with kept ones worth a millionth (the last 5-13 of Pavilion's 30-50 iterations a
  // solve); on the six real sets the stall test took 9 % off the global BA iterations left
  // after reassociation_interim_iterations' budget, with the same ATEs in 29 of 30 runs
  // (docs/benchmarks.md, "A budget for re-association's global BAs").
  options.optimizer.stall_iterations = 5;
  return options;
}

// The stages' metric defaults in multiples of kPlanarReferenceSceneScale (pipeline.h).
EpipolarDepthOptions defaultPipelineDepthOptions() {
  EpipolarDepthOptions options;
  options.min_depth = 10.0;
  options.max_depth = 1500.0;
  return options;
}

CurveInitialiserOptions defaultPipelineInitialiserOptions() {
  CurveInitialiserOptions options;
  options.min_chord = 7.4e-3;
  return options;
}

CorrespondenceOptions defaultPipelineCorrespondenceOptions() {
  CorrespondenceOptions options;
  options.min_depth = 0.74;
  return options;
}

CurveMapOptions defaultPipelineMapOptions() {
  CurveMapOptions options;
  options.min_keyframe_translation = 0.74;
  return options;
}

CurveBundleAdjustmentOptions defaultPipelineBundleAdjustmentOptions() {
  CurveBundleAdjustmentOptions options;
  options.lambda1 = 0.018;
  options.scale_sigma = 7.4e-3;
  options.kernel = RobustKernelType::kCauchy;
  return options;
}

void PipelineOptions::validate() const {
  undistort.validate();
  edges.validate();
  chains.validate();
  field.validate();
  depth.validate();
  initialiser.validate();
  extension.validate();
  correspondence.validate();
  map.validate();
  ba.validate();
  local_ba.validate();
  global_ba.validate();
  tracking.validate();
  sanity.validate();
  const OptionCheck require("PipelineOptions");
  require(local_ba_max_curve_keyframes == 0 || local_ba_max_curve_keyframes > local_ba.local_window,
          "local_ba_max_curve_keyframes", local_ba_max_curve_keyframes,
          "must be 0 (all) or more than local_ba.local_window (" +
              std::to_string(local_ba.local_window) + ")");
  require(point_depth_margin >= 1.0 && point_depth_margin < 1e6, "point_depth_margin",
          point_depth_margin, "finite and >= 1");
  require(std::isfinite(scene_scale) && scene_scale >= 0.0, "scene_scale", scene_scale,
          "must be finite and >= 0 (0 derives it)");
  require(curve_precision_max_keyframes >= 0, "curve_precision_max_keyframes",
          curve_precision_max_keyframes, ">= 0");
  require(last_global_ba_kernel_width == 0.0 ||
              (std::isfinite(last_global_ba_kernel_width) && last_global_ba_kernel_width > 0.0),
          "last_global_ba_kernel_width", last_global_ba_kernel_width,
          "must be 0 (ba.kernel_width) or finite and > 0");
  require(registration_threads >= 1 && registration_threads <= 64, "registration_threads",
          registration_threads, "in [1, 64]");
  require(depth_reference_candidates >= 1, "depth_reference_candidates", depth_reference_candidates,
          ">= 1");
  require(reassociation_rounds >= 0, "reassociation_rounds", reassociation_rounds, ">= 0");
  require(reassociation_interim_iterations >= 0, "reassociation_interim_iterations",
          reassociation_interim_iterations, ">= 0");
  require(std::isfinite(reassociation_max_edge_distance_px) &&
              reassociation_max_edge_distance_px >= 0.0,
          "reassociation_max_edge_distance_px", reassociation_max_edge_distance_px,
          "must be finite and >= 0");
  require(
      reassociation_max_viewing_angle_deg >= 0.0 && reassociation_max_viewing_angle_deg <= 180.0,
      "reassociation_max_viewing_angle_deg", reassociation_max_viewing_angle_deg,
      "must be in [0, 180]");
  require(reassociation_occluder_depth_ratio > 0.0 && reassociation_occluder_depth_ratio <= 1.0,
          "reassociation_occluder_depth_ratio", reassociation_occluder_depth_ratio,
          "must be in (0, 1]");
  require(std::isfinite(explained_radius_px) && explained_radius_px >= 0.0, "explained_radius_px",
          explained_radius_px, "must be finite and >= 0");
}

struct Pipeline::Impl {
  Impl(const Camera& source_camera, const PipelineOptions& pipeline_options)
      : options((pipeline_options.validate(), pipeline_options)),
        undistorter(source_camera, options.undistort),
        camera(std::make_shared<const Camera>(undistorter.camera())),
        initialiser(options.initialiser),
        gate(options),
        map(options.map) {}

  double unit() const { return gate.unit(); }
  void moveKeyframesToSceneScale();

  KeyframeStats addFrame(const PipelineFrame& frame);
  KeyframeImage prepareImage(const cv::Mat& image_bgr) const {
    return prepareKeyframeImage(image_bgr, undistorter, options.edges, options.chains,
                                options.field);
  }
  void addKeyframe(const PipelineFrame& frame, const KeyframeImage& image, KeyframeStats* stats);
  void trackPose(Keyframe* keyframe);
  /// Segment i of curve `id`.
  struct SegmentRef {
    int id;
    int i;
  };
  /// One attempt to register a segment in keyframe k (see attemptRegistration).
  struct SegmentAttempt {
    /// Skipped: most of it lies on already explained edges, or behind a nearer curve.
    bool explained_elsewhere = false;
    CorrespondenceVerdict verdict;
    /// Its projection into keyframe k, when it registered or a mask was checked (else empty).
    std::vector<cv::Point> polyline;
    std::vector<double> depths;  ///< Its vertices' depths, with the occlusion check.
  };
  SegmentAttempt attemptRegistration(int k, const KeyframeView& view, SegmentRef segment,
                                     const CorrespondenceOptions& checks, const cv::Mat* explained,
                                     const NearestCurveDepths* occluders) const;
  std::vector<SegmentAttempt> attemptAll(int k, const KeyframeView& view,
                                         const std::vector<SegmentRef>& segments,
                                         const CorrespondenceOptions& checks,
                                         const cv::Mat* explained) const;
  void addRegistration(int k, SegmentRef segment, const SegmentAttempt& attempt);
  void registerTier(int k, CurveState state, bool skip_explained, cv::Mat* explained,
                    KeyframeStats* stats);
  void registerMap(int k, cv::Mat* explained, KeyframeStats* stats);
  void reassociate(ReassociationRound* round);
  void reassociateIn(int k, const std::vector<int>& ids, const CorrespondenceOptions& checks,
                     ReassociationRound* round);
  /// Calls draw(polyline, depths) for the projection of every segment observed in keyframe k.
  template <typename Draw>
  void forEachObservedProjection(int k, Draw draw) const;
  cv::Mat explainedEdges(int k) const;
  NearestCurveDepths nearestCurveDepths(int k) const;
  /// Samples along a segment's projection when it is matched against explained edges.
  int projectionSamples() const { return 2 * options.correspondence.samples_per_segment + 1; }
  /// Width (px) of the band a registered segment explains around its projection.
  int explainedThickness() const {
    return 2 * static_cast<int>(std::ceil(options.explained_radius_px)) + 1;
  }
  std::vector<int> depthReferences(int k, const std::vector<EdgeChain>& chains) const;
  EpipolarDepthOptions depthOptions(int k) const;
  PoseStage poseStage(const std::string& name) const;
  std::vector<CurveStatistics> curveStatisticsInPoseUnits() const;
  std::optional<CurveCentrePrecision> curvePrecisionInPoseUnits() const;
  void initialiseCurves(int k, const std::vector<EdgeChain>& chains, KeyframeStats* stats);
  std::vector<OpenEnd> openEnds(int k) const;
  void addInitialCurve(int k, const InitialCurve& initial, const ChainDepths& depths,
                       const std::vector<int>& reference_keyframes, std::vector<OpenEnd>* open_ends,
                       KeyframeStats* stats);
  void registerNewSegments(int k, int id, const std::vector<int>& segment_ids,
                           const InitialCurve& initial, const ChainDepths& depths,
                           const std::vector<int>& reference_keyframes);
  CurveBundleAdjustmentInput bundleInput(CurveSelection selection, std::vector<int>* ids) const;
  std::vector<int> addPointsTo(CurveBundleAdjustmentInput* input) const;
  void checkFit(bool drop);
  ScheduleReport bundleAdjust(CurveSelection selection, const SchedulerOptions& scheduler,
                              const CurveBundleAdjustmentOptions& ba, bool refine_poses,
                              CurveSampleCounts* samples);
  SceneExtent currentExtent() const;
  void checkCurves(bool drop);
  /// One global BA of every promoted curve; `interim`: a re-association round follows.
  ScheduleReport globalBundleAdjust(bool interim, CurveSampleCounts* samples);
  /// The global BA and the re-association rounds after it, into `result`; returns whether the
  /// curves were checked since the last BA.
  bool runGlobalRounds(PipelineResult* result);
  /// The keyframes, curves and points in the unit of the poses given, and the run's sanity.
  void collectResult(int promoted, PipelineResult* result) const;

  PipelineOptions options;
  ImageUndistorter undistorter;
  std::shared_ptr<const Camera> camera;
  CurveInitialiser initialiser;
  KeyframeGate gate;
  CurveMap map;
  std::vector<Keyframe> keyframes;
  std::vector<KeyframeStats> frames;
  bool finished = false;
  std::vector<Eigen::Vector3d> points;  // The hybrid graph's, world frame, pose units.
  // The sanity checks (checkCurves): what they found, the last extent (scene scale) and the
  // global BAs run so far.
  std::vector<ImplausibleCurve> implausible;
  SceneExtent extent;
  int global_bas = 0;
  double kernel_width_of_last_global_ba = 0.0;  // The edge kernel it weighed with.
};

// Once the gate knows the scene scale (see PipelineOptions::scene_scale): the keyframes before
// it all sit at frame 0's centre, kept in pose units; they move to the new unit, and no curve
// exists yet (no baseline, no depth).
void Pipeline::Impl::moveKeyframesToSceneScale() {
  CURVESFM_CHECK(map.size() == 0) << "curves exist before the scene scale is known";
  for (Keyframe& keyframe : keyframes) {
    keyframe.initial_cam_from_world = toSceneScale(keyframe.given_cam_from_world, unit());
    keyframe.cam_from_world = toSceneScale(
        keyframe.given_frontend_cam_from_world.value_or(keyframe.given_cam_from_world), unit());
  }
}

// Keyframe k's data from the frame and its image stage; the frame's poses in the scene scale.
void Pipeline::Impl::addKeyframe(const PipelineFrame& frame, const KeyframeImage& image,
                                 KeyframeStats* stats) {
  Keyframe keyframe;
  keyframe.frame_index = stats->frame_index;
  keyframe.timestamp = frame.timestamp;
  keyframe.given_cam_from_world = frame.initial_cam_from_world;
  keyframe.initial_cam_from_world = toSceneScale(frame.initial_cam_from_world, unit());
  keyframe.cam_from_world = keyframe.initial_cam_from_world;
  if (frame.frontend_cam_from_world) {
    keyframe.given_frontend_cam_from_world = frame.frontend_cam_from_world;
    keyframe.cam_from_world = toSceneScale(*frame.frontend_cam_from_world, unit());
  }
  keyframe.points = frame.points;
  keyframe.image_bgr = image.image_bgr;
  keyframe.grey_float = image.grey_float;
  keyframe.field = image.field;
  keyframes.push_back(std::move(keyframe));

  stats->undistort_seconds = image.undistort_seconds;
  stats->edges_seconds = image.edges_seconds;
  stats->field_seconds = image.field_seconds;
  stats->edge_pixels = cv::countNonZero(image.edges);
  stats->canny_high_threshold = image.canny_high_threshold;
  stats->canny_low_threshold = image.canny_low_threshold;
  stats->chains = static_cast<int>(image.chains.size());
}

void Pipeline::Impl::trackPose(Keyframe* keyframe) {
  CurveBundleAdjustmentInput input;
  input.camera = camera;
  input.cam_from_world = {keyframe->cam_from_world};
  input.fields = {keyframe->field};
  // Global curves only: temporary ones come straight from depth and were never refined.
  for (const int id : map.curvesIn(CurveState::kGlobal)) {
    const PolyBezier& curve = map.curve(id).curve;
    const int exported = static_cast<int>(input.curves.size());
    input.curves.push_back(curve);
    for (int i = 0; i < curve.numSegments(); ++i) {
      if (checkPositiveDepth(curve.segment(i), keyframe->cam_from_world, options.correspondence)
              .passed) {
        input.observations.push_back({exported, i, 0});
      }
    }
  }
  if (input.observations.empty()) return;
  CurveBundleAdjustmentOptions ba = options.ba;
  ba.fix_first_pose = false;
  ba.fix_scale = false;
  ba.lambda1 = 0.0;
  ba.lambda2 = 0.0;
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, ba);
  for (const VariableCategory c :
       {VariableCategory::kCurvePoint, VariableCategory::kDirection, VariableCategory::kLength}) {
    problem.config.setConstant(c);
  }
  const OptimizationSummary summary =
      optimize(problem.graph, &problem.values, problem.config, options.tracking);
  if (summary.usable) keyframe->cam_from_world = extractPoses(problem.values, 1)[0];
}

// Projects `segment` into keyframe k and, unless more than half of it lies on `explained` (when
// given: edges another curve explains, which it must not take over) or behind `occluders`, runs
// the correspondence checks. Reads the map only, so attempts may run concurrently.
Pipeline::Impl::SegmentAttempt Pipeline::Impl::attemptRegistration(
    int k, const KeyframeView& view, SegmentRef segment, const CorrespondenceOptions& checks,
    const cv::Mat* explained, const NearestCurveDepths* occluders) const {
  const MapCurve& curve = map.curve(segment.id);
  const BezierSegmentParams params = curve.curve.segment(segment.i);
  SegmentAttempt attempt;
  // Every curve is tried in every keyframe and few register: the projection is drawn only for
  // the two masks and for a segment that registered. Depths only for the occlusion check.
  const auto project = [&] {
    attempt.polyline = projectSegment(params, keyframes[k].cam_from_world, *camera,
                                      projectionSamples(), occluders ? &attempt.depths : nullptr);
  };
  const bool masked = explained || occluders;
  if (masked) project();
  if ((explained && fractionOnMask(attempt.polyline, *explained) > 0.5) ||
      (occluders && occluders->fractionOccluded(attempt.polyline, attempt.depths) > 0.5)) {
    attempt.explained_elsewhere = true;
    return attempt;
  }
  attempt.verdict = registerSegment(params, view, curve.segments[segment.i].history(), checks);
  if (attempt.verdict.registered && !masked) project();
  return attempt;
}

// attemptRegistration for each of `segments` in keyframe k against one fixed `explained` mask,
// on registration_threads threads; the attempts in the order of `segments`.
std::vector<Pipeline::Impl::SegmentAttempt> Pipeline::Impl::attemptAll(
    int k, const KeyframeView& view, const std::vector<SegmentRef>& segments,
    const CorrespondenceOptions& checks, const cv::Mat* explained) const {
  std::vector<SegmentAttempt> attempts(segments.size());
  // In blocks taken as the threads come free: curves differ in cost, and a thread may share its
  // core with the image stage ahead, where a fixed split would leave the others waiting for it.
  // A block of 32 attempts (1-2 us each) outweighs handing it out many times over and leaves the
  // other threads at most some 50 us to wait at the end.
  constexpr int kBlock = 32;
  forEachInParallel(
      options.registration_threads, static_cast<int>(segments.size()), kBlock, [&](int, int s) {
        attempts[s] = attemptRegistration(k, view, segments[s], checks, explained, nullptr);
      });
  return attempts;
}

void Pipeline::Impl::addRegistration(int k, SegmentRef segment, const SegmentAttempt& attempt) {
  map.addObservation(segment.id, segment.i,
                     registration(segment.id, segment.i, k, attempt.verdict));
}

void Pipeline::Impl::registerTier(int k, CurveState state, bool skip_explained, cv::Mat* explained,
                                  KeyframeStats* stats) {
  std::vector<SegmentRef> segments;
  for (const int id : map.curvesIn(state)) {
    for (int i = 0; i < map.curve(id).curve.numSegments(); ++i) segments.push_back({id, i});
  }
  // The tier's attempts all read the mask as the earlier tiers left it.
  std::vector<SegmentAttempt> attempts =
      attemptAll(k, viewOf(keyframes[k], *camera), segments, options.correspondence,
                 skip_explained ? explained : nullptr);
  std::vector<std::vector<cv::Point>> registered;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    SegmentAttempt& attempt = attempts[s];
    if (attempt.explained_elsewhere) {
      ++stats->rejected_duplicate;
    } else if (!attempt.verdict.registered) {
      countRejection(attempt.verdict.failed_check, stats);
    } else {
      addRegistration(k, segments[s], attempt);
      ++stats->registered_segments;
      if (!attempt.polyline.empty()) registered.push_back(std::move(attempt.polyline));
    }
  }
  cv::polylines(*explained, registered, false, cv::Scalar(255), explainedThickness());
}

void Pipeline::Impl::registerMap(int k, cv::Mat* explained, KeyframeStats* stats) {
  // Global first, so that a temporary duplicate cannot claim edges a global curve explains
  // (paper §3.3); disabled curves last, to notice when they are seen again.
  registerTier(k, CurveState::kGlobal, false, explained, stats);
  registerTier(k, CurveState::kTemporary, true, explained, stats);
  registerTier(k, CurveState::kDisabled, true, explained, stats);
}

// Registers every promoted curve's segments in every keyframe that does not observe them yet,
// with the same four checks (tightened by the reassociation_* options), at the refined poses and
// curves; counts what it added and what it left to other curves in `round`.
void Pipeline::Impl::reassociate(ReassociationRound* round) {
  std::vector<int> ids = map.curvesIn(CurveState::kGlobal);
  for (const int id : map.curvesIn(CurveState::kDisabled)) {
    if (map.curve(id).promoted) ids.push_back(id);
  }
  CorrespondenceOptions checks = options.correspondence;
  if (options.reassociation_max_edge_distance_px > 0.0) {
    checks.max_mean_edge_distance_px = options.reassociation_max_edge_distance_px;
  }
  if (options.reassociation_max_viewing_angle_deg > 0.0) {
    checks.max_viewing_angle_deg = options.reassociation_max_viewing_angle_deg;
  }
  for (int k = 0; k < static_cast<int>(keyframes.size()); ++k) {
    reassociateIn(k, ids, checks, round);
  }
}

// Re-association in keyframe k of the segments of curves `ids` it does not observe yet. Without
// masks a keyframe's attempts are independent (each segment is tried once, and only its own
// registration changes its history) and run together; with them each registration extends the
// masks the next attempt reads.
void Pipeline::Impl::reassociateIn(int k, const std::vector<int>& ids,
                                   const CorrespondenceOptions& checks, ReassociationRound* round) {
  const KeyframeView view = viewOf(keyframes[k], *camera);
  std::vector<SegmentRef> segments;
  for (const int id : ids) {
    for (int i = 0; i < map.curve(id).curve.numSegments(); ++i) {
      if (!map.curve(id).segments[i].observedIn(k)) segments.push_back({id, i});
    }
  }
  if (!options.reassociation_skip_explained && !options.reassociation_skip_occluded) {
    const std::vector<SegmentAttempt> attempts = attemptAll(k, view, segments, checks, nullptr);
    for (std::size_t s = 0; s < segments.size(); ++s) {
      if (!attempts[s].verdict.registered) continue;
      addRegistration(k, segments[s], attempts[s]);
      ++round->added_observations;
    }
    return;
  }
  cv::Mat explained;
  if (options.reassociation_skip_explained) explained = explainedEdges(k);
  std::optional<NearestCurveDepths> occluders;
  if (options.reassociation_skip_occluded) occluders = nearestCurveDepths(k);
  for (const SegmentRef& segment : segments) {
    const SegmentAttempt attempt =
        attemptRegistration(k, view, segment, checks, explained.empty() ? nullptr : &explained,
                            occluders ? &*occluders : nullptr);
    round->left_to_other_curves += attempt.explained_elsewhere;
    if (!attempt.verdict.registered) continue;
    addRegistration(k, segment, attempt);
    ++round->added_observations;
    if (attempt.polyline.empty()) continue;
    if (!explained.empty()) {
      cv::polylines(explained, std::vector<std::vector<cv::Point>>{attempt.polyline}, false,
                    cv::Scalar(255), explainedThickness());
    }
    if (occluders) occluders->add(attempt.polyline, attempt.depths);
  }
}

template <typename Draw>
void Pipeline::Impl::forEachObservedProjection(int k, Draw draw) const {
  std::vector<double> depths;
  for (int id = 0; id < map.size(); ++id) {
    const MapCurve& curve = map.curve(id);
    // Curves the sanity checks dropped explain nothing.
    if (curve.state == CurveState::kImplausible) continue;
    for (int i = 0; i < curve.curve.numSegments(); ++i) {
      if (!curve.segments[i].observedIn(k)) continue;
      std::vector<cv::Point> polyline =
          projectSegment(curve.curve.segment(i), keyframes[k].cam_from_world, *camera,
                         projectionSamples(), &depths);
      if (!polyline.empty()) draw(std::move(polyline), depths);
    }
  }
}

// The pixels of keyframe k that the segments observed there explain: their projections at the
// current poses and curves, drawn explainedThickness() px wide.
cv::Mat Pipeline::Impl::explainedEdges(int k) const {
  cv::Mat explained = cv::Mat::zeros(camera->height(), camera->width(), CV_8UC1);
  std::vector<std::vector<cv::Point>> polylines;
  forEachObservedProjection(k, [&](std::vector<cv::Point> polyline, const std::vector<double>&) {
    polylines.push_back(std::move(polyline));
  });
  cv::polylines(explained, polylines, false, cv::Scalar(255), explainedThickness());
  return explained;
}

// The depth of the nearest segment observed in keyframe k around each pixel, over the band
// explainedEdges() draws.
NearestCurveDepths Pipeline::Impl::nearestCurveDepths(int k) const {
  NearestCurveDepths nearest(camera->width(), camera->height(), explainedThickness() / 2,
                             options.reassociation_occluder_depth_ratio);
  forEachObservedProjection(
      k, [&](const std::vector<cv::Point>& polyline, const std::vector<double>& depths) {
        nearest.add(polyline, depths);
      });
  return nearest;
}

// The keyframe poses now, in the unit of the poses given; a pose nothing moved is returned
// exactly as given, without the grid's rounding.
PoseStage Pipeline::Impl::poseStage(const std::string& name) const {
  PoseStage stage{name, {}};
  for (const Keyframe& keyframe : keyframes) {
    const bool moved =
        keyframe.cam_from_world.translation() != keyframe.initial_cam_from_world.translation() ||
        keyframe.cam_from_world.rotation().coeffs() !=
            keyframe.initial_cam_from_world.rotation().coeffs();
    stage.keyframe_cam_from_world.push_back(moved ? scaledPose(keyframe.cam_from_world, unit())
                                                  : keyframe.given_cam_from_world);
  }
  return stage;
}

// The statistics of the curves finish() exports (the promoted ones, in the same order), with
// lengths back in pose units and each curve's initialising keyframe.
std::vector<CurveStatistics> Pipeline::Impl::curveStatisticsInPoseUnits() const {
  if (keyframes.size() < 2) return {};
  std::vector<int> ids;
  std::vector<CurveStatistics> stats =
      curveStatistics(bundleInput(CurveSelection::kPromoted, &ids), options.ba);
  for (std::size_t c = 0; c < stats.size(); ++c) {
    stats[c].length *= unit();
    stats[c].median_camera_distance *= unit();
    stats[c].first_keyframe = map.curve(ids[c]).first_keyframe;
  }
  return stats;
}

// How precisely the final map's curves fix the centres, weighed as the last global BA weighs
// them; ATEs back in pose units.
std::optional<CurveCentrePrecision> Pipeline::Impl::curvePrecisionInPoseUnits() const {
  const int n = static_cast<int>(keyframes.size());
  if (global_bas == 0 || n < 3 || n > options.curve_precision_max_keyframes) return std::nullopt;
  std::vector<int> ids;
  const CurveBundleAdjustmentInput input = bundleInput(CurveSelection::kPromoted, &ids);
  if (input.observations.empty()) return std::nullopt;
  CurveBundleAdjustmentOptions ba = options.ba;
  ba.kernel_width = kernel_width_of_last_global_ba;
  CurveCentrePrecision precision = curveCentrePrecision(buildCurveBundleAdjustment(input, ba), n);
  precision.predicted_centre_ate *= unit();
  precision.predicted_centre_ate_correlated *= unit();
  return precision;
}

// The depth range of keyframe k's epipolar search: from the points it sees when there are
// enough (PipelineOptions::point_depth_range), else the options' range.
EpipolarDepthOptions Pipeline::Impl::depthOptions(int k) const {
  constexpr std::size_t kMinPoints = 10;
  EpipolarDepthOptions depth = options.depth;
  const Keyframe& keyframe = keyframes[k];
  if (!options.point_depth_range || keyframe.points.size() < kMinPoints) return depth;
  std::vector<double> depths;
  for (const PointSighting& sighting : keyframe.points) {
    const double z = (keyframe.cam_from_world * (points[sighting.point] / unit())).z();
    if (z > 0.0) depths.push_back(z);
  }
  if (depths.size() < kMinPoints) return depth;
  std::sort(depths.begin(), depths.end());
  const double low = depths[depths.size() / 20];
  const double high = depths[depths.size() - 1 - depths.size() / 20];
  depth.min_depth = low / options.point_depth_margin;
  depth.max_depth = high * options.point_depth_margin;
  return depth;
}

std::vector<int> Pipeline::Impl::depthReferences(int k,
                                                 const std::vector<EdgeChain>& chains) const {
  std::vector<int> candidates;
  for (int j = k - 1; j >= 0 && j >= k - options.depth_reference_candidates; --j) {
    candidates.push_back(j);
  }
  std::vector<Pose3> candidate_poses;
  for (const int j : candidates) candidate_poses.push_back(keyframes[j].cam_from_world);
  std::vector<int> references;
  for (const ReferenceCandidate& c : rankReferenceFrames(
           keyframes[k].cam_from_world, candidate_poses, *camera, chains, depthOptions(k))) {
    if (c.eligible) references.push_back(candidates[c.index]);
  }
  return references;
}

void Pipeline::Impl::initialiseCurves(int k, const std::vector<EdgeChain>& chains,
                                      KeyframeStats* stats) {
  if (k == 0 || chains.empty() || gate.sceneScale() <= 0.0) return;
  Clock::time_point start = Clock::now();
  const std::vector<int> reference_keyframes = depthReferences(k, chains);
  std::vector<DepthReferenceView> references;
  for (const int j : reference_keyframes) {
    references.push_back({keyframes[j].grey_float, keyframes[j].cam_from_world});
  }
  const ChainDepths depths =
      estimateChainDepths(keyframes[k].grey_float, keyframes[k].cam_from_world, chains, references,
                          *camera, depthOptions(k));
  stats->valid_depths = depths.counts.valid();
  stats->depth_seconds = secondsSince(start);

  start = Clock::now();
  const CurveInitialisation initialisation =
      initialiser.initialise(*camera, keyframes[k].cam_from_world, chains, depths);
  std::vector<OpenEnd> open_ends = openEnds(k);
  for (const InitialCurve& initial : initialisation.curves) {
    addInitialCurve(k, initial, depths, reference_keyframes, &open_ends, stats);
  }
  stats->initialise_seconds = secondsSince(start);
}

// The ends of the curves whose end segment keyframe k registered: the edge pixels next to them
// belong to the same chain, so a new curve lifted from there may continue the curve.
std::vector<OpenEnd> Pipeline::Impl::openEnds(int k) const {
  std::vector<OpenEnd> ends;
  if (!options.extension.enabled) return ends;
  for (int id = 0; id < map.size(); ++id) {
    const MapCurve& c = map.curve(id);
    for (const CurveEnd end : {CurveEnd::kFront, CurveEnd::kBack}) {
      if (!c.segments[endSegment(c.curve, end)].observedIn(k)) continue;
      const std::optional<OpenEnd> open =
          openEnd(id, c.curve, end, keyframes[k].cam_from_world, *camera);
      if (open) ends.push_back(*open);
    }
  }
  return ends;
}

// Adds `initial` to the map: appended to the open end it continues smoothly (that end is then
// used up), else as a curve of its own.
void Pipeline::Impl::addInitialCurve(int k, const InitialCurve& initial, const ChainDepths& depths,
                                     const std::vector<int>& reference_keyframes,
                                     std::vector<OpenEnd>* open_ends, KeyframeStats* stats) {
  const std::optional<CurveJoin> join =
      findJoin(initial.curve, *open_ends, keyframes[k].cam_from_world, *camera, options.extension);
  if (!join) {
    const int id = map.addCurve(initial.curve, k);
    std::vector<int> segment_ids(initial.curve.numSegments());
    std::iota(segment_ids.begin(), segment_ids.end(), 0);
    registerNewSegments(k, id, segment_ids, initial, depths, reference_keyframes);
    ++stats->new_curves;
    return;
  }
  const OpenEnd open = (*open_ends)[join->open_end];
  open_ends->erase(open_ends->begin() + join->open_end);
  const ExtendedCurve extended =
      extendCurve(map.curve(open.curve).curve, open.end, initial.curve, join->new_end);
  map.extendCurve(open.curve, extended.curve, open.end);
  registerNewSegments(k, open.curve, extended.added_segments, initial, depths, reference_keyframes);
  ++stats->extended_curves;
}

// Registers in keyframe k, and in the reference view its depth came from, each segment i of
// `initial`, which is segment segment_ids[i] of map curve `id`.
void Pipeline::Impl::registerNewSegments(int k, int id, const std::vector<int>& segment_ids,
                                         const InitialCurve& initial, const ChainDepths& depths,
                                         const std::vector<int>& reference_keyframes) {
  const std::vector<PixelDepth>& chain_depths = depths.chains[initial.chain];
  for (std::size_t i = 0; i < segment_ids.size(); ++i) {
    const int s = segment_ids[i];
    const BezierSegmentParams segment = map.curve(id).curve.segment(s);
    const ObservedSegmentAppearance here =
        measureSegment(segment, k, keyframes[k], *camera, options.correspondence);
    // The reference view saw the segment too (its depth came from there); verify it as any other
    // registration, against what keyframe k measured.
    const int reference = dominantReference(chain_depths, initial.segment_pixels[i]);
    if (reference >= 0) {
      const int j = reference_keyframes[reference];
      SegmentHistory history;
      history.reference_appearance = here.appearance;
      history.mean_viewing_direction_in_world = here.viewing_direction_in_world;
      const CorrespondenceVerdict verdict =
          registerSegment(segment, viewOf(keyframes[j], *camera), history, options.correspondence);
      if (verdict.registered) {
        map.addObservation(id, s, registration(id, s, j, verdict));
      }
    }
    map.addObservation(id, s, here);
  }
}

CurveBundleAdjustmentInput Pipeline::Impl::bundleInput(CurveSelection selection,
                                                       std::vector<int>* ids) const {
  CurveBundleAdjustmentInput input;
  input.camera = camera;
  for (const Keyframe& keyframe : keyframes) {
    input.cam_from_world.push_back(keyframe.cam_from_world);
    input.motion_prior_cam_from_world.push_back(keyframe.initial_cam_from_world);
    input.fields.push_back(keyframe.field);
  }
  // The scale gauge: the initial baseline of the first two keyframes, so the map keeps the unit
  // of the initial poses.
  input.scale_distance = cameraCentreDistance(keyframes[1].initial_cam_from_world,
                                              keyframes[0].initial_cam_from_world);
  ExportedCurves exported = map.exportCurves(selection);
  input.curves = std::move(exported.curves);
  input.segment_reference_lengths = std::move(exported.initial_chords);
  input.observations = std::move(exported.observations);
  *ids = std::move(exported.ids);
  return input;
}

// The points the keyframes see, in the scene scale, and their observations; returns the index
// into `points` of each point given to the BA.
std::vector<int> Pipeline::Impl::addPointsTo(CurveBundleAdjustmentInput* input) const {
  std::vector<int> used;
  if (!options.ba.points || points.empty()) return used;
  std::vector<int> index(points.size(), -1);
  for (std::size_t j = 0; j < keyframes.size(); ++j) {
    for (const PointSighting& sighting : keyframes[j].points) {
      CURVESFM_CHECK(sighting.point >= 0 && sighting.point < static_cast<int>(points.size()))
          << "keyframe " << j << " sees point " << sighting.point << " of " << points.size();
      int& i = index[sighting.point];
      if (i < 0) {
        i = static_cast<int>(used.size());
        used.push_back(sighting.point);
        input->points.push_back(points[sighting.point] / unit());
      }
      input->point_observations.push_back(
          {static_cast<int>(j), i, sighting.pixel, sighting.keypoint, sighting.keypoint_size});
    }
  }
  return used;
}

ScheduleReport Pipeline::Impl::bundleAdjust(CurveSelection selection,
                                            const SchedulerOptions& scheduler,
                                            const CurveBundleAdjustmentOptions& ba,
                                            bool refine_poses, CurveSampleCounts* samples) {
  std::vector<int> ids;
  CurveBundleAdjustmentInput input = bundleInput(selection, &ids);
  if (input.observations.empty()) return {};
  if (scheduler.scope == Scope::kLocal) {
    input.observations =
        thinLocalObservations(input.observations, options.local_ba_max_curve_keyframes,
                              scheduler.local_window, static_cast<int>(keyframes.size()) - 1);
  }
  const std::vector<int> point_ids = addPointsTo(&input);
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, ba);
  if (!refine_poses) problem.config.setConstant(VariableCategory::kPose);
  SchedulerOptions schedule = scheduler;
  schedule.fix_first_pose = ba.fix_first_pose;
  const ScheduleReport report =
      runSchedule(problem.graph, &problem.values, problem.config, schedule);
  const std::vector<Pose3> refined = extractPoses(problem.values, keyframes.size());
  for (std::size_t j = 0; j < keyframes.size(); ++j) keyframes[j].cam_from_world = refined[j];
  map.updateCurves(ids, extractCurves(problem.values, input.curves));
  const std::vector<Eigen::Vector3d> refined_points =
      extractPoints(problem.values, point_ids.size());
  for (std::size_t i = 0; i < point_ids.size(); ++i) {
    points[point_ids[i]] = refined_points[i] * unit();
  }
  if (samples != nullptr) *samples = countCurveSamples(problem.graph, problem.values);
  return report;
}

// The scene's extent now, in the scene scale: the keyframe centres and the points, or without
// points the end points of the curves that reached the global map. Runaway curves are few among
// many, so the percentiles leave them out of an extent they define.
SceneExtent Pipeline::Impl::currentExtent() const {
  constexpr std::size_t kMinPoints = 10;
  std::vector<Eigen::Vector3d> centres;
  for (const Keyframe& keyframe : keyframes) {
    centres.push_back(keyframe.cam_from_world.inverseTranslation());
  }
  std::vector<Eigen::Vector3d> scene;
  if (points.size() >= kMinPoints) {
    for (const Eigen::Vector3d& p : points) scene.push_back(p / unit());
    return sceneExtent(centres, scene, "points", options.sanity);
  }
  for (const PolyBezier& curve : map.exportCurves(CurveSelection::kPromoted).curves) {
    scene.insert(scene.end(), curve.points().begin(), curve.points().end());
  }
  return sceneExtent(centres, scene, "curves", options.sanity);
}

// Judges every curve that reached the global map against the current extent, and after a global
// BA by how it fits its views (checkFit, when SanityOptions asks for it); with `drop`, drops the
// implausible ones from the map.
void Pipeline::Impl::checkCurves(bool drop) {
  extent = currentExtent();
  if (extent.valid()) {
    const ExportedCurves promoted = map.exportCurves(CurveSelection::kPromoted);
    for (std::size_t i = 0; i < promoted.ids.size(); ++i) {
      const CurveCheck check =
          checkCurve(promoted.curves[i], extent, options.sanity.samples_per_segment);
      if (check.reason == CurveImplausibility::kNone) continue;
      implausible.push_back({promoted.ids[i], promoted.curves[i].numSegments(),
                             check.length * unit(), check.reason, global_bas, drop});
      if (drop) map.dropImplausible(promoted.ids[i]);
    }
  }
  // A curve's fit means something only once a global BA has fitted it; its run along the
  // epipolar planes is geometry, judged from the frontend's map on.
  const bool fit_checks =
      options.sanity.max_curve_residual_px > 0.0 || options.sanity.min_chord_ratio > 0.0;
  if ((fit_checks && global_bas > 0) || options.sanity.min_epipolar_angle_deg > 0.0) {
    checkFit(drop);
  }
}

// Judges every curve still in the map by how it fits its views after a global BA: its residual
// RMS (SanityOptions::max_curve_residual_px) and its chord ratio (min_chord_ratio).
void Pipeline::Impl::checkFit(bool drop) {
  const SanityOptions& sanity = options.sanity;
  std::vector<int> ids;
  const CurveBundleAdjustmentInput input = bundleInput(CurveSelection::kPromoted, &ids);
  const std::vector<CurveStatistics> stats = curveStatistics(input, options.ba);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    CurveImplausibility reason = CurveImplausibility::kNone;
    if (global_bas > 0 && sanity.max_curve_residual_px > 0.0 &&
        stats[i].residual_rms_px > sanity.max_curve_residual_px) {
      reason = CurveImplausibility::kHighResidual;
    } else if (global_bas > 0 && stats[i].chord_ratio < sanity.min_chord_ratio) {
      reason = CurveImplausibility::kCollapsed;
    } else if (stats[i].epipolar_angle_deg < sanity.min_epipolar_angle_deg) {
      reason = CurveImplausibility::kAlongEpipolar;
    }
    if (reason == CurveImplausibility::kNone) continue;
    const CurveCheck check = checkCurve(input.curves[i], extent, sanity.samples_per_segment);
    implausible.push_back(
        {ids[i], input.curves[i].numSegments(), check.length * unit(), reason, global_bas, drop});
    if (drop) map.dropImplausible(ids[i]);
  }
}

KeyframeStats Pipeline::Impl::addFrame(const PipelineFrame& frame) {
  CURVESFM_CHECK(!finished) << "Pipeline::addFrame after finish()";
  KeyframeStats stats;
  stats.frame_index = static_cast<int>(frames.size());
  stats.timestamp = frame.timestamp;
  const double known_scale = gate.sceneScale();
  const bool is_keyframe = gate.admit(frame.initial_cam_from_world);
  if (gate.sceneScale() != known_scale) moveKeyframesToSceneScale();
  if (!is_keyframe) {
    frames.push_back(stats);
    return stats;
  }
  const int k = static_cast<int>(keyframes.size());
  stats.keyframe_index = k;
  CURVESFM_CHECK(frame.image || !frame.image_bgr.empty())
      << "frame " << stats.frame_index << " is a keyframe but came without its image";
  CURVESFM_CHECK(frame.image || frame.image_bgr.type() == CV_8UC3)
      << "frame " << stats.frame_index << ": expected a CV_8UC3 BGR image, found type "
      << frame.image_bgr.type() << " (" << frame.image_bgr.channels() << " channels)";
  std::shared_ptr<const KeyframeImage> image = frame.image;
  if (!image) image = std::make_shared<const KeyframeImage>(prepareImage(frame.image_bgr));
  // From here on every length is in the scene scale.
  addKeyframe(frame, *image, &stats);
  const std::vector<EdgeChain>& chains = image->chains;
  const cv::Mat& edges = image->edges;

  const Clock::time_point start = Clock::now();
  if (options.track_keyframe_pose && k > 0) trackPose(&keyframes[k]);
  cv::Mat explained = cv::Mat::zeros(edges.size(), CV_8UC1);
  registerMap(k, &explained, &stats);
  stats.correspondence_seconds = secondsSince(start);

  initialiseCurves(k, unexplainedRuns(chains, explained, options.chains.min_length_px), &stats);
  map.endKeyframe(k);
  // No later keyframe takes this one as a depth reference: its largest image (4 bytes a pixel).
  if (k >= options.depth_reference_candidates) {
    keyframes[k - options.depth_reference_candidates].grey_float.release();
  }

  if (keyframes.size() >= 2 && map.count(CurveState::kGlobal) > 0) {
    const Clock::time_point local_ba_start = Clock::now();
    const ScheduleReport report = bundleAdjust(CurveSelection::kGlobal, options.local_ba,
                                               options.ba, options.local_ba_refines_poses, nullptr);
    // The whole call: building the window's graph and writing the curves back count too.
    stats.local_ba_seconds = secondsSince(local_ba_start);
    stats.local_ba_initial_cost = report.initial_cost;
    stats.local_ba_final_cost = report.final_cost;
    stats.local_ba_iterations = report.total_iterations;
  }
  stats.global_curves = map.count(CurveState::kGlobal);
  stats.temporary_curves = map.count(CurveState::kTemporary);
  frames.push_back(stats);
  return stats;
}

std::vector<bool> selectKeyframes(const std::vector<Pose3>& initial_cam_from_world,
                                  const PipelineOptions& options) {
  KeyframeGate gate(options);
  std::vector<bool> keyframes;
  keyframes.reserve(initial_cam_from_world.size());
  for (const Pose3& pose : initial_cam_from_world) keyframes.push_back(gate.admit(pose));
  return keyframes;
}

KeyframeTimes keyframeTimes(const std::vector<KeyframeStats>& frames) {
  KeyframeTimes t;
  for (const KeyframeStats& s : frames) {
    if (s.keyframe_index < 0) continue;
    ++t.keyframes;
    t.undistort_ms += s.undistort_seconds;
    t.edges_ms += s.edges_seconds;
    t.field_ms += s.field_seconds;
    t.depth_ms += s.depth_seconds;
    t.correspondence_ms += s.correspondence_seconds;
    t.initialise_ms += s.initialise_seconds;
    t.frontend_ms += s.frontendSeconds();
    t.image_stage_ms += s.imageStageSeconds();
    t.local_ba_ms += s.local_ba_seconds;
    t.slowest_frontend_ms = std::max(t.slowest_frontend_ms, 1e3 * s.frontendSeconds());
  }
  const double ms_per_keyframe = t.keyframes == 0 ? 0.0 : 1e3 / t.keyframes;
  for (double* v : {&t.undistort_ms, &t.edges_ms, &t.field_ms, &t.depth_ms, &t.correspondence_ms,
                    &t.initialise_ms, &t.frontend_ms, &t.image_stage_ms, &t.local_ba_ms}) {
    *v *= ms_per_keyframe;
  }
  return t;
}

double PipelineResult::globalBaSeconds() const {
  double seconds = global_ba.total_seconds;
  for (const ReassociationRound& round : reassociation) seconds += round.global_ba.total_seconds;
  return seconds;
}

Pipeline::Pipeline(const Camera& camera, const PipelineOptions& options)
    : impl_(std::make_unique<Impl>(camera, options)) {}

Pipeline::~Pipeline() = default;

KeyframeStats Pipeline::addFrame(const PipelineFrame& frame) { return impl_->addFrame(frame); }

KeyframeImage Pipeline::prepareImage(const cv::Mat& image_bgr) const {
  return impl_->prepareImage(image_bgr);
}

PipelineResult Pipeline::finish() {
  Impl& impl = *impl_;
  CURVESFM_CHECK(!impl.finished) << "Pipeline::finish called twice";
  impl.finished = true;
  PipelineResult result;
  result.pose_stages.push_back(impl.poseStage("incremental"));
  // Every curve that reached the global map: the curves the sanity checks judge.
  const int promoted =
      static_cast<int>(impl.map.exportCurves(CurveSelection::kPromoted).ids.size());
  // Global BA starts from the initial poses, not from those the frontend was given.
  for (Keyframe& keyframe : impl.keyframes) {
    if (keyframe.given_frontend_cam_from_world) {
      keyframe.cam_from_world = keyframe.initial_cam_from_world;
    }
  }
  bool checked_since_ba = false;
  if (impl.options.run_global_ba && impl.keyframes.size() >= 2) {
    checked_since_ba = impl.runGlobalRounds(&result);
  }
  if (!checked_since_ba) impl.checkCurves(impl.options.sanity.drop_implausible_curves);
  impl.collectResult(promoted, &result);
  return result;
}

// An interim BA (one a re-association round follows) runs on the budget; the last does not, and
// may weigh the edges with its own kernel width.
ScheduleReport Pipeline::Impl::globalBundleAdjust(bool interim, CurveSampleCounts* samples) {
  SchedulerOptions scheduler = options.global_ba;
  const int budget = options.reassociation_interim_iterations;
  if (interim && budget > 0) {
    scheduler.optimizer.max_iterations = std::min(scheduler.optimizer.max_iterations, budget);
  }
  CurveBundleAdjustmentOptions ba = options.ba;
  if (!interim && options.last_global_ba_kernel_width > 0.0) {
    ba.kernel_width = options.last_global_ba_kernel_width;
  }
  ScheduleReport report =
      bundleAdjust(CurveSelection::kPromoted, scheduler, ba, /*refine_poses=*/true, samples);
  ++global_bas;
  kernel_width_of_last_global_ba = ba.kernel_width;
  return report;
}

bool Pipeline::Impl::runGlobalRounds(PipelineResult* result) {
  const int rounds = options.reassociation_rounds;
  const bool drop = options.sanity.drop_implausible_curves;
  // A check right after another with no BA between would judge the same map against an extent
  // rebuilt from fewer curves, and could drop more for nothing having moved.
  bool checked_since_ba = false;
  if (drop) checkCurves(true);
  result->global_ba = globalBundleAdjust(rounds > 0, &result->final_samples);
  result->pose_stages.push_back(poseStage("global_ba"));
  for (int r = 0; r < rounds; ++r) {
    // Before re-association, so that no runaway curve gains observations.
    if (drop) checkCurves(true);
    checked_since_ba = drop;
    ReassociationRound round;
    reassociate(&round);
    // A round that adds nothing ends them; the BA before it was interim, so under a budget the
    // round's own BA still runs to convergence.
    const bool last = r + 1 == rounds || round.added_observations == 0;
    if (round.added_observations == 0 && options.reassociation_interim_iterations == 0) break;
    checked_since_ba = false;
    round.global_ba = globalBundleAdjust(!last, &result->final_samples);
    result->reassociation.push_back(std::move(round));
    result->pose_stages.push_back(poseStage("reassociation_" + std::to_string(r + 1)));
    if (last) break;
  }
  return checked_since_ba;
}

void Pipeline::Impl::collectResult(int promoted, PipelineResult* result) const {
  // Back from the scene scale to the unit of the poses given.
  const double pose_unit = unit();
  result->scene_scale = gate.sceneScale();
  for (const Keyframe& keyframe : keyframes) {
    result->keyframe_timestamps.push_back(keyframe.timestamp);
    result->keyframe_initial_cam_from_world.push_back(keyframe.given_cam_from_world);
  }
  // Not the last stage's: with frontend poses and no global BA, that is the frontend's.
  result->keyframe_cam_from_world = poseStage("result").keyframe_cam_from_world;
  for (const PolyBezier& curve : map.exportCurves(CurveSelection::kPromoted).curves) {
    result->curves.push_back(scaledCurve(curve, pose_unit));
  }
  result->curve_statistics = curveStatisticsInPoseUnits();
  result->curve_precision = curvePrecisionInPoseUnits();
  if (options.ba.points) result->points = points;
  result->frames = frames;

  RunSanity& sanity = result->sanity;
  sanity.extent = extent.scaled(pose_unit);
  sanity.checked_curves = promoted;
  sanity.implausible_curves = implausible;
  sanity.pose_move =
      largestPoseMove(result->keyframe_initial_cam_from_world, result->keyframe_cam_from_world);
  sanity.verdicts =
      judgeRun(static_cast<int>(keyframes.size()), static_cast<int>(result->curves.size()),
               promoted, static_cast<int>(implausible.size()), sanity.pose_move, options.sanity);
}

void Pipeline::setPoints(std::vector<Eigen::Vector3d> points_in_world) {
  CURVESFM_CHECK(impl_->frames.empty()) << "Pipeline::setPoints after the first frame";
  impl_->points = std::move(points_in_world);
}

const Camera& Pipeline::undistortedCamera() const { return *impl_->camera; }

const cv::Mat& Pipeline::keyframeImage(int k) const {
  CURVESFM_CHECK(k >= 0 && k < static_cast<int>(impl_->keyframes.size()))
      << "keyframe " << k << " out of range (" << impl_->keyframes.size() << " keyframes)";
  return impl_->keyframes[k].image_bgr;
}

}  // namespace curvesfm
