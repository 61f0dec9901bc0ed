#include "frontend/mapping/point_initialiser.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "core/check.h"
#include "core/clock.h"
#include "core/errors.h"
#include "core/median.h"
#include "core/point_triangulation.h"
#include "core/similarity_alignment.h"
#include "factors/point_bundle_adjustment.h"
#include "factors/pose_variables.h"
#include "graph/key.h"

namespace curvesfm {

OptimizerOptions PointInitialiserOptions::defaultLocalSolver() {
  OptimizerOptions o;
  o.linear_solver = LinearSolver::kGraphSchur;
  o.max_iterations = 10;
  return o;
}

OptimizerOptions PointInitialiserOptions::defaultGlobalSolver() {
  OptimizerOptions o;
  o.linear_solver = LinearSolver::kGraphSchur;
  o.max_iterations = 30;
  // Most of the map's global BAs ran into the 30-iteration limit on a cost falling by less than
  // 0.1 % over 5 iterations: the stall test ends them 4x sooner with the initialiser's ATE within
  // 0.7 % on the six real sets (docs/benchmarks.md, "A budget for re-association's global BAs").
  o.stall_iterations = 5;
  return o;
}

void LoopMatchOptions::validate() const {
  const OptionCheck require("LoopMatchOptions");
  require(min_covisible_fraction > 0.0 && min_covisible_fraction <= 1.0, "min_covisible_fraction",
          min_covisible_fraction, "in (0, 1]");
  require(max_view_angle_deg > 0.0 && max_view_angle_deg <= 180.0, "max_view_angle_deg",
          max_view_angle_deg, "in (0, 180]");
  require(max_shared_fraction >= 0.0 && max_shared_fraction <= 1.0, "max_shared_fraction",
          max_shared_fraction, "in [0, 1]");
  require.positive("max_merge_error_px", max_merge_error_px);
  require(max_rounds >= 1, "max_rounds", max_rounds, ">= 1");
}

void PointInitialiserOptions::validate() const {
  undistort.validate();
  klt.validate();
  features.validate();
  tracks.validate();
  two_view.validate();
  registration.validate();
  ba.validate();
  local_ba.validate();
  global_ba.validate();
  loops.validate();
  const OptionCheck require("PointInitialiserOptions");
  require(pair_search_frames >= 1, "pair_search_frames", pair_search_frames, ">= 1");
  require(max_pair_gap >= 1, "max_pair_gap", max_pair_gap, ">= 1");
  require.nonNegative("min_pair_flow_px", min_pair_flow_px);
  require(pair_flow_step >= 1.0 && pair_flow_step < 1e6, "pair_flow_step", pair_flow_step,
          "finite and >= 1");
  require(min_pair_median_parallax_deg >= 0.0 && min_pair_median_parallax_deg < 90.0,
          "min_pair_median_parallax_deg", min_pair_median_parallax_deg, "in [0, 90)");
  require(pair_parallax_cap_deg > 0.0 && pair_parallax_cap_deg <= 90.0, "pair_parallax_cap_deg",
          pair_parallax_cap_deg, "in (0, 90]");
  require.positive("max_reprojection_error_px", max_reprojection_error_px);
  require(min_triangulation_angle_deg >= 0.0 && min_triangulation_angle_deg < 90.0,
          "min_triangulation_angle_deg", min_triangulation_angle_deg, "in [0, 90)");
  require(local_ba_frames >= 1, "local_ba_frames", local_ba_frames, ">= 1");
  require(global_ba_growth > 1.0 && global_ba_growth < 1e6, "global_ba_growth", global_ba_growth,
          "finite and > 1");
  require(max_registration_trials >= 1, "max_registration_trials", max_registration_trials, ">= 1");
  require(tracking_threads >= 0, "tracking_threads", tracking_threads, ">= 0");
  require(fallback_min_inliers >= 4, "fallback_min_inliers", fallback_min_inliers, ">= 4");
  require(max_models >= 1, "max_models", max_models, ">= 1");
  require(min_merge_points >= 3, "min_merge_points", min_merge_points, ">= 3");
  require(precision_max_frames >= 0, "precision_max_frames", precision_max_frames, ">= 0");
  require(given_poses_gate_scale >= 0.0 && given_poses_gate_scale < 1e6, "given_poses_gate_scale",
          given_poses_gate_scale, "finite and >= 0");
  require(given_poses_gate_scale == 0.0 || refine_at_given_poses, "given_poses_gate_scale",
          given_poses_gate_scale,
          "0 unless refine_at_given_poses (the gate is the refined points')");
  require(given_poses_max_gate_px >= max_reprojection_error_px && given_poses_max_gate_px < 1e6,
          "given_poses_max_gate_px", given_poses_max_gate_px,
          "finite and >= max_reprojection_error_px");
}

int PointInitialisation::registeredFrames() const {
  return static_cast<int>(std::count_if(frames.begin(), frames.end(), [](const auto& f) {
    return f.status == FrameRegistration::kRegistered;
  }));
}

namespace {

// OpenCV's thread count for one scope, restored after: cv::setNumThreads is process-wide.
class TrackingThreads {
 public:
  explicit TrackingThreads(int threads) : previous_(cv::getNumThreads()) {
    cv::setNumThreads(threads > 0 ? threads : -1);
  }
  ~TrackingThreads() { cv::setNumThreads(previous_); }
  TrackingThreads(const TrackingThreads&) = delete;
  TrackingThreads& operator=(const TrackingThreads&) = delete;

 private:
  int previous_;
};

// A point of a model: its position and the registered frames whose observation it uses. A
// removed point keeps its slot (track -1) so that indices stay valid.
struct MapPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int track = -1;
  std::vector<int> frames;
  bool alive() const { return track >= 0; }
  bool seenIn(int frame) const {
    return std::find(frames.begin(), frames.end(), frame) != frames.end();
  }
};

// One sub-model of the reconstruction.
struct Model {
  std::pair<int, int> pair = {-1, -1};
  std::vector<std::optional<Pose3>> poses;  // Per frame.
  std::vector<int> registration_order;
  std::vector<MapPoint> points;
  std::vector<int> point_of_track;  // Per track: its point, or -1.
  int registered_at_last_global_ba = 0;

  Model(int frames, int tracks) : poses(frames), point_of_track(tracks, -1) {}
  int registered() const { return static_cast<int>(registration_order.size()); }
  void registerFrame(int frame, const Pose3& pose) {
    poses[frame] = pose;
    registration_order.push_back(frame);
  }
  int addPoint(const Eigen::Vector3d& position, int track, std::vector<int> frames) {
    point_of_track[track] = static_cast<int>(points.size());
    points.push_back({position, track, std::move(frames)});
    return point_of_track[track];
  }
  void removePoint(int p) {
    point_of_track[points[p].track] = -1;
    points[p].track = -1;
    points[p].frames.clear();
  }
};

Eigen::Vector3d centreOf(const Pose3& cam_from_world) {
  return cam_from_world.inverseTranslation();
}

}  // namespace

