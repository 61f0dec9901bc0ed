#include "apps/cli/initialisation_output.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "apps/cli/report_json.h"
#include "core/check.h"
#include "core/clock.h"
#include "core/curve_export.h"
#include "core/errors.h"
#include "core/trajectory_evaluation.h"
#include "core/tum_dataset.h"

namespace curvesfm {
namespace {

// "3-7, 12, 20-21": frame indices as ranges, for the lines that list unregistered frames.
std::string frameRanges(const std::vector<int>& frames) {
  std::string text;
  for (std::size_t i = 0; i < frames.size();) {
    std::size_t j = i;
    while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
    if (!text.empty()) text += ", ";
    text += std::to_string(frames[i]);
    if (j > i) text += "-" + std::to_string(frames[j]);
    i = j + 1;
  }
  return text;
}

nlohmann::json optimizationToJson(const InitialiserBundleAdjustment& ba) {
  const OptimizationSummary& s = ba.summary;
  return {{"scope", ba.scope},
          {"model", ba.model},
          {"frames", ba.frames},
          {"points", ba.points},
          {"observations", ba.observations},
          {"initial_cost", s.initial_cost},
          {"final_cost", s.final_cost},
          {"iterations", s.iterations},
          {"termination", s.termination},
          {"seconds", s.total_seconds}};
}

// Sums of the BAs of one scope: the report lists every solve, the summary line these.
struct BaTotals {
  int solves = 0, iterations = 0;
  double seconds = 0.0;
};

std::map<std::string, BaTotals> baTotals(const PointInitialisation& result) {
  std::map<std::string, BaTotals> totals;
  for (const InitialiserBundleAdjustment& ba : result.bundle_adjustments) {
    BaTotals& t = totals[ba.scope];
    ++t.solves;
    t.iterations += ba.summary.iterations;
    t.seconds += ba.summary.total_seconds;
  }
  return totals;
}

// Feeds every image of `sequence` to `initialiser`, printing progress.
void trackSequence(const ImageSequence& sequence, PointInitialiser* initialiser,
                   Clock::time_point start) {
  const int frames = static_cast<int>(sequence.images.size());
  const int every = std::max(1, frames / 10);
  for (int i = 0; i < frames; ++i) {
    initialiser->addFrame(loadCameraImage(sequence.images[i].image_path, sequence.camera));
    if ((i + 1) % every == 0 || i + 1 == frames) {
      std::printf("init: tracked %d/%d frames (%.1f s)\n", i + 1, frames, secondsSince(start));
      std::fflush(stdout);
    }
  }
}

// Beyond this the refined focal length is more likely a weakly determined one than the
// correction of a camera given roughly (7-Scenes' colour camera: 4 %).
constexpr double kImplausibleFocalChange = 0.15;

void printRefinedFocal(const Camera& given, double focal_scale) {
  if (focal_scale == 1.0) return;
  const Camera refined = given.withFocalScale(focal_scale);
  std::printf(
      "init: focal lengths refined x%.4f: fx %.2f, fy %.2f px (given %.2f, %.2f); the same "
      "camera for another run: --camera %s\n",
      focal_scale, refined.fx(), refined.fy(), given.fx(), given.fy(),
      formatCameraString(refined).c_str());
  if (std::abs(focal_scale - 1.0) > kImplausibleFocalChange) {
    std::printf(
        "init: warning: the refined focal length is %.0f %% off the one given: implausible for a "
        "calibrated camera; check the camera, or run without --points-ba-refine-focal\n",
        100.0 * std::abs(focal_scale - 1.0));
  }
}

}  // namespace

nlohmann::json cameraToJson(const Camera& camera) {
  const CameraIntrinsics& c = camera.intrinsics();
  return {{"width", c.width}, {"height", c.height}, {"fx", c.fx}, {"fy", c.fy},
          {"cx", c.cx},       {"cy", c.cy},         {"k1", c.k1}, {"k2", c.k2},
          {"p1", c.p1},       {"p2", c.p2},         {"k3", c.k3}};
}

PointInitialisation initialiseSequence(const ImageSequence& sequence,
                                       const PointInitialiserOptions& options) {
  PointInitialiser initialiser(sequence.camera, options);
  const int frames = static_cast<int>(sequence.images.size());
  const int every = std::max(1, frames / 10);
  const Clock::time_point start = Clock::now();
  trackSequence(sequence, &initialiser, start);
  initialiser.setProgress([every, start](int model, int registered, int total, int points) {
    if (registered % every != 0 && registered != total) return;
    std::printf("init: model %d registered %d/%d frames, %d points (%.1f s)\n", model, registered,
                total, points, secondsSince(start));
    std::fflush(stdout);
  });
  initialiser.setLoopProgress([start](int round, const LoopMatchStats& loops) {
    if (round == 0) {
      std::printf(
          "init: loop matches: %d candidate pairs matched (%d verified), %d matches (%.1f s)\n",
          loops.candidate_pairs, loops.verified_pairs, loops.matches, secondsSince(start));
    } else {
      std::printf("init: loop round %d: %d tracks merged so far, global BA done (%.1f s)\n", round,
                  loops.merges, secondsSince(start));
    }
    std::fflush(stdout);
  });
  return initialiser.finish();
}

PointInitialisation triangulateAtPoses(const ImageSequence& sequence,
                                       const std::vector<DatasetFrame>& frames,
                                       const PointInitialiserOptions& options) {
  PointInitialiser initialiser(sequence.camera, options);
  trackSequence(sequence, &initialiser, Clock::now());
  std::map<std::string, Pose3> pose_of_image;
  for (const DatasetFrame& frame : frames) {
    pose_of_image.emplace(frame.image_path, frame.initial_cam_from_world);
  }
  std::vector<std::optional<Pose3>> poses;
  for (const SequenceImage& image : sequence.images) {
    const auto found = pose_of_image.find(image.image_path);
    poses.push_back(found == pose_of_image.end() ? std::nullopt
                                                 : std::optional<Pose3>(found->second));
  }
  return initialiser.finishAtPoses(poses);
}

std::vector<DatasetFrame> initialisedFrames(const ImageSequence& sequence,
                                            const PointInitialisation& result) {
  std::vector<DatasetFrame> frames;
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    if (!result.frames[i].cam_from_world) continue;
    frames.push_back({sequence.images[i].timestamp, sequence.images[i].image_path,
                      *result.frames[i].cam_from_world});
  }
  return frames;
}

