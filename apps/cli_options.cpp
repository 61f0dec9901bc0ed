#include "apps/cli_options.h"

#include <memory>

#include "core/errors.h"

#include "apps/config_file.h"

namespace curvesfm {
namespace {

// `--name VALUE` for an enum: the option keeps the name the user gave (so the echoed
// configuration shows names), a check rejects unknown names with the list of accepted ones,
// and the parsed value lands in `*target`.
template <class Enum>
CLI::Option* addEnumOption(CLI::App* command, const std::string& name, Enum* target,
                           Enum (*parse)(const std::string&, const std::string&),
                           const std::string& description) {
  const std::string field = name;
  return command
      ->add_option_function<std::string>(
          "--" + name, [target, parse, field](const std::string& value) {
            *target = parse(value, field);
          },
          description)
      ->check(CLI::Validator(
          [parse, field](std::string& value) -> std::string {
            try {
              parse(value, field);
              return "";
            } catch (const InvalidOptions& e) {
              return e.what();
            }
          },
          "NAME"))
      ->default_str(toString(*target));
}

nlohmann::json costsToJson(const std::map<std::string, FactorTypeCost>& costs) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [type, cost] : costs) json[type] = {{"count", cost.count}, {"cost", cost.cost}};
  return json;
}

}  // namespace

void addOptimizerFlags(CLI::App* command, OptimizerOptions* options) {
  addEnumOption(command, "linear-solver", &options->linear_solver, parseLinearSolver,
                "Linear solver of each step: sparse_schur, dense_schur, iterative_schur, "
                "sparse_normal_cholesky");
  addEnumOption(command, "trust-region", &options->trust_region, parseTrustRegion,
                "Trust-region strategy: levenberg_marquardt, dogleg");
  command->add_option("--max-iterations", options->max_iterations, "Maximum solver iterations")
      ->capture_default_str();
  command->add_option("--threads", options->num_threads, "Solver threads")->capture_default_str();
  command->add_option("--function-tolerance", options->function_tolerance,
                      "Stop when the relative cost change falls below this")
      ->capture_default_str();
  command->add_option("--gradient-tolerance", options->gradient_tolerance,
                      "Stop when the max gradient falls below this")
      ->capture_default_str();
  command->add_option("--parameter-tolerance", options->parameter_tolerance,
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
  return addEnumOption(command, name, kernel, parseRobustKernelType,
                       description + ": none, huber, cauchy, tukey");
}

void addConfigFlag(CLI::App* command) {
  command->add_option("--config", "YAML file of options (keys are long flag names); flags given "
                                  "on the command line override it");
}

nlohmann::json optionsToJson(const CLI::App& command) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [name, value] : effectiveOptions(command)) json[name] = value;
  return json;
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

}  // namespace curvesfm
