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
/// into its own parameter blocks, attaches manifolds, robust losses and constant flags, and
/// copies results back with writeBack().
///
/// A variable gets a parameter block of its own (ambient coordinates), except for the free
/// variables of a curve when OptimizerOptions::curve_blocks is on: those share one block of
/// tangent offsets from their start values (VariableBinding), and the curve's constant
/// variables wait at their start values beside it.
class CeresProblem {
 public:
  /// Only `options.curve_blocks` and `options.max_curve_block_size` matter here. Throws
  /// KeyDoesNotExist / IncorrectType for a factor key missing from or mistyped in `values`.
  CeresProblem(const FactorGraph& graph, const Values& values, const ProblemConfig& config,
               const OptimizerOptions& options = {});
  CeresProblem(const CeresProblem&) = delete;
  CeresProblem& operator=(const CeresProblem&) = delete;

  ceres::Problem& problem() { return *problem_; }
  /// The parameter block that holds `key` (its own or its curve's); nullptr if no factor uses
  /// it.
  double* block(Key key);
  /// Keys of all variables, in the order factors first use them.
  const std::vector<Key>& keys() const { return keys_; }
  int numConstant() const { return num_constant_; }
  int numBlocks() const { return static_cast<int>(blocks_.size()); }
  /// Curves that share one block.
  int numCurveBlocks() const { return num_curve_blocks_; }
  bool hasFreePose() const;

  /// Copies every variable back into `values`.
  void writeBack(Values* values) const;

  /// Cost per Factor::typeName() at the current parameter blocks (after a Solve, the solution),
  /// with FactorGraph::costByType's meaning and arithmetic (NoiseModel::cost of each factor's
  /// error), but read straight from the blocks with no per-factor allocation, so optimize() can
  /// afford it before and after every solve.
  std::map<std::string, FactorTypeCost> costByType() const;

  /// Schur ordering: group 0 (eliminated) holds every free structure block that shares no
  /// factor with another free structure block, group 1 the poses and the rest. Returns nullptr
  /// and sets `why_not` when group 0 would be empty or smaller than the coupled rest (then
  /// Ceres' own independent set eliminates more). `description` gets "E eliminated, R reduced
  /// blocks".
  std::shared_ptr<ceres::ParameterBlockOrdering> structureFirstOrdering(
      std::string* why_not, std::string* description) const;

  /// Independent sets of the free blocks for Ceres' inner iterations, by first-fit colouring
  /// in the order the blocks were added: group 0 is a maximal independent set, group 1 one of the
  /// rest, and so on (the structure of Ceres' own recursive choice). Ceres builds its choice
  /// from a hash set of its block pointers, so it changes with heap addresses and so do the
  /// results; this one depends only on the graph.
  std::shared_ptr<ceres::ParameterBlockOrdering> innerIterationOrdering() const;

 private:
  /// One Ceres parameter block.
  struct Block {
    std::size_t offset = 0;  ///< Into storage_.
    int size = 0;
    bool constant = false;
    bool pose = false;
  };
  /// Where one variable lives.
  struct Slot {
    VariableType type = VariableType::kPoint3;
    int block = 0;
    bool shared = false;     ///< In a curve block, as an offset from its anchor.
    int column = 0;          ///< Shared: first column in the block, -1 if held at the anchor.
    std::size_t anchor = 0;  ///< Shared: into anchors_.
  };

  /// Assigns every used variable its slot and sizes storage_ and anchors_.
  void layOut(const std::vector<Key>& used, const std::unordered_map<Key, VariableType>& types,
              const OptimizerOptions& options);
  void addBlocks(const Values& values);
  void addFactor(const std::shared_ptr<const Factor>& factor);
  double* blockData(int block) { return storage_.data() + blocks_[block].offset; }
  const double* blockData(int block) const { return storage_.data() + blocks_[block].offset; }
  const ceres::LossFunction* lossFor(const RobustKernel& kernel);
  /// Index of `name` in type_names_, added if new.
  int typeIndex(const char* name);

  FactorGraph graph_;  // shares the factors; structureFirstOrdering() and costByType() read them
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<Key> keys_;
  std::unordered_map<Key, Slot> slots_;
  std::vector<Block> blocks_;
  std::vector<double> storage_;  ///< Block data: ambient values, or a curve's tangent offsets.
  std::vector<double> anchors_;  ///< Start values (ambient) of the variables in curve blocks.
  std::vector<std::unique_ptr<RobustLoss>> losses_;
  // Per factor, in graph order: its cost function (owned by problem_), the index of its type
  // name, and its parameter blocks (a run of indices into blocks_ from factor_block_begin_[i]).
  std::vector<const FactorCostFunction*> cost_functions_;
  std::vector<int> factor_types_;
  std::vector<int> factor_blocks_;
  std::vector<std::size_t> factor_block_begin_;
  int max_residual_dimension_ = 0;
  std::vector<std::string> type_names_;
  int num_constant_ = 0;
  int num_curve_blocks_ = 0;
  ProblemConfig config_;
};

/// Maps our options onto Ceres' (linear solver, preconditioner, trust region, tolerances...).
ceres::Solver::Options toCeresOptions(const OptimizerOptions& options);

}  // namespace curvesfm