std::vector<std::vector<PointSighting>> initialisedSightings(const PointInitialisation& result) {
  std::vector<int> registered_index(result.frames.size(), -1);
  int next = 0;
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    if (result.frames[i].cam_from_world) registered_index[i] = next++;
  }
  std::vector<std::vector<PointSighting>> sightings(next);
  for (std::size_t p = 0; p < result.points.size(); ++p) {
    for (const TrackObservation& o : result.points[p].observations) {
      sightings[registered_index[o.frame]].push_back(
          {static_cast<int>(p), o.pixel, o.keypoint, o.keypoint_size});
    }
  }
  return sightings;
}

std::vector<std::vector<PointSighting>> sightingsOfFrames(const ImageSequence& sequence,
                                                          const std::vector<DatasetFrame>& frames,
                                                          const PointInitialisation& result) {
  // initialisedSightings() is per registered image, in image order; `frames` may be in another.
  const std::vector<std::vector<PointSighting>> per_registered = initialisedSightings(result);
  std::map<std::string, std::size_t> registered_of_image;
  std::size_t next = 0;
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    if (result.frames[i].cam_from_world)
      registered_of_image[sequence.images[i].image_path] = next++;
  }
  std::vector<std::vector<PointSighting>> sightings;
  for (const DatasetFrame& frame : frames) {
    const auto found = registered_of_image.find(frame.image_path);
    sightings.push_back(found == registered_of_image.end() ? std::vector<PointSighting>()
                                                           : per_registered[found->second]);
  }
  return sightings;
}

std::vector<StampedPose> initialisedTrajectory(const ImageSequence& sequence,
                                               const PointInitialisation& result) {
  std::vector<StampedPose> trajectory;
  for (const DatasetFrame& frame : initialisedFrames(sequence, result)) {
    trajectory.push_back({frame.timestamp, frame.initial_cam_from_world.inverse()});
  }
  return trajectory;
}

void writeInitialisedPoints(const std::string& path, const PointInitialisation& result,
                            const std::vector<Eigen::Vector3d>* refined_positions) {
  CURVESFM_CHECK(!refined_positions || refined_positions->size() == result.points.size())
      << refined_positions->size() << " refined positions for " << result.points.size()
      << " points";
  std::vector<ExportedPoint> points;
  points.reserve(result.points.size());
  for (std::size_t i = 0; i < result.points.size(); ++i) {
    const InitialisedPoint& p = result.points[i];
    points.push_back({refined_positions ? (*refined_positions)[i] : p.position, p.colour_bgr[2],
                      p.colour_bgr[1], p.colour_bgr[0], static_cast<int>(p.observations.size())});
  }
  writePointsPly(path, points);
}

