#include "apps/run_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/config_file.h"
#include "apps/cli/initialisation_output.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/report_json.h"
#include "core/check.h"
#include "core/clock.h"
#include "core/colmap_model.h"
#include "core/curve_export.h"
#include "core/dataset_io.h"
#include "core/errors.h"
#include "core/heap_policy.h"
#include "core/median.h"
#include "core/parallel.h"
#include "core/peak_memory.h"
#include "core/trajectory_evaluation.h"
#include "core/tum_dataset.h"
#include "frontend/mapping/start_model.h"

namespace curvesfm {

// The images of a run with their initial poses, wherever those came from.
struct RunInput {
  ImageSequence sequence;
  std::string init_poses_source;  // A file, a COLMAP model, or "initialiser".
  std::vector<DatasetFrame> frames;
  std::optional<PointInitialisation> initialisation;  // When the initialiser ran.
  // Per frame, the initialiser's points it sees (the hybrid graph's input); empty otherwise.
  std::vector<std::vector<PointSighting>> sightings;
  // Per frame, the pose the frontend works at (--diagnose-frontend-poses); empty otherwise.
  std::vector<Pose3> frontend_poses;
};

namespace {

namespace fs = std::filesystem;

std::string joinPath(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

// ---------------------------------------------------------------------------------------------
// Run.

void printProgress(const KeyframeStats& s, int frames) {
  std::printf(
      "frame %d/%d keyframe %d: curves %d global / %d temporary, registered %d (rejected %d: "
      "%d duplicate, %d edge distance, %d appearance, %d other), new %d, extended %d, "
      "frontend %.0f ms, local BA %.0f ms\n",
      s.frame_index + 1, frames, s.keyframe_index, s.global_curves, s.temporary_curves,
      s.registered_segments, s.rejectedSegments(), s.rejected_duplicate, s.rejected_edge_distance,
      s.rejected_appearance, s.rejected_depth + s.rejected_viewing_direction, s.new_curves,
      s.extended_curves, 1e3 * s.frontendSeconds(), 1e3 * s.local_ba_seconds);
  std::fflush(stdout);
}

// Loads the keyframes' images and runs their image stage (Pipeline::prepareImage), with
// `ahead` one keyframe ahead on a second thread: keyframe k + 1's image stage then runs while
// keyframe k's depth search, correspondence and local BA do (mostly beside the first two, which
// take about as long), since it depends on the image alone. Only the
// keyframes' images are read (selectKeyframes).
class KeyframeImageFeed {
 public:
  KeyframeImageFeed(const Pipeline& pipeline, const RunInput& input, std::vector<bool> keyframes,
                    bool ahead)
      : pipeline_(pipeline), input_(input), keyframes_(std::move(keyframes)), ahead_(ahead) {
    if (ahead_) startAfter(-1);
  }

  /// The image stage of frame i, which must be the next keyframe.
  std::shared_ptr<const KeyframeImage> take(int i) {
    if (!ahead_) return prepare(i);
    const Clock::time_point start = Clock::now();
    CURVESFM_CHECK(next_frame_ == i) << "frame " << i << " taken out of order";
    std::shared_ptr<const KeyframeImage> image = next_.get();  // Rethrows a failed load.
    wait_seconds_ += secondsSince(start);
    startAfter(i);
    return image;
  }
  /// Time spent waiting for a keyframe's image stage run ahead (s).
  double waitSeconds() const { return wait_seconds_; }

 private:
  std::shared_ptr<const KeyframeImage> prepare(int i) const {
    const cv::Mat image = loadFrameImage(input_.frames[i], input_.sequence.camera);
    return std::make_shared<const KeyframeImage>(pipeline_.prepareImage(image));
  }
  void startAfter(int i) {
    next_frame_ = i + 1;
    while (next_frame_ < static_cast<int>(keyframes_.size()) && !keyframes_[next_frame_]) {
      ++next_frame_;
    }
    if (next_frame_ == static_cast<int>(keyframes_.size())) return;
    next_ = std::async(std::launch::async, [this, frame = next_frame_] { return prepare(frame); });
  }

  const Pipeline& pipeline_;
  const RunInput& input_;
  const std::vector<bool> keyframes_;
  const bool ahead_;
  int next_frame_ = -1;
  std::future<std::shared_ptr<const KeyframeImage>> next_;
  double wait_seconds_ = 0.0;
};

std::vector<Pose3> initialPoses(const RunInput& input) {
  std::vector<Pose3> poses;
  for (const DatasetFrame& frame : input.frames) poses.push_back(frame.initial_cam_from_world);
  return poses;
}

// Whether the image stage runs ahead on a thread of its own: `setting` true or false, or auto:
// when the process has a core beyond the threads of a keyframe's own stages (depth search,
// registration, local BA). On two cores with --threads 2 the stage ahead only shared the cores:
// its stages took 27-30 ms a kitchen keyframe against 20-26 on the main thread, for the same run
// time within noise (docs/benchmarks.md, sessions 42 and 43).
bool imagesAhead(const std::string& setting, const PipelineOptions& options) {
  if (setting != "auto") return setting == "true";
  const int keyframe_threads = std::max({options.depth.num_threads, options.registration_threads,
                                         options.local_ba.optimizer.num_threads});
  return availableCores() > keyframe_threads;
}

// Feeds every frame with an initial pose to the pipeline; returns the time spent waiting for
// the image stage of keyframes prepared ahead (s).
double feedFrames(Pipeline* pipeline, const RunInput& input,
                  const std::vector<Pose3>& frontend_poses, const PipelineOptions& options,
                  bool images_ahead) {
  const int n = static_cast<int>(input.frames.size());
  if (input.initialisation) {
    std::vector<Eigen::Vector3d> points;
    for (const InitialisedPoint& p : input.initialisation->points) points.push_back(p.position);
    pipeline->setPoints(std::move(points));
  }
  const std::vector<bool> keyframes = selectKeyframes(initialPoses(input), options);
  KeyframeImageFeed images(*pipeline, input, keyframes, images_ahead);
  for (int i = 0; i < n; ++i) {
    const DatasetFrame& frame = input.frames[i];
    const KeyframeStats s = pipeline->addFrame(
        {frame.timestamp, cv::Mat(), frame.initial_cam_from_world,
         input.sightings.empty() ? std::vector<PointSighting>{} : input.sightings[i],
         frontend_poses.empty() ? std::optional<Pose3>() : frontend_poses[i],
         keyframes[i] ? images.take(i) : nullptr});
    if (s.keyframe_index >= 0) printProgress(s, n);
  }
  return images.waitSeconds();
}

// Per frame of `input`, the pose a relift pass lifts its map at: the keyframe's refined pose in
// `previous`, else the pose the previous pass worked at (the keyframes are chosen on the initial
// poses, so every pass has the same ones and the other frames only pass through).
std::vector<Pose3> reliftPoses(const RunInput& input, const std::vector<Pose3>& previous_frontend,
                               const PipelineResult& previous) {
  std::map<double, Pose3> refined;
  for (std::size_t k = 0; k < previous.keyframe_timestamps.size(); ++k) {
    refined.emplace(previous.keyframe_timestamps[k], previous.keyframe_cam_from_world[k]);
  }
  std::vector<Pose3> poses;
  for (std::size_t i = 0; i < input.frames.size(); ++i) {
    const auto it = refined.find(input.frames[i].timestamp);
    if (it != refined.end()) {
      poses.push_back(it->second);
    } else {
      poses.push_back(previous_frontend.empty() ? input.frames[i].initial_cam_from_world
                                                : previous_frontend[i]);
    }
  }
  return poses;
}

// ATE (Sim(3)) of the initial and refined keyframe trajectories, when there is a ground truth.
struct AteResult {
  std::optional<TrajectoryEvaluation> initial, refined;
  std::string problem;  // Why they are missing, if they are.
};

AteResult evaluateAte(const PipelineResult& r, const ImageSequence& d) {
  AteResult ate;
  if (d.ground_truth.empty()) return ate;
  try {
    const TrajectoryEvaluationOptions options;  // Sim(3), 0.02 s.
    ate.initial =
        compareTrajectories(stampedPoses(r.keyframe_timestamps, r.keyframe_initial_cam_from_world),
                            d.ground_truth, options, "initial keyframes", d.ground_truth_source);
    ate.refined =
        compareTrajectories(stampedPoses(r.keyframe_timestamps, r.keyframe_cam_from_world),
                            d.ground_truth, options, "refined keyframes", d.ground_truth_source);
  } catch (const TrajectoryEvaluationError& e) {
    ate.problem = e.what();
  }
  return ate;
}

void printReliftPass(int pass, int passes, const AteResult& ate) {
  if (ate.refined) {
    std::printf("relift %d of %d: lifting the curves again at the refined poses (ATE %.6f)\n", pass,
                passes, ate.refined->ate.rmse);
  } else {
    std::printf("relift %d of %d: lifting the curves again at the refined poses\n", pass, passes);
  }
  std::fflush(stdout);
}

// How far one stage moved the keyframe poses from the start (Sim(3)-aligned camera centres, pose
// units), and their ATE against the ground truth then (NaN without one).
struct StageMotion {
  std::string name;
  double moved_rmse = 0.0;
  double ate_rmse = std::nan("");
};

std::vector<StageMotion> stageMotions(const PipelineResult& r, const ImageSequence& d) {
  std::vector<StageMotion> motions;
  if (r.keyframe_timestamps.size() < 3) return motions;
  const TrajectoryEvaluationOptions options;  // Sim(3), 0.02 s.
  const std::vector<StampedPose> start =
      stampedPoses(r.keyframe_timestamps, r.keyframe_initial_cam_from_world);
  for (const PoseStage& stage : r.pose_stages) {
    const std::vector<StampedPose> poses =
        stampedPoses(r.keyframe_timestamps, stage.keyframe_cam_from_world);
    StageMotion m{stage.name};
    try {
      m.moved_rmse = compareTrajectories(poses, start, options, stage.name, "start").ate.rmse;
      if (!d.ground_truth.empty()) {
        m.ate_rmse =
            compareTrajectories(poses, d.ground_truth, options, stage.name, d.ground_truth_source)
                .ate.rmse;
      }
    } catch (const TrajectoryEvaluationError&) {
      continue;  // The final ATE reports the problem.
    }
    motions.push_back(m);
  }
  return motions;
}

nlohmann::json stageMotionsJson(const std::vector<StageMotion>& motions, double scene_scale) {
  nlohmann::json stages = nlohmann::json::array();
  for (const StageMotion& m : motions) {
    nlohmann::json stage;
    stage["stage"] = m.name;
    stage["moved_rmse"] = m.moved_rmse;
    stage["moved_in_scene_scale"] =
        scene_scale > 0.0 ? nlohmann::json(m.moved_rmse / scene_scale) : nlohmann::json();
    stage["ate_rmse"] = std::isnan(m.ate_rmse) ? nlohmann::json() : nlohmann::json(m.ate_rmse);
    stages.push_back(stage);
  }
  return stages;
}

void printStageMotions(const std::vector<StageMotion>& motions) {
  if (motions.empty()) return;
  std::printf("poses moved from the start (Sim(3) rmse, pose units)");
  for (const StageMotion& m : motions) {
    std::printf("%s %s %.4g", &m == &motions.front() ? ":" : ",", m.name.c_str(), m.moved_rmse);
    if (!std::isnan(m.ate_rmse)) std::printf(" (ATE %.4g)", m.ate_rmse);
  }
  std::printf("\n");
}

// ---------------------------------------------------------------------------------------------
// Per-curve statistics (issue 14's diagnosis).

void writeCurveStatisticsCsv(const std::string& path, const std::vector<CurveStatistics>& stats,
                             const std::vector<bool>& exported) {
  std::ofstream out(path);
  if (!out) throw IoError(path, "cannot open for writing");
  out << "curve,first_keyframe,keyframes,observations,length,median_camera_distance,"
         "triangulation_angle_deg,residual_rms_px,pose_pull,pose_pull_share,last_keyframe,"
         "worst_keyframe,chord_ratio,epipolar_angle_deg,exported\n";
  for (std::size_t c = 0; c < stats.size(); ++c) {
    const CurveStatistics& s = stats[c];
    out << c << "," << s.first_keyframe << "," << s.keyframes << "," << s.observations << ","
        << s.length << "," << s.median_camera_distance << "," << s.triangulation_angle_deg << ","
        << s.residual_rms_px << "," << s.pose_pull << "," << s.pose_pull_share << ","
        << s.last_keyframe << "," << s.worst_keyframe << "," << s.chord_ratio << ","
        << s.epipolar_angle_deg << "," << (exported[c] ? 1 : 0) << "\n";
  }
  if (!out) throw IoError(path, "cannot write");
}

// The curves written to curves.obj and curves.ply: those whose depth along themselves their views
// observe (CurveStatistics::epipolar_angle_deg at least min_epipolar_angle_deg). The others
// still held the poses in the BA, across their edges, but where along their views' rays they lie
// is the lifting's guess: on the 200-frame synthetic walk they were most of the map's length off
// the true curves (docs/benchmarks.md).
struct CurveExport {
  std::vector<PolyBezier> curves;
  std::vector<std::size_t> ids;  ///< Each exported curve's index in the map (and curves.csv).
  std::vector<bool> flags;       ///< Per curve of the map: exported.
};

CurveExport selectExportedCurves(const std::vector<PolyBezier>& curves,
                                 const std::vector<CurveStatistics>& stats,
                                 double min_epipolar_angle_deg) {
  CURVESFM_CHECK(curves.size() == stats.size())
      << stats.size() << " curve statistics for " << curves.size() << " curves";
  CurveExport exported;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const bool observed = stats[c].epipolar_angle_deg >= min_epipolar_angle_deg;
    exported.flags.push_back(observed);
    if (!observed) continue;
    exported.curves.push_back(curves[c]);
    exported.ids.push_back(c);
  }
  return exported;
}

void printExport(const CurveExport& exported, std::size_t map_curves, double min_angle_deg) {
  if (map_curves == 0) return;
  std::printf(
      "export: %zu of %zu curves in curves.obj and curves.ply; %zu run within %.3g deg of their "
      "views' epipolar planes, their depth along themselves unobserved (curves.csv: exported 0; "
      "--export-min-epipolar-angle)\n",
      exported.ids.size(), map_curves, map_curves - exported.ids.size(), min_angle_deg);
}

// The worst curves of `ranking`, as JSON (index into curves.obj / curves.csv).
nlohmann::json worstCurvesJson(const std::vector<CurveStatistics>& stats, CurveRanking ranking) {
  nlohmann::json worst = nlohmann::json::array();
  for (std::size_t c : worstCurves(stats, ranking, kWorstCurvesListed)) {
    const CurveStatistics& s = stats[c];
    worst.push_back({{"curve", c},
                     {"first_keyframe", s.first_keyframe},
                     {"last_keyframe", s.last_keyframe},
                     {"worst_keyframe", s.worst_keyframe},
                     {"keyframes", s.keyframes},
                     {"length", s.length},
                     {"chord_ratio", s.chord_ratio},
                     {"epipolar_angle_deg", s.epipolar_angle_deg},
                     {"median_camera_distance", s.median_camera_distance},
                     {"triangulation_angle_deg", s.triangulation_angle_deg},
                     {"residual_rms_px", s.residual_rms_px},
                     {"pose_pull_share", s.pose_pull_share}});
  }
  return worst;
}

// Upper median of the curves' track lengths (keyframes observing them); 0 without curves.
int medianTrackKeyframes(const std::vector<CurveStatistics>& stats) {
  std::vector<double> keyframes;
  for (const CurveStatistics& s : stats) keyframes.push_back(s.keyframes);
  return keyframes.empty() ? 0 : static_cast<int>(upperMedian(keyframes));
}

// A curve whose chords shrank below this fraction of their lengths at creation counts as
// collapsed in the summary: a point on an edge, which fits any view (docs/benchmarks.md).
constexpr double kCollapsedChordRatio = 0.1;

// Fraction of the curves whose chord ratio is below kCollapsedChordRatio; 0 without curves.
double collapsedFraction(const std::vector<CurveStatistics>& stats) {
  if (stats.empty()) return 0.0;
  const auto collapsed = std::count_if(stats.begin(), stats.end(), [](const CurveStatistics& s) {
    return s.chord_ratio < kCollapsedChordRatio;
  });
  return static_cast<double>(collapsed) / static_cast<double>(stats.size());
}

nlohmann::json curveStatisticsJson(const std::vector<CurveStatistics>& stats) {
  std::vector<double> ratios;
  for (const CurveStatistics& s : stats) ratios.push_back(s.chord_ratio);
  return {{"file", "curves.csv"},
          {"median_track_keyframes", medianTrackKeyframes(stats)},
          {"median_chord_ratio", ratios.empty() ? 0.0 : upperMedian(ratios)},
          {"collapsed_fraction", collapsedFraction(stats)},
          {"most_pull", worstCurvesJson(stats, CurveRanking::kPull)},
          {"highest_residual", worstCurvesJson(stats, CurveRanking::kResidual)}};
}

// One line: the residual spread and how concentrated the pull on the poses is.
void printCurveStatistics(const std::vector<CurveStatistics>& stats) {
  if (stats.empty()) return;
  std::vector<double> residuals;
  std::vector<double> shares;
  for (const CurveStatistics& s : stats) {
    residuals.push_back(s.residual_rms_px);
    shares.push_back(s.pose_pull_share);
  }
  std::sort(residuals.begin(), residuals.end());
  std::sort(shares.rbegin(), shares.rend());
  const std::size_t top = std::min<std::size_t>(10, shares.size());
  const double top_share = std::accumulate(shares.begin(), shares.begin() + top, 0.0);
  std::printf(
      "curves: track median %d keyframes; residual rms median %.2f px, 90th percentile %.2f px; "
      "the %zu curves pulling the poses most hold %.0f %% of the pull; %.0f %% collapsed (chords "
      "below %.1f of their lengths at creation) (curves.csv, report.json curve_statistics)\n",
      medianTrackKeyframes(stats), residuals[residuals.size() / 2],
      residuals[residuals.size() * 9 / 10], top, 100.0 * top_share,
      100.0 * collapsedFraction(stats), kCollapsedChordRatio);
}

// ---------------------------------------------------------------------------------------------
// Output.

OverlayScene overlayScene(const Pipeline& pipeline, const PipelineResult& r) {
  OverlayScene scene{
      pipeline.undistortedCamera(), {}, r.keyframe_cam_from_world, r.curves, r.curve_statistics};
  for (std::size_t k = 0; k < r.keyframe_cam_from_world.size(); ++k) {
    scene.keyframe_images.push_back(pipeline.keyframeImage(static_cast<int>(k)));
  }
  return scene;
}

nlohmann::json frameToJson(const KeyframeStats& s) {
  return {
      {"frame_index", s.frame_index},
      {"keyframe_index", s.keyframe_index},
      {"timestamp", s.timestamp},
      {"seconds",
       {{"undistort", s.undistort_seconds},
        {"edges", s.edges_seconds},
        {"field", s.field_seconds},
        {"depth", s.depth_seconds},
        {"correspondence", s.correspondence_seconds},
        {"initialise", s.initialise_seconds},
        {"frontend", s.frontendSeconds()},
        {"local_ba", s.local_ba_seconds}}},
      {"edge_pixels", s.edge_pixels},
      {"canny_thresholds", {{"high", s.canny_high_threshold}, {"low", s.canny_low_threshold}}},
      {"chains", s.chains},
      {"valid_depths", s.valid_depths},
      {"registered_segments", s.registered_segments},
      {"rejected_segments",
       {{"total", s.rejectedSegments()},
        {"duplicate", s.rejected_duplicate},
        {"depth", s.rejected_depth},
        {"edge_distance", s.rejected_edge_distance},
        {"viewing_direction", s.rejected_viewing_direction},
        {"appearance", s.rejected_appearance}}},
      {"new_curves", s.new_curves},
      {"extended_curves", s.extended_curves},
      {"global_curves", s.global_curves},
      {"temporary_curves", s.temporary_curves},
      {"local_ba_cost", {{"initial", s.local_ba_initial_cost}, {"final", s.local_ba_final_cost}}},
      {"local_ba_iterations", s.local_ba_iterations}};
}

// The first and the last solve a schedule ran (its skipped phases aside); nullptr if none ran.
const ScheduleRound* firstSolvedRound(const ScheduleReport& report) {
  const auto solved = std::find_if(report.rounds.begin(), report.rounds.end(),
                                   [](const ScheduleRound& round) { return !round.skipped; });
  return solved == report.rounds.end() ? nullptr : &*solved;
}
const ScheduleRound* lastSolvedRound(const ScheduleReport& report) {
  const auto solved = std::find_if(report.rounds.rbegin(), report.rounds.rend(),
                                   [](const ScheduleRound& round) { return !round.skipped; });
  return solved == report.rounds.rend() ? nullptr : &*solved;
}

// Costs per factor type before the first and after the last solve of global BA.
nlohmann::json globalCostsToJson(const ScheduleReport& report) {
  const ScheduleRound* first = firstSolvedRound(report);
  if (!first) return nlohmann::json::object();
  return {{"initial", costsToJson(first->summary.initial_cost_by_type)},
          {"final", costsToJson(lastSolvedRound(report)->summary.final_cost_by_type)}};
}

// The costs per factor type after the run's last BA (the re-association rounds' last, else the
// first global BA): the fit its poses and map end at. Per curve observation it tells which of
// several starts of one set the images agree with best; across sets it means little.
std::map<std::string, FactorTypeCost> finalFit(const PipelineResult& result) {
  const ScheduleRound* last = lastSolvedRound(
      result.reassociation.empty() ? result.global_ba : result.reassociation.back().global_ba);
  return last ? last->summary.final_cost_by_type : std::map<std::string, FactorTypeCost>();
}

void printFinalFit(const std::map<std::string, FactorTypeCost>& fit) {
  const auto curves = fit.find("curve_reprojection");  // CurveReprojectionFactor::typeName()
  if (curves == fit.end() || curves->second.count == 0) return;
  std::printf(
      "fit: curve cost %.4f per observation over %d observations after the last global BA (lower "
      "means the images agree better; it compares starts of one set, report.json final_fit)\n",
      curves->second.cost / curves->second.count, curves->second.count);
}

// The ATE that the curves' edge noise alone would leave, in the poses' unit and, with a ground
// truth, in its unit through the refined trajectory's alignment scale.
void printCurvePrecision(const std::optional<CurveCentrePrecision>& precision,
                         const AteResult& ate) {
  if (!precision) return;
  std::printf(
      "curves' precision: their edge noise, %.3f px per sample (%d samples of %d observations, "
      "lag-1 correlation %.2f), alone would leave the centres an ATE of %.3g (samples independent) "
      "to %.3g (correlated along each observation) in the poses' unit",
      precision->pixel_sigma, precision->samples, precision->observations,
      precision->sample_correlation, precision->predicted_centre_ate,
      precision->predicted_centre_ate_correlated);
  if (ate.refined) {
    const double scale = ate.refined->ground_truth_from_estimate.scale;
    std::printf(", %.3g to %.3g in the ground truth's", scale * precision->predicted_centre_ate,
                scale * precision->predicted_centre_ate_correlated);
  }
  std::printf(" (a floor: no bias, no wrong edge; %.1f s; report.json curve_precision)\n",
              precision->seconds);
}

nlohmann::json curvePrecisionJson(const std::optional<CurveCentrePrecision>& precision) {
  if (!precision) return nullptr;
  // JSON has no infinity: curves that leave a centre free say so in words.
  const auto ate = [](double value) -> nlohmann::json {
    return std::isinf(value) ? nlohmann::json("infinite") : nlohmann::json(value);
  };
  return {{"observations", precision->observations},
          {"samples", precision->samples},
          {"pixel_sigma", precision->pixel_sigma},
          {"sample_correlation", precision->sample_correlation},
          {"predicted_centre_ate", ate(precision->predicted_centre_ate)},
          {"predicted_centre_ate_correlated", ate(precision->predicted_centre_ate_correlated)},
          {"seconds", precision->seconds}};
}

nlohmann::json ateToJson(const AteResult& ate) {
  const auto stats = [](const std::optional<TrajectoryEvaluation>& e) -> nlohmann::json {
    if (!e) return nullptr;
    const ErrorStatistics& s = e->ate;
    return {{"matched", s.count}, {"rmse", s.rmse},
            {"mean", s.mean},     {"median", s.median},
            {"std", s.std},       {"min", s.min},
            {"max", s.max},       {"scale", e->ground_truth_from_estimate.scale}};
  };
  nlohmann::json per_pose = nullptr;
  if (ate.initial && ate.refined) {
    per_pose = {{"initial", matchedPosesToJson(*ate.initial)},
                {"refined", matchedPosesToJson(*ate.refined)}};
  }
  return {{"alignment", "sim3"},
          {"initial_m", stats(ate.initial)},
          {"refined_m", stats(ate.refined)},
          {"per_pose", per_pose},
          {"problem", ate.problem}};
}

void writeConfigYaml(const std::string& path, const CLI::App& command) {
  std::ofstream out(path);
  if (!(out << "# curvesfm run: the options in force; rerun with --config " << path << "\n"
            << effectiveOptionsYaml(command))) {
    throw IoError(path, "cannot write");
  }
}

void printAte(const AteResult& ate, const std::string& ground_truth_path) {
  if (ate.initial && ate.refined) {
    std::printf(
        "ATE (sim3) vs %s over %d keyframes, in its unit: initial rmse %.6f (max %.6f), refined "
        "rmse %.6f (max %.6f)\n",
        ground_truth_path.c_str(), ate.refined->ate.count, ate.initial->ate.rmse,
        ate.initial->ate.max, ate.refined->ate.rmse, ate.refined->ate.max);
  } else if (!ate.problem.empty()) {
    std::printf("ATE: not computed: %s\n", ate.problem.c_str());
  }
}

// The frontend budget is per keyframe; local BA is reported apart. The image stage (undistortion,
// edges, field) runs ahead on its own thread with --images-ahead, so its part is given apart.
void printFrontendStages(const std::vector<KeyframeStats>& frames) {
  const KeyframeTimes t = keyframeTimes(frames);
  if (t.keyframes == 0) return;
  std::printf(
      "frontend per keyframe (mean ms): undistort %.1f, edges %.1f, field %.1f, depth %.1f, "
      "correspondence %.1f, initialise %.1f; total %.1f (image stage %.1f, the rest %.1f), "
      "slowest keyframe %.1f\n",
      t.undistort_ms, t.edges_ms, t.field_ms, t.depth_ms, t.correspondence_ms, t.initialise_ms,
      t.frontend_ms, t.image_stage_ms, t.frontend_ms - t.image_stage_ms, t.slowest_frontend_ms);
}

// A line at most every `interval` seconds of a global BA (re-association rounds included), so
// that a long solve never looks stuck; 0 prints every iteration.
std::function<void(const IterationProgress&)> globalBaProgress(double interval) {
  auto last_printed = std::make_shared<double>(0.0);
  return [interval, last_printed](const IterationProgress& p) {
    if (p.iteration == 0) *last_printed = 0.0;
    if (p.iteration == 0 || p.seconds - *last_printed < interval) return;
    *last_printed = p.seconds;
    std::printf("global BA: iteration %d, cost %.6g, %.1f s\n", p.iteration, p.cost, p.seconds);
    std::fflush(stdout);
  };
}

// How the map grew over a run: curves started, new curves appended to an existing one, and
// the registrations of map segments in later keyframes. Few registrations and many edge-distance
// rejections mean short tracks: a map that keeps each keyframe's pose error instead of averaging
// it (docs/benchmarks.md, "A noisy start over a held map").
struct CurveGrowth {
  int started = 0;
  int extended = 0;
  int registered = 0;
  int rejected = 0;
  int rejected_edge_distance = 0;
};

CurveGrowth curveGrowth(const std::vector<KeyframeStats>& frames) {
  CurveGrowth growth;
  for (const KeyframeStats& s : frames) {
    growth.started += s.new_curves;
    growth.extended += s.extended_curves;
    growth.registered += s.registered_segments;
    growth.rejected += s.rejectedSegments();
    growth.rejected_edge_distance += s.rejected_edge_distance;
  }
  return growth;
}

// image_wait_seconds: the time spent waiting for images prepared ahead, < 0 if none were.
void printSummary(const RunInput& input, const PipelineResult& r, double seconds,
                  double image_wait_seconds) {
  double frontend = 0.0, image_stage = 0.0, local_ba = 0.0;
  for (const KeyframeStats& s : r.frames) {
    frontend += s.frontendSeconds();
    image_stage += s.imageStageSeconds();
    local_ba += s.local_ba_seconds;
  }
  const CurveGrowth growth = curveGrowth(r.frames);
  const CurveSampleCounts& samples = r.final_samples;
  const int images = static_cast<int>(input.sequence.images.size());
  std::printf(
      "run: %zu frames (%d of %d images without an initial pose skipped), %zu keyframes, "
      "%zu curves (%d segments) in the global map\n",
      input.frames.size(), images - static_cast<int>(input.frames.size()), images,
      r.keyframe_cam_from_world.size(), r.curves.size(), totalSegments(r.curves));
  std::printf(
      "map: %d curves started, %d new curves appended to an existing curve's end; %d segment "
      "registrations in later keyframes, %d rejected (%d for edge distance)\n",
      growth.started, growth.extended, growth.registered, growth.rejected,
      growth.rejected_edge_distance);
  if (!r.global_ba.rounds.empty()) {
    std::printf("global BA: cost %.6g -> %.6g, %d iterations, %.2f s (%s)\n",
                r.global_ba.initial_cost, r.global_ba.final_cost, r.global_ba.total_iterations,
                r.global_ba.total_seconds, r.global_ba.stop_reason.c_str());
  }
  for (std::size_t i = 0; i < r.reassociation.size(); ++i) {
    const ScheduleReport& ba = r.reassociation[i].global_ba;
    std::printf(
        "re-association %zu: %d observations added (%d segments left to other curves), global BA "
        "cost %.6g -> %.6g, %.2f s\n",
        i + 1, r.reassociation[i].added_observations, r.reassociation[i].left_to_other_curves,
        ba.initial_cost, ba.final_cost, ba.total_seconds);
  }
  std::printf(
      "samples: %d on field, %d behind camera, %d outside image, %d beyond reach, %d wrong "
      "orientation\n",
      samples.on_field, samples.behind_camera, samples.outside_image, samples.beyond_reach,
      samples.wrong_orientation);
  std::printf(
      "time: frontend %.2f s, local BA %.2f s, global BA %.2f s, total %.2f s; peak memory %.0f "
      "MiB\n",
      frontend, local_ba, r.globalBaSeconds(), seconds, peakResidentMiB());
  if (image_wait_seconds >= 0.0) {
    std::printf(
        "images ahead: the image stage (%.2f s of the frontend) ran on a second thread, each "
        "keyframe's beside the previous keyframe's work; %.2f s waited for it\n",
        image_stage, image_wait_seconds);
  }
  printFrontendStages(r.frames);
}

nlohmann::json reassociationToJson(const std::vector<ReassociationRound>& rounds) {
  nlohmann::json json = nlohmann::json::array();
  for (const ReassociationRound& round : rounds) {
    json.push_back({{"added_observations", round.added_observations},
                    {"left_to_other_curves", round.left_to_other_curves},
                    {"global_ba", scheduleReportToJson(round.global_ba)}});
  }
  return json;
}

nlohmann::json vectorToJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

const char* implausibilityText(CurveImplausibility reason) {
  switch (reason) {
    case CurveImplausibility::kOutsideExtent:
      return "outside the extent";
    case CurveImplausibility::kLongerThanExtent:
      return "longer than the extent";
    case CurveImplausibility::kHighResidual:
      return "residual above the bound";
    case CurveImplausibility::kCollapsed:
      return "chords below the bound";
    case CurveImplausibility::kAlongEpipolar:
      return "along its epipolar planes";
    case CurveImplausibility::kNone:
      break;
  }
  return "plausible";
}

int countImplausible(const RunSanity& s, CurveImplausibility reason) {
  return static_cast<int>(
      std::count_if(s.implausible_curves.begin(), s.implausible_curves.end(),
                    [reason](const ImplausibleCurve& c) { return c.reason == reason; }));
}

nlohmann::json sanityToJson(const RunSanity& s) {
  nlohmann::json extent = nullptr;
  if (s.extent.valid()) {
    extent = {{"min", vectorToJson(s.extent.min)},
              {"max", vectorToJson(s.extent.max)},
              {"diagonal", s.extent.diagonal()},
              {"from", s.extent.source.empty() ? "cameras" : "cameras and " + s.extent.source}};
  }
  nlohmann::json curves = nlohmann::json::array();
  for (const ImplausibleCurve& c : s.implausible_curves) {
    curves.push_back({{"id", c.id},
                      {"segments", c.segments},
                      {"length", c.length},
                      {"reason", toString(c.reason)},
                      {"after_global_bas", c.after_global_bas},
                      {"dropped", c.dropped}});
  }
  nlohmann::json move = nullptr;
  if (s.pose_move.keyframe >= 0) {
    move = {{"keyframe", s.pose_move.keyframe},
            {"distance", s.pose_move.distance},
            {"spacing", s.pose_move.spacing},
            {"spacings", s.pose_move.spacings()}};
  }
  nlohmann::json verdicts = nlohmann::json::array();
  for (const RunVerdict& v : s.verdicts) {
    verdicts.push_back({{"kind", toString(v.kind)}, {"message", v.message}});
  }
  return {{"extent", extent},
          {"counts",
           {{"checked", s.checked_curves},
            {"implausible", s.implausible_curves.size()},
            {"dropped", s.droppedCurves()},
            {"outside_extent", countImplausible(s, CurveImplausibility::kOutsideExtent)},
            {"longer_than_extent", countImplausible(s, CurveImplausibility::kLongerThanExtent)},
            {"high_residual", countImplausible(s, CurveImplausibility::kHighResidual)},
            {"collapsed", countImplausible(s, CurveImplausibility::kCollapsed)},
            {"along_epipolar", countImplausible(s, CurveImplausibility::kAlongEpipolar)}}},
          {"implausible_curves", curves},
          {"largest_pose_move", move},
          {"verdicts", verdicts}};
}

// The sanity lines of the summary: the extent, the implausible curves (the first few listed) and
// the largest pose move, then one "warning:" line per verdict.
void printSanity(const RunSanity& s) {
  constexpr std::size_t kListed = 10;
  if (s.extent.valid()) {
    const Eigen::Vector3d size = s.extent.max - s.extent.min;
    std::printf("sanity: scene extent %.4g x %.4g x %.4g (diagonal %.4g, from the cameras%s%s)",
                size.x(), size.y(), size.z(), s.extent.diagonal(),
                s.extent.source.empty() ? "" : " and the ", s.extent.source.c_str());
  } else {
    std::printf("sanity: no scene extent (too few cameras and points)");
  }
  std::printf(
      "; %zu of %d curves of the global map implausible (%d outside the extent, %d longer than "
      "it, %d above the residual bound, %d below the chord-ratio bound, %d along their epipolar "
      "planes), %d dropped",
      s.implausible_curves.size(), s.checked_curves,
      countImplausible(s, CurveImplausibility::kOutsideExtent),
      countImplausible(s, CurveImplausibility::kLongerThanExtent),
      countImplausible(s, CurveImplausibility::kHighResidual),
      countImplausible(s, CurveImplausibility::kCollapsed),
      countImplausible(s, CurveImplausibility::kAlongEpipolar), s.droppedCurves());
  if (s.pose_move.keyframe >= 0) {
    std::printf("; largest pose move %.3g keyframe spacings (keyframe %d)", s.pose_move.spacings(),
                s.pose_move.keyframe);
  }
  std::printf("\n");
  for (std::size_t i = 0; i < s.implausible_curves.size() && i < kListed; ++i) {
    const ImplausibleCurve& c = s.implausible_curves[i];
    std::printf("  curve %d: %d segments, length %.4g, %s, %s after %d global BA%s\n", c.id,
                c.segments, c.length, implausibilityText(c.reason), c.dropped ? "dropped" : "kept",
                c.after_global_bas, c.after_global_bas == 1 ? "" : "s");
  }
  if (s.implausible_curves.size() > kListed) {
    std::printf("  ... and %zu more (report.json, sanity.implausible_curves)\n",
                s.implausible_curves.size() - kListed);
  }
  for (const RunVerdict& v : s.verdicts) std::printf("warning: %s\n", v.message.c_str());
}

// What the images say about a given start (StartModel); when its poses are off each on its own,
// the BA ties each keyframe to its start (the start prior, at the measured sigmas) instead of
// tying each motion to the start's (the motion prior), unless the start prior was asked for; a
// start so tied runs at most StartModelOptions::reassociation_rounds re-association rounds.
std::optional<StartModelEstimate> readStartModel(const RunInput& input,
                                                 const StartModelOptions& options,
                                                 PipelineOptions* pipeline) {
  if (!options.from_images || !input.initialisation || input.init_poses_source == "initialiser") {
    return std::nullopt;
  }
  const StartModelEstimate e =
      // The initialiser's pixels are those of the undistorted images (ImageUndistorter).
      estimateStartModel(input.sequence.camera.withoutDistortion(), *input.initialisation, options);
  std::printf(
      "start: %s (%d frames registered again on their points move %.3g deg, %.2f x the PnP's own "
      "noise, and %.3g spacings RMS per axis; their rotations' variogram grows %.2f x from lag 1 "
      "to %d)",
      toString(e.model).c_str(), e.frames_measured, e.rotation_rms_deg, e.rotation_to_measurement,
      e.centre_rms_spacings, e.variogram_growth, e.variogram_lag);
  CurveBundleAdjustmentOptions* ba = &pipeline->ba;
  if (tiesEachPose(e, options) && !ba->start_prior) {
    ba->motion_prior = false;
    ba->start_prior = true;
    ba->start_prior_rotation_sigma_deg = options.rotation_prior_sigma_scale * e.rotation_rms_deg;
    // The centre's sigma is relative to the keyframes' spacing, which for every frame a keyframe
    // (the benches) is the frames' one measured here.
    ba->start_prior_centre_sigma_rel =
        std::max(options.prior_sigma_scale * e.centre_rms_spacings, 1e-6);
    if (options.reassociation_rounds >= 0) {
      pipeline->reassociation_rounds =
          std::min(pipeline->reassociation_rounds, options.reassociation_rounds);
    }
    std::printf(
        "; the BA ties each keyframe to its start (start prior %.3g deg, %.3g spacings) "
        "instead of each motion to the start's, and lifts the map again at the refined poses "
        "(--start-model-relift-passes %d), with at most %d re-association rounds a pass "
        "(--start-model-reassociation-rounds)",
        ba->start_prior_rotation_sigma_deg, ba->start_prior_centre_sigma_rel, options.relift_passes,
        pipeline->reassociation_rounds);
  }
  std::printf("\n");
  return e;
}

nlohmann::json startModelJson(const std::optional<StartModelEstimate>& e, bool switched,
                              const CurveBundleAdjustmentOptions& ba) {
  if (!e) return nullptr;
  nlohmann::json json = {{"model", toString(e->model)},
                         {"frames_measured", e->frames_measured},
                         {"rotation_rms_deg", e->rotation_rms_deg},
                         {"centre_rms", e->centre_rms},
                         {"centre_rms_spacings", e->centre_rms_spacings},
                         {"rotation_to_measurement", e->rotation_to_measurement},
                         {"variogram_lag", e->variogram_lag},
                         {"variogram_growth", e->variogram_growth},
                         {"switched_to_start_prior", switched}};
  // The sigmas the switch gave the start prior, in --ba-start-prior-*'s units.
  json["start_prior_rotation_sigma_deg"] =
      switched ? nlohmann::json(ba.start_prior_rotation_sigma_deg) : nlohmann::json(nullptr);
  json["start_prior_centre_sigma_spacings"] =
      switched ? nlohmann::json(ba.start_prior_centre_sigma_rel) : nlohmann::json(nullptr);
  return json;
}

bool globalBaUsable(const ScheduleReport& report) {
  for (const ScheduleRound& round : report.rounds) {
    if (!round.skipped && !round.summary.usable) return false;
  }
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

RunCommand::RunCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "run",
      "Curve structure from motion on a calibrated image sequence in any layout of the README, "
      "from given initial poses or, without them, from the point-based initialiser's: writes "
      "trajectory.txt, trajectory_initial.txt, curves.ply, curves.obj, curves.csv, report.json, "
      "config.yaml and, with --overlays, the curves drawn on each keyframe coloured by a "
      "statistic and the worst curves one by one; `curvesfm report` draws them.");
  addConfigFlag(command_);
  CLI::App* c = command_;
  c->add_option("--dataset", dataset_dir_,
                "Dataset folder in any layout of the README (TUM: rgb.txt, camera.yaml, optional "
                "groundtruth.txt and init_poses.txt)")
      ->required();
  c->add_option("--out", out_dir_, "Output folder (created if needed)")->required();
  c->add_option("--init-poses", init_poses_path_,
                "Initial poses: a TUM file 'timestamp tx ty tz qx qy qz qw' (camera-to-world) or a "
                "COLMAP model folder; default DATASET/init_poses.txt, else the point initialiser");
  c->add_option("--max-dt", max_dt_,
                "Largest time difference between an image and its initial pose (s)")
      ->capture_default_str();
  c->add_option("--points-at-given-poses", points_at_given_poses_,
                "With given initial poses, triangulate the initialiser's tracks at them (points "
                "for the depth ranges and --ba-points)")
      ->capture_default_str();
  c->add_option("--images-ahead", images_ahead_,
                "Load and prepare the next keyframe's image (undistortion, edges, field) on a "
                "second thread while this one's depth search, correspondence and local BA run: "
                "true, false, or auto (when the process has more cores than those stages' "
                "threads); the results are the same")
      ->check(CLI::IsMember({"auto", "true", "false"}))
      ->capture_default_str();
  c->add_option("--diagnose-frontend-poses", frontend_poses_path_,
                "Diagnosis: lift and register curves at these poses (TUM or COLMAP model, in the "
                "initial poses' frame and unit, e.g. the ground truth beside a perturbed copy of "
                "it), then start global BA from the initial poses");
  c->add_option("--relift-passes", relift_passes_,
                "After the run, this many more, each lifting and registering the curves again at "
                "the previous one's refined poses, with BA started from and its priors tied to "
                "the initial poses (each pass costs a run; a start the images call off per pose "
                "gets at least --start-model-relift-passes)")
      ->capture_default_str();
  c->add_flag("--overlays", overlays_,
              "Write OUT/overlays/NNNNNN.png, the final curves drawn on keyframe NNNNNN coloured "
              "by --overlay-colour-by with a legend, and OUT/worst_curves/: the 10 curves of "
              "highest residual and the 10 pulling the poses most, each highlighted on the "
              "keyframe where its residual is largest, indexed in worst_curves.md");
  c->add_option("--export-samples", export_samples_per_segment_,
                "Samples per segment of the curves in curves.ply and curves.obj")
      ->capture_default_str();
  c->add_option("--export-min-epipolar-angle", export_min_epipolar_angle_deg_,
                "curves.ply and curves.obj hold only the curves whose median sample runs at least "
                "this far out of their views' epipolar planes (deg; the others' depth along "
                "themselves is unobserved; they stay in the BA and in curves.csv; 0: all)")
      ->capture_default_str();
  c->add_option("--progress-interval", progress_interval_s_,
                "Seconds between the progress lines of a global BA (0: one per iteration)")
      ->capture_default_str();
  addImageSequenceOptions(&table_, &sequence_);
  addPointInitialiserOptions(&table_, &initialiser_, "/points");
  addStartModelOptions(&table_, &start_model_, "/start_model");
  addPipelineOptions(&table_, &options_, "/pipeline");
  const OptionPlace overlay_place{"/overlay", "overlay-", "Overlays", ""};
  addCurveOverlayOptions(&table_, &overlay_, overlay_place);
  addOverlayColouringOptions(&table_, &overlay_colouring_, overlay_place);
  table_.addFlags(c);
}

void RunCommand::validate() const {
  table_.validate();
  // The run's own flags, named as the user types them.
  const OptionCheck require("RunCommand");
  require(export_samples_per_segment_ >= 1 && export_samples_per_segment_ <= 1000, "export-samples",
          export_samples_per_segment_, "in [1, 1000]");
  require(export_min_epipolar_angle_deg_ >= 0.0 && export_min_epipolar_angle_deg_ < 90.0,
          "export-min-epipolar-angle", export_min_epipolar_angle_deg_, "in [0, 90)");
  require(max_dt_ >= 0.0 && max_dt_ < 1e6, "max-dt", max_dt_, "finite and >= 0");
  require(relift_passes_ >= 0 && relift_passes_ <= 100, "relift-passes", relift_passes_,
          "in [0, 100]");
  require(progress_interval_s_ >= 0.0 && progress_interval_s_ < 1e6, "progress-interval",
          progress_interval_s_, "finite and >= 0");
}

nlohmann::json RunCommand::runOptionsJson() const {
  nlohmann::json options = table_.toJson();
  options["export_samples_per_segment"] = export_samples_per_segment_;
  options["export_min_epipolar_angle_deg"] = export_min_epipolar_angle_deg_;
  options["max_dt"] = max_dt_;
  options["progress_interval_s"] = progress_interval_s_;
  options["points_at_given_poses"] = points_at_given_poses_;
  options["diagnose_frontend_poses"] = frontend_poses_path_;
  options["relift_passes"] = relift_passes_;
  options["images_ahead"] = images_ahead_;
  return options;
}

// The --diagnose-frontend-poses pose of every frame of `input`, matched by timestamp as the
// initial poses are; IoError naming the file if a frame has none.
std::vector<Pose3> RunCommand::frontendPoses(const RunInput& input) const {
  std::string source;
  const std::vector<StampedPose> poses =
      readInitialPoses(frontend_poses_path_, input.sequence, &source);
  std::map<std::string, Pose3> by_image;
  for (const DatasetFrame& f : framesWithPoses(input.sequence, poses, max_dt_, source)) {
    by_image.emplace(f.image_path, f.initial_cam_from_world);
  }
  std::vector<Pose3> frontend;
  for (const DatasetFrame& f : input.frames) {
    const auto it = by_image.find(f.image_path);
    if (it == by_image.end()) {
      throw IoError(frontend_poses_path_, "has no pose within --max-dt of image " + f.image_path);
    }
    frontend.push_back(it->second);
  }
  return frontend;
}

namespace {

// " (gate G px[, S x their median error M px])": how the points at given poses were gated.
std::string gateText(const PointInitialisation& points, double gate_scale) {
  char text[160];
  if (points.given_poses_median_error_px > 0.0) {
    std::snprintf(text, sizeof(text), " (gate %.3g px, %.3g x their median error %.3g px)",
                  points.given_poses_gate_px, gate_scale, points.given_poses_median_error_px);
  } else {
    std::snprintf(text, sizeof(text), " (gate %.3g px)", points.given_poses_gate_px);
  }
  return text;
}

// "P % of the observations descriptor keypoints, median diameter D px": those
// --ba-keypoint-sigma weighs, and the size --ba-keypoint-reference-size compares with.
std::string keypointShareText(const std::vector<std::vector<PointSighting>>& sightings) {
  std::size_t all = 0;
  std::vector<double> sizes;
  for (const std::vector<PointSighting>& frame : sightings) {
    for (const PointSighting& s : frame) {
      ++all;
      if (s.keypoint) sizes.push_back(s.keypoint_size);
    }
  }
  char text[120];
  const int length =
      std::snprintf(text, sizeof(text), "%.0f %% of the observations descriptor keypoints",
                    all > 0 ? 100.0 * sizes.size() / all : 0.0);
  if (!sizes.empty()) {
    std::snprintf(text + length, sizeof(text) - length, ", median diameter %.1f px",
                  upperMedian(sizes));
  }
  return text;
}

}  // namespace

RunInput RunCommand::loadInput() const {
  RunInput input;
  std::optional<FallbackCamera> model_camera;
  if (!init_poses_path_.empty() && fs::is_directory(init_poses_path_)) {
    model_camera = colmapModelCamera(init_poses_path_);
  }
  input.sequence = loadImageSequence(dataset_dir_, sequence_, model_camera);
  const std::vector<StampedPose> poses =
      readInitialPoses(init_poses_path_, input.sequence, &input.init_poses_source);
  if (!poses.empty()) {
    if (initialiser_.ba.refine_focal) {
      std::printf(
          "run: note: --points-ba-refine-focal does nothing with given poses (they hold the "
          "camera given; only the initialiser's own reconstruction refines it)\n");
    }
    input.frames = framesWithPoses(input.sequence, poses, max_dt_, input.init_poses_source);
    if (!frontend_poses_path_.empty()) input.frontend_poses = frontendPoses(input);
    if (points_at_given_poses_ && input.frames.size() >= 2) {
      std::printf("run: triangulating the tracks of the %zu images at the given poses\n",
                  input.sequence.images.size());
      input.initialisation = triangulateAtPoses(input.sequence, input.frames, initialiser_);
      input.sightings = sightingsOfFrames(input.sequence, input.frames, *input.initialisation);
      const ReprojectionSummary& reprojection = input.initialisation->reprojection;
      std::string seen = std::to_string(input.initialisation->points.size()) + " points from " +
                         std::to_string(input.initialisation->num_tracks) +
                         " tracks at the given poses" +
                         gateText(*input.initialisation, initialiser_.given_poses_gate_scale);
      if (reprojection.observations > 0) seen += "; " + reprojectionLine(reprojection);
      seen += "; " + keypointShareText(input.sightings);
      std::printf("run: %s\n", seen.c_str());
    }
    return input;
  }
  if (!frontend_poses_path_.empty()) {
    // The initialiser's frame and unit are its own: poses given beside it would not match.
    throw InvalidOptions("run", "diagnose-frontend-poses", frontend_poses_path_,
                         "needs initial poses in the same frame (--init-poses or "
                         "DATASET/init_poses.txt), not the point initialiser's")
        .withFlag("diagnose-frontend-poses");
  }
  std::printf(
      "run: no initial poses (no --init-poses, no %s/init_poses.txt): running the point "
      "initialiser on the %zu images first\n",
      dataset_dir_.c_str(), input.sequence.images.size());
  input.init_poses_source = "initialiser";
  input.initialisation = initialiseSequence(input.sequence, initialiser_);
  printInitialisationSummary(input.sequence, *input.initialisation);
  // The poses and points hold the camera the initialiser refined: so must the curves.
  input.sequence.camera = input.sequence.camera.withFocalScale(input.initialisation->focal_scale);
  input.frames = initialisedFrames(input.sequence, *input.initialisation);
  input.sightings = initialisedSightings(*input.initialisation);
  return input;
}

struct RunCommand::Outcome {
  std::unique_ptr<Pipeline> pipeline;  // The last pass's, for its camera and overlays.
  PipelineResult result;
  PipelineOptions options;  // As run: the start model may have tied the start per pose.
  std::optional<StartModelEstimate> start_model;
  bool tied_start = false;
  int relift_passes = 0;
  bool images_ahead = false;  // --images-ahead as resolved for this run.
  double image_wait_seconds = 0.0;
};

struct RunCommand::Evaluation {
  AteResult ate;
  std::vector<StageMotion> motions;
  std::map<std::string, FactorTypeCost> fit;  // The images' agreement: cost per observation.
};

struct RunCommand::Written {
  CurveExport exported;
  int overlays = 0;
  int worst_curve_images = 0;
};

namespace {

// The process's exit status: 1 when nothing plausible was reconstructed or a global BA failed,
// each with one line on stderr after the summary.
int exitStatus(const PipelineResult& result) {
  std::fflush(stdout);  // The summary first, then why the run failed, if it did.
  if (result.curves.empty() && result.sanity.droppedCurves() > 0) {
    std::fprintf(stderr,
                 "run: every curve of the global map (%d) was implausible and dropped: nothing "
                 "plausible was reconstructed (see the sanity lines and report.json)\n",
                 result.sanity.droppedCurves());
    return 1;
  }
  if (result.curves.empty()) {
    std::fprintf(stderr,
                 "run: no curve reached the global map: nothing was reconstructed (see "
                 "the keyframe lines and report.json)\n");
    return 1;
  }
  std::vector<const ScheduleReport*> global_solves = {&result.global_ba};
  for (const ReassociationRound& round : result.reassociation) {
    global_solves.push_back(&round.global_ba);
  }
  for (const ScheduleReport* report : global_solves) {
    if (!globalBaUsable(*report)) {
      std::fprintf(stderr, "run: global BA failed: %s\n", report->stop_reason.c_str());
      return 1;
    }
  }
  return 0;
}

}  // namespace

int RunCommand::run() const {
  validate();
  const Clock::time_point start = Clock::now();
  const RunInput input = loadInput();
  const ImageSequence& d = input.sequence;
  if (input.initialisation && input.frames.size() < 2) {
    std::fflush(stdout);  // The initialiser's summary first, then why the run stops.
    std::fprintf(stderr, "run: the initialiser registered %zu frames: nothing to refine (%s)\n",
                 input.frames.size(), input.initialisation->failure.c_str());
    return 1;
  }
  createOutputFolder(out_dir_);
  std::printf("run: %s (%s layout), %zu of %zu images with an initial pose (%s), camera %dx%d\n",
              dataset_dir_.c_str(), d.layout.c_str(), input.frames.size(), d.images.size(),
              input.init_poses_source.c_str(), d.camera.width(), d.camera.height());
  const Outcome outcome = refine(input);
  const Evaluation evaluation{evaluateAte(outcome.result, d), stageMotions(outcome.result, d),
                              finalFit(outcome.result)};
  const Written written = writeOutputs(input, outcome);
  const double seconds = secondsSince(start);
  writeJsonFile(joinPath(out_dir_, "report.json"),
                reportJson(input, outcome, evaluation, written, seconds));
  printResults(input, outcome, evaluation, written, seconds);
  return exitStatus(outcome.result);
}

// Reads how the start is to be held, then runs the pipeline once, and once more per relift pass
// at the previous pass's refined poses.
RunCommand::Outcome RunCommand::refine(const RunInput& input) const {
  Outcome outcome;
  outcome.options = options_;
  outcome.start_model = readStartModel(input, start_model_, &outcome.options);
  outcome.options.global_ba.optimizer.on_iteration = globalBaProgress(progress_interval_s_);
  outcome.tied_start = outcome.options.ba.start_prior && !options_.ba.start_prior;
  outcome.relift_passes =
      std::max(relift_passes_, outcome.tied_start ? start_model_.relift_passes : 0);
  outcome.images_ahead = imagesAhead(images_ahead_, outcome.options);
  std::vector<Pose3> frontend_poses = input.frontend_poses;
  for (int pass = 0; pass <= outcome.relift_passes; ++pass) {
    if (pass > 0) {
      printReliftPass(pass, outcome.relift_passes, evaluateAte(outcome.result, input.sequence));
      frontend_poses = reliftPoses(input, frontend_poses, outcome.result);
    }
    outcome.pipeline = std::make_unique<Pipeline>(input.sequence.camera, outcome.options);
    outcome.image_wait_seconds += feedFrames(outcome.pipeline.get(), input, frontend_poses,
                                             outcome.options, outcome.images_ahead);
    outcome.result = outcome.pipeline->finish();
  }
  return outcome;
}

// Trajectories, points, curves with their statistics, config.yaml and, with --overlays, the
// overlays and the worst curves.
RunCommand::Written RunCommand::writeOutputs(const RunInput& input, const Outcome& outcome) const {
  const PipelineResult& result = outcome.result;
  writeTrajectory(joinPath(out_dir_, "trajectory.txt"),
                  stampedPoses(result.keyframe_timestamps, result.keyframe_cam_from_world));
  writeTrajectory(joinPath(out_dir_, "trajectory_initial.txt"),
                  stampedPoses(result.keyframe_timestamps, result.keyframe_initial_cam_from_world));
  if (input.initialisation) {
    // The hybrid graph refined the points with the curves; else they are the initialiser's.
    writeInitialisedPoints(joinPath(out_dir_, "points.ply"), *input.initialisation,
                           result.points.empty() ? nullptr : &result.points);
  }
  Written written;
  written.exported =
      selectExportedCurves(result.curves, result.curve_statistics, export_min_epipolar_angle_deg_);
  const CurveExport& exported = written.exported;
  writeCurvesPly(joinPath(out_dir_, "curves.ply"), exported.curves, export_samples_per_segment_);
  writeCurvesObj(joinPath(out_dir_, "curves.obj"), exported.curves, export_samples_per_segment_,
                 exported.ids);
  writeCurveStatisticsCsv(joinPath(out_dir_, "curves.csv"), result.curve_statistics,
                          exported.flags);
  writeConfigYaml(joinPath(out_dir_, "config.yaml"), *command_);
  if (overlays_) {
    const OverlayScene scene = overlayScene(*outcome.pipeline, result);
    written.overlays = writeOverlays(joinPath(out_dir_, "overlays"), scene, overlay_,
                                     overlay_colouring_.colour_by);
    written.worst_curve_images =
        writeWorstCurves(joinPath(out_dir_, "worst_curves"), scene, overlay_);
  }
  return written;
}

nlohmann::json RunCommand::reportJson(const RunInput& input, const Outcome& outcome,
                                      const Evaluation& evaluation, const Written& written,
                                      double seconds) const {
  const ImageSequence& d = input.sequence;
  const PipelineResult& result = outcome.result;
  nlohmann::json frames = nlohmann::json::array();
  for (const KeyframeStats& s : result.frames) frames.push_back(frameToJson(s));
  const CurveGrowth growth = curveGrowth(result.frames);
  nlohmann::json options = runOptionsJson();
  options["images_ahead_resolved"] = outcome.images_ahead;
  return {
      {"command", "run"},
      {"curvesfm", versionJson()},
      {"heap", describe(heapPolicy())},
      {"config", optionsToJson(*command_)},
      {"options", options},
      {"dataset",
       {{"dir", dataset_dir_},
        {"layout", d.layout},
        {"camera", d.camera_source},
        {"init_poses", input.init_poses_source},
        {"groundtruth", d.ground_truth_source},
        {"images", d.images.size()},
        {"frames_with_initial_pose", input.frames.size()}}},
      {"initialiser", input.initialisation ? initialisationToJson(d, *input.initialisation)
                                           : nlohmann::json(nullptr)},
      // The pinhole camera of the undistorted keyframes (the report draws their frusta with it).
      {"camera", cameraToJson(outcome.pipeline->undistortedCamera())},
      {"start_model", startModelJson(outcome.start_model, outcome.tied_start, outcome.options.ba)},
      {"relift_passes_run", outcome.relift_passes},
      {"reassociation_rounds_allowed", outcome.options.reassociation_rounds},
      {"scene_scale", result.scene_scale},
      {"counts",
       {{"frames", input.frames.size()},
        {"keyframes", result.keyframe_cam_from_world.size()},
        {"curves", result.curves.size()},
        {"segments", totalSegments(result.curves)},
        {"curves_exported", written.exported.ids.size()},
        {"curves_started", growth.started},
        {"curves_extended", growth.extended},
        {"segments_registered", growth.registered},
        {"registrations_rejected", growth.rejected},
        {"registrations_rejected_edge_distance", growth.rejected_edge_distance},
        {"overlays", written.overlays},
        {"worst_curve_images", written.worst_curve_images}}},
      {"frames", frames},
      {"global_ba", scheduleReportToJson(result.global_ba)},
      {"global_ba_cost_by_type", globalCostsToJson(result.global_ba)},
      {"reassociation", reassociationToJson(result.reassociation)},
      {"final_fit", costsToJson(evaluation.fit)},
      {"curve_precision", curvePrecisionJson(result.curve_precision)},
      {"final_samples", sampleCountsToJson(result.final_samples)},
      {"ate", ateToJson(evaluation.ate)},
      {"pose_stages", stageMotionsJson(evaluation.motions, result.scene_scale)},
      {"curve_statistics", curveStatisticsJson(result.curve_statistics)},
      {"sanity", sanityToJson(result.sanity)},
      {"total_seconds", seconds},
      {"image_wait_seconds", outcome.image_wait_seconds},
      {"peak_memory_mib", peakResidentMiB()}};
}

void RunCommand::printResults(const RunInput& input, const Outcome& outcome,
                              const Evaluation& evaluation, const Written& written,
                              double seconds) const {
  const PipelineResult& result = outcome.result;
  printSummary(input, result, seconds, outcome.images_ahead ? outcome.image_wait_seconds : -1.0);
  printAte(evaluation.ate, input.sequence.ground_truth_source);
  printStageMotions(evaluation.motions);
  printFinalFit(evaluation.fit);
  printCurvePrecision(result.curve_precision, evaluation.ate);
  printCurveStatistics(result.curve_statistics);
  printExport(written.exported, result.curves.size(), export_min_epipolar_angle_deg_);
  printSanity(result.sanity);
  std::printf(
      "written: %s (trajectory.txt, trajectory_initial.txt, curves.ply, curves.obj, curves.csv, "
      "report.json, config.yaml%s%s)\n",
      out_dir_.c_str(), input.initialisation ? ", points.ply" : "",
      overlays_ ? ", overlays/, worst_curves/" : "");
}

}  // namespace curvesfm
