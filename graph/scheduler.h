#pragma once

#include <string>
#include <vector>

#include "core/enum_names.h"
#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/values.h"

namespace curvesfm {

/// How the free variables are split into solves. Poses are the variables of category kPose;
/// structure is every other category (points, curve points, directions, lengths, and any
/// kOther symbol), read from the keys: the scheduler knows no concrete factor.
enum class Strategy {
  /// One solve over every free variable.
  kJoint,
  /// Rounds of two solves: poses with structure constant, then structure with poses constant,
  /// until a round lowers the cost by less than round_tolerance (relative) or max_rounds.
  kAlternating,
  /// One joint solve with Ceres' inner iterations (OptimizerOptions::use_inner_iterations).
  kInnerIterations,
};

/// Which variables are free at all (before the strategy splits them).
enum class Scope {
  /// Every variable some factor touches.
  kGlobal,
  /// Local window bundle adjustment: the last local_window poses (by index, among the pose keys
  /// the graph uses) and every structure variable that shares a factor with one of them are
  /// free; all other variables are constant. Factors whose variables are all constant are not
  /// sent to the solver.
  kLocal,
};

template <>
struct EnumNames<Strategy> {
  static constexpr std::array<std::pair<Strategy, const char*>, 3> kNames = {{
      {Strategy::kJoint, "joint"},
      {Strategy::kAlternating, "alternating"},
      {Strategy::kInnerIterations, "inner_iterations"},
  }};
};
template <>
struct EnumNames<Scope> {
  static constexpr std::array<std::pair<Scope, const char*>, 2> kNames = {{
      {Scope::kGlobal, "global"},
      {Scope::kLocal, "local"},
  }};
};

/// What the scheduler solves and when it stops. The gauge: with fix_first_pose the pose of
/// smallest index among those the graph uses is constant in every phase (in both scopes); the
/// scale of a monocular problem is NOT fixed here, the caller adds a factor for it (e.g. a
/// camera-distance factor between the first two poses). Further constants come from the caller's
/// base ProblemConfig.
struct SchedulerOptions {
  Strategy strategy = Strategy::kJoint;  ///< How free variables are split into solves.
  Scope scope = Scope::kGlobal;          ///< Which variables are free.
  /// Poses free in local scope: the local_window highest-index poses; >= 1 (unused in global).
  int local_window = 5;
  /// Alternating only: most rounds (each one poses solve and one structure solve); >= 1.
  int max_rounds = 10;
  /// Alternating only: stop when a round lowers the cost by less than this fraction of the
  /// cost at its start, (before - after) / before; >= 0 and finite (0 runs until the cost stops
  /// falling or max_rounds).
  double round_tolerance = 1e-4;
  /// Hold the pose of smallest index constant (the rotation and translation gauge).
  bool fix_first_pose = true;
  /// Solver settings of every solve; max_iterations applies per phase. kInnerIterations turns
  /// use_inner_iterations on; the other strategies use it as given.
  OptimizerOptions optimizer;

  /// Throws InvalidOptions naming the field, its value and the constraint (optimizer's too).
  void validate() const;
};

/// One solve of a schedule (a "phase").
struct ScheduleRound {
  int round = 0;      ///< 1-based round; alternating rounds have a "poses" and a "structure" phase.
  std::string phase;  ///< "joint", "poses" or "structure".
  /// The phase had no free variable (e.g. "structure" in a graph without structure) and was not
  /// solved; `summary` is then empty.
  bool skipped = false;
  /// The solve. Its costs cover every active factor over all its variables (factors whose
  /// variables are all constant in this phase included), so they compare across phases.
  OptimizationSummary summary;
};

/// What runSchedule() did. All costs (0.5 * sum rho, Ceres' convention) are those of the active
/// factors: the whole graph in global scope, the factors touching a free variable in local scope.
struct ScheduleReport {
  Strategy strategy = Strategy::kJoint;
  Scope scope = Scope::kGlobal;
  std::vector<ScheduleRound> rounds;  ///< Every phase, in order, skipped ones included.
  int num_rounds = 0;                 ///< Rounds started (joint: 1; 0 when no factor is active).
  int num_factors = 0;                ///< Factors in the graph.
  int num_active_factors = 0;         ///< Factors sent to the solver.
  double initial_cost = 0.0;          ///< Active cost before the first solve.
  double final_cost = 0.0;            ///< Active cost after the last solve.
  int total_iterations = 0;           ///< Ceres iterations over all phases.
  double total_seconds = 0.0;         ///< Wall time of runSchedule(), selection included.
  /// Joint: Ceres reported CONVERGENCE. Alternating: a round met round_tolerance (or nothing was
  /// free). False when max_rounds ran out, a solve failed or Ceres hit its iteration limit.
  bool converged = false;
  std::string stop_reason;  ///< Why the schedule stopped, in words.
  /// Things the caller should know, e.g. a round whose cost did not decrease.
  std::vector<std::string> warnings;

  /// A header line, then a table with one block per phase: round, phase, cost before and after
  /// per factor type (and in total), iterations, seconds, free / constant variables.
  std::string toString() const;
};

/// Optimises `values` (updated in place) over the free variables chosen by `options.scope`,
/// minus the gauge and the constants of `base`, with `options.strategy`. Variables no active
/// factor touches are left alone. An empty graph, or a phase without free variables, is not an
/// error. Throws InvalidOptions for bad options, and what optimize() throws (KeyDoesNotExist,
/// IncorrectType) for a factor key missing from or mistyped in `values`.
ScheduleReport runSchedule(const FactorGraph& graph, Values* values, const ProblemConfig& base,
                           const SchedulerOptions& options);

}  // namespace curvesfm
