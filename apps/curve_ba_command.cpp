#include "apps/curve_ba_command.h"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/cli/cli_options.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/report_json.h"
#include "core/errors.h"
#include "factors/pose_variables.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

int countPartlyHidden(const CurveScene& scene) {
  int hidden = 0;
  for (const CurveObservation& obs : scene.observations) hidden += obs.partlyHidden();
  return hidden;
}

void printScene(const CurveScene& scene, const CurveSceneOptions& options) {
  std::printf(
      "scene: %zu keyframes (%s), %zu curves (%s, %d segments), %zu observations "
      "(%d partly hidden), seed %u\n",
      scene.keyframes.size(), toString(options.camera_path).c_str(), scene.true_curves.size(),
      toString(options.curve_kind).c_str(), totalSegments(scene.true_curves),
      scene.observations.size(), countPartlyHidden(scene), options.seed);
}

nlohmann::json sceneCountsToJson(const CurveScene& scene) {
  return {{"keyframes", scene.keyframes.size()},
          {"curves", scene.true_curves.size()},
          {"segments", totalSegments(scene.true_curves)},
          {"observations", scene.observations.size()},
          {"partly_hidden_observations", countPartlyHidden(scene)}};
}

void printErrors(const char* label, const CurveSceneErrors& e) {
  std::printf(
      "%-8s camera ATE (sim3) %.6f m, position rmse %.6f m, rotation mean %.5f deg, "
      "curve mean error %.6f m (aligned %.6f m, max %.6f m)\n",
      label, e.position_ate_sim3, e.position_rmse, e.rotation_mean_deg, e.curve_mean_error,
      e.curve_mean_error_aligned, e.curve_max_error);
}

nlohmann::json errorsToJson(const CurveSceneErrors& e) {
  return {{"camera_ate_sim3_m", e.position_ate_sim3},
          {"camera_position_rmse_m", e.position_rmse},
          {"rotation_mean_deg", e.rotation_mean_deg},
          {"curve_mean_error_m", e.curve_mean_error},
          {"curve_max_error_m", e.curve_max_error},
          {"curve_mean_error_aligned_m", e.curve_mean_error_aligned}};
}

void printSamples(const char* label, const CurveSampleCounts& s) {
  std::printf(
      "%-8s samples: %d on field, %d behind camera, %d outside image, %d beyond reach, "
      "%d wrong orientation\n",
      label, s.on_field, s.behind_camera, s.outside_image, s.beyond_reach, s.wrong_orientation);
}

// Ceres' IsSolutionUsable for every phase that ran.
bool allSolvesUsable(const ScheduleReport& report) {
  for (const ScheduleRound& round : report.rounds) {
    if (!round.skipped && !round.summary.usable) return false;
  }
  return true;
}

// Where the problem stands at one moment, as the summary and the report need it.
struct Snapshot {
  CurveSceneErrors errors;
  CurveSampleCounts samples;
  std::map<std::string, FactorTypeCost> costs;
};

Snapshot snapshot(const CurveScene& scene, const CurveBundleAdjustmentProblem& problem) {
  const std::vector<PolyBezier> curves = extractCurves(problem.values, scene.initial_curves);
  const std::vector<Pose3> poses = extractPoses(problem.values, scene.keyframes.size());
  return {evaluateCurveScene(scene, poses, curves),
          countCurveSamples(problem.graph, problem.values),
          problem.graph.costByType(problem.values)};
}

nlohmann::json snapshotToJson(const Snapshot& s) {
  return {{"errors", errorsToJson(s.errors)},
          {"samples", sampleCountsToJson(s.samples)},
          {"cost_by_type", costsToJson(s.costs)}};
}

void writeReport(const std::string& path, const nlohmann::json& report) {
  writeJsonFile(path, report);
  std::printf("report: %s\n", path.c_str());
}

}  // namespace

CurveBaCommand::CurveBaCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "curve-ba",
      "Synthetic curve bundle adjustment (rendered images, Canny edges, perturbed start) with "
      "the scheduler: prints each round and the camera and curve errors before and after.");
  addConfigFlag(command_);
  addCurveSceneOptions(&table_, &scene_, {"/scene", "", "Scene", ""});
  addCurveBundleAdjustmentOptions(&table_, &ba_, {"/bundle_adjustment", "", "Objective", ""});
  addSchedulerOptions(&table_, &scheduler_, {"/scheduler", "", "Schedule", ""},
                      &ba_.fix_first_pose);
  table_.addFlags(command_);
  command_->add_option("--report", report_path_,
                       "Write a JSON report (configuration, rounds, errors, sample counts)");
}

SchedulerOptions CurveBaCommand::schedulerOptions() const {
  SchedulerOptions scheduler = scheduler_;
  scheduler.fix_first_pose = ba_.fix_first_pose;
  return scheduler;
}

void CurveBaCommand::validate() const { table_.validate(); }

int CurveBaCommand::run() const {
  validate();
  const SchedulerOptions scheduler = schedulerOptions();
  const CurveScene scene = makeCurveScene(scene_);
  printScene(scene, scene_);
  CurveBundleAdjustmentProblem problem =
      buildCurveBundleAdjustment(makeCurveBundleAdjustmentInput(scene), ba_);
  const Snapshot before = snapshot(scene, problem);
  const ScheduleReport schedule =
      runSchedule(problem.graph, &problem.values, problem.config, scheduler);
  const Snapshot after = snapshot(scene, problem);

  std::printf("%s", schedule.toString().c_str());
  printErrors("before:", before.errors);
  printErrors("after:", after.errors);
  printSamples("before:", before.samples);
  printSamples("after:", after.samples);

  if (!report_path_.empty()) {
    writeReport(report_path_, {{"command", "curve-ba"},
                               {"curvesfm", versionJson()},
                               {"config", optionsToJson(*command_)},
                               {"options", table_.toJson()},
                               {"scene", sceneCountsToJson(scene)},
                               {"before", snapshotToJson(before)},
                               {"after", snapshotToJson(after)},
                               {"schedule", scheduleReportToJson(schedule)}});
  }
  return allSolvesUsable(schedule) ? 0 : 1;
}

}  // namespace curvesfm
