#include "apps/eval_map_command.h"

#include <algorithm>
#include <cmath>
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
#include "core/tum_dataset.h"
#include "frontend/image/image_undistorter.h"

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

// The ground truth cut into parts no longer than `spacing`: each part as a two-point polyline,
// with its midpoint and length.
struct CurveParts {
  Polylines3 pieces;
  std::vector<Eigen::Vector3d> midpoints;
  std::vector<Eigen::Vector3d> directions;  // Unit; any unit vector for a part of no length.
  std::vector<double> lengths;
};

CurveParts cutIntoParts(const Polylines3& curves, double spacing) {
  CurveParts parts;
  for (const auto& polyline : curves) {
    for (std::size_t i = 0; i + 1 < polyline.size(); ++i) {
      const Eigen::Vector3d& a = polyline[i];
      const Eigen::Vector3d& b = polyline[i + 1];
      const double length = (b - a).norm();
      const int n = std::max(1, static_cast<int>(std::ceil(length / spacing)));
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d start = a + (b - a) * (static_cast<double>(k) / n);
        const Eigen::Vector3d end = a + (b - a) * (static_cast<double>(k + 1) / n);
        parts.pieces.push_back({start, end});
        parts.midpoints.push_back(0.5 * (start + end));
        parts.directions.push_back(length > 0.0 ? Eigen::Vector3d((b - a) / length)
                                                : Eigen::Vector3d::UnitX());
        parts.lengths.push_back(length / n);
      }
    }
  }
  return parts;
}

nlohmann::json recallsToJson(const CurveMapEvaluation& e) {
  nlohmann::json out = nlohmann::json::array();
  for (const CurveMapScore& s : e.scores) out.push_back({{"tau", s.tau}, {"recall", s.recall}});
  return out;
}

// One figure of every score, " / " between them.
template <typename Figure>
std::string scoresText(const CurveMapEvaluation& e, const char* format, Figure figure) {
  std::string text;
  for (const CurveMapScore& s : e.scores) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), format, figure(s));
    text += (text.empty() ? "" : " / ") + std::string(buffer);
  }
  return text;
}

std::string tausText(const CurveMapEvaluation& e) {
  return scoresText(e, "%g", [](const CurveMapScore& s) { return s.tau; });
}

std::string recallsText(const CurveMapEvaluation& e) {
  return scoresText(e, "%.3f", [](const CurveMapScore& s) { return s.recall; });
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
  addEdgeCoverageOptions(&table_, &edge_coverage_options_,
                         {"/edge_coverage", "edge-coverage-", "Edge coverage", ""});
  table_.addFlags(c);
  c->add_option("--align-frames", align_frames_,
                "With --align sim3, fit the alignment to the camera frames (each centre and the "
                "tips of its axes at the cameras' median distance to the ground-truth curves) "
                "instead of the centres alone, whose fit leaves the rotation about a straight "
                "trajectory's line free")
      ->capture_default_str();
  c->add_option(
       "--edge-coverage", edge_coverage_,
       "Also project the ground-truth curves into every image of --dataset at its "
       "ground-truth pose and report the share of their length the images show as an edge of "
       "its direction (run's default Canny; in at least --edge-coverage-min-views images and "
       "--edge-coverage-min-share of those it lies in), whether the map has a curve there in "
       "the images, and the recall on each part: how much of the ground truth an edge-based "
       "map could hold at all (occlusion is not modelled, so upper bounds)")
      ->capture_default_str();
  c->add_option("--edge-coverage-min-views", edge_coverage_min_views_,
                "Views on an edge that make a ground-truth point visible as an edge (two: the "
                "least a triangulation needs)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  c->add_option("--edge-coverage-min-share", edge_coverage_min_share_,
                "... and on an edge in at least this share of the images it lies in (a point of "
                "a textured region falls near some edge of its direction in a few by chance)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--json", json_path_, "Write every figure, the alignment and the options as JSON");
}

