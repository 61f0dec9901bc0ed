#include "apps/curve_ba_command.h"

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/cli/cli_options.h"
#include "apps/cli/report_json.h"
#include "core/errors.h"
#include "factors/pose_variables.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

void addSceneFlags(CLI::App* c, CurveSceneOptions* scene) {
  c->add_option("--keyframes", scene->num_keyframes, "Keyframes (rendered images)")
      ->capture_default_str();
  addEnumFlag(c, "camera-path", &scene->camera_path,
              "Where the keyframes are: orbit, forward_walk");
  c->add_option("--curves", scene->num_curves, "3D curves in the room")->capture_default_str();
  addEnumFlag(c, "curve-kind", &scene->curve_kind, "Shape of the curves: line, arc, helix, mixed");
  c->add_option("--segments-per-curve", scene->segments_per_curve, "Cubic segments per curve")
      ->capture_default_str();
  c->add_option("--image-noise", scene->pixel_noise,
                "Std dev of the image intensity noise (8-bit units)")
      ->capture_default_str();
  c->add_option("--clutter", scene->num_clutter_edges, "Edges per image that belong to no 3D curve")
      ->capture_default_str();
  c->add_option("--occlusion", scene->occlusion_fraction,
                "Probability that 30-50% of a curve is hidden in a keyframe")
      ->capture_default_str();
  c->add_option("--pose-noise-trans", scene->pose_noise_translation,
                "Start-guess camera centre noise (m)")
      ->capture_default_str();
  c->add_option("--pose-noise-rot", scene->pose_noise_rotation_deg,
                "Start-guess rotation noise (deg)")
      ->capture_default_str();
  c->add_option("--curve-point-noise", scene->curve_point_noise,
                "Start-guess noise of the curve points Q (m)")
      ->capture_default_str();
  c->add_option("--curve-tangent-noise", scene->curve_tangent_noise_deg,
                "Start-guess noise of the tangents v per component (deg)")
      ->capture_default_str();
  c->add_option("--curve-length-noise", scene->curve_length_noise,
                "Start-guess relative noise of the tangent lengths d1, d2")
      ->capture_default_str();
  c->add_option("--seed", scene->seed, "Random seed")->capture_default_str();
}

void addObjectiveFlags(CLI::App* c, CurveBundleAdjustmentOptions* ba) {
  c->add_option("--samples-per-segment", ba->samples_per_segment,
                "s: residuals per (segment, keyframe) pair are s + 1")
      ->capture_default_str();
  addBoolFlag(c, "subpixel-edges", &ba->use_subpixel_edges,
              "Measure against the sub-pixel edge position (false: the edge pixel centre)");
  c->add_option("--max-normal-angle", ba->max_normal_angle_deg,
                "Match a sample only to an edge whose normal is within this angle of the "
                "curve's (deg); 90 accepts every match")
      ->capture_default_str();
  addMeasurementFlags(c, ba);
  c->add_option("--lambda1", ba->lambda1,
                "Weight of the segment-length term (px^2/m^2); 0 drops it")
      ->capture_default_str();
  c->add_option("--lambda2", ba->lambda2, "Weight of the tangent term (px^2/rad^2); 0 drops it")
      ->capture_default_str();
}

nlohmann::json sceneOptionsToJson(const CurveSceneOptions& o) {
  const CameraIntrinsics& k = o.intrinsics;
  const Eigen::Vector3d& v = o.volume_half_extents;
  return {
      {"num_keyframes", o.num_keyframes},
      {"camera_path", toString(o.camera_path)},
      {"camera_distance", o.camera_distance},
      {"arc_degrees", o.arc_degrees},
      {"walk_length", o.walk_length},
      {"intrinsics",
       {{"fx", k.fx},
        {"fy", k.fy},
        {"cx", k.cx},
        {"cy", k.cy},
        {"k1", k.k1},
        {"k2", k.k2},
        {"p1", k.p1},
        {"p2", k.p2},
        {"k3", k.k3},
        {"width", k.width},
        {"height", k.height}}},
      {"num_curves", o.num_curves},
      {"curve_kind", toString(o.curve_kind)},
      {"segments_per_curve", o.segments_per_curve},
      {"min_curve_length", o.min_curve_length},
      {"max_curve_length", o.max_curve_length},
      {"volume_half_extents", {v.x(), v.y(), v.z()}},
      {"min_camera_distance", o.min_camera_distance},
      {"edge_blur_sigma_px", o.edge_blur_sigma_px},
      {"step_contrast", o.step_contrast},
      {"pixel_noise", o.pixel_noise},
      {"canny_low_threshold", o.canny_low_threshold},
      {"canny_high_threshold", o.canny_high_threshold},
      {"num_clutter_edges", o.num_clutter_edges},
      {"occlusion_fraction", o.occlusion_fraction},
      {"min_visible_fraction", o.min_visible_fraction},
      {"visibility_margin_px", o.visibility_margin_px},
      {"min_projected_length_px", o.min_projected_length_px},
      {"pose_noise_translation", o.pose_noise_translation},
      {"pose_noise_rotation_deg", o.pose_noise_rotation_deg},
      {"curve_point_noise", o.curve_point_noise},
      {"curve_tangent_noise_deg", o.curve_tangent_noise_deg},
      {"curve_length_noise", o.curve_length_noise},
      {"seed", o.seed},
  };
}

nlohmann::json objectiveOptionsToJson(const CurveBundleAdjustmentOptions& o) {
  return {{"samples_per_segment", o.samples_per_segment},
          {"use_subpixel_edges", o.use_subpixel_edges},
          {"max_normal_angle_deg", o.max_normal_angle_deg},
          {"pixel_sigma", o.pixel_sigma},
          {"kernel", toString(o.kernel)},
          {"kernel_width", o.kernel_width},
          {"lambda1", o.lambda1},
          {"lambda2", o.lambda2},
          {"fix_first_pose", o.fix_first_pose},
          {"fix_scale", o.fix_scale},
          {"scale_sigma", o.scale_sigma}};
}

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
  addSceneFlags(command_, &scene_);
  addObjectiveFlags(command_, &ba_);
  addSchedulerFlags(command_, &scheduler_);
  command_->add_option("--report", report_path_,
                       "Write a JSON report (configuration, rounds, errors, sample counts)");
}

SchedulerOptions CurveBaCommand::schedulerOptions() const {
  SchedulerOptions scheduler = scheduler_;
  scheduler.fix_first_pose = ba_.fix_first_pose;
  return scheduler;
}

void CurveBaCommand::validate() const {
  scene_.validate();
  ba_.validate();
  schedulerOptions().validate();
}

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
                               {"config", optionsToJson(*command_)},
                               {"options",
                                {{"scene", sceneOptionsToJson(scene_)},
                                 {"bundle_adjustment", objectiveOptionsToJson(ba_)},
                                 {"scheduler", schedulerOptionsToJson(scheduler)}}},
                               {"scene", sceneCountsToJson(scene)},
                               {"before", snapshotToJson(before)},
                               {"after", snapshotToJson(after)},
                               {"schedule", scheduleReportToJson(schedule)}});
  }
  return allSolvesUsable(schedule) ? 0 : 1;
}

}  // namespace curvesfm
