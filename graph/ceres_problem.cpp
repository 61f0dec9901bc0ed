#include "graph/ceres_problem.h"

#include <algorithm>

#include "graph/ceres_manifolds.h"

namespace curvesfm {

CeresProblem::CeresProblem(const FactorGraph& graph, const Values& values,
                           const ProblemConfig& config)
    : graph_(graph), config_(config) {
  // Parameter blocks must not move once Ceres holds pointers: size the storage first.
  std::size_t total = 0;
  std::size_t num_factor_keys = 0;
  std::unordered_map<Key, VariableType> used;
  for (const auto& factor : graph) {
    const std::vector<VariableType> expected = factor->variableTypes();
    num_factor_keys += factor->keys().size();
    for (std::size_t i = 0; i < factor->keys().size(); ++i) {
      const Key key = factor->keys()[i];
      const VariableType stored = values.type(key);
      if (stored != expected[i]) throw IncorrectType(key, stored, expected[i]);
      if (used.emplace(key, stored).second) total += ambientDim(stored);
    }
  }
  storage_.reserve(total);

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(problem_options);

  factor_types_.reserve(graph.size());
  factor_blocks_.reserve(num_factor_keys);
  std::vector<double*> blocks;
  for (const auto& factor : graph) {
    blocks.clear();
    for (Key key : factor->keys()) {
      const auto it = offsets_.find(key);
      blocks.push_back(it != offsets_.end() ? storage_.data() + it->second
                                            : addVariable(key, used.at(key), values));
    }
    problem_->AddResidualBlock(
        new FactorCostFunction(factor),
        const_cast<ceres::LossFunction*>(lossFor(factor->noiseModel().kernel)), blocks);
    factor_types_.push_back(typeIndex(factor->typeName()));
    factor_blocks_.insert(factor_blocks_.end(), blocks.begin(), blocks.end());
    max_residual_dimension_ = std::max(max_residual_dimension_, factor->residualDimension());
    max_factor_keys_ = std::max(max_factor_keys_, factor->keys().size());
  }
}

int CeresProblem::typeIndex(const char* name) {
  // A graph has a handful of factor types: a linear scan beats hashing the name.
  for (std::size_t i = 0; i < type_names_.size(); ++i) {
    if (type_names_[i] == name) return static_cast<int>(i);
  }
  type_names_.emplace_back(name);
  return static_cast<int>(type_names_.size()) - 1;
}

double* CeresProblem::addVariable(Key key, VariableType type, const Values& values) {
  const std::size_t offset = storage_.size();
  storage_.resize(offset + ambientDim(type));
  values.toAmbient(key, storage_.data() + offset);
  offsets_.emplace(key, offset);
  keys_.push_back(key);
  double* block = storage_.data() + offset;
  problem_->AddParameterBlock(block, ambientDim(type),
                              const_cast<ceres::Manifold*>(manifoldFor(type)));
  if (config_.isConstant(key)) {
    problem_->SetParameterBlockConstant(block);
    ++num_constant_;
  }
  return block;
}

const ceres::LossFunction* CeresProblem::lossFor(const RobustKernel& kernel) {
  if (kernel.type() == RobustKernelType::kNone) return nullptr;
  // Factors of one kind share one kernel: keep one loss object per distinct kernel.
  for (const auto& loss : losses_) {
    const RobustKernel& existing = loss->kernel();
    if (existing.type() == kernel.type() && existing.width() == kernel.width()) return loss.get();
  }
  losses_.push_back(std::make_unique<RobustLoss>(kernel));
  return losses_.back().get();
}

double* CeresProblem::block(Key key) {
  const auto it = offsets_.find(key);
  return it == offsets_.end() ? nullptr : storage_.data() + it->second;
}

void CeresProblem::writeBack(Values* values) const {
  for (const Key key : keys_) values->setFromAmbient(key, storage_.data() + offsets_.at(key));
}

std::map<std::string, FactorTypeCost> CeresProblem::costByType() const {
  // Ceres' EvaluateResidualBlock would do, but it re-applies every manifold's PlusJacobian and
  // may allocate scratch per block; the factors themselves need neither.
  std::vector<FactorTypeCost> by_index(type_names_.size());
  std::vector<double> error(max_residual_dimension_);
  const std::vector<double*> no_jacobians(max_factor_keys_, nullptr);
  const double* const* blocks = factor_blocks_.data();
  for (std::size_t i = 0; i < graph_.size(); ++i) {
    const Factor& factor = *graph_[i];
    factor.evaluateRaw(blocks, error.data(), no_jacobians.data());
    blocks += factor.keys().size();
    const double squared_norm =
        Eigen::Map<const Eigen::VectorXd>(error.data(), factor.residualDimension()).squaredNorm();
    FactorTypeCost& entry = by_index[factor_types_[i]];
    ++entry.count;
    entry.cost += factor.noiseModel().cost(squared_norm);
  }
  std::map<std::string, FactorTypeCost> by_type;
  for (std::size_t t = 0; t < type_names_.size(); ++t) by_type.emplace(type_names_[t], by_index[t]);
  return by_type;
}

std::shared_ptr<ceres::ParameterBlockOrdering> CeresProblem::structureFirstOrdering(
    std::string* why_not) const {
  auto isFreeStructure = [this](Key key) {
    return categoryOf(key) != VariableCategory::kPose && !config_.isConstant(key);
  };
  for (const auto& factor : graph_) {
    Key first_structure;
    bool seen = false;
    for (Key key : factor->keys()) {
      if (!isFreeStructure(key)) continue;
      if (seen && key != first_structure) {
        *why_not = "factor couples " + first_structure.toString() + " and " + key.toString();
        return nullptr;
      }
      first_structure = key;
      seen = true;
    }
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    double* block = const_cast<double*>(storage_.data()) + offsets_.at(keys_[i]);
    ordering->AddElementToGroup(block, categoryOf(keys_[i]) == VariableCategory::kPose ? 1 : 0);
  }
  return ordering;
}

std::shared_ptr<ceres::ParameterBlockOrdering> CeresProblem::innerIterationOrdering() const {
  // Free neighbours of each block: variables that share a factor with it.
  std::unordered_map<Key, std::size_t> index;
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    if (!config_.isConstant(keys_[i])) index.emplace(keys_[i], i);
  }
  std::vector<std::vector<std::size_t>> neighbours(keys_.size());
  for (const auto& factor : graph_) {
    for (Key a : factor->keys()) {
      const auto ia = index.find(a);
      if (ia == index.end()) continue;
      for (Key b : factor->keys()) {
        const auto ib = index.find(b);
        if (ib != index.end() && ib->second != ia->second)
          neighbours[ia->second].push_back(ib->second);
      }
    }
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<int> group(keys_.size(), -1);
  std::vector<char> taken;
  for (std::size_t i = 0; i < keys_.size(); ++i) {
    if (!index.count(keys_[i])) continue;
    taken.assign(neighbours[i].size() + 1, 0);
    for (std::size_t n : neighbours[i]) {
      if (group[n] >= 0 && group[n] < static_cast<int>(taken.size())) taken[group[n]] = 1;
    }
    group[i] = static_cast<int>(std::find(taken.begin(), taken.end(), 0) - taken.begin());
    ordering->AddElementToGroup(const_cast<double*>(storage_.data()) + offsets_.at(keys_[i]),
                                group[i]);
  }
  return ordering;
}

ceres::Solver::Options toCeresOptions(const OptimizerOptions& options) {
  ceres::Solver::Options ceres_options;
  switch (options.linear_solver) {
    case LinearSolver::kSparseSchur:
      ceres_options.linear_solver_type = ceres::SPARSE_SCHUR;
      break;
    case LinearSolver::kDenseSchur:
      ceres_options.linear_solver_type = ceres::DENSE_SCHUR;
      break;
    case LinearSolver::kIterativeSchur:
      ceres_options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      ceres_options.preconditioner_type = ceres::SCHUR_JACOBI;
      break;
    case LinearSolver::kSparseNormalCholesky:
      ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
      break;
  }
  ceres_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  ceres_options.trust_region_strategy_type =
      options.trust_region == TrustRegion::kDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  ceres_options.max_num_iterations = options.max_iterations;
  ceres_options.num_threads = options.num_threads;
  ceres_options.function_tolerance = options.function_tolerance;
  ceres_options.gradient_tolerance = options.gradient_tolerance;
  ceres_options.parameter_tolerance = options.parameter_tolerance;
  ceres_options.use_inner_iterations = options.use_inner_iterations;
  ceres_options.minimizer_progress_to_stdout = options.verbose;
  ceres_options.logging_type = options.verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  return ceres_options;
}

}  // namespace curvesfm
