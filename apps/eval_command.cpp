#include "apps/eval_command.h"

#include <stdlib.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/plot_scripts.h"
#include "apps/cli/report_json.h"
#include "core/angles.h"
#include "core/dataset_io.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

double rotationAngleDeg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(rotation).angle() * kRadToDeg;
}

void printSummary(const TrajectoryEvaluation& e) {
  std::printf("matched %zu of %d estimated poses (%d ground-truth) within %g s\n", e.matches.size(),
              e.estimate_poses, e.ground_truth_poses, e.options.max_dt);
  const Sim3& a = e.ground_truth_from_estimate;
  std::printf(
      "alignment %s (ground truth from estimate): scale %.6f, rotation %.4f deg, "
      "translation [%.6f, %.6f, %.6f] m\n",
      toString(e.options.alignment).c_str(), a.scale, rotationAngleDeg(a.rotation),
      a.translation.x(), a.translation.y(), a.translation.z());
}

void printStatistics(const TrajectoryEvaluation& e) {
  const ErrorStatistics* columns[] = {&e.ate, &e.rpe_translation_stats, &e.rpe_rotation_stats};
  std::printf("ATE over %d matched poses; RPE over motions from matched pose k to k+%d",
              e.ate.count, e.options.rpe_delta);
  if (e.rpe_translation_stats.count == 0) std::printf(" (none: too few matched poses)");
  std::printf("\n");
  std::printf("%-8s %14s %14s %14s\n", "", "ATE (m)", "RPE trans (m)", "RPE rot (deg)");
  const auto row = [&](const char* name, double ErrorStatistics::*field) {
    std::printf("%-8s", name);
    for (const ErrorStatistics* s : columns) std::printf(" %14.6f", s->*field);
    std::printf("\n");
  };
  row("rmse", &ErrorStatistics::rmse);
  row("mean", &ErrorStatistics::mean);
  row("median", &ErrorStatistics::median);
  row("std", &ErrorStatistics::std);
  row("min", &ErrorStatistics::min);
  row("max", &ErrorStatistics::max);
  std::printf("%-8s %14d %14d %14d\n", "count", e.ate.count, e.rpe_translation_stats.count,
              e.rpe_rotation_stats.count);
}

nlohmann::json perPoseToJson(const TrajectoryEvaluation& e) {
  nlohmann::json poses = {{"estimate_timestamp", nlohmann::json::array()},
                          {"ground_truth_timestamp", nlohmann::json::array()},
                          {"ate_m", nlohmann::json::array()}};
  for (const MatchedPose& m : e.matches) {
    poses["estimate_timestamp"].push_back(m.estimate_timestamp);
    poses["ground_truth_timestamp"].push_back(m.ground_truth_timestamp);
    poses["ate_m"].push_back(m.position_error);
  }
  // The figure draws these as they are, so that Python never repeats the alignment.
  const nlohmann::json positions = matchedPosesToJson(e);
  poses["aligned_position"] = positions["aligned_position"];
  poses["ground_truth_position"] = positions["ground_truth_position"];
  return poses;
}

// A new empty file in the temporary folder, removed with this object.
class TemporaryFile {
 public:
  TemporaryFile(const std::string& prefix, const std::string& suffix) {
    std::string pattern =
        (std::filesystem::temp_directory_path() / (prefix + "XXXXXX" + suffix)).string();
    const int fd = mkstemps(pattern.data(), static_cast<int>(suffix.size()));
    if (fd < 0) throw IoError(pattern, "cannot create a temporary file");
    close(fd);
    path_ = pattern;
  }
  ~TemporaryFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The figure's format follows the extension, and the package writes only these two.
std::string checkPlotExtension(std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (extension == ".png" || extension == ".pdf") return "";
  return "'" + path + "': expected a file name ending in .png or .pdf";
}

// Every estimated pose, matched or not, so that the file replaces the estimate one for one.
void writeAlignedEstimate(const std::string& path, const std::vector<StampedPose>& estimate,
                          const Sim3& ground_truth_from_estimate) {
  std::vector<StampedPose> aligned = estimate;
  for (StampedPose& pose : aligned)
    pose.world_from_cam = ground_truth_from_estimate.transformPose(pose.world_from_cam);
  writeTrajectory(path, aligned);
  std::printf("aligned estimate: %s\n", path.c_str());
}

}  // namespace

