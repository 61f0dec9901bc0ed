#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/trajectory_evaluation.h"
#include "factors/curve_reprojection_factor.h"
#include "graph/optimizer.h"
#include "graph/robust_kernel.h"
#include "graph/scheduler.h"

namespace curvesfm {

/// Registers `--<name>` taking an enum by name. `parse(value, name)` converts it and throws
/// InvalidOptions listing the accepted names for an unknown one, which CLI11 turns into a usage
/// error naming the flag. The option keeps the name the user gave, so the echoed configuration
/// shows names; the default shown is `toString(*target)`.
template <class Enum>
CLI::Option* addEnumFlag(CLI::App* command, const std::string& name, Enum* target,
                         Enum (*parse)(const std::string&, const std::string&),
                         const std::string& description) {
  return command
      ->add_option_function<std::string>(
          "--" + name,
          [target, parse, name](const std::string& value) { *target = parse(value, name); },
          description)
      ->check(CLI::Validator(
          [parse, name](std::string& value) -> std::string {
            try {
              parse(value, name);
              return "";
            } catch (const InvalidOptions& e) {
              return e.what();
            }
          },
          "NAME"))
      ->default_str(toString(*target));
}

/// Registers `--<name> BOOL` (true/false, yes/no, on/off, 1/0; echoed as true or false): a
/// switch whose default is on needs a value, since a YAML `false` cannot switch a bare flag off.
CLI::Option* addBoolFlag(CLI::App* command, const std::string& name, bool* target,
                         const std::string& description);

/// Registers the OptimizerOptions flags (--linear-solver, --trust-region, --max-iterations,
/// --threads, --function-tolerance, ..., --verbose) on `command`, writing into `options`.
void addOptimizerFlags(CLI::App* command, OptimizerOptions* options);

/// Registers `--<name>` taking a robust kernel name (none, huber, cauchy, tukey).
CLI::Option* addKernelFlag(CLI::App* command, const std::string& name, RobustKernelType* kernel,
                           const std::string& description);

/// Registers the measurement and gauge flags point and curve bundle adjustment share on
/// `command`: --pixel-sigma, --kernel, --kernel-width, --fix-first-pose, --fix-scale,
/// --scale-sigma. `Options` is PointBundleAdjustmentOptions or CurveBundleAdjustmentOptions.
template <class Options>
void addMeasurementFlags(CLI::App* command, Options* options) {
  command->add_option("--pixel-sigma", options->pixel_sigma, "Std dev of an image residual (px)")
      ->capture_default_str();
  addKernelFlag(command, "kernel", &options->kernel, "Robust kernel on image residuals");
  command->add_option("--kernel-width", options->kernel_width, "Kernel width (sigmas)")
      ->capture_default_str();
  addBoolFlag(command, "fix-first-pose", &options->fix_first_pose,
              "Hold the first camera constant (rotation and translation gauge)");
  addBoolFlag(command, "fix-scale", &options->fix_scale,
              "Hold the distance between the first two cameras at its true value (scale gauge)");
  command
      ->add_option("--scale-sigma", options->scale_sigma,
                   "Std dev of that distance constraint (scene units)")
      ->capture_default_str();
}

/// Registers the SchedulerOptions flags (--strategy, --scope, --local-window, --max-rounds,
/// --round-tolerance) and those of its OptimizerOptions on `command`. fix_first_pose is left to
/// the caller, which holds one gauge switch for the graph builder and the scheduler.
void addSchedulerFlags(CLI::App* command, SchedulerOptions* options);

/// Parses `args` (without the program name) into `app`; if `app` itself or the selected
/// sub-command (nested ones included, e.g. `synth planar`) got `--config FILE`, parses again with
/// the file's flags in front of the user's own so that flags given on the command line win, and
/// required flags may come from the file; that needs options that keep the last value given
/// (`app->option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)` before the
/// sub-commands are added). Throws CLI::ParseError (unknown flag, bad value) and what
/// configFileArguments() throws (unreadable or malformed config file).
void parseCommandLine(CLI::App* app, const std::vector<std::string>& args);

/// Adds `--config FILE.yaml` (YAML keys are long flag names) to `command`.
void addConfigFlag(CLI::App* command);

/// The effective options of `command` as a JSON object (for report.json).
nlohmann::json optionsToJson(const CLI::App& command);

/// An OptimizationSummary as a JSON object (for report.json).
nlohmann::json summaryToJson(const OptimizationSummary& summary);

/// Costs per factor type as {type: {count, cost}} (for report.json).
nlohmann::json costsToJson(const std::map<std::string, FactorTypeCost>& costs);

/// Every field of the options as a JSON object, enums by name (for report.json).
nlohmann::json optimizerOptionsToJson(const OptimizerOptions& options);
nlohmann::json schedulerOptionsToJson(const SchedulerOptions& options);

/// A ScheduleReport as a JSON object: totals, stop reason, warnings and every phase with its
/// solver summary (for report.json).
nlohmann::json scheduleReportToJson(const ScheduleReport& report);

/// Where curve samples fall (CurveSampleCounts) as a JSON object with a total.
nlohmann::json sampleCountsToJson(const CurveSampleCounts& counts);

/// The matched poses of `evaluation` in match order, as {"timestamp": [...] (the estimate's, s),
/// "error_m": [...] (ATE), "aligned_position": [[x, y, z], ...] (the aligned estimated camera
/// centre), "ground_truth_position": [[x, y, z], ...]} in the ground truth's world (m), so that
/// figures draw the alignment without computing it again.
nlohmann::json matchedPosesToJson(const TrajectoryEvaluation& evaluation);

/// Writes `json` (indented) to `path`; IoError naming the path if it cannot.
void writeJsonFile(const std::string& path, const nlohmann::json& json);

}  // namespace curvesfm
