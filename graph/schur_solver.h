#pragma once

#include <optional>
#include <string>

#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/values.h"

namespace curvesfm {

// Levenberg-Marquardt with the structure eliminated by our own Schur complement
// (LinearSolver::kGraphSchur).
//
// The free variables split into poses and structure. Structure variables that share a factor
// form a group (a curve's Q, v and d; a point alone); a factor then touches at most one group
// and any number of poses. Each step eliminates every group with a dense Cholesky of its
// damped block, solves the reduced system over the poses with a dense Cholesky, and
// back-substitutes each group's step. Ceres' Schur eliminator does the same on the curve blocks
// (OptimizerOptions::curve_blocks) but forms every observation's products over its curve's whole
// block, with runtime-sized kernels; here each observation's Jacobian stays as narrow as its
// segment, the group's products are one rank update, and the groups are spread over the threads.
//
// The objective, the damping (Marquardt's clamped diagonal), the step acceptance, the radius
// updates and the tolerances are Ceres' (graph/levenberg_marquardt.h), so the optimum is that
// of optimize() with a Ceres solver; the path differs only by rounding, and by the chart: each
// variable is retracted at its current value, where Ceres' curve blocks move in one chart
// anchored at the start. The result does not depend on which thread took which group, but
// differs by rounding between thread counts (each thread sums its own share of the reduced
// system).

/// The largest reduced system it forms: free poses x 6 (a dense matrix per thread, 288 MB each
/// at the limit, still less than Ceres' Jacobians of a 1,000-keyframe sequence).
constexpr int kGraphSchurMaxReducedDimension = 6000;
/// The largest structure group it eliminates as one dense block (tangent dimensions).
constexpr int kGraphSchurMaxGroupDimension = 2000;

/// Minimises the graph's cost over the free variables of `values` (updated in place) as
/// described above. Uses options' max_iterations, initial_trust_region_radius, the three
/// tolerances, num_threads and on_iteration. Returns nullopt and says why in `why_not`, leaving
/// `values` untouched, when the problem exceeds the limits above or the options ask for what
/// only Ceres has (inner iterations, the dogleg trust region); optimize() then hands it to
/// Ceres.
std::optional<OptimizationSummary> optimizeWithGraphSchur(const FactorGraph& graph, Values* values,
                                                          const ProblemConfig& config,
                                                          const OptimizerOptions& options,
                                                          std::string* why_not);

}  // namespace curvesfm
