#include "graph/scheduler.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iterator>
#include <sstream>
#include <unordered_set>

#include "core/check.h"
#include "core/clock.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr VariableCategory kStructureCategories[] = {
    VariableCategory::kPoint, VariableCategory::kCurvePoint, VariableCategory::kDirection,
    VariableCategory::kLength, VariableCategory::kOther};

bool isPose(Key key) { return categoryOf(key) == VariableCategory::kPose; }

// The factors sent to the solver, the variables they touch and what every phase holds constant.
struct ActiveSet {
  const FactorGraph* input = nullptr;
  FactorGraph reduced;  // local scope: the factors touching a free variable
  bool is_reduced = false;
  std::vector<Key> keys;  // distinct keys of the active factors, sorted
  ProblemConfig config;   // the caller's constants, the gauge and the scope's constants

  const FactorGraph& graph() const { return is_reduced ? reduced : *input; }
};

std::vector<Key> distinctKeys(const FactorGraph& graph) {
  std::vector<Key> keys;
  for (const auto& factor : graph) {
    keys.insert(keys.end(), factor->keys().begin(), factor->keys().end());
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

// Distinct pose keys of the graph; sorting orders them by index (they share one symbol).
std::vector<Key> poseKeys(const FactorGraph& graph) {
  std::vector<Key> poses;
  for (const auto& factor : graph) {
    std::copy_if(factor->keys().begin(), factor->keys().end(), std::back_inserter(poses), isPose);
  }
  std::sort(poses.begin(), poses.end());
  poses.erase(std::unique(poses.begin(), poses.end()), poses.end());
  return poses;
}

// Local scope: the window's poses and the structure they share a factor with are free; the
// factors touching one of them are active and their other variables constant.
void selectLocal(const std::vector<Key>& poses, int window, ActiveSet* active) {
  const std::size_t size = std::min(poses.size(), static_cast<std::size_t>(window));
  const std::unordered_set<Key> window_poses(poses.end() - size, poses.end());
  std::unordered_set<Key> free_keys = window_poses;
  for (const auto& factor : *active->input) {
    const auto& keys = factor->keys();
    if (std::none_of(keys.begin(), keys.end(),
                     [&](Key key) { return window_poses.count(key) > 0; })) {
      continue;
    }
    for (Key key : keys) {
      if (!isPose(key)) free_keys.insert(key);
    }
  }
  for (const auto& factor : *active->input) {
    const auto& keys = factor->keys();
    if (std::any_of(keys.begin(), keys.end(), [&](Key key) { return free_keys.count(key) > 0; })) {
      active->reduced.add(factor);
    }
  }
  active->is_reduced = true;
  active->keys = distinctKeys(active->reduced);
  for (Key key : active->keys) {
    if (free_keys.count(key) == 0) active->config.setConstant(key);
  }
}

ActiveSet selectActive(const FactorGraph& graph, const ProblemConfig& base,
                       const SchedulerOptions& options) {
  ActiveSet active;
  active.input = &graph;
  active.config = base;
  const std::vector<Key> poses = poseKeys(graph);
  if (options.fix_first_pose && !poses.empty()) active.config.setConstant(poses.front());
  if (options.scope == Scope::kLocal) {
    selectLocal(poses, options.local_window, &active);
  } else {
    active.keys = distinctKeys(graph);
  }
  return active;
}

bool hasFreeVariable(const ActiveSet& active, const ProblemConfig& config) {
  return std::any_of(active.keys.begin(), active.keys.end(),
                     [&](Key key) { return !config.isConstant(key); });
}

// Solves one phase, or records it as skipped when nothing in it is free. Returns whether it ran.
bool runPhase(const ActiveSet& active, Values* values, int round, const char* phase,
              const ProblemConfig& config, const OptimizerOptions& optimizer,
              ScheduleReport* report) {
  ScheduleRound entry;
  entry.round = round;
  entry.phase = phase;
  entry.skipped = !hasFreeVariable(active, config);
  if (!entry.skipped) {
    entry.summary = optimize(active.graph(), values, config, optimizer);
    report->total_iterations += entry.summary.iterations;
  }
  report->rounds.push_back(std::move(entry));
  return !report->rounds.back().skipped;
}

void stop(bool converged, std::string reason, ScheduleReport* report) {
  report->converged = converged;
  report->stop_reason = std::move(reason);
}

// A failed solve (Ceres' solution not usable, e.g. a linear solver failure) ends the schedule.
void stopIfFailed(const ScheduleRound& entry, ScheduleReport* report) {
  if (entry.skipped || entry.summary.usable) return;
  stop(false,
       "round " + std::to_string(entry.round) + ", phase " + entry.phase +
           " failed: " + entry.summary.termination + " (" + entry.summary.message + ")",
       report);
}

void runJoint(const ActiveSet& active, Values* values, const SchedulerOptions& options,
              ScheduleReport* report) {
  OptimizerOptions optimizer = options.optimizer;
  if (options.strategy == Strategy::kInnerIterations) optimizer.use_inner_iterations = true;
  report->num_rounds = 1;
  if (!runPhase(active, values, 1, "joint", active.config, optimizer, report)) {
    stop(true, "nothing to solve: every active variable is constant", report);
    return;
  }
  const OptimizationSummary& summary = report->rounds.back().summary;
  stop(summary.termination == "CONVERGENCE",
       "joint solve: " + summary.termination + " (" + summary.message + ")", report);
  stopIfFailed(report->rounds.back(), report);
}

// Cost at the start and end of the phases report->rounds[first..]; false if none ran.
bool roundCosts(const ScheduleReport& report, std::size_t first, double* before, double* after) {
  bool ran = false;
  for (std::size_t i = first; i < report.rounds.size(); ++i) {
    const ScheduleRound& entry = report.rounds[i];
    if (entry.skipped) continue;
    if (!ran) *before = entry.summary.initial_cost;
    *after = entry.summary.final_cost;
    ran = true;
  }
  return ran;
}

// Judges the finished round whose phases start at report->rounds[first]: returns true (and
// says why in the report) when the schedule should stop.
bool roundEndsSchedule(int round, std::size_t first, const SchedulerOptions& options,
                       ScheduleReport* report) {
  const bool poses_ran = !report->rounds[first].skipped;
  const bool structure_ran = !report->rounds[first + 1].skipped;
  if (!poses_ran && !structure_ran) {
    stop(true, "nothing to solve: every active variable is constant", report);
    return true;
  }
  double before = 0.0;
  double after = 0.0;
  roundCosts(*report, first, &before, &after);
  if (after > before) {
    report->warnings.push_back("round " + std::to_string(round) + ": cost rose from " +
                               formatOptionValue(before) + " to " + formatOptionValue(after));
  }
  if (!poses_ran || !structure_ran) {
    // With one phase empty a round is a joint solve; another round would repeat it.
    const OptimizationSummary& summary = report->rounds[poses_ran ? first : first + 1].summary;
    stop(summary.termination == "CONVERGENCE",
         std::string("only the ") + (poses_ran ? "poses" : "structure") +
             " phase has free variables, so one round is a full solve: " + summary.termination,
         report);
    return true;
  }
  const double change = before > 0.0 ? (before - after) / before : 0.0;
  if (change < options.round_tolerance) {
    stop(true,
         "round " + std::to_string(round) + ": relative cost change " + formatOptionValue(change) +
             " < round_tolerance " + formatOptionValue(options.round_tolerance),
         report);
    return true;
  }
  if (round < options.max_rounds) return false;
  stop(false,
       "max_rounds = " + std::to_string(options.max_rounds) +
           " reached; last relative cost change " + formatOptionValue(change),
       report);
  return true;
}

void runAlternating(const ActiveSet& active, Values* values, const SchedulerOptions& options,
                    ScheduleReport* report) {
  ProblemConfig poses_config = active.config;
  for (VariableCategory category : kStructureCategories) poses_config.setConstant(category);
  ProblemConfig structure_config = active.config;
  structure_config.setConstant(VariableCategory::kPose);
  for (int round = 1; round <= options.max_rounds; ++round) {
    report->num_rounds = round;
    const std::size_t first = report->rounds.size();
    runPhase(active, values, round, "poses", poses_config, options.optimizer, report);
    stopIfFailed(report->rounds.back(), report);
    if (!report->stop_reason.empty()) return;
    runPhase(active, values, round, "structure", structure_config, options.optimizer, report);
    stopIfFailed(report->rounds.back(), report);
    if (!report->stop_reason.empty() || roundEndsSchedule(round, first, options, report)) return;
  }
}

void writeCostRows(std::ostream& os, const ScheduleRound& entry) {
  const OptimizationSummary& summary = entry.summary;
  os << std::setw(5) << entry.round << "  " << std::left << std::setw(11) << entry.phase
     << std::setw(22) << "total" << std::right << std::setw(8) << summary.num_factors
     << std::setw(14) << summary.initial_cost << std::setw(14) << summary.final_cost << std::setw(7)
     << summary.iterations << std::fixed << std::setprecision(3) << std::setw(9)
     << summary.total_seconds << std::defaultfloat << std::setprecision(6) << "  "
     << summary.num_free_variables << "/" << summary.num_constant_variables << "\n";
  for (const auto& [type, initial] : summary.initial_cost_by_type) {
    const auto it = summary.final_cost_by_type.find(type);
    const double final_cost = it == summary.final_cost_by_type.end() ? 0.0 : it->second.cost;
    os << std::setw(18) << "" << std::left << std::setw(22) << type << std::right << std::setw(8)
       << initial.count << std::setw(14) << initial.cost << std::setw(14) << final_cost << "\n";
  }
}

}  // namespace

void SchedulerOptions::validate() const {
  const OptionCheck require("SchedulerOptions");
  require(local_window >= 1, "local_window", local_window, "must be >= 1");
  require(max_rounds >= 1, "max_rounds", max_rounds, "must be >= 1");
  require.nonNegative("round_tolerance", round_tolerance);
  optimizer.validate();
}

std::string ScheduleReport::toString() const {
  std::ostringstream os;
  os << std::setprecision(6);
  os << "schedule " << curvesfm::toString(strategy) << ", " << curvesfm::toString(scope)
     << " scope: " << num_rounds << (num_rounds == 1 ? " round, " : " rounds, ")
     << num_active_factors << " of " << num_factors << " factors active, cost " << initial_cost
     << " -> " << final_cost << ", " << total_iterations << " iterations, " << std::fixed
     << std::setprecision(3) << total_seconds << " s" << std::defaultfloat << std::setprecision(6)
     << "; " << (converged ? "converged" : "not converged") << ": " << stop_reason << "\n";
  os << "round  " << std::left << std::setw(11) << "phase" << std::setw(22) << "factor type"
     << std::right << std::setw(8) << "count" << std::setw(14) << "cost before" << std::setw(14)
     << "cost after" << std::setw(7) << "iters" << std::setw(9) << "seconds"
     << "  free/constant\n";
  for (const ScheduleRound& entry : rounds) {
    if (entry.skipped) {
      os << std::setw(5) << entry.round << "  " << std::left << std::setw(11) << entry.phase
         << std::right << "skipped: no free variable\n";
      continue;
    }
    writeCostRows(os, entry);
  }
  for (const std::string& warning : warnings) os << "warning: " << warning << "\n";
  return os.str();
}

ScheduleReport runSchedule(const FactorGraph& graph, Values* values, const ProblemConfig& base,
                           const SchedulerOptions& options) {
  options.validate();
  CURVESFM_CHECK(values != nullptr) << "runSchedule: values is null";
  const auto start = Clock::now();
  ScheduleReport report;
  report.strategy = options.strategy;
  report.scope = options.scope;
  report.num_factors = static_cast<int>(graph.size());
  const ActiveSet active = selectActive(graph, base, options);
  report.num_active_factors = static_cast<int>(active.graph().size());
  if (active.graph().empty()) {
    stop(true, graph.empty() ? "empty graph" : "no factor touches a free variable", &report);
  } else if (options.strategy == Strategy::kAlternating) {
    runAlternating(active, values, options, &report);
  } else {
    runJoint(active, values, options, &report);
  }
  if (!roundCosts(report, 0, &report.initial_cost, &report.final_cost)) {
    report.initial_cost = report.final_cost = active.graph().cost(*values);
  }
  report.total_seconds = secondsSince(start);
  return report;
}

}  // namespace curvesfm