struct PointInitialiser::State {
  PointInitialiserOptions options;
  ImageUndistorter undistorter;
  std::shared_ptr<const Camera> camera;  // The undistorted pinhole camera.
  FeatureTrackBuilder builder;
  FeatureTracks tracks;
  PointInitialisation out;
  int frames_added = 0;
  PointInitialiser::Progress progress;
  PointInitialiser::LoopProgress loop_progress;
  double add_frame_seconds = 0.0;  // Undistortion and tracks, frame by frame.
  // OpenCV's thread count while tracking: set at the first frame, restored once the tracks are
  // built (switching it per frame would rebuild OpenCV's thread pool every time).
  std::optional<TrackingThreads> tracking_threads;

  State(const Camera& source, const PointInitialiserOptions& o)
      : options((o.validate(), o)),
        undistorter(source, o.undistort),
        camera(std::make_shared<Camera>(undistorter.camera())),
        builder(o.tracks, o.klt, o.features) {}

  int numFrames() const { return tracks.num_frames; }

  // -------------------------------------------------------------------------------------------
  // Geometry of one observation.

  const Eigen::Vector2d& pixelOf(int track, int frame) const {
    const Eigen::Vector2d* p = tracks.pixel(track, frame);
    CURVESFM_CHECK(p != nullptr) << "track " << track << " is not seen in frame " << frame;
    return *p;
  }

  // Whether `point` lies in front of the frame and reprojects within the map's bound.
  bool reprojects(const Model& model, int frame, int track, const Eigen::Vector3d& point) const {
    return reprojectsWithin(model, frame, pixelOf(track, frame), point,
                            options.max_reprojection_error_px);
  }

  // Whether `point` lies in front of the frame and reprojects within `bound_px` of `pixel`.
  bool reprojectsWithin(const Model& model, int frame, const Eigen::Vector2d& pixel,
                        const Eigen::Vector3d& point, double bound_px) const {
    return reprojectionErrorPx(model, frame, pixel, point) <= bound_px;
  }

  // The distance from `pixel` to `point` projected into the frame (px), infinite when the point
  // does not project (behind the camera).
  double reprojectionErrorPx(const Model& model, int frame, const Eigen::Vector2d& pixel,
                             const Eigen::Vector3d& point) const {
    Eigen::Vector2d projected;
    if (!camera->project(*model.poses[frame] * point, &projected)) {
      return std::numeric_limits<double>::infinity();
    }
    return (projected - pixel).norm();
  }

  // The widest ray angle among (at most 8 evenly spread) frames: the gate needs the baseline the
  // track spans, and its ends give nearly all of it.
  double angleDeg(const Model& model, const std::vector<int>& frames,
                  const Eigen::Vector3d& point) const {
    std::vector<Eigen::Vector3d> centres;
    const std::size_t step = std::max<std::size_t>(1, frames.size() / 8);
    for (std::size_t i = 0; i < frames.size(); i += step) {
      centres.push_back(centreOf(*model.poses[frames[i]]));
    }
    centres.push_back(centreOf(*model.poses[frames.back()]));
    return maxTriangulationAngleDeg(centres, point);
  }

  // -------------------------------------------------------------------------------------------
  // Triangulation.

  std::vector<int> registeredFramesOf(const Model& model, int track) const {
    std::vector<int> frames;
    for (const TrackObservation& o : tracks.tracks[track].observations) {
      if (model.poses[o.frame]) frames.push_back(o.frame);
    }
    return frames;
  }

  // The frame of `frames` whose centre lies farthest from frame a's (-1 if none but a).
  int farthestFrame(const Model& model, const std::vector<int>& frames, int a) const {
    int b = -1;
    double widest = -1.0;
    const Eigen::Vector3d centre_a = centreOf(*model.poses[a]);
    for (int f : frames) {
      const double d = (centreOf(*model.poses[f]) - centre_a).norm();
      if (f != a && d > widest) {
        widest = d;
        b = f;
      }
    }
    return b;
  }

  bool triangulatePair(const Model& model, int track, int a, int b, Eigen::Vector3d* point) const {
    return triangulateDlt({*model.poses[a], *model.poses[b]},
                          {camera->pixelToNormalized(pixelOf(track, a)),
                           camera->pixelToNormalized(pixelOf(track, b))},
                          point);
  }

  // Triangulates `track` from its registered observations (see the header, step 4); `anchor` is
  // the frame to pair with the farthest other one (the new frame), or -1 for the track's ends.
  bool triangulateTrack(Model* model, int track, int anchor) const {
    const std::vector<int> frames = registeredFramesOf(*model, track);
    if (frames.size() < 2) return false;
    const int a = anchor >= 0 ? anchor : frames.front();
    const int b = farthestFrame(*model, frames, a);
    Eigen::Vector3d point;
    if (b < 0 || !triangulatePair(*model, track, a, b, &point)) return false;
    const Eigen::Vector3d centre_a = centreOf(*model->poses[a]);
    if (!reprojects(*model, a, track, point) || !reprojects(*model, b, track, point) ||
        triangulationAngleDeg(centre_a, centreOf(*model->poses[b]), point) <
            options.min_triangulation_angle_deg) {
      return false;
    }
    std::vector<int> kept;
    for (int f : frames) {
      if (f == a || f == b || reprojects(*model, f, track, point)) kept.push_back(f);
    }
    model->addPoint(point, track, kept);
    return true;
  }

  // Triangulates every track seen in `frame` that has no point yet; returns how many.
  int triangulateFrame(Model* model, int frame) const {
    int added = 0;
    for (int track : tracks.frame_tracks[frame]) {
      if (model->point_of_track[track] < 0 && triangulateTrack(model, track, frame)) ++added;
    }
    return added;
  }

  int retriangulateAll(Model* model) const {
    int added = 0;
    for (int track = 0; track < static_cast<int>(tracks.tracks.size()); ++track) {
      if (model->point_of_track[track] < 0 && triangulateTrack(model, track, -1)) ++added;
    }
    return added;
  }

  // Drops observations beyond the reprojection bound, then points with fewer than two frames or
  // too small an angle. Returns the points removed.
  int filterPoints(Model* model, const std::vector<int>& candidates) const {
    int removed = 0;
    for (int p : candidates) {
      MapPoint& point = model->points[p];
      if (!point.alive()) continue;
      std::vector<int> kept;
      for (int f : point.frames) {
        if (reprojects(*model, f, point.track, point.position)) kept.push_back(f);
      }
      point.frames = kept;
      if (point.frames.size() < 2 ||
          angleDeg(*model, point.frames, point.position) < options.min_triangulation_angle_deg) {
        model->removePoint(p);
        ++removed;
      }
    }
    return removed;
  }

  std::vector<int> allPoints(const Model& model) const {
    std::vector<int> all(model.points.size());
    std::iota(all.begin(), all.end(), 0);
    return all;
  }

  // -------------------------------------------------------------------------------------------
  // Bundle adjustment.