std::string reprojectionLine(const ReprojectionSummary& r) {
  char text[200];
  std::snprintf(text, sizeof(text),
                "%d observations reproject with rms %.3f px, mean residual (%.3f, %.3f) px",
                r.observations, r.rms_px, r.mean_px.x(), r.mean_px.y());
  std::string line = text;
  if (!r.precision) return line;
  if (std::isinf(r.precision->predicted_ate)) return line + "; they do not fix every centre";
  std::snprintf(text, sizeof(text),
                "; their noise, %.3f px per coordinate, alone would leave the centres an ATE of "
                "%.3g (the poses' unit)",
                r.precision->pixel_sigma, r.precision->predicted_ate);
  return line + text;
}

namespace {

// The predicted ATE in the unit `scale` takes the poses' to: a number, "infinite" where the
// points do not fix every centre, null when not computed.
nlohmann::json predictedCentreAteJson(const ReprojectionSummary& r, double scale) {
  if (!r.precision) return nullptr;
  if (std::isinf(r.precision->predicted_ate)) return "infinite";
  return scale * r.precision->predicted_ate;
}

nlohmann::json precisionJson(const ReprojectionSummary& r) {
  if (!r.precision) return nullptr;
  return {{"pixel_sigma", r.precision->pixel_sigma},
          {"predicted_centre_ate", predictedCentreAteJson(r, 1.0)}};
}

}  // namespace

nlohmann::json initialisationToJson(const ImageSequence& sequence,
                                    const PointInitialisation& result) {
  nlohmann::json frames = nlohmann::json::array();
  for (std::size_t i = 0; i < result.frames.size(); ++i) {
    const InitialisedFrame& f = result.frames[i];
    nlohmann::json frame = {{"index", i},
                            {"image", sequence.images[i].name},
                            {"timestamp", sequence.images[i].timestamp},
                            {"status", toString(f.status)},
                            {"model", f.model},
                            {"correspondences", f.correspondences},
                            {"inliers", f.inliers},
                            {"klt_tracked", result.track_stats[i].klt_tracked},
                            {"matching_frame", result.track_stats[i].matching_frame},
                            {"descriptor_matches", result.track_stats[i].matches}};
    if (f.status == FrameRegistration::kRejected) frame["rejection"] = toString(f.rejection);
    frames.push_back(frame);
  }
  nlohmann::json bas = nlohmann::json::array();
  for (const InitialiserBundleAdjustment& ba : result.bundle_adjustments) {
    bas.push_back(optimizationToJson(ba));
  }
  const InitialiserTimes& t = result.seconds;
  const TwoViewGeometry& g = result.initial_geometry;
  return {{"counts",
           {{"frames", result.frames.size()},
            {"registered", result.registeredFrames()},
            {"tracks", result.num_tracks},
            {"points", result.points.size()},
            {"models", result.models},
            {"merged_models", result.merged_models},
            {"pairs_tried", result.pairs_tried}}},
          {"loops",
           {{"candidate_pairs", result.loops.candidate_pairs},
            {"verified_pairs", result.loops.verified_pairs},
            {"matches", result.loops.matches},
            {"merges", result.loops.merges},
            {"rounds", result.loops.rounds}}},
          {"reprojection",
           {{"observations", result.reprojection.observations},
            {"mean_px", {result.reprojection.mean_px.x(), result.reprojection.mean_px.y()}},
            {"rms_px", result.reprojection.rms_px},
            {"precision", precisionJson(result.reprojection)}}},
          {"scale_convention", result.scale_convention},
          {"given_poses_gate_px", result.given_poses_gate_px},
          {"given_poses_median_error_px", result.given_poses_median_error_px},
          {"focal_scale", result.focal_scale},
          {"initial_pair",
           {{"frames", {result.initial_pair.first, result.initial_pair.second}},
            {"model", toString(g.model)},
            {"inliers", g.num_inliers},
            {"points", g.points_in_cam_a.size()},
            {"median_parallax_deg", g.median_parallax_deg}}},
          {"failure", result.failure},
          {"frames", frames},
          {"bundle_adjustments", bas},
          {"seconds",
           {{"undistort", t.undistort},
            {"klt", t.klt},
            {"matching", t.matching},
            {"pair_search", t.pair_search},
            {"registration", t.registration},
            {"triangulation", t.triangulation},
            {"local_ba", t.local_ba},
            {"global_ba", t.global_ba},
            {"merge", t.merge},
            {"loops", t.loops},
            {"precision", t.precision},
            {"total", t.total},
            {"tracks_ms_per_640x480_frame",
             t.tracksMsPerVgaFrame(static_cast<int>(result.frames.size()), sequence.camera.width(),
                                   sequence.camera.height())}}}};
}

