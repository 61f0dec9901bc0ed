#include "apps/cli_options.h"

#include <algorithm>
#include <fstream>
#include <memory>

#include "apps/config_file.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// The selected (possibly nested) sub-command's --config file, or empty when none was given.
std::string configPath(const CLI::App& app, const CLI::App** selected) {
  const CLI::Option* config = app.get_option_no_throw("--config");
  if (config && config->count() > 0) {
    *selected = &app;
    return config->as<std::string>();
  }
  for (const CLI::App* command : app.get_subcommands()) {
    const std::string nested = configPath(*command, selected);
    if (!nested.empty()) return nested;
  }
  return "";
}

// Where `command`'s own flags begin in `args`: after its name, which for a nested sub-command
// is looked up after its parent's (a flag value may spell a command name too).
std::vector<std::string>::iterator afterCommandName(const CLI::App& command,
                                                    std::vector<std::string>* args) {
  auto begin = args->begin();
  const CLI::App* parent = command.get_parent();
  if (!parent) return begin;  // A program without sub-commands: its flags start at once.
  if (parent && parent->get_parent()) begin = afterCommandName(*parent, args);
  return std::find(begin, args->end(), command.get_name()) + 1;
}

}  // namespace

nlohmann::json costsToJson(const std::map<std::string, FactorTypeCost>& costs) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [type, cost] : costs) json[type] = {{"count", cost.count}, {"cost", cost.cost}};
  return json;
}

CLI::Option* addBoolFlag(CLI::App* command, const std::string& name, bool* target,
                         const std::string& description) {
  // Normalised so that the echoed configuration reads true or false whatever was typed.
  const CLI::Validator spellings(
      [](std::string& value) -> std::string {
        const std::string lower = CLI::detail::to_lower(value);
        if (lower == "true" || lower == "yes" || lower == "on" || lower == "1") {
          value = "true";
        } else if (lower == "false" || lower == "no" || lower == "off" || lower == "0") {
          value = "false";
        } else {
          return "expected true or false (or yes/no, on/off, 1/0), found '" + value + "'";
        }
        return "";
      },
      "");
  return command->add_option("--" + name, *target, description)
      ->transform(spellings)
      ->type_name("BOOL")
      ->default_str(*target ? "true" : "false");
}

void addOptimizerFlags(CLI::App* command, OptimizerOptions* options) {
  addEnumFlag(command, "linear-solver", &options->linear_solver, parseLinearSolver,
              "Linear solver of each step: sparse_schur, dense_schur, iterative_schur, "
              "sparse_normal_cholesky");
  addEnumFlag(command, "trust-region", &options->trust_region, parseTrustRegion,
              "Trust-region strategy: levenberg_marquardt, dogleg");
  command->add_option("--max-iterations", options->max_iterations, "Maximum solver iterations")
      ->capture_default_str();
  command->add_option("--threads", options->num_threads, "Solver threads")->capture_default_str();
  command
      ->add_option("--function-tolerance", options->function_tolerance,
                   "Stop when the relative cost change falls below this")
      ->capture_default_str();
  command
      ->add_option("--gradient-tolerance", options->gradient_tolerance,
                   "Stop when the max gradient falls below this")
      ->capture_default_str();
  command
      ->add_option("--parameter-tolerance", options->parameter_tolerance,
                   "Stop when the relative step falls below this")
      ->capture_default_str();
  command->add_flag("!--no-structure-first", options->structure_first_ordering,
                    "Let Ceres choose the Schur elimination order");
  command->add_flag("--inner-iterations", options->use_inner_iterations,
                    "Use Ceres inner iterations");
  command->add_flag("--verbose", options->verbose, "Print the solver's per-iteration log");
}

CLI::Option* addKernelFlag(CLI::App* command, const std::string& name, RobustKernelType* kernel,
                           const std::string& description) {
  return addEnumFlag(command, name, kernel, parseRobustKernelType,
                     description + ": none, huber, cauchy, tukey");
}

void addSchedulerFlags(CLI::App* command, SchedulerOptions* options) {
  addEnumFlag(command, "strategy", &options->strategy, parseStrategy,
              "How the free variables are split into solves: joint, alternating (poses, then "
              "structure, per round), inner_iterations");
  addEnumFlag(command, "scope", &options->scope, parseScope,
              "Free variables: global (all), local (the last --local-window cameras and the "
              "structure they see)");
  command->add_option("--local-window", options->local_window, "Free cameras in local scope")
      ->capture_default_str();
  command->add_option("--max-rounds", options->max_rounds, "Alternating: most rounds")
      ->capture_default_str();
  command
      ->add_option("--round-tolerance", options->round_tolerance,
                   "Alternating: stop when a round lowers the cost by less than this fraction")
      ->capture_default_str();
  addOptimizerFlags(command, &options->optimizer);
}

void parseCommandLine(CLI::App* app, const std::vector<std::string>& args) {
  const CLI::App* command = nullptr;
  try {
    // CLI11 takes a vector in reverse order.
    app->parse(std::vector<std::string>(args.rbegin(), args.rend()));
  } catch (const CLI::RequiredError&) {
    // A required flag may come from the config file. CLI11 checks requirements after reading
    // every argument, so --config is known here; the second parse checks again.
    if (configPath(*app, &command).empty()) throw;
  }
  const std::string path = configPath(*app, &command);
  if (path.empty()) return;
  std::vector<std::string> expanded = args;
  const auto position = afterCommandName(*command, &expanded);
  const std::vector<std::string> from_file = configFileArguments(path, *command);
  expanded.insert(position, from_file.begin(), from_file.end());
  app->clear();
  app->parse(std::vector<std::string>(expanded.rbegin(), expanded.rend()));
}

void addConfigFlag(CLI::App* command) {
  command->add_option("--config",
                      "YAML file of options (keys are long flag names); flags given "
                      "on the command line override it");
}

nlohmann::json optionsToJson(const CLI::App& command) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [name, value] : effectiveOptions(command)) json[name] = value;
  return json;
}

nlohmann::json optimizerOptionsToJson(const OptimizerOptions& options) {
  return {{"linear_solver", toString(options.linear_solver)},
          {"trust_region", toString(options.trust_region)},
          {"max_iterations", options.max_iterations},
          {"num_threads", options.num_threads},
          {"function_tolerance", options.function_tolerance},
          {"gradient_tolerance", options.gradient_tolerance},
          {"parameter_tolerance", options.parameter_tolerance},
          {"structure_first_ordering", options.structure_first_ordering},
          {"use_inner_iterations", options.use_inner_iterations},
          {"verbose", options.verbose}};
}

nlohmann::json schedulerOptionsToJson(const SchedulerOptions& options) {
  return {{"strategy", toString(options.strategy)},
          {"scope", toString(options.scope)},
          {"local_window", options.local_window},
          {"max_rounds", options.max_rounds},
          {"round_tolerance", options.round_tolerance},
          {"fix_first_pose", options.fix_first_pose},
          {"optimizer", optimizerOptionsToJson(options.optimizer)}};
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

void writeJsonFile(const std::string& path, const nlohmann::json& json) {
  std::ofstream out(path);
  if (!(out << json.dump(2) << "\n")) throw IoError(path, "cannot write");
}

}  // namespace curvesfm
