#include "apps/eval_map_command.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/report_json.h"
#include "core/dataset_io.h"
#include "core/errors.h"
#include "core/median.h"

namespace curvesfm {
namespace {

nlohmann::json xyz(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

void printScores(const CurveMapEvaluation& e) {
  // Sample counts: estimated within tau / inside the crop, ground truth within tau / all.
  std::printf("%-8s %9s %9s %9s %11s %11s %11s %11s\n", "tau", "precision", "recall", "F",
              "est within", "est inside", "gt within", "gt all");
  for (const CurveMapScore& s : e.scores) {
    std::printf("%-8g %9.4f %9.4f %9.4f %11d %11d %11d %11d\n", s.tau, s.precision, s.recall,
                s.f_score, s.estimate_samples_within, e.estimate_samples_inside,
                s.ground_truth_samples_within, e.ground_truth_samples);
  }
}

nlohmann::json evaluationToJson(const CurveMapEvaluation& e) {
  nlohmann::json scores = nlohmann::json::array();
  for (const CurveMapScore& s : e.scores) {
    scores.push_back({{"tau", s.tau},
                      {"precision", s.precision},
                      {"recall", s.recall},
                      {"f_score", s.f_score},
                      {"estimate_samples_within", s.estimate_samples_within},
                      {"ground_truth_samples_within", s.ground_truth_samples_within}});
  }
  return {
      {"sample_spacing", e.sample_spacing},
      {"crop", {{"enabled", e.options.crop}, {"min", xyz(e.crop_min)}, {"max", xyz(e.crop_max)}}},
      {"estimate",
       {{"polylines", e.estimate_polylines},
        {"samples", e.estimate_samples},
        {"samples_inside", e.estimate_samples_inside},
        {"length", e.estimate_length},
        {"length_inside", e.estimate_length_inside}}},
      {"ground_truth",
       {{"polylines", e.ground_truth_polylines},
        {"samples", e.ground_truth_samples},
        {"length", e.ground_truth_length}}},
      {"scores", scores}};
}

// The median distance from the matched ground-truth camera centres to the ground-truth curves'
// points (at most kMaxPoints of them, evenly spread): how far the cameras look, and the length at
// which the camera axes enter a frame alignment. 0 when there is no point.
double medianViewingDistance(const std::vector<MatchedPose>& matches,
                             const Polylines3& ground_truth) {
  constexpr std::size_t kMaxPoints = 2000;
  std::vector<Eigen::Vector3d> points;
  for (const auto& polyline : ground_truth)
    points.insert(points.end(), polyline.begin(), polyline.end());
  const std::size_t step = std::max<std::size_t>(1, points.size() / kMaxPoints);
  std::vector<double> distances;
  for (const MatchedPose& m : matches) {
    for (std::size_t i = 0; i < points.size(); i += step) {
      distances.push_back((points[i] - m.ground_truth.translation()).norm());
    }
  }
  return upperMedian(std::move(distances));
}

// Re-aligns `alignment` (a Sim(3) from the camera centres) from the camera frames instead
// (alignCameraFrames): centres and the tips of their axes at the cameras' viewing distance.
// Returns that distance, 0 when the frames could not be used (the centres' alignment stays).
double alignByCameraFrames(const std::vector<StampedPose>& trajectory,
                           const Polylines3& ground_truth, TrajectoryEvaluation* alignment) {
  const double axis_length = medianViewingDistance(alignment->matches, ground_truth);
  if (!(axis_length > 0.0)) return 0.0;
  std::vector<Pose3> truth, estimate;
  for (const MatchedPose& m : alignment->matches) {
    truth.push_back(m.ground_truth.inverse());
    estimate.push_back(trajectory[m.match.estimate_index].world_from_cam.inverse());
  }
  alignment->ground_truth_from_estimate = alignCameraFrames(truth, estimate, axis_length);
  return axis_length;
}

}  // namespace

EvalMapCommand::EvalMapCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "eval-map",
      "Curve-map evaluation: precision, recall and F-score at distance thresholds tau of a run's "
      "curves against ground-truth curves, after aligning the run's trajectory onto the ground "
      "truth's (Sim(3) by default).");
  addConfigFlag(command_);
  CLI::App* c = command_;
  c->add_option("--run", run_dir_,
                "Output folder of `curvesfm run`: its curves.obj and trajectory.txt");
  c->add_option("--curves", curves_path_,
                "Estimated curves instead of RUN/curves.obj: a .obj of polylines, or a folder in a "
                "ground-truth format");
  c->add_option("--trajectory", trajectory_path_,
                "Estimated trajectory instead of RUN/trajectory.txt (TUM, camera-to-world)");
  CLI::Option* dataset =
      c->add_option("--dataset", dataset_dir_,
                    "Dataset whose ground-truth trajectory the estimate is aligned onto (any "
                    "layout of the README)");
  c->add_option("--gt-trajectory", ground_truth_trajectory_path_,
                "Ground-truth trajectory instead of the dataset's (TUM, camera-to-world)")
      ->excludes(dataset);
  c->add_option("--gt-curves", ground_truth_curves_path_,
                "Ground-truth curves: a folder with gt-points.txt and gt-edges.txt (Pavilion), "
                "with crv-3D-pts.txt and crv-ids.txt (synthcurves), or a .obj of polylines")
      ->required();
  addImageSequenceOptions(&table_, &sequence_);
  addTrajectoryEvaluationOptions(&table_, &alignment_,
                                 {"/alignment", "", "Trajectory alignment", ""});
  addCurveMapEvaluationOptions(&table_, &options_, {"/curve_map", "", "Curve map", ""});
  table_.addFlags(c);
  c->add_option("--align-frames", align_frames_,
                "With --align sim3, fit the alignment to the camera frames (each centre and the "
                "tips of its axes at the cameras' median distance to the ground-truth curves) "
                "instead of the centres alone, whose fit leaves the rotation about a straight "
                "trajectory's line free")
      ->capture_default_str();
  c->add_option("--json", json_path_, "Write every figure, the alignment and the options as JSON");
}

