#pragma once

#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "graph/ceres_cost_function.h"
#include "graph/factor_graph.h"
#include "graph/optimizer.h"
#include "graph/values.h"

namespace curvesfm {

/// The bridge from a factor graph to a ceres::Problem. It copies the variables that factors use
/// into its own parameter blocks (ambient coordinates), attaches manifolds, robust losses and
/// constant flags, and copies results back with writeBack().
class CeresProblem {
 public:
  /// Throws KeyDoesNotExist / IncorrectType for a factor key missing from or mistyped in
  /// `values`.
  CeresProblem(const FactorGraph& graph, const Values& values, const ProblemConfig& config);
  CeresProblem(const CeresProblem&) = delete;
  CeresProblem& operator=(const CeresProblem&) = delete;

  ceres::Problem& problem() { return *problem_; }
  /// The parameter block of `key` (ambient coordinates); nullptr if no factor uses it.
  double* block(Key key);
  /// Keys of all parameter blocks, in the order they were added.
  const std::vector<Key>& keys() const { return keys_; }
  int numConstant() const { return num_constant_; }

  /// Copies every parameter block back into `values`.
  void writeBack(Values* values) const;

  /// Cost per Factor::typeName() at the current parameter blocks (after a Solve, the solution),
  /// with FactorGraph::costByType's meaning and arithmetic (NoiseModel::cost of each factor's
  /// error), but read straight from the blocks with no per-factor allocation, so optimize() can
  /// afford it before and after every solve.
  std::map<std::string, FactorTypeCost> costByType() const;

  /// Schur ordering with every free non-pose variable in group 0 and the poses in group 1.
  /// Returns nullptr and sets `why_not` if two free non-pose variables share a factor, since
  /// the eliminated group must be an independent set.
  std::shared_ptr<ceres::ParameterBlockOrdering> structureFirstOrdering(std::string* why_not) const;

  /// Independent sets of the free variables for Ceres' inner iterations, by first-fit colouring
  /// in the order the blocks were added: group 0 is a maximal independent set, group 1 one of the
  /// rest, and so on (the structure of Ceres' own recursive choice). Ceres builds its choice
  /// from a hash set of its block pointers, so it changes with heap addresses and so do the
  /// results; this one depends only on the graph.
  std::shared_ptr<ceres::ParameterBlockOrdering> innerIterationOrdering() const;

 private:
  /// Adds the parameter block of `key` (initialised from `values`) and returns it.
  double* addVariable(Key key, VariableType type, const Values& values);
  const ceres::LossFunction* lossFor(const RobustKernel& kernel);
  /// Index of `name` in type_names_, added if new.
  int typeIndex(const char* name);

  FactorGraph graph_;  // shares the factors; structureFirstOrdering() and costByType() read them
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<Key> keys_;
  std::unordered_map<Key, std::size_t> offsets_;
  std::vector<double> storage_;
  std::vector<std::unique_ptr<RobustLoss>> losses_;
  // Per factor, in graph order: the index of its type name, and its parameter blocks (one run
  // of factor->keys().size() pointers per factor).
  std::vector<int> factor_types_;
  std::vector<const double*> factor_blocks_;
  int max_residual_dimension_ = 0;
  std::size_t max_factor_keys_ = 0;
  std::vector<std::string> type_names_;
  int num_constant_ = 0;
  ProblemConfig config_;
};

/// Maps our options onto Ceres' (linear solver, preconditioner, trust region, tolerances...).
ceres::Solver::Options toCeresOptions(const OptimizerOptions& options);

}  // namespace curvesfm
