#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>

#include "core/enum_names.h"
#include "graph/factor_graph.h"
#include "graph/key.h"
#include "graph/values.h"

namespace curvesfm {

/// What to optimise: the variables held constant, by key or by category (COLMAP keeps this
/// apart from how to solve, and so do we). Everything else that a factor touches is free.
struct ProblemConfig {
  std::set<Key> constant_keys;                     ///< Held at their current value.
  std::set<VariableCategory> constant_categories;  ///< Every variable of these categories.

  void setConstant(Key key) { constant_keys.insert(key); }
  void setConstant(VariableCategory category) { constant_categories.insert(category); }
  bool isConstant(Key key) const {
    return constant_keys.count(key) > 0 || constant_categories.count(categoryOf(key)) > 0;
  }
};

enum class LinearSolver {
  kSparseSchur,
  kDenseSchur,
  kIterativeSchur,
  kSparseNormalCholesky,
  kGraphSchur
};
enum class TrustRegion { kLevenbergMarquardt, kDogleg };

template <>
struct EnumNames<LinearSolver> {
  static constexpr std::array<std::pair<LinearSolver, const char*>, 5> kNames = {{
      {LinearSolver::kSparseSchur, "sparse_schur"},
      {LinearSolver::kDenseSchur, "dense_schur"},
      {LinearSolver::kIterativeSchur, "iterative_schur"},
      {LinearSolver::kSparseNormalCholesky, "sparse_normal_cholesky"},
      {LinearSolver::kGraphSchur, "graph_schur"},
  }};
};
template <>
struct EnumNames<TrustRegion> {
  static constexpr std::array<std::pair<TrustRegion, const char*>, 2> kNames = {{
      {TrustRegion::kLevenbergMarquardt, "levenberg_marquardt"},
      {TrustRegion::kDogleg, "dogleg"},
  }};
};

/// Where a running solve is, after one of its iterations (for a progress display).
struct IterationProgress {
  int iteration = 0;           ///< 0: the start, before any step.
  double cost = 0.0;           ///< Cost after the iteration (Ceres' convention).
  double seconds = 0.0;        ///< Since the solve started.
  bool step_accepted = false;  ///< The iteration's step lowered the cost and was kept.
};

/// How to solve (the Ceres settings we expose).
struct OptimizerOptions {
  /// Linear solver of each step. Schur solvers eliminate structure (points, curve variables)
  /// first; iterative_schur uses the SCHUR_JACOBI preconditioner; sparse ones use SuiteSparse.
  /// A solve with every pose held (structure only) uses sparse_normal_cholesky whatever this
  /// says: there is no reduced system, and the step is the same. graph_schur is not Ceres: our
  /// own Levenberg-Marquardt with every curve and point eliminated by a dense Schur complement
  /// and a dense reduced system over the poses (graph/schur_solver.h; same objective, damping
  /// and stopping rules; the ordering and curve blocks do not apply). Beyond its size limits, and
  /// with inner iterations or dogleg, it hands the problem to Ceres' sparse_schur and says so in
  /// the summary's ordering.
  LinearSolver linear_solver = LinearSolver::kSparseSchur;
  TrustRegion trust_region = TrustRegion::kLevenbergMarquardt;  ///< Step strategy.
  int max_iterations = 50;                                      ///< Outer iterations; >= 0.
  /// The first step's trust region (Ceres' initial_trust_region_radius; Levenberg-Marquardt's
  /// first damping is its inverse). Ceres' default 1e4 lets the first steps go nearly
  /// undamped, and a solve far from its optimum rejects a handful of them first; > 0.
  double initial_trust_region_radius = 1e4;
  int num_threads = 1;                ///< Threads for evaluation and linear algebra; >= 1.
  double function_tolerance = 1e-6;   ///< Stop when |dcost|/cost < this; > 0.
  double gradient_tolerance = 1e-10;  ///< Stop when max |gradient| < this; > 0.
  double parameter_tolerance = 1e-8;  ///< Stop when |dx| / (|x| + tol) < this; > 0.
  /// Stop when the lowest cost so far fell by less than stall_tolerance of itself over the
  /// last stall_iterations iterations, kept or rejected, counted from the first step that lowers
  /// the cost (the rejected ones before it shrink the first trust region); 0: off, >= 0. The
  /// nearest-edge cost is rough at the pixel scale: near its minimum Levenberg-Marquardt
  /// alternates rejected steps with kept ones that gain a millionth, which function_tolerance
  /// (one step's change) does not end (docs/benchmarks.md, "A budget for re-association's
  /// global BAs").
  int stall_iterations = 0;
  double stall_tolerance = 1e-3;  ///< See stall_iterations; > 0.
  /// Schur elimination order: structure first, poses last. Falls back to Ceres' automatic
  /// ordering (and says so in the summary) when most structure blocks share a factor with
  /// another one (a block per curve variable).
  bool structure_first_ordering = true;
  /// One solver block per curve: its free Q, v and d together, held as offsets from their start
  /// values (anchored charts, see retractAnchored), so that every curve factor touches one pose
  /// block and one structure block and the Schur complement eliminates whole curves: the reduced
  /// system holds the poses (and any structure still coupled). Same objective and optimum as a
  /// block per variable, where Ceres can eliminate only an independent subset of the curve
  /// variables and the rest stays in the reduced system. Only when some pose is free (with
  /// every pose held the curves do not meet in a reduced system, and a block per variable keeps
  /// each Jacobian as narrow as its segment) and without inner iterations (which refine each
  /// block alone; on whole curves they did worse on the strategy bench).
  bool curve_blocks = true;
  /// A curve with more free tangent dimensions than this (7 per segment + 5) keeps a block per
  /// variable: every observation fills a Jacobian as wide as its curve's block; >= 1.
  int max_curve_block_size = 229;
  /// With every pose held, solve each connected component of the free variables (each curve,
  /// each point) alone with our own dense Levenberg-Marquardt (graph/component_solver.h) instead
  /// of one Ceres solve over all of them, whose single trust region rejects every curve's step
  /// when one curve overshoots. Same objective and tolerances; max_iterations then counts per
  /// component. Off by default: the pipeline's local BA is 3x faster with it, but each curve run
  /// to its own tolerance ends on the favourable side of the nearest-edge residual's jumps, and
  /// the first global BA then finds no step that lowers the cost (docs/benchmarks.md,
  /// "Structure-only solves").
  bool solve_components_apart = false;
  /// Ceres inner iterations (a non-linear refinement of each step per independent block set).
  bool use_inner_iterations = false;
  bool verbose = false;  ///< Print Ceres' per-iteration log to stdout.
  /// Called after every iteration, e.g. to print a progress line during a long solve; empty for
  /// none. A hook for the program, not a tunable: no flag sets it, and report.json lists it
  /// without a value.
  std::function<void(const IterationProgress&)> on_iteration;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// What one optimisation did. Costs follow Ceres' convention: cost = 0.5 * sum rho(|r / sigma|^2).
struct OptimizationSummary {
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::map<std::string, FactorTypeCost> initial_cost_by_type;  ///< Per Factor::typeName().
  std::map<std::string, FactorTypeCost> final_cost_by_type;
  int iterations = 0;         ///< Outer iterations Ceres ran (excluding iteration 0).
  bool usable = false;        ///< Ceres' IsSolutionUsable(): converged or hit a limit.
  std::string termination;    ///< "CONVERGENCE", "NO_CONVERGENCE" (iteration limit), ...
  std::string message;        ///< Ceres' reason for terminating.
  std::string linear_solver;  ///< Linear solver Ceres actually used.
  /// "structure_first (E eliminated, R reduced blocks)", why Ceres chose ("automatic (...)"),
  /// or "none (...)" when no pose is free.
  std::string ordering;
  int num_curve_blocks = 0;  ///< Curves solved as one block each (OptimizerOptions::curve_blocks).
  int num_factors = 0;
  int num_free_variables = 0;
  int num_constant_variables = 0;
  int num_residuals = 0;
  int num_effective_parameters = 0;  ///< Free tangent dimensions.
  double setup_seconds = 0.0;        ///< Graph to Ceres problem, and per-type costs.
  double solve_seconds = 0.0;        ///< Ceres Solve() wall time.
  double minimizer_seconds = 0.0;    ///< Ceres' time in the minimiser (iterations only).
  double writeback_seconds = 0.0;    ///< Results back into Values, and per-type costs.
  double total_seconds = 0.0;
  std::string full_report;  ///< Ceres' FullReport().

  /// A compact multi-line block: costs before/after per factor type, iterations, times.
  std::string toString() const;
};

/// Minimises the graph's cost over the free variables of `values` (updated in place) with Ceres.
/// Every key a factor uses must be in `values` with the factor's type (KeyDoesNotExist /
/// IncorrectType otherwise); variables no factor touches are left alone.
OptimizationSummary optimize(const FactorGraph& graph, Values* values, const ProblemConfig& config,
                             const OptimizerOptions& options);

}  // namespace curvesfm