nlohmann::json printInitialisationSummary(const ImageSequence& sequence,
                                          const PointInitialisation& result) {
  const int frames = static_cast<int>(result.frames.size());
  std::printf(
      "init: %d of %d frames registered (%d models, %d merged), %zu points from %d tracks\n",
      result.registeredFrames(), frames, result.models, result.merged_models, result.points.size(),
      result.num_tracks);
  if (result.reprojection.observations > 0) {
    std::printf("init: %s\n", reprojectionLine(result.reprojection).c_str());
  }
  std::map<std::string, std::vector<int>> unregistered;
  for (int i = 0; i < frames; ++i) {
    const InitialisedFrame& f = result.frames[i];
    if (f.status == FrameRegistration::kRegistered) continue;
    std::string reason = toString(f.status);
    if (f.status == FrameRegistration::kRejected) reason += " (" + toString(f.rejection) + ")";
    unregistered[reason].push_back(i);
  }
  for (const auto& [reason, list] : unregistered) {
    std::printf("init: not registered, %s: frames %s\n", reason.c_str(), frameRanges(list).c_str());
  }
  printRefinedFocal(sequence.camera, result.focal_scale);
  const InitialiserTimes& t = result.seconds;
  std::printf(
      "init time: tracks %.2f s (KLT %.2f, descriptors %.2f; %.1f ms per frame, %.1f ms per "
      "640x480 "
      "frame), pair search %.2f s, registration %.2f s, triangulation %.2f s, "
      "local BA %.2f s, global BA %.2f s, precision %.2f s, total %.2f s\n",
      t.klt + t.matching + t.undistort, t.klt, t.matching,
      frames > 0 ? 1e3 * (t.klt + t.matching + t.undistort) / frames : 0.0,
      t.tracksMsPerVgaFrame(frames, sequence.camera.width(), sequence.camera.height()),
      t.pair_search, t.registration, t.triangulation, t.local_ba, t.global_ba, t.precision,
      t.total);
  const LoopMatchStats& loops = result.loops;
  if (loops.candidate_pairs > 0) {
    std::printf(
        "init loops: %d candidate pairs (%d verified), %d matches, %d tracks merged in %d "
        "rounds, %.2f s (global BA counted below)\n",
        loops.candidate_pairs, loops.verified_pairs, loops.matches, loops.merges, loops.rounds,
        t.loops);
  }
  for (const auto& [scope, totals] : baTotals(result)) {
    std::printf("init BA %s: %d solves, %d iterations, %.2f s\n", scope.c_str(), totals.solves,
                totals.iterations, totals.seconds);
  }
  if (sequence.ground_truth.empty() || result.registeredFrames() < 3) return nullptr;
  try {
    const TrajectoryEvaluation e = compareTrajectories(
        initialisedTrajectory(sequence, result), sequence.ground_truth,
        TrajectoryEvaluationOptions{}, "initialiser trajectory", sequence.ground_truth_source);
    std::printf(
        "init ATE (sim3) vs %s over %d frames: rmse %.6f, mean %.6f, median %.6f (ground "
        "truth unit)\n",
        sequence.ground_truth_source.c_str(), e.ate.count, e.ate.rmse, e.ate.mean, e.ate.median);
    const nlohmann::json predicted =
        predictedCentreAteJson(result.reprojection, e.ground_truth_from_estimate.scale);
    if (predicted.is_number()) {
      std::printf("init ATE from the points' pixel noise alone: %.6f (ground truth unit)\n",
                  predicted.get<double>());
    }
    return {{"alignment", "sim3"},
            {"matched", e.ate.count},
            {"rmse", e.ate.rmse},
            {"mean", e.ate.mean},
            {"median", e.ate.median},
            {"max", e.ate.max},
            {"rpe_translation_rmse", e.rpe_translation_stats.rmse},
            {"predicted_from_pixel_noise", predicted}};
  } catch (const TrajectoryEvaluationError& e) {
    std::printf("init ATE: not computed: %s\n", e.what());
    return {{"problem", e.what()}};
  }
}

}  // namespace curvesfm
