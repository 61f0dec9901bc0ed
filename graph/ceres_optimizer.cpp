// optimize() from graph/optimizer.h; it lives in a ceres_* file because it drives Ceres.
#include <ceres/solver.h>

#include <algorithm>
#include <optional>

#include "core/clock.h"
#include "graph/ceres_problem.h"
#include "graph/component_solver.h"
#include "graph/levenberg_marquardt.h"
#include "graph/optimizer.h"
#include "graph/schur_solver.h"

namespace curvesfm {
namespace {

bool isSchur(LinearSolver solver) {
  return solver == LinearSolver::kSparseSchur || solver == LinearSolver::kDenseSchur ||
         solver == LinearSolver::kIterativeSchur || solver == LinearSolver::kGraphSchur;
}

// Hands every iteration of a solve to OptimizerOptions::on_iteration, and ends a stalled one
// (OptimizerOptions::stall_iterations).
class IterationHook : public ceres::IterationCallback {
 public:
  explicit IterationHook(const OptimizerOptions& options)
      : hook_(options.on_iteration),
        window_(options.stall_iterations),
        tolerance_(options.stall_tolerance) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (hook_) hook_({s.iteration, s.cost, s.cumulative_time_in_seconds, s.step_is_successful});
    if (s.iteration == 0) {
      stall_.emplace(window_, tolerance_, s.cost);
      return ceres::SOLVER_CONTINUE;
    }
    return stall_ && stall_->stalled(s.cost) ? ceres::SOLVER_TERMINATE_SUCCESSFULLY
                                             : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::function<void(const IterationProgress&)>& hook_;
  int window_;
  double tolerance_;
  std::optional<StallTest> stall_;
};

}  // namespace

OptimizationSummary optimize(const FactorGraph& graph, Values* values, const ProblemConfig& config,
                             const OptimizerOptions& options) {
  options.validate();
  if (options.solve_components_apart && !hasFreePose(graph, config)) {
    return optimizeComponents(graph, values, config, options);
  }
  std::string graph_schur_refused;
  if (options.linear_solver == LinearSolver::kGraphSchur) {
    std::optional<OptimizationSummary> summary =
        optimizeWithGraphSchur(graph, values, config, options, &graph_schur_refused);
    if (summary) return *summary;
  }
  const auto start = Clock::now();
  OptimizationSummary summary;
  summary.num_factors = static_cast<int>(graph.size());

  CeresProblem bridge(graph, *values, config, options);
  summary.initial_cost_by_type = bridge.costByType();
  ceres::Solver::Options ceres_options = toCeresOptions(options);
  summary.ordering = "automatic";
  if (isSchur(options.linear_solver) && !bridge.hasFreePose()) {
    // With every pose held nothing is left for a Schur complement to reduce to: the normal
    // equations are block diagonal per curve and point, and a sparse Cholesky of them gives
    // the same step without the eliminator's per-block overhead.
    ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    summary.ordering = "none (no free pose: sparse normal Cholesky)";
  } else if (options.structure_first_ordering) {
    std::string why_not;
    std::string blocks;
    ceres_options.linear_solver_ordering = bridge.structureFirstOrdering(&why_not, &blocks);
    summary.ordering = ceres_options.linear_solver_ordering ? "structure_first (" + blocks + ")"
                                                            : "automatic (" + why_not + ")";
  }
  if (options.use_inner_iterations) {
    ceres_options.inner_iteration_ordering = bridge.innerIterationOrdering();
  }
  if (!graph_schur_refused.empty()) {
    summary.ordering += "; Ceres instead of graph_schur: " + graph_schur_refused;
  }
  summary.num_constant_variables = bridge.numConstant();
  summary.num_curve_blocks = bridge.numCurveBlocks();
  summary.num_free_variables = static_cast<int>(bridge.keys().size()) - bridge.numConstant();
  summary.setup_seconds = secondsSince(start);

  IterationHook hook(options);
  if (options.on_iteration || options.stall_iterations > 0) {
    ceres_options.callbacks.push_back(&hook);
  }
  const auto solve_start = Clock::now();
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(ceres_options, &bridge.problem(), &ceres_summary);
  summary.solve_seconds = secondsSince(solve_start);

  const auto writeback_start = Clock::now();
  bridge.writeBack(values);
  summary.final_cost_by_type = bridge.costByType();
  summary.writeback_seconds = secondsSince(writeback_start);

  summary.initial_cost = ceres_summary.initial_cost;
  summary.final_cost = ceres_summary.final_cost;
  // Ceres lists iteration 0 (the starting point) too.
  summary.iterations = std::max(0, static_cast<int>(ceres_summary.iterations.size()) - 1);
  summary.usable = ceres_summary.IsSolutionUsable();
  summary.termination = ceres::TerminationTypeToString(ceres_summary.termination_type);
  summary.message = ceres_summary.message;
  if (ceres_summary.termination_type == ceres::USER_SUCCESS) {
    // Only IterationHook ends a solve this way: a stalled cost, converged as in graph_schur.
    summary.termination = "CONVERGENCE";
    summary.message = "Cost stalled.";
  }
  summary.linear_solver = ceres::LinearSolverTypeToString(ceres_summary.linear_solver_type_used);
  summary.num_residuals = ceres_summary.num_residuals;
  summary.num_effective_parameters = ceres_summary.num_effective_parameters;
  summary.minimizer_seconds = ceres_summary.minimizer_time_in_seconds;
  summary.full_report = ceres_summary.FullReport();
  summary.total_seconds = secondsSince(start);
  return summary;
}

}  // namespace curvesfm
