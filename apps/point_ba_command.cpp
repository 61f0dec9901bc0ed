#include "apps/point_ba_command.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "apps/cli/cli_options.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/report_json.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

void printErrors(const char* label, const PointSceneErrors& errors) {
  std::printf(
      "%-8s camera ATE (sim3) %.6f m, position rmse %.6f m, rotation mean %.5f deg, "
      "point rmse %.6f m, reprojection rmse %.4f px\n",
      label, errors.position_ate_sim3, errors.position_rmse, errors.rotation_mean_deg,
      errors.point_rmse, errors.reprojection_rmse_px);
}

nlohmann::json errorsToJson(const PointSceneErrors& errors) {
  return {{"camera_ate_sim3_m", errors.position_ate_sim3},
          {"camera_position_rmse_m", errors.position_rmse},
          {"rotation_mean_deg", errors.rotation_mean_deg},
          {"point_rmse_m", errors.point_rmse},
          {"reprojection_rmse_px", errors.reprojection_rmse_px}};
}

}  // namespace

PointBaCommand::PointBaCommand(CLI::App* app) {
  command_ = app->add_subcommand(
      "point-ba",
      "Synthetic point bundle adjustment through the factor-graph layer: prints the camera, "
      "point and reprojection errors before and after.");
  addConfigFlag(command_);
  CLI::App* c = command_;
  addPointSceneOptions(&table_, &scene_, {"/scene", "", "Scene", ""});
  addPointBundleAdjustmentOptions(&table_, &ba_, {"/bundle_adjustment", "", "Objective", ""});
  addOptimizerOptions(&table_, &optimizer_, {"/optimizer", "", "Solver", ""});
  table_.addFlags(c);
  c->add_option("--report", report_path_, "Write a JSON report (configuration, errors, solver)");
}

int PointBaCommand::run() const {
  validate();

  const PointScene scene = makePointScene(scene_);
  std::printf("scene: %zu cameras, %zu points, %zu observations (seed %u)\n",
              scene.true_cam_from_world.size(), scene.true_points.size(), scene.observations.size(),
              scene_.seed);
  PointBundleAdjustmentProblem problem =
      buildPointBundleAdjustment({scene.camera, scene.initial_cam_from_world, scene.initial_points,
                                  scene.observations, scene.trueScaleDistance()},
                                 ba_);
  const PointSceneErrors before =
      evaluatePointScene(scene, scene.initial_cam_from_world, scene.initial_points);

  const OptimizationSummary summary =
      optimize(problem.graph, &problem.values, problem.config, optimizer_);
  const PointSceneErrors after =
      evaluatePointScene(scene, extractPoses(problem.values, scene.true_cam_from_world.size()),
                         extractPoints(problem.values, scene.true_points.size()));

  std::printf("%s\n", summary.toString().c_str());
  if (optimizer_.verbose) std::printf("%s\n", summary.full_report.c_str());
  printErrors("before:", before);
  printErrors("after:", after);
  if (ba_.refine_focal) {
    std::printf("focal lengths refined x%.6f (the scene's camera is exact: 1)\n",
                extractFocalScale(problem.values));
  }

  if (!report_path_.empty()) {
    const nlohmann::json report = {
        {"command", "point-ba"},
        {"curvesfm", versionJson()},
        {"config", optionsToJson(*command_)},
        {"options", table_.toJson()},
        {"scene",
         {{"cameras", scene.true_cam_from_world.size()},
          {"points", scene.true_points.size()},
          {"observations", scene.observations.size()}}},
        {"errors_before", errorsToJson(before)},
        {"errors_after", errorsToJson(after)},
        {"optimizer", summaryToJson(summary)},
        {"focal_scale", extractFocalScale(problem.values)},
    };
    writeJsonFile(report_path_, report);
    std::printf("report: %s\n", report_path_.c_str());
  }
  return summary.usable ? 0 : 1;
}

}  // namespace curvesfm