std::string EvalMapCommand::curvesPath() const {
  if (!curves_path_.empty()) return curves_path_;
  return (std::filesystem::path(run_dir_) / "curves.obj").string();
}

std::string EvalMapCommand::trajectoryPath() const {
  if (!trajectory_path_.empty()) return trajectory_path_;
  return (std::filesystem::path(run_dir_) / "trajectory.txt").string();
}

void EvalMapCommand::validate() const {
  table_.validate();
  if (run_dir_.empty() && curves_path_.empty()) {
    throw CLI::ValidationError("eval-map", "give --run RUN_DIR or --curves FILE");
  }
  if (alignment_.alignment == AlignmentKind::kNone) return;
  if (run_dir_.empty() && trajectory_path_.empty()) {
    throw CLI::ValidationError("eval-map",
                               "--align " + toString(alignment_.alignment) +
                                   " needs the estimated trajectory: give --run or --trajectory "
                                   "(or --align none)");
  }
  if (dataset_dir_.empty() && ground_truth_trajectory_path_.empty()) {
    throw CLI::ValidationError("eval-map",
                               "--align " + toString(alignment_.alignment) +
                                   " needs the ground-truth trajectory: give --dataset or "
                                   "--gt-trajectory (or --align none)");
  }
}

int EvalMapCommand::run() const {
  // Every input is read before the work, so that a bad file fails at once.
  const std::string curves_path = curvesPath();
  Polylines3 estimate = readCurveMap(curves_path);
  const Polylines3 ground_truth = readCurveMap(ground_truth_curves_path_);

  std::optional<TrajectoryEvaluation> alignment;
  double frames_axis_length = 0.0;  // > 0: aligned by camera frames, their axes this long.
  std::string ground_truth_source = ground_truth_trajectory_path_;
  if (alignment_.alignment != AlignmentKind::kNone) {
    const std::string trajectory_path = trajectoryPath();
    const std::vector<StampedPose> trajectory = readTrajectory(trajectory_path);
    std::vector<StampedPose> ground_truth_trajectory;
    if (!ground_truth_trajectory_path_.empty()) {
      ground_truth_trajectory = readTrajectory(ground_truth_trajectory_path_);
    } else {
      const ImageSequence sequence = loadImageSequence(dataset_dir_, sequence_);
      if (sequence.ground_truth.empty()) {
        throw IoError(dataset_dir_,
                      "has no ground-truth trajectory to align the estimate with "
                      "(give --gt-trajectory, or --align none)");
      }
      ground_truth_trajectory = sequence.ground_truth;
      ground_truth_source = sequence.ground_truth_source;
    }
    alignment = compareTrajectories(trajectory, ground_truth_trajectory, alignment_,
                                    trajectory_path, ground_truth_source);
    if (align_frames_ && alignment_.alignment == AlignmentKind::kSim3) {
      frames_axis_length = alignByCameraFrames(trajectory, ground_truth, &*alignment);
    }
    const Sim3& gt_from_estimate = alignment->ground_truth_from_estimate;
    for (auto& polyline : estimate) {
      for (Eigen::Vector3d& p : polyline) p = gt_from_estimate * p;
    }
    std::printf(
        "alignment %s of %s onto %s: %zu matched poses, ATE rmse %.6f; scale %.6f, translation "
        "[%.6f, %.6f, %.6f]\n",
        toString(alignment_.alignment).c_str(), trajectory_path.c_str(),
        ground_truth_source.c_str(), alignment->matches.size(), alignment->ate.rmse,
        gt_from_estimate.scale, gt_from_estimate.translation.x(), gt_from_estimate.translation.y(),
        gt_from_estimate.translation.z());
    if (frames_axis_length > 0.0) {
      std::printf(
          "  fitted to the camera frames (centres and axes %.4g long, the cameras' median distance "
          "to the ground-truth curves; the ATE is the centres' own fit)\n",
          frames_axis_length);
    }
  } else {
    std::printf("alignment none: the curves are taken in the ground truth's frame as they are\n");
  }

  const CurveMapEvaluation e = evaluateCurveMap(estimate, ground_truth, options_);
  std::printf("estimate %s: %d polylines, length %.4f\n", curves_path.c_str(), e.estimate_polylines,
              e.estimate_length);
  std::printf("ground truth %s (%s): %d polylines, length %.4f\n",
              ground_truth_curves_path_.c_str(),
              toString(detectCurveMapFormat(ground_truth_curves_path_)).c_str(),
              e.ground_truth_polylines, e.ground_truth_length);
  if (e.options.crop) {
    std::printf(
        "crop: ground-truth bounding box + %g on every side, [%.4f, %.4f, %.4f] .. [%.4f, %.4f, "
        "%.4f]: %d of %d estimated samples inside (length %.4f of %.4f)\n",
        e.options.crop_margin, e.crop_min.x(), e.crop_min.y(), e.crop_min.z(), e.crop_max.x(),
        e.crop_max.y(), e.crop_max.z(), e.estimate_samples_inside, e.estimate_samples,
        e.estimate_length_inside, e.estimate_length);
  } else {
    std::printf("crop: off, all %d estimated samples count\n", e.estimate_samples);
  }
  std::printf(
      "sample spacing %g; precision and recall are fractions of curve length (ground-truth "
      "units)\n",
      e.sample_spacing);
  printScores(e);

  if (!json_path_.empty()) {
    nlohmann::json report = evaluationToJson(e);
    report["command"] = "eval-map";
    report["curvesfm"] = versionJson();
    report["config"] = optionsToJson(*command_);
    report["options"] = table_.toJson();
    report["inputs"] = {
        {"curves", curves_path},
        {"ground_truth_curves", ground_truth_curves_path_},
        {"ground_truth_format", toString(detectCurveMapFormat(ground_truth_curves_path_))}};
    report["alignment"] = nullptr;
    if (alignment) {
      report["inputs"]["trajectory"] = trajectoryPath();
      report["inputs"]["ground_truth_trajectory"] = ground_truth_source;
      report["alignment"] = alignmentToJson(*alignment);
      report["alignment"]["matched"] = alignment->matches.size();
      report["alignment"]["ate"] = statisticsToJson(alignment->ate);
      report["alignment"]["frames_axis_length"] =
          frames_axis_length > 0.0 ? nlohmann::json(frames_axis_length) : nlohmann::json(nullptr);
    }
    writeJsonFile(json_path_, report);
    std::printf("json: %s\n", json_path_.c_str());
  }
  return 0;
}

}  // namespace curvesfm
