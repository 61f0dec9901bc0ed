#include "apps/cli/report_json.h"

#include <Eigen/Geometry>
#include <fstream>

#include "apps/cli/version_info.h"  // generated under the build tree (apps/cli/CMakeLists.txt)
#include "core/angles.h"
#include "core/errors.h"

namespace curvesfm {

nlohmann::json versionJson() {
  return {{"version", CURVESFM_VERSION}, {"commit", CURVESFM_GIT_COMMIT}};
}

nlohmann::json costsToJson(const std::map<std::string, FactorTypeCost>& costs) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [type, cost] : costs) json[type] = {{"count", cost.count}, {"cost", cost.cost}};
  return json;
}

nlohmann::json scheduleReportToJson(const ScheduleReport& report) {
  nlohmann::json rounds = nlohmann::json::array();
  for (const ScheduleRound& round : report.rounds) {
    nlohmann::json entry = {
        {"round", round.round}, {"phase", round.phase}, {"skipped", round.skipped}};
    if (!round.skipped) entry["summary"] = summaryToJson(round.summary);
    rounds.push_back(entry);
  }
  return {{"strategy", toString(report.strategy)},
          {"scope", toString(report.scope)},
          {"num_rounds", report.num_rounds},
          {"num_factors", report.num_factors},
          {"num_active_factors", report.num_active_factors},
          {"initial_cost", report.initial_cost},
          {"final_cost", report.final_cost},
          {"total_iterations", report.total_iterations},
          {"total_seconds", report.total_seconds},
          {"converged", report.converged},
          {"stop_reason", report.stop_reason},
          {"warnings", report.warnings},
          {"rounds", rounds}};
}

nlohmann::json summaryToJson(const OptimizationSummary& summary) {
  return {
      {"initial_cost", summary.initial_cost},
      {"final_cost", summary.final_cost},
      {"cost_convention", "0.5 * sum rho(|r / sigma|^2)"},
      {"initial_cost_by_type", costsToJson(summary.initial_cost_by_type)},
      {"final_cost_by_type", costsToJson(summary.final_cost_by_type)},
      {"iterations", summary.iterations},
      {"usable", summary.usable},
      {"termination", summary.termination},
      {"message", summary.message},
      {"linear_solver", summary.linear_solver},
      {"ordering", summary.ordering},
      {"num_factors", summary.num_factors},
      {"num_free_variables", summary.num_free_variables},
      {"num_constant_variables", summary.num_constant_variables},
      {"num_curve_blocks", summary.num_curve_blocks},
      {"num_residuals", summary.num_residuals},
      {"num_effective_parameters", summary.num_effective_parameters},
      {"seconds",
       {{"setup", summary.setup_seconds},
        {"solve", summary.solve_seconds},
        {"minimizer", summary.minimizer_seconds},
        {"writeback", summary.writeback_seconds},
        {"total", summary.total_seconds}}},
  };
}

nlohmann::json sampleCountsToJson(const CurveSampleCounts& counts) {
  return {{"on_field", counts.on_field},
          {"behind_camera", counts.behind_camera},
          {"outside_image", counts.outside_image},
          {"beyond_reach", counts.beyond_reach},
          {"wrong_orientation", counts.wrong_orientation},
          {"total", counts.total()}};
}

nlohmann::json matchedPosesToJson(const TrajectoryEvaluation& evaluation) {
  nlohmann::json poses = {{"timestamp", nlohmann::json::array()},
                          {"error_m", nlohmann::json::array()},
                          {"aligned_position", nlohmann::json::array()},
                          {"ground_truth_position", nlohmann::json::array()}};
  const auto xyz = [](const Eigen::Vector3d& p) { return nlohmann::json{p.x(), p.y(), p.z()}; };
  for (const MatchedPose& m : evaluation.matches) {
    poses["timestamp"].push_back(m.estimate_timestamp);
    poses["error_m"].push_back(m.position_error);
    poses["aligned_position"].push_back(xyz(m.aligned_estimate.translation()));
    poses["ground_truth_position"].push_back(xyz(m.ground_truth.translation()));
  }
  return poses;
}

nlohmann::json statisticsToJson(const ErrorStatistics& s) {
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max}};
}

nlohmann::json alignmentToJson(const TrajectoryEvaluation& e) {
  const Sim3& a = e.ground_truth_from_estimate;
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r)
    rotation.push_back({a.rotation(r, 0), a.rotation(r, 1), a.rotation(r, 2)});
  return {{"kind", toString(e.options.alignment)},
          {"maps", "ground_truth_from_estimate: x_gt = scale * rotation * x_est + translation"},
          {"scale", a.scale},
          {"rotation", rotation},
          {"rotation_angle_deg", Eigen::AngleAxisd(a.rotation).angle() * kRadToDeg},
          {"translation_m", {a.translation.x(), a.translation.y(), a.translation.z()}}};
}

void writeJsonFile(const std::string& path, const nlohmann::json& json) {
  std::ofstream out(path);
  if (!(out << json.dump(2) << "\n")) throw IoError(path, "cannot write");
}

}  // namespace curvesfm