EvalCommand::EvalCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "eval",
      "Trajectory evaluation: ATE (rmse, mean, median, std, min, max) and RPE of an estimated TUM "
      "trajectory against the ground truth, after timestamp association and alignment.");
  addConfigFlag(command_);
  CLI::App* c = command_;
  c->add_option(
       "--est", estimate_path_,
       "Estimated trajectory, TUM lines 'timestamp tx ty tz qx qy qz qw' (camera-to-world)")
      ->required();
  c->add_option("--gt", ground_truth_path_, "Ground-truth trajectory, same format")->required();
  addTrajectoryEvaluationOptions(&table_, &options_, {"", "", "Evaluation", ""});
  table_.addFlags(c);
  c->add_option("--json", json_path_,
                "Write all figures, the alignment, per-pose errors and the options as JSON");
  c->add_option("--plot", plot_path_,
                "Draw a PNG or PDF (by extension): top view of both trajectories (left) and the "
                "ATE over time (right), with python3 -m curvesfm_plots eval")
      ->check(CLI::Validator(checkPlotExtension, "FILE.png|FILE.pdf"));
  c->add_option("--aligned-out", aligned_path_,
                "Write every estimated pose carried into the ground truth's world by the "
                "alignment, as a TUM trajectory (e.g. an aligned start for `run --init-poses`)");
}

int EvalCommand::run() const {
  const std::vector<StampedPose> estimate = readTrajectory(estimate_path_);
  const std::vector<StampedPose> ground_truth = readTrajectory(ground_truth_path_);
  const TrajectoryEvaluation evaluation =
      compareTrajectories(estimate, ground_truth, options_, estimate_path_, ground_truth_path_);

  printSummary(evaluation);
  printStatistics(evaluation);
  if (!aligned_path_.empty())
    writeAlignedEstimate(aligned_path_, estimate, evaluation.ground_truth_from_estimate);

  // The figure is drawn from the JSON, so --plot writes it too, to a temporary file without --json.
  std::optional<TemporaryFile> temporary_json;
  std::string json_path = json_path_;
  if (json_path.empty() && !plot_path_.empty()) {
    temporary_json.emplace("curvesfm_eval_", ".json");
    json_path = temporary_json->path();
  }
  if (!json_path.empty()) {
    writeJsonFile(
        json_path,
        {{"command", "eval"},
         {"curvesfm", versionJson()},
         {"config", optionsToJson(*command_)},
         {"estimate", {{"path", estimate_path_}, {"poses", evaluation.estimate_poses}}},
         {"ground_truth", {{"path", ground_truth_path_}, {"poses", evaluation.ground_truth_poses}}},
         {"matched", evaluation.matches.size()},
         {"options", table_.toJson()},
         {"alignment", alignmentToJson(evaluation)},
         {"ate_m", statisticsToJson(evaluation.ate)},
         {"rpe_translation_m", statisticsToJson(evaluation.rpe_translation_stats)},
         {"rpe_rotation_deg", statisticsToJson(evaluation.rpe_rotation_stats)},
         {"per_pose", perPoseToJson(evaluation)},
         {"per_rpe_pair",
          {{"translation_m", evaluation.rpe_translation},
           {"rotation_deg", evaluation.rpe_rotation_deg}}}});
    if (!temporary_json) std::printf("json: %s\n", json_path.c_str());
  }
  if (!plot_path_.empty()) {
    // The package prints "plot: FILE" itself.
    runPlotPackageOrThrow("eval --plot", {"eval", json_path, plot_path_});
  }
  return 0;
}

}  // namespace curvesfm