nlohmann::json EvalMapCommand::reportEdgeCoverage(const Polylines3& estimate,
                                                  const Polylines3& ground_truth,
                                                  const std::vector<DatasetFrame>& frames,
                                                  const ImageSequence& sequence,
                                                  double spacing) const {
  const ImageUndistorter undistorter(sequence.camera);
  const CurveParts parts = cutIntoParts(ground_truth, spacing);
  EdgeCoverageCounter counter(parts.midpoints, parts.directions, edge_coverage_options_);
  counter.setNearbyCurves(estimate);
  for (const DatasetFrame& frame : frames) {
    counter.addView(undistorter.undistort(loadFrameImage(frame, sequence.camera)),
                    frame.initial_cam_from_world, undistorter.camera());
  }
  // Shown as an edge: on an edge in at least min_views images and in at least min_share of the
  // images it projects into (a point of a textured region falls near some edge of its direction
  // in a few views by chance). Of that part, the map has a curve there in the images by the same
  // count of views, whatever that curve's depth.
  const int min_views = edge_coverage_min_views_;
  const double min_share = edge_coverage_min_share_;
  const auto enough = [&](int views, int in_image) {
    return views >= min_views && views >= min_share * in_image;
  };
  double total = 0.0, in_views = 0.0, on_edge = 0.0, shown_length = 0.0, mapped_length = 0.0;
  Polylines3 shown, not_shown, shown_mapped, shown_unmapped;
  for (std::size_t i = 0; i < parts.lengths.size(); ++i) {
    const PointViews& views = counter.views()[i];
    const double length = parts.lengths[i];
    total += length;
    if (views.in_image >= min_views) in_views += length;
    if (views.on_edge >= min_views) on_edge += length;
    if (!enough(views.on_edge, views.in_image)) {
      not_shown.push_back(parts.pieces[i]);
      continue;
    }
    shown_length += length;
    shown.push_back(parts.pieces[i]);
    if (enough(views.near_curve, views.in_image)) {
      mapped_length += length;
      shown_mapped.push_back(parts.pieces[i]);
    } else {
      shown_unmapped.push_back(parts.pieces[i]);
    }
  }
  const auto share = [total](double length) { return total > 0.0 ? length / total : 0.0; };
  const CurveMapEvaluation on_shown = evaluateCurveMap(estimate, shown, options_);
  const CurveMapEvaluation on_rest = evaluateCurveMap(estimate, not_shown, options_);
  const CurveMapEvaluation on_mapped = evaluateCurveMap(estimate, shown_mapped, options_);
  const CurveMapEvaluation on_unmapped = evaluateCurveMap(estimate, shown_unmapped, options_);
  std::printf(
      "edge coverage (%d images of %s at their ground-truth poses; an edge pixel within %g px, "
      "its normal within %g deg of the curve's): of the ground truth's length %.3f lies in >= %d "
      "images, %.3f on an edge in >= %d, %.3f shown as an edge (in >= %d images and >= %g of "
      "those it lies in; occlusion not modelled: upper bounds)\n",
      counter.numViews(), dataset_dir_.c_str(), edge_coverage_options_.max_edge_distance_px,
      edge_coverage_options_.max_normal_angle_deg, share(in_views), min_views, share(on_edge),
      min_views, share(shown_length), min_views, min_share);
  std::printf("  recall at tau %s on the part shown as an edge: %s; on the rest: %s\n",
              tausText(on_shown).c_str(), recallsText(on_shown).c_str(),
              recallsText(on_rest).c_str());
  std::printf(
      "  of the part shown as an edge, %.3f of the ground truth's length has a curve of the map "
      "within %g px in the images (as many of them; any depth): recall there %s, elsewhere %s\n",
      share(mapped_length), edge_coverage_options_.max_edge_distance_px,
      recallsText(on_mapped).c_str(), recallsText(on_unmapped).c_str());
  return {{"images", counter.numViews()},
          {"min_views", min_views},
          {"min_share", min_share},
          {"max_edge_distance_px", edge_coverage_options_.max_edge_distance_px},
          {"max_normal_angle_deg", edge_coverage_options_.max_normal_angle_deg},
          {"share_in_min_views", share(in_views)},
          {"share_on_edge_in_min_views", share(on_edge)},
          {"share_shown", share(shown_length)},
          {"share_shown_with_a_curve_in_the_images", share(mapped_length)},
          {"recall_on_shown_part", recallsToJson(on_shown)},
          {"recall_elsewhere", recallsToJson(on_rest)},
          {"recall_on_shown_part_with_a_curve_in_the_images", recallsToJson(on_mapped)},
          {"recall_on_shown_part_without", recallsToJson(on_unmapped)}};
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
  if (edge_coverage_ && dataset_dir_.empty()) {
    throw CLI::ValidationError("eval-map",
                               "--edge-coverage needs the images and ground-truth poses: give "
                               "--dataset");
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
  const std::optional<ImageSequence> sequence = sequenceIfNeeded();
  // The images at their ground-truth poses, for the edge coverage.
  const std::vector<DatasetFrame> frames =
      edge_coverage_ ? framesWithPoses(*sequence, sequence->ground_truth, alignment_.max_dt,
                                       sequence->ground_truth_source)
                     : std::vector<DatasetFrame>();
  const MapAlignment alignment = alignEstimate(sequence, ground_truth, &estimate);

  const CurveMapEvaluation e = evaluateCurveMap(estimate, ground_truth, options_);
  printEvaluation(curves_path, e);
  const nlohmann::json edge_coverage =
      edge_coverage_
          ? reportEdgeCoverage(estimate, ground_truth, frames, *sequence, 10.0 * e.sample_spacing)
          : nlohmann::json(nullptr);
  if (!json_path_.empty()) writeJsonReport(curves_path, e, alignment, edge_coverage);
  return 0;
}

std::optional<ImageSequence> EvalMapCommand::sequenceIfNeeded() const {
  const bool align = alignment_.alignment != AlignmentKind::kNone;
  if (!(align && ground_truth_trajectory_path_.empty()) && !edge_coverage_) return std::nullopt;
  ImageSequence sequence = loadImageSequence(dataset_dir_, sequence_);
  if (sequence.ground_truth.empty()) {
    throw IoError(dataset_dir_, edge_coverage_
                                    ? "has no ground-truth trajectory to project the "
                                      "ground-truth curves with (--edge-coverage)"
                                    : "has no ground-truth trajectory to align the estimate "
                                      "with (give --gt-trajectory, or --align none)");
  }
  return sequence;
}

MapAlignment EvalMapCommand::alignEstimate(const std::optional<ImageSequence>& sequence,
                                           const Polylines3& ground_truth,
                                           Polylines3* estimate) const {
  MapAlignment aligned;
  aligned.ground_truth_source = ground_truth_trajectory_path_;
  if (alignment_.alignment == AlignmentKind::kNone) {
    std::printf("alignment none: the curves are taken in the ground truth's frame as they are\n");
    return aligned;
  }
  const std::string trajectory_path = trajectoryPath();
  const std::vector<StampedPose> trajectory = readTrajectory(trajectory_path);
  std::vector<StampedPose> ground_truth_trajectory;
  if (!ground_truth_trajectory_path_.empty()) {
    ground_truth_trajectory = readTrajectory(ground_truth_trajectory_path_);
  } else {
    ground_truth_trajectory = sequence->ground_truth;
    aligned.ground_truth_source = sequence->ground_truth_source;
  }
  aligned.evaluation = compareTrajectories(trajectory, ground_truth_trajectory, alignment_,
                                           trajectory_path, aligned.ground_truth_source);
  TrajectoryEvaluation& evaluation = *aligned.evaluation;
  if (align_frames_ && alignment_.alignment == AlignmentKind::kSim3) {
    aligned.frames_axis_length = alignByCameraFrames(trajectory, ground_truth, &evaluation);
  }
  const Sim3& gt_from_estimate = evaluation.ground_truth_from_estimate;
  for (auto& polyline : *estimate) {
    for (Eigen::Vector3d& p : polyline) p = gt_from_estimate * p;
  }
  std::printf(
      "alignment %s of %s onto %s: %zu matched poses, ATE rmse %.6f; scale %.6f, translation "
      "[%.6f, %.6f, %.6f]\n",
      toString(alignment_.alignment).c_str(), trajectory_path.c_str(),
      aligned.ground_truth_source.c_str(), evaluation.matches.size(), evaluation.ate.rmse,
      gt_from_estimate.scale, gt_from_estimate.translation.x(), gt_from_estimate.translation.y(),
      gt_from_estimate.translation.z());
  if (aligned.frames_axis_length > 0.0) {
    std::printf(
        "  fitted to the camera frames (centres and axes %.4g long, the cameras' median distance "
        "to the ground-truth curves; the ATE is the centres' own fit)\n",
        aligned.frames_axis_length);
  }
  return aligned;
}

void EvalMapCommand::printEvaluation(const std::string& curves_path,
                                     const CurveMapEvaluation& e) const {
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
}

void EvalMapCommand::writeJsonReport(const std::string& curves_path, const CurveMapEvaluation& e,
                                     const MapAlignment& alignment,
                                     const nlohmann::json& edge_coverage) const {
  nlohmann::json report = evaluationToJson(e);
  report["command"] = "eval-map";
  report["curvesfm"] = versionJson();
  report["config"] = optionsToJson(*command_);
  report["options"] = table_.toJson();
  report["inputs"] = {
      {"curves", curves_path},
      {"ground_truth_curves", ground_truth_curves_path_},
      {"ground_truth_format", toString(detectCurveMapFormat(ground_truth_curves_path_))}};
  report["edge_coverage"] = edge_coverage;
  report["alignment"] = nullptr;
  if (alignment.evaluation) {
    const TrajectoryEvaluation& evaluation = *alignment.evaluation;
    report["inputs"]["trajectory"] = trajectoryPath();
    report["inputs"]["ground_truth_trajectory"] = alignment.ground_truth_source;
    report["alignment"] = alignmentToJson(evaluation);
    report["alignment"]["matched"] = evaluation.matches.size();
    report["alignment"]["ate"] = statisticsToJson(evaluation.ate);
    report["alignment"]["frames_axis_length"] = alignment.frames_axis_length > 0.0
                                                    ? nlohmann::json(alignment.frames_axis_length)
                                                    : nlohmann::json(nullptr);
  }
  writeJsonFile(json_path_, report);
  std::printf("json: %s\n", json_path_.c_str());
}

}  // namespace curvesfm
