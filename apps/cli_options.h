#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "graph/optimizer.h"
#include "graph/robust_kernel.h"

namespace curvesfm {

/// Registers the OptimizerOptions flags (--linear-solver, --trust-region, --max-iterations,
/// --threads, --function-tolerance, ..., --verbose) on `command`, writing into `options`.
void addOptimizerFlags(CLI::App* command, OptimizerOptions* options);

/// Registers `--<name>` taking a robust kernel name (none, huber, cauchy, tukey).
CLI::Option* addKernelFlag(CLI::App* command, const std::string& name, RobustKernelType* kernel,
                           const std::string& description);

/// Adds `--config FILE.yaml` (YAML keys are long flag names) to `command`.
void addConfigFlag(CLI::App* command);

/// The effective options of `command` as a JSON object (for report.json).
nlohmann::json optionsToJson(const CLI::App& command);

/// An OptimizationSummary as a JSON object (for report.json).
nlohmann::json summaryToJson(const OptimizationSummary& summary);

}  // namespace curvesfm