  // Refines the poses of `free_frames` and every point they see, holding the other frames that
  // see those points; the gauge as in the header (step 5).
  void bundleAdjust(Model* model, const std::vector<int>& free_frames, const std::string& scope,
                    int model_id) {
    const Clock::time_point start = Clock::now();
    const std::set<int> free(free_frames.begin(), free_frames.end());
    std::vector<int> points;
    std::set<int> frames(free.begin(), free.end());
    for (int p = 0; p < static_cast<int>(model->points.size()); ++p) {
      const MapPoint& point = model->points[p];
      if (!point.alive()) continue;
      if (std::none_of(point.frames.begin(), point.frames.end(),
                       [&](int f) { return free.count(f) > 0; })) {
        continue;
      }
      points.push_back(p);
      frames.insert(point.frames.begin(), point.frames.end());
    }
    if (points.empty()) return;

    // Cameras in the order the gauge needs: the pair first when present, then by frame.
    std::vector<int> cameras;
    for (int f : {model->pair.first, model->pair.second}) {
      if (frames.count(f)) cameras.push_back(f);
    }
    for (int f : frames) {
      if (f != model->pair.first && f != model->pair.second) cameras.push_back(f);
    }
    std::map<int, int> camera_index;
    PointBundleAdjustmentInput input;
    input.camera = camera;
    for (int f : cameras) {
      camera_index[f] = static_cast<int>(input.cam_from_world.size());
      input.cam_from_world.push_back(*model->poses[f]);
    }
    for (int p : points) {
      const MapPoint& point = model->points[p];
      const int index = static_cast<int>(input.points.size());
      input.points.push_back(point.position);
      // Every observation weighs alike, as in COLMAP: weighing keypoints by their size made the
      // initialiser's ATE worse on four of six real sets (docs/benchmarks.md, session 55).
      for (int f : point.frames) {
        input.observations.push_back({camera_index.at(f), index, pixelOf(point.track, f)});
      }
    }
    const int held = static_cast<int>(cameras.size() - free.size());
    PointBundleAdjustmentOptions ba = options.ba;
    ba.refine_focal = options.ba.refine_focal && scope == "global";
    // Two held frames fix all seven degrees of freedom; otherwise hold the reference frame and
    // the distance to the pair's second frame, as in two-view BA.
    const bool pair_in =
        cameras.size() >= 2 && cameras[0] == model->pair.first && cameras[1] == model->pair.second;
    ba.fix_first_pose = held < 2 && pair_in;
    ba.fix_scale = held < 2 && pair_in;
    PointBundleAdjustmentProblem problem = buildPointBundleAdjustment(input, ba);
    for (std::size_t i = 0; i < cameras.size(); ++i) {
      if (!free.count(cameras[i])) problem.config.setConstant(poseKey(i));
    }
    if (held < 2 && !pair_in) {
      // No pair and fewer than two held frames: hold the oldest two so the gauge stays put.
      for (std::size_t i = 0; i < std::min<std::size_t>(2, cameras.size()); ++i) {
        problem.config.setConstant(poseKey(i));
      }
    }
    OptimizerOptions solver = scope == "local" ? options.local_ba : options.global_ba;
    // graph_schur reduces to the poses alone, so Ceres takes a free focal length; it sums its
    // threads' shares in the order they finish, and one thread keeps the result the same bits.
    if (ba.refine_focal) solver.num_threads = 1;
    InitialiserBundleAdjustment report;
    report.scope = scope;
    report.model = model_id;
    report.frames = static_cast<int>(cameras.size());
    report.points = static_cast<int>(points.size());
    report.observations = static_cast<int>(input.observations.size());
    report.summary = optimize(problem.graph, &problem.values, problem.config, solver);
    const std::vector<Pose3> poses = extractPoses(problem.values, cameras.size());
    for (std::size_t i = 0; i < cameras.size(); ++i) model->poses[cameras[i]] = poses[i];
    const std::vector<Eigen::Vector3d> positions = extractPoints(problem.values, points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      model->points[points[i]].position = positions[i];
    if (ba.refine_focal) scaleFocalLengths(extractFocalScale(problem.values));
    report.summary.full_report.clear();  // Kept small: the report holds many solves.
    out.bundle_adjustments.push_back(std::move(report));
    (scope == "local" ? out.seconds.local_ba : out.seconds.global_ba) += secondsSince(start);
  }

  // Every later registration, triangulation and BA, and the result, see the refined camera.
  void scaleFocalLengths(double factor) {
    camera = std::make_shared<Camera>(camera->withFocalScale(factor));
    out.focal_scale *= factor;
  }

  void globalRefinement(Model* model, int model_id) {
    bundleAdjust(model, model->registration_order, "global", model_id);
    const Clock::time_point start = Clock::now();
    filterPoints(model, allPoints(*model));
    const int added = retriangulateAll(model);
    out.seconds.triangulation += secondsSince(start);
    if (added > 0) bundleAdjust(model, model->registration_order, "global", model_id);
    model->registered_at_last_global_ba = model->registered();
  }

  // -------------------------------------------------------------------------------------------
  // Initial pair.

  struct PairCandidate {
    int a = -1, b = -1;
    double score = -1.0;
    std::vector<int> shared;
    TwoViewGeometry geometry;
  };

  double medianFlow(const std::vector<int>& shared, int a, int b) const {
    std::vector<double> flow;
    flow.reserve(shared.size());
    for (int t : shared) flow.push_back((pixelOf(t, a) - pixelOf(t, b)).norm());
    return upperMedian(flow);
  }

  std::optional<PairCandidate> findInitialPair(const std::vector<bool>& available,
                                               std::map<std::string, int>* rejections) {
    const Clock::time_point start = Clock::now();
    TwoViewOptions two_view = options.two_view;
    two_view.min_median_parallax_deg = options.min_pair_median_parallax_deg;
    std::optional<PairCandidate> best;
    int searched = 0;
    for (int a = 0; a < numFrames() && searched < options.pair_search_frames; ++a) {
      if (!available[a]) continue;
      ++searched;
      double next_flow = options.min_pair_flow_px;
      for (int b = a + 1; b < numFrames() && b - a <= options.max_pair_gap; ++b) {
        if (!available[b]) continue;
        std::vector<int> shared = tracks.sharedTracks(a, b);
        if (static_cast<int>(shared.size()) < two_view.min_matches) {
          ++(*rejections)["too_few_shared_tracks"];
          continue;
        }
        const double flow = medianFlow(shared, a, b);
        if (flow < next_flow) {
          ++(*rejections)[flow < options.min_pair_flow_px ? "too_little_flow" : "flow_step"];
          continue;
        }
        next_flow = std::max(next_flow, options.pair_flow_step * flow);
        std::vector<Eigen::Vector2d> pa, pb;
        for (int t : shared) {
          pa.push_back(pixelOf(t, a));
          pb.push_back(pixelOf(t, b));
        }
        ++out.pairs_tried;
        TwoViewGeometry g = estimateTwoViewGeometry(*camera, pa, pb, two_view);
        if (!g.accepted) {
          ++(*rejections)[toString(g.rejection)];
          continue;
        }
        const double score =
            g.num_inliers * std::min(g.median_parallax_deg, options.pair_parallax_cap_deg);
        if (!best || score > best->score) best = PairCandidate{a, b, score, shared, std::move(g)};
      }
    }
    out.seconds.pair_search += secondsSince(start);
    return best;
  }

  Model startModel(const PairCandidate& pair, int model_id) {
    Model model(numFrames(), static_cast<int>(tracks.tracks.size()));
    model.pair = {pair.a, pair.b};
    model.registerFrame(pair.a, Pose3());
    model.registerFrame(pair.b, pair.geometry.cam_b_from_cam_a);
    for (std::size_t i = 0; i < pair.geometry.points_in_cam_a.size(); ++i) {
      model.addPoint(pair.geometry.points_in_cam_a[i], pair.shared[pair.geometry.point_indices[i]],
                     {pair.a, pair.b});
    }
    bundleAdjust(&model, {pair.a, pair.b}, "two_view", model_id);
    filterPoints(&model, allPoints(model));
    normaliseScale(&model);
    return model;
  }

  // The gauge's scale: the median depth of the pair's points in its first frame becomes 1.
  void normaliseScale(Model* model) const {
    std::vector<double> depths;
    for (const MapPoint& p : model->points) {
      if (p.alive()) depths.push_back((*model->poses[model->pair.first] * p.position).z());
    }
    const double scale = upperMedian(depths);
    if (!(scale > 0.0)) return;
    for (MapPoint& p : model->points) p.position /= scale;
    for (auto& pose : model->poses) {
      if (pose) pose = Pose3(pose->rotation(), pose->translation() / scale);
    }
  }

  // -------------------------------------------------------------------------------------------
  // Registration.

  // Unregistered frames that see model points, most first (ties: lower frame).
  std::vector<std::pair<int, int>> registrationCandidates(const Model& model) const {
    std::vector<std::pair<int, int>> candidates;  // (-count, frame) sorts as wanted.
    for (int f = 0; f < numFrames(); ++f) {
      if (model.poses[f]) continue;
      int count = 0;
      for (int t : tracks.frame_tracks[f]) count += model.point_of_track[t] >= 0;
      if (count > 0) candidates.emplace_back(-count, f);
    }
    std::sort(candidates.begin(), candidates.end());
    return candidates;
  }

  // Registers the best candidate that passes PnP's thresholds; when none does, the candidates
  // are tried once more with fallback_min_inliers, so that a stretch of frames seeing few
  // triangulable points (a turn towards distant background) does not close the model.
  bool registerNext(Model* model, int model_id) {
    const std::vector<std::pair<int, int>> candidates = registrationCandidates(*model);
    const int trials =
        std::min<int>(options.max_registration_trials, static_cast<int>(candidates.size()));
    AbsolutePoseOptions fallback = options.registration;
    fallback.min_inliers = std::min(fallback.min_inliers, options.fallback_min_inliers);
    for (const AbsolutePoseOptions* thresholds : {&options.registration, &fallback}) {
      if (thresholds == &fallback && fallback.min_inliers == options.registration.min_inliers)
        break;
      for (int c = 0; c < trials; ++c) {
        if (tryRegister(model, candidates[c].second, model_id, *thresholds)) return true;
      }
    }
    return false;
  }

  bool tryRegister(Model* model, int frame, int model_id, const AbsolutePoseOptions& thresholds) {
    const Clock::time_point start = Clock::now();
    std::vector<int> point_ids;
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    for (int t : tracks.frame_tracks[frame]) {
      const int p = model->point_of_track[t];
      if (p < 0) continue;
      point_ids.push_back(p);
      points.push_back(model->points[p].position);
      pixels.push_back(pixelOf(t, frame));
    }
    const AbsolutePose pose = estimateAbsolutePose(*camera, points, pixels, thresholds);
    InitialisedFrame& status = out.frames[frame];
    status.correspondences = static_cast<int>(points.size());
    status.inliers = pose.num_inliers;
    out.seconds.registration += secondsSince(start);
    if (!pose.accepted) {
      if (status.status != FrameRegistration::kRegistered) {
        status.status = FrameRegistration::kRejected;
        status.rejection = pose.rejection;
      }
      return false;
    }
    model->registerFrame(frame, pose.cam_from_world);
    for (std::size_t i = 0; i < point_ids.size(); ++i) {
      if (pose.inliers[i]) model->points[point_ids[i]].frames.push_back(frame);
    }
    const Clock::time_point triangulation = Clock::now();
    triangulateFrame(model, frame);
    out.seconds.triangulation += secondsSince(triangulation);
    localRefinement(model, frame, model_id);
    if (model->registered() >= options.global_ba_growth * model->registered_at_last_global_ba) {
      globalRefinement(model, model_id);
    }
    if (progress) {
      const auto live = std::count_if(model->points.begin(), model->points.end(),
                                      [](const MapPoint& p) { return p.alive(); });
      progress(model_id, model->registered(), numFrames(), static_cast<int>(live));
    }
    return true;
  }

  void localRefinement(Model* model, int frame, int model_id) {
    const std::vector<int>& order = model->registration_order;
    const int first = std::max(0, static_cast<int>(order.size()) - options.local_ba_frames);
    const std::vector<int> window(order.begin() + first, order.end());
    bundleAdjust(model, window, "local", model_id);
    std::vector<int> seen;
    for (int t : tracks.frame_tracks[frame]) {
      if (model->point_of_track[t] >= 0) seen.push_back(model->point_of_track[t]);
    }
    filterPoints(model, seen);
  }

  // -------------------------------------------------------------------------------------------
  // Models.

  std::vector<Model> buildModels() {
    std::vector<Model> models;
    std::vector<bool> available(numFrames(), true);
    std::map<std::string, int> rejections;
    while (static_cast<int>(models.size()) < options.max_models) {
      if (std::count(available.begin(), available.end(), true) < 2) break;
      const std::optional<PairCandidate> pair = findInitialPair(available, &rejections);
      if (!pair) break;
      const int id = static_cast<int>(models.size());
      if (id == 0) {
        out.initial_pair = {pair->a, pair->b};
        out.initial_geometry = pair->geometry;
      }
      Model model = startModel(*pair, id);
      while (registerNext(&model, id)) {
      }
      globalRefinement(&model, id);
      for (int f : model.registration_order) available[f] = false;
      models.push_back(std::move(model));
    }
    out.models = static_cast<int>(models.size());
    if (models.empty()) out.failure = noPairMessage(rejections);
    return models;
  }

  std::string noPairMessage(const std::map<std::string, int>& rejections) const {
    std::ostringstream message;
    message << "no initial pair among the first " << options.pair_search_frames
            << " frames (pairs up to " << options.max_pair_gap << " frames apart, "
            << tracks.tracks.size() << " tracks):";
    for (const auto& [reason, count] : rejections) message << " " << reason << " " << count << ",";
    message << " too little texture or motion for points";
    return message.str();
  }

  // The Sim(3) taking `source`'s map onto `target`'s: through the points both triangulated when
  // there are enough, else through a frame both registered.
  std::optional<Sim3> mergeTransform(const Model& source, const Model& target) const {
    if (std::optional<Sim3> t = pointMergeTransform(source, target)) return t;
    return frameMergeTransform(source, target);
  }

  // Depths in `frame` of the live points that `model` observes in it.
  std::vector<double> depthsIn(const Model& model, int frame) const {
    std::vector<double> depths;
    for (const MapPoint& p : model.points) {
      if (p.alive() && p.seenIn(frame)) {
        depths.push_back((*model.poses[frame] * p.position).z());
      }
    }
    return depths;
  }

  // The Sim(3) from a frame both models registered (PnP placed it in each, so it ties them even
  // when they triangulated different tracks, as two models that meet at one frame do): its two
  // poses give the rotation and translation, the ratio of the median depths of the points each
  // model sees in it the scale (global BA then refines them through the tracks that the merged
  // frames share). Uses the shared frame where both see the most points; nullopt when none has
  // min_merge_points in each.
  std::optional<Sim3> frameMergeTransform(const Model& source, const Model& target) const {
    int frame = -1;
    std::size_t most = 0;
    double source_depth = 0.0, target_depth = 0.0;
    for (int f : source.registration_order) {
      if (!target.poses[f]) continue;
      const std::vector<double> s = depthsIn(source, f), t = depthsIn(target, f);
      const std::size_t seen = std::min(s.size(), t.size());
      if (static_cast<int>(seen) < options.min_merge_points || seen <= most) continue;
      frame = f;
      most = seen;
      source_depth = upperMedian(s);
      target_depth = upperMedian(t);
    }
    if (frame < 0 || !(source_depth > 0.0) || !(target_depth > 0.0)) return std::nullopt;
    // cam_from_target * t == scale * cam_from_source for the shared camera.
    const Eigen::Matrix3d r_source = source.poses[frame]->rotation().toRotationMatrix();
    const Eigen::Matrix3d r_target = target.poses[frame]->rotation().toRotationMatrix();
    Sim3 t;
    t.scale = target_depth / source_depth;
    t.rotation = r_target.transpose() * r_source;
    t.translation = r_target.transpose() * (t.scale * source.poses[frame]->translation() -
                                            target.poses[frame]->translation());
    return t;
  }

  // The Sim(3) through the tracks both models triangulated, with one inlier pass (residuals
  // within 3 x their median); nullopt with too few shared points.
  std::optional<Sim3> pointMergeTransform(const Model& source, const Model& target) const {
    std::vector<Eigen::Vector3d> from, to;
    for (const MapPoint& p : source.points) {
      if (!p.alive() || target.point_of_track[p.track] < 0) continue;
      from.push_back(p.position);
      to.push_back(target.points[target.point_of_track[p.track]].position);
    }
    if (static_cast<int>(from.size()) < options.min_merge_points) return std::nullopt;
    const auto fit = [](const std::vector<Eigen::Vector3d>& a,
                        const std::vector<Eigen::Vector3d>& b) -> std::optional<Sim3> {
      Eigen::Matrix3Xd source_points(3, a.size()), target_points(3, b.size());
      for (std::size_t i = 0; i < a.size(); ++i) {
        source_points.col(i) = a[i];
        target_points.col(i) = b[i];
      }
      if (!hasSpreadForScale(source_points)) return std::nullopt;
      return alignPointSets(source_points, target_points, AlignmentKind::kSim3);
    };
    std::optional<Sim3> first = fit(from, to);
    if (!first) return std::nullopt;
    std::vector<double> residuals;
    for (std::size_t i = 0; i < from.size(); ++i)
      residuals.push_back((*first * from[i] - to[i]).norm());
    const double bound = 3.0 * upperMedian(residuals);
    std::vector<Eigen::Vector3d> inlier_from, inlier_to;
    for (std::size_t i = 0; i < from.size(); ++i) {
      if (residuals[i] <= bound) {
        inlier_from.push_back(from[i]);
        inlier_to.push_back(to[i]);
      }
    }
    if (static_cast<int>(inlier_from.size()) < options.min_merge_points) return std::nullopt;
    return fit(inlier_from, inlier_to);
  }

  // Carries `source` into `target` by `t`: its frames and points that `target` lacks.
  void mergeInto(const Model& source, const Sim3& t, Model* target) const {
    for (int f : source.registration_order) {
      if (target->poses[f]) continue;
      target->registerFrame(f, t.transformPose(source.poses[f]->inverse()).inverse());
    }
    for (const MapPoint& p : source.points) {
      if (!p.alive()) continue;
      if (target->point_of_track[p.track] >= 0) {
        // Shared: the observations of frames the target took from the source join its point.
        MapPoint& q = target->points[target->point_of_track[p.track]];
        for (int f : p.frames) {
          if (!q.seenIn(f)) q.frames.push_back(f);
        }
        continue;
      }
      target->addPoint(t * p.position, p.track, p.frames);
    }
  }

  // The largest model absorbs every other one it can be aligned with; the rest stay apart.
  Model mergeModels(std::vector<Model> models, std::vector<int>* model_of_frame) {
    const Clock::time_point start = Clock::now();
    int reference = 0;
    for (int m = 1; m < static_cast<int>(models.size()); ++m) {
      if (models[m].registered() > models[reference].registered()) reference = m;
    }
    Model merged = models[reference];
    for (int f : merged.registration_order) (*model_of_frame)[f] = reference;
    out.merged_models = 1;
    bool merged_any = false;
    for (int m = 0; m < static_cast<int>(models.size()); ++m) {
      if (m == reference) continue;
      const std::optional<Sim3> t = mergeTransform(models[m], merged);
      if (!t) continue;
      for (int f : models[m].registration_order) {
        if (!merged.poses[f]) (*model_of_frame)[f] = m;
      }
      mergeInto(models[m], *t, &merged);
      ++out.merged_models;
      merged_any = true;
    }
    out.seconds.merge += secondsSince(start);
    // A free focal length moves in every model's global BA: a reference built before the last
    // model was refined under an older camera than the one written, so it is refined again.
    const bool older_camera =
        options.ba.refine_focal && reference != static_cast<int>(models.size()) - 1;
    if (merged_any || older_camera) globalRefinement(&merged, reference);
    return merged;
  }

  // -------------------------------------------------------------------------------------------
  // Loop matches (LoopMatchOptions).

  // One end of a loop match: keypoint `keypoint` of a matching frame, and the track that
  // observes it or -1 (a lone keypoint).
  struct LoopEnd {
    int frame = -1;
    int keypoint = -1;
    Eigen::Vector2d pixel;
    int track = -1;
    double size = 0.0;  // The keypoint's diameter (px), for the hybrid graph's keypoint weight.
  };
  using LoopMatch = std::pair<LoopEnd, LoopEnd>;

  // Which track each loop end belongs to as merges proceed: a merged-away track points to the
  // track that took it, and a lone keypoint that joined a track belongs to it from then on (so
  // that a keypoint matched from two frames joins one track, not one each).
  struct TrackMerges {
    std::vector<int> alias;
    std::map<std::pair<int, int>, int> track_of_lone_keypoint;  // By (frame, keypoint).

    explicit TrackMerges(int tracks) : alias(tracks) { std::iota(alias.begin(), alias.end(), 0); }
    LoopEnd resolve(LoopEnd end) const {
      if (end.track < 0) {
        const auto owner = track_of_lone_keypoint.find({end.frame, end.keypoint});
        if (owner != track_of_lone_keypoint.end()) end.track = owner->second;
      }
      while (end.track >= 0 && alias[end.track] != end.track) end.track = alias[end.track];
      return end;
    }
    void record(const LoopEnd& from, int to) {
      if (from.track >= 0) {
        alias[from.track] = to;
      } else {
        track_of_lone_keypoint[{from.frame, from.keypoint}] = to;
      }
    }
  };

  enum class MergeOutcome {
    kMerged,
    kNotYet,  // No point yet, or one that does not explain both: global BA may change that.
    kNever,   // One track already, or both observe one frame: merges only make tracks longer.
  };

  // Whether two registered frames look like a loop: much of what `a` sees projects into `b`,
  // little of it is tracked there.
  bool isLoopCandidate(const Model& model, int a, int b) const {
    const LoopMatchOptions& o = options.loops;
    const Eigen::Vector3d centre_a = centreOf(*model.poses[a]);
    const Eigen::Vector3d centre_b = centreOf(*model.poses[b]);
    int seen = 0, covisible = 0, shared = 0;
    for (int t : tracks.frame_tracks[a]) {
      const int p = model.point_of_track[t];
      if (p < 0) continue;
      const MapPoint& point = model.points[p];
      if (!point.seenIn(a)) continue;
      ++seen;
      Eigen::Vector2d pixel;
      if (!camera->project(*model.poses[b] * point.position, &pixel) || !camera->isInImage(pixel) ||
          triangulationAngleDeg(centre_a, centre_b, point.position) > o.max_view_angle_deg)
        continue;
      ++covisible;
      shared += point.seenIn(b);
    }
    return seen > 0 && covisible >= o.min_covisible_fraction * seen &&
           shared <= o.max_shared_fraction * covisible;
  }

  std::vector<LoopMatch> findLoopMatches(const Model& model) {
    std::vector<LoopMatch> found;
    const std::vector<MatchingFrameFeatures>& frames = tracks.matching_frames;
    for (std::size_t j = 0; j < frames.size(); ++j) {
      for (std::size_t i = 0; i < j; ++i) {
        const MatchingFrameFeatures& a = frames[i];
        const MatchingFrameFeatures& b = frames[j];
        if (!model.poses[a.frame] || !model.poses[b.frame] ||
            tracks.matched_pairs.count({a.frame, b.frame}) ||
            !isLoopCandidate(model, a.frame, b.frame))
          continue;
        ++out.loops.candidate_pairs;
        const std::vector<FeatureMatch> matches =
            verifiedMatches(a.features, b.features, options.features, options.tracks);
        out.loops.verified_pairs += !matches.empty();
        for (const FeatureMatch& m : matches) {
          const LoopEnd end_a{a.frame, m.index_a, m.pixel_a, a.track_of_keypoint[m.index_a],
                              a.features.sizes[m.index_a]};
          const LoopEnd end_b{b.frame, m.index_b, m.pixel_b, b.track_of_keypoint[m.index_b],
                              b.features.sizes[m.index_b]};
          if (end_a.track < 0 && end_b.track < 0) continue;
          if (end_a.track == end_b.track) continue;
          found.emplace_back(end_a, end_b);
        }
      }
    }
    out.loops.matches = static_cast<int>(found.size());
    return found;
  }

  // The observations a loop end brings: its track's, or the keypoint alone.
  std::vector<TrackObservation> observationsOf(const LoopEnd& end) const {
    if (end.track >= 0) return tracks.tracks[end.track].observations;
    return {{end.frame, end.pixel, /*keypoint=*/true, end.size}};
  }

  // Both ends' observations by frame; nullopt when both observe one frame (a track holds one
  // observation per frame).
  std::optional<std::vector<TrackObservation>> joinedObservations(const LoopEnd& a,
                                                                  const LoopEnd& b) const {
    std::vector<TrackObservation> joined = observationsOf(a);
    for (const TrackObservation& o : observationsOf(b)) {
      const auto same_frame = [&o](const TrackObservation& j) { return j.frame == o.frame; };
      if (std::any_of(joined.begin(), joined.end(), same_frame)) return std::nullopt;
      joined.push_back(o);
    }
    std::sort(
        joined.begin(), joined.end(),
        [](const TrackObservation& x, const TrackObservation& y) { return x.frame < y.frame; });
    return joined;
  }

  // The merged point: the points' mean weighted by their observations (COLMAP's merge).
  static Eigen::Vector3d mergedPosition(const Model& model, std::initializer_list<int> points) {
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    double weight = 0.0;
    for (int p : points) {
      if (p < 0) continue;
      const double observations = static_cast<double>(model.points[p].frames.size());
      weighted += observations * model.points[p].position;
      weight += observations;
    }
    return weighted / weight;
  }

  // The registered frames of `observations`, if `position` reprojects within the loop bound into
  // every one of them.
  std::optional<std::vector<int>> framesExplained(const Model& model,
                                                  const std::vector<TrackObservation>& observations,
                                                  const Eigen::Vector3d& position) const {
    std::vector<int> frames;
    for (const TrackObservation& o : observations) {
      if (!model.poses[o.frame]) continue;
      if (!reprojectsWithin(model, o.frame, o.pixel, position, options.loops.max_merge_error_px))
        return std::nullopt;
      frames.push_back(o.frame);
    }
    return frames;
  }

  // Gives `from`'s observations (a track, or a lone keypoint when from.track < 0) to track `to`.
  void moveObservations(const LoopEnd& from, int to, std::vector<TrackObservation> joined) {
    for (const TrackObservation& o : observationsOf(from)) {
      std::vector<int>& in_frame = tracks.frame_tracks[o.frame];
      if (from.track >= 0) {
        const auto listed = std::find(in_frame.begin(), in_frame.end(), from.track);
        CURVESFM_CHECK(listed != in_frame.end())
            << "track " << from.track << " is not listed in frame " << o.frame;
        in_frame.erase(listed);
      }
      in_frame.insert(std::lower_bound(in_frame.begin(), in_frame.end(), to), to);
    }
    tracks.tracks[to].observations = std::move(joined);
    if (from.track >= 0) tracks.tracks[from.track].observations.clear();
  }

  // Merges the two ends' tracks when one point explains every registered observation of both
  // (see LoopMatchOptions).
  MergeOutcome tryMerge(Model* model, const LoopMatch& match, TrackMerges* merges) {
    LoopEnd a = merges->resolve(match.first);
    LoopEnd b = merges->resolve(match.second);
    if (a.track == b.track) return MergeOutcome::kNever;
    if (a.track < 0) std::swap(a, b);  // `a` holds a track; `b` may be a lone keypoint.
    std::optional<std::vector<TrackObservation>> joined = joinedObservations(a, b);
    if (!joined) return MergeOutcome::kNever;
    const int pa = model->point_of_track[a.track];
    const int pb = b.track >= 0 ? model->point_of_track[b.track] : -1;
    if (pa < 0 && pb < 0) return MergeOutcome::kNotYet;
    const Eigen::Vector3d position = mergedPosition(*model, {pa, pb});
    const std::optional<std::vector<int>> frames = framesExplained(*model, *joined, position);
    if (!frames) return MergeOutcome::kNotYet;

    moveObservations(b, a.track, std::move(*joined));
    merges->record(b, a.track);
    for (int p : {pa, pb}) {
      if (p >= 0) model->removePoint(p);
    }
    model->addPoint(position, a.track, *frames);
    return MergeOutcome::kMerged;
  }

  // Merges the tracks that loop matches join, with a global BA after each round of merges. The
  // matching frames' descriptors are released after: nothing else needs them.
  void closeLoops(Model* model, int model_id) {
    if (!options.loops.enabled) {
      releaseMatchingFrames();
      return;
    }
    const Clock::time_point start = Clock::now();
    std::vector<LoopMatch> pending = findLoopMatches(*model);
    releaseMatchingFrames();
    TrackMerges merges(static_cast<int>(tracks.tracks.size()));
    out.seconds.loops += secondsSince(start);
    if (loop_progress) loop_progress(0, out.loops);
    for (int round = 0; round < options.loops.max_rounds && !pending.empty(); ++round) {
      const Clock::time_point round_start = Clock::now();
      std::vector<LoopMatch> left;
      int merged = 0;
      for (const LoopMatch& m : pending) {
        const MergeOutcome outcome = tryMerge(model, m, &merges);
        merged += outcome == MergeOutcome::kMerged;
        if (outcome == MergeOutcome::kNotYet) left.push_back(m);
      }
      pending = std::move(left);
      out.seconds.loops += secondsSince(round_start);
      if (merged == 0) break;
      out.loops.merges += merged;
      ++out.loops.rounds;
      globalRefinement(model, model_id);
      if (loop_progress) loop_progress(out.loops.rounds, out.loops);
    }
  }

  void releaseMatchingFrames() {
    std::vector<MatchingFrameFeatures>().swap(tracks.matching_frames);
  }

  // -------------------------------------------------------------------------------------------
  // Output.

  std::vector<InitialisedPoint> initialisedPoints(const Model& model) const {
    std::vector<InitialisedPoint> points;
    for (const MapPoint& p : model.points) {
      if (!p.alive()) continue;
      InitialisedPoint point;
      point.position = p.position;
      point.colour_bgr = tracks.tracks[p.track].colour_bgr;
      std::vector<int> frames = p.frames;
      std::sort(frames.begin(), frames.end());
      for (int f : frames) point.observations.push_back(*tracks.observation(p.track, f));
      points.push_back(std::move(point));
    }
    return points;
  }

  // `poses_fitted`: the poses were refined with the points, not given.
  void writeResult(bool poses_fitted, const Model& merged, const std::vector<Model>& models,
                   const std::vector<int>& model_of_frame) {
    for (int f = 0; f < numFrames(); ++f) {
      InitialisedFrame& frame = out.frames[f];
      if (merged.poses[f]) {
        frame.status = FrameRegistration::kRegistered;
        frame.model = model_of_frame[f];
        frame.cam_from_world = merged.poses[f];
        continue;
      }
      const bool elsewhere = std::any_of(models.begin(), models.end(),
                                         [f](const Model& m) { return m.poses[f].has_value(); });
      if (models.empty()) {
        frame.status = FrameRegistration::kNoModel;
      } else if (elsewhere) {
        frame.status = FrameRegistration::kUnmergedModel;
      } else if (frame.status == FrameRegistration::kNotTried && !tracks.frame_tracks[f].empty()) {
        frame.status = FrameRegistration::kNoCorrespondences;
      }
    }
    out.points = initialisedPoints(merged);
    out.reprojection = reprojectionSummary(*camera, out);
    const int posed = out.registeredFrames();
    if (out.reprojection.observations > 0 && posed >= 3 && posed <= options.precision_max_frames) {
      const Clock::time_point start = Clock::now();
      out.reprojection.precision = centrePrecision(*camera, out, poses_fitted);
      out.seconds.precision = secondsSince(start);
    }
  }

  void addFrame(const cv::Mat& image) {
    CURVESFM_CHECK(image.cols == camera->width() && image.rows == camera->height())
        << "frame " << frames_added << " is " << image.cols << "x" << image.rows
        << " but the camera is " << camera->width() << "x" << camera->height();
    const Clock::time_point start = Clock::now();
    if (!tracking_threads) tracking_threads.emplace(options.tracking_threads);
    const cv::Mat undistorted = undistorter.undistort(image);
    out.seconds.undistort += secondsSince(start);
    builder.addFrame(undistorted);
    ++frames_added;
    add_frame_seconds += secondsSince(start);
  }

  // Builds the tracks from the frames added (the first half of finish() and finishAtPoses()).
  void buildTracks() {
    if (!tracking_threads) tracking_threads.emplace(options.tracking_threads);
    tracks = builder.finish();
    tracking_threads.reset();
    out.num_tracks = static_cast<int>(tracks.tracks.size());
    out.track_stats = tracks.frames;
    for (const FeatureTrackFrameStats& s : tracks.frames) {
      out.seconds.klt += s.klt_seconds;
      out.seconds.matching += s.match_seconds;
    }
    out.frames.assign(numFrames(), InitialisedFrame{});
  }

  // The point of `track` at poses held: the two-view point of its first view and the one
  // farthest from it, refined by least squares over every registered view within `gate_px` of
  // it, twice (a view the seed puts beyond the gate may come within it of the refined point).
  // Adds it with the views within the gate; false when fewer than two remain or their rays are
  // too close to parallel.
  bool triangulateTrackAtPoses(Model* model, int track, double gate_px) const {
    const std::vector<int> frames = registeredFramesOf(*model, track);
    if (frames.size() < 2) return false;
    const int b = farthestFrame(*model, frames, frames.front());
    Eigen::Vector3d point;
    if (b < 0 || !triangulatePair(*model, track, frames.front(), b, &point)) return false;
    const auto framesWithinGate = [&] {
      std::vector<int> within;
      for (int f : frames) {
        if (reprojectsWithin(*model, f, pixelOf(track, f), point, gate_px)) within.push_back(f);
      }
      return within;
    };
    for (int round = 0; round < 2; ++round) {
      const std::vector<int> within = framesWithinGate();
      if (within.size() < 2) return false;
      std::vector<Pose3> poses;
      std::vector<Eigen::Vector2d> normalized;
      for (int f : within) {
        poses.push_back(*model->poses[f]);
        normalized.push_back(camera->pixelToNormalized(pixelOf(track, f)));
      }
      if (!refinePointAtPoses(poses, normalized, &point)) return false;
    }
    std::vector<int> kept = framesWithinGate();
    if (kept.size() < 2 || angleDeg(*model, kept, point) < options.min_triangulation_angle_deg) {
      return false;
    }
    model->addPoint(point, track, std::move(kept));
    return true;
  }

  // Triangulates every track as finish() does: two views each, observations within the bound.
  void triangulateFromTwoViews(Model* model) const {
    retriangulateAll(model);
    filterPoints(model, allPoints(*model));
  }

  // Triangulates every track at the model's poses within `gate_px` (triangulateTrackAtPoses).
  void triangulateEveryTrackAtPoses(Model* model, double gate_px) const {
    for (int track = 0; track < static_cast<int>(tracks.tracks.size()); ++track) {
      triangulateTrackAtPoses(model, track, gate_px);
    }
  }

  // The median reprojection error of the points of `model` over their views (px; 0 for none).
  double medianErrorOfPoints(const Model& model) const {
    std::vector<double> errors;
    for (const MapPoint& point : model.points) {
      if (!point.alive()) continue;
      // Every view kept lies within the gate, so every error is finite.
      for (int f : point.frames) {
        errors.push_back(reprojectionErrorPx(model, f, pixelOf(point.track, f), point.position));
      }
    }
    return errors.empty() ? 0.0 : upperMedian(errors);
  }

  // Triangulates every track at the model's (given) poses: refined over its views within a gate
  // that follows the residuals, or as finish() would without refine_at_given_poses.
  void triangulateAtPoses(Model* model) {
    out.given_poses_gate_px = options.max_reprojection_error_px;
    if (!options.refine_at_given_poses) {
      triangulateFromTwoViews(model);
      return;
    }
    Model two_view = *model;
    triangulateFromTwoViews(&two_view);
    out.two_view_points = initialisedPoints(two_view);
    if (options.given_poses_gate_scale > 0.0) {
      // The residuals are read on points triangulated within the widest gate; a track's point
      // does not depend on the others', so when the gate chosen is that one the probe is the map.
      Model probe = *model;
      triangulateEveryTrackAtPoses(&probe, options.given_poses_max_gate_px);
      out.given_poses_median_error_px = medianErrorOfPoints(probe);
      out.given_poses_gate_px =
          std::clamp(options.given_poses_gate_scale * out.given_poses_median_error_px,
                     options.max_reprojection_error_px, options.given_poses_max_gate_px);
      if (out.given_poses_gate_px == options.given_poses_max_gate_px) {
        *model = std::move(probe);
        return;
      }
    }
    triangulateEveryTrackAtPoses(model, out.given_poses_gate_px);
  }

  PointInitialisation finishAtPoses(const std::vector<std::optional<Pose3>>& cam_from_world) {
    CURVESFM_CHECK(static_cast<int>(cam_from_world.size()) == frames_added)
        << "finishAtPoses: " << cam_from_world.size() << " poses for " << frames_added << " frames";
    const Clock::time_point start = Clock::now();
    buildTracks();
    releaseMatchingFrames();
    Model model(numFrames(), static_cast<int>(tracks.tracks.size()));
    for (int f = 0; f < numFrames(); ++f) {
      if (cam_from_world[f]) model.registerFrame(f, *cam_from_world[f]);
    }
    const Clock::time_point triangulation = Clock::now();
    triangulateAtPoses(&model);
    out.seconds.triangulation += secondsSince(triangulation);
    out.models = out.merged_models = model.registered() > 0 ? 1 : 0;
    out.scale_convention = "the given poses' unit";
    writeResult(false, model, {model}, std::vector<int>(numFrames(), 0));
    out.seconds.total = add_frame_seconds + secondsSince(start);
    return std::move(out);
  }

  PointInitialisation finish() {
    const Clock::time_point start = Clock::now();
    buildTracks();
    std::vector<Model> models = buildModels();
    if (!models.empty()) {
      std::vector<int> model_of_frame(numFrames(), -1);
      Model merged = mergeModels(models, &model_of_frame);
      closeLoops(&merged, model_of_frame[merged.pair.first]);
      writeResult(true, merged, models, model_of_frame);
    } else {
      writeResult(true, Model(numFrames(), 0), models, std::vector<int>(numFrames(), -1));
    }
    out.seconds.total = add_frame_seconds + secondsSince(start);
    return std::move(out);
  }
};

ReprojectionSummary reprojectionSummary(const Camera& camera, const PointInitialisation& result) {
  ReprojectionSummary summary;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double squares = 0.0;
  for (const InitialisedPoint& point : result.points) {
    for (const TrackObservation& o : point.observations) {
      CURVESFM_CHECK(o.frame >= 0 && o.frame < static_cast<int>(result.frames.size()))
          << "an observation in frame " << o.frame << " of " << result.frames.size();
      const std::optional<Pose3>& pose = result.frames[o.frame].cam_from_world;
      Eigen::Vector2d projected;
      if (!pose || !camera.project(*pose * point.position, &projected)) continue;
      const Eigen::Vector2d residual = o.pixel - projected;
      sum += residual;
      squares += residual.squaredNorm();
      ++summary.observations;
    }
  }
  if (summary.observations == 0) return summary;
  summary.mean_px = sum / summary.observations;
  summary.rms_px = std::sqrt(squares / summary.observations);
  return summary;
}

double InitialiserTimes::tracksMsPerVgaFrame(int frames, int width, int height) const {
  if (frames <= 0 || width <= 0 || height <= 0) return 0.0;
  return 1e3 * (undistort + klt + matching) / frames * (640.0 * 480.0) /
         (static_cast<double>(width) * height);
}

std::optional<CentrePrecision> centrePrecision(const Camera& camera,
                                               const PointInitialisation& result,
                                               bool poses_fitted) {
  PointBundleAdjustmentInput input;
  input.camera = std::make_shared<Camera>(camera);
  std::vector<int> camera_of_frame(result.frames.size(), -1);
  for (std::size_t f = 0; f < result.frames.size(); ++f) {
    if (!result.frames[f].cam_from_world) continue;
    camera_of_frame[f] = static_cast<int>(input.cam_from_world.size());
    input.cam_from_world.push_back(*result.frames[f].cam_from_world);
  }
  for (const InitialisedPoint& point : result.points) {
    const int index = static_cast<int>(input.points.size());
    input.points.push_back(point.position);
    for (const TrackObservation& o : point.observations) {
      CURVESFM_CHECK(o.frame >= 0 && o.frame < static_cast<int>(result.frames.size()))
          << "an observation in frame " << o.frame << " of " << result.frames.size();
      if (camera_of_frame[o.frame] >= 0) {
        input.observations.push_back({camera_of_frame[o.frame], index, o.pixel});
      }
    }
  }
  const double sigma = estimatedPixelSigma(input, poses_fitted);
  if (!(sigma > 0.0)) return std::nullopt;  // NaN: nothing left free.
  return CentrePrecision{sigma, predictedCentreAte(input, sigma)};
}

PointInitialiser::PointInitialiser(const Camera& camera, const PointInitialiserOptions& options)
    : state_(std::make_unique<State>(camera, options)) {}

PointInitialiser::~PointInitialiser() = default;

void PointInitialiser::addFrame(const cv::Mat& image) { state_->addFrame(image); }

PointInitialisation PointInitialiser::finish() { return state_->finish(); }

PointInitialisation PointInitialiser::finishAtPoses(
    const std::vector<std::optional<Pose3>>& cam_from_world) {
  return state_->finishAtPoses(cam_from_world);
}

const Camera& PointInitialiser::undistortedCamera() const { return *state_->camera; }

void PointInitialiser::setProgress(Progress progress) { state_->progress = std::move(progress); }

void PointInitialiser::setLoopProgress(LoopProgress progress) {
  state_->loop_progress = std::move(progress);
}

}  // namespace curvesfm
