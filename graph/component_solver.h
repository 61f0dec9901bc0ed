#pragma once

#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/values.h"

namespace curvesfm {

// Levenberg-Marquardt over the connected components of the free variables, each alone.
//
// With every pose held, no two curves (or points) share a free variable: the problem is a sum of
// independent small problems, one per curve. One Ceres solve over all of them runs one trust
// region for the whole map, so a single curve whose step overshoots has every curve's step
// rejected, and the solve keeps going while any curve still moves: on Pavilion's local BAs half
// the iterations were rejected steps, and a third of the time came after the cost was within
// 0.1 % of its end. Solved apart, each curve takes as many steps as it needs under its own
// damping, and the dense normal equations of a curve (at most a few dozen unknowns) cost less
// than a sparse Cholesky's bookkeeping.
//
// Each component is minimised by the same Levenberg-Marquardt as Ceres' (Marquardt's diagonal
// damping, Ceres' trust-region updates and tolerances, Triggs' correction for the robust kernel),
// so the objective and its optimum are those of optimize(); only the path differs. Components run
// on options.num_threads threads; each writes back only its own variables, so the result does not
// depend on the thread count.

/// True when some factor touches a pose that `config` leaves free.
bool hasFreePose(const FactorGraph& graph, const ProblemConfig& config);

/// Minimises the graph's cost over the free variables of `values`, one connected component at a
/// time (see above). Uses options' max_iterations (per component), initial_trust_region_radius,
/// function, gradient and parameter tolerances, num_threads and on_iteration (called at the start
/// and the end only); the Ceres-specific fields do not apply. In the summary, iterations is the
/// most any component took, termination is "CONVERGENCE" when every component converged, and
/// ordering says how many components were solved.
OptimizationSummary optimizeComponents(const FactorGraph& graph, Values* values,
                                       const ProblemConfig& config,
                                       const OptimizerOptions& options);

}  // namespace curvesfm
