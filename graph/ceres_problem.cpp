#include "graph/ceres_problem.h"

#include <algorithm>

#include "graph/ceres_manifolds.h"

namespace curvesfm {
namespace {

// Curve points, directions and lengths carry their curve as the key's major index.
bool isCurveVariable(Key key) {
  const VariableCategory category = categoryOf(key);
  return key.hasMinor() &&
         (category == VariableCategory::kCurvePoint || category == VariableCategory::kDirection ||
          category == VariableCategory::kLength);
}

}  // namespace

CeresProblem::CeresProblem(const FactorGraph& graph, const Values& values,
                           const ProblemConfig& config, const OptimizerOptions& options)
    : graph_(graph), config_(config) {
  std::vector<Key> used;
  std::unordered_map<Key, VariableType> types;
  std::size_t num_factor_keys = 0;
  for (const auto& factor : graph) {
    const std::vector<VariableType> expected = factor->variableTypes();
    num_factor_keys += factor->keys().size();
    for (std::size_t i = 0; i < factor->keys().size(); ++i) {
      const Key key = factor->keys()[i];
      const VariableType stored = values.type(key);
      if (stored != expected[i]) throw IncorrectType(key, stored, expected[i]);
      if (types.emplace(key, stored).second) used.push_back(key);
    }
  }
  layOut(used, types, options);

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  addBlocks(values);

  cost_functions_.reserve(graph.size());
  factor_types_.reserve(graph.size());
  factor_block_begin_.reserve(graph.size() + 1);
  factor_blocks_.reserve(num_factor_keys);
  for (const auto& factor : graph) addFactor(factor);
  factor_block_begin_.push_back(factor_blocks_.size());
}

void CeresProblem::layOut(const std::vector<Key>& used,
                          const std::unordered_map<Key, VariableType>& types,
                          const OptimizerOptions& options) {
  // With every pose held, no reduced system couples the curves: each is solved alone either
  // way, and a block per variable keeps its Jacobians as narrow as its segments. Inner
  // iterations refine each block alone, and whole curves did worse there than their variables
  // (strategy bench, docs/benchmarks.md).
  const bool any_free_pose = std::any_of(used.begin(), used.end(), [this](Key key) {
    return categoryOf(key) == VariableCategory::kPose && !config_.isConstant(key);
  });
  // Free tangent dimensions per curve: a curve with any, and not too many, gets one block.
  std::unordered_map<std::uint64_t, int> curve_size;
  if (options.curve_blocks && any_free_pose && !options.use_inner_iterations) {
    for (Key key : used) {
      if (isCurveVariable(key) && !config_.isConstant(key)) {
        curve_size[key.index()] += tangentDim(types.at(key));
      }
    }
  }
  std::unordered_map<std::uint64_t, int> curve_block;
  std::size_t storage = 0;
  std::size_t anchors = 0;
  for (Key key : used) {
    Slot slot;
    slot.type = types.at(key);
    const bool constant = config_.isConstant(key);
    num_constant_ += constant ? 1 : 0;
    const auto size = isCurveVariable(key) ? curve_size.find(key.index()) : curve_size.end();
    if (size != curve_size.end() && size->second <= options.max_curve_block_size) {
      const auto [it, added] = curve_block.emplace(key.index(), static_cast<int>(blocks_.size()));
      if (added) {
        blocks_.push_back({storage, 0, false, false});
        storage += size->second;
        ++num_curve_blocks_;
      }
      Block& block = blocks_[it->second];
      slot.block = it->second;
      slot.shared = true;
      slot.anchor = anchors;
      anchors += ambientDim(slot.type);
      slot.column = constant ? -1 : block.size;
      if (!constant) block.size += tangentDim(slot.type);
    } else {
      slot.block = static_cast<int>(blocks_.size());
      // Intrinsics, which every image shares, stay in the reduced system beside the poses.
      const VariableCategory category = categoryOf(key);
      blocks_.push_back(
          {storage, ambientDim(slot.type), constant,
           category == VariableCategory::kPose || category == VariableCategory::kIntrinsics});
      storage += ambientDim(slot.type);
    }
    slots_.emplace(key, slot);
    keys_.push_back(key);
  }
  // Ceres holds pointers into these from now on: they never grow again.
  storage_.assign(storage, 0.0);
  anchors_.assign(anchors, 0.0);
}

void CeresProblem::addBlocks(const Values& values) {
  // Ceres gets the blocks in the order of their first variable; a curve block starts at zero.
  std::vector<char> added(blocks_.size(), 0);
  for (Key key : keys_) {
    const Slot& slot = slots_.at(key);
    double* data = blockData(slot.block);
    values.toAmbient(key, slot.shared ? anchors_.data() + slot.anchor : data);
    if (added[slot.block]) continue;
    added[slot.block] = 1;
    const Block& block = blocks_[slot.block];
    const ceres::Manifold* manifold = slot.shared ? nullptr : manifoldFor(slot.type);
    problem_->AddParameterBlock(data, block.size, const_cast<ceres::Manifold*>(manifold));
    if (block.constant) problem_->SetParameterBlockConstant(data);
  }
}

void CeresProblem::addFactor(const std::shared_ptr<const Factor>& factor) {
  const std::size_t begin = factor_blocks_.size();
  std::vector<VariableBinding> bindings;
  bindings.reserve(factor->keys().size());
  for (Key key : factor->keys()) {
    const Slot& slot = slots_.at(key);
    const auto end = factor_blocks_.begin() + static_cast<std::ptrdiff_t>(factor_blocks_.size());
    const auto at =
        std::find(factor_blocks_.begin() + static_cast<std::ptrdiff_t>(begin), end, slot.block);
    const int position =
        static_cast<int>(at - factor_blocks_.begin() - static_cast<std::ptrdiff_t>(begin));
    if (at == end) factor_blocks_.push_back(slot.block);
    bindings.push_back({slot.type, position, slot.shared ? anchors_.data() + slot.anchor : nullptr,
                        slot.shared ? slot.column : 0});
  }
  std::vector<int> sizes;
  std::vector<double*> pointers;
  for (std::size_t i = begin; i < factor_blocks_.size(); ++i) {
    sizes.push_back(blocks_[factor_blocks_[i]].size);
    pointers.push_back(blockData(factor_blocks_[i]));
  }
  auto* cost = new FactorCostFunction(factor, std::move(bindings), sizes);
  problem_->AddResidualBlock(
      cost, const_cast<ceres::LossFunction*>(lossFor(factor->noiseModel().kernel)), pointers);
  cost_functions_.push_back(cost);
  factor_types_.push_back(typeIndex(factor->typeName()));
  factor_block_begin_.push_back(begin);
  max_residual_dimension_ = std::max(max_residual_dimension_, factor->residualDimension());
}

int CeresProblem::typeIndex(const char* name) {
  // A graph has a handful of factor types: a linear scan beats hashing the name.
  for (std::size_t i = 0; i < type_names_.size(); ++i) {
    if (type_names_[i] == name) return static_cast<int>(i);
  }
  type_names_.emplace_back(name);
  return static_cast<int>(type_names_.size()) - 1;
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

bool CeresProblem::hasFreePose() const {
  return std::any_of(blocks_.begin(), blocks_.end(),
                     [](const Block& block) { return block.pose && !block.constant; });
}

double* CeresProblem::block(Key key) {
  const auto it = slots_.find(key);
  return it == slots_.end() ? nullptr : blockData(it->second.block);
}

void CeresProblem::writeBack(Values* values) const {
  double x[Pose3::kAmbientDim];
  for (const Key key : keys_) {
    const Slot& slot = slots_.at(key);
    if (!slot.shared) {
      values->setFromAmbient(key, blockData(slot.block));
    } else if (slot.column >= 0) {
      retractAnchored(slot.type, anchors_.data() + slot.anchor, blockData(slot.block) + slot.column,
                      x);
      values->setFromAmbient(key, x);
    }
  }
}

std::map<std::string, FactorTypeCost> CeresProblem::costByType() const {
  // Ceres' EvaluateResidualBlock would do, but it re-applies every manifold's PlusJacobian and
  // may allocate scratch per block; the factors themselves need neither.
  std::vector<FactorTypeCost> by_index(type_names_.size());
  std::vector<double> error(max_residual_dimension_);
  std::vector<const double*> blocks;
  for (std::size_t i = 0; i < graph_.size(); ++i) {
    blocks.clear();
    for (std::size_t b = factor_block_begin_[i]; b < factor_block_begin_[i + 1]; ++b) {
      blocks.push_back(blockData(factor_blocks_[b]));
    }
    cost_functions_[i]->evaluateError(blocks.data(), error.data());
    const Factor& factor = *graph_[i];
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
    std::string* why_not, std::string* description) const {
  auto isFreeStructure = [this](int b) { return !blocks_[b].constant && !blocks_[b].pose; };
  // A free structure block that shares a factor with another one cannot be eliminated.
  std::vector<char> coupled(blocks_.size(), 0);
  std::string example;
  for (std::size_t i = 0; i < graph_.size(); ++i) {
    int first = -1;
    for (std::size_t b = factor_block_begin_[i]; b < factor_block_begin_[i + 1]; ++b) {
      const int block = factor_blocks_[b];
      if (!isFreeStructure(block)) continue;
      if (first < 0) {
        first = block;
        continue;
      }
      coupled[first] = coupled[block] = 1;
      if (example.empty()) example = "factor " + std::string(graph_[i]->typeName()) + " couples";
    }
  }
  int independent = 0;
  int dependent = 0;
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    if (!isFreeStructure(static_cast<int>(b))) continue;
    (coupled[b] ? dependent : independent) += 1;
  }
  // When most structure is coupled (a block per curve variable), Ceres' own maximal
  // independent set eliminates more of it than the independent blocks alone would.
  if (independent == 0 || dependent >= independent) {
    *why_not = example.empty() ? "no free structure" : example + " two structure blocks";
    return nullptr;
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const bool eliminate = isFreeStructure(static_cast<int>(b)) && !coupled[b];
    ordering->AddElementToGroup(const_cast<double*>(blockData(static_cast<int>(b))),
                                eliminate ? 0 : 1);
  }
  const int reduced =
      static_cast<int>(std::count_if(blocks_.begin(), blocks_.end(),
                                     [](const Block& block) { return !block.constant; })) -
      independent;
  *description =
      std::to_string(independent) + " eliminated, " + std::to_string(reduced) + " reduced blocks";
  return ordering;
}

std::shared_ptr<ceres::ParameterBlockOrdering> CeresProblem::innerIterationOrdering() const {
  // Free neighbours of each block: blocks that share a factor with it.
  std::vector<std::vector<int>> neighbours(blocks_.size());
  for (std::size_t i = 0; i < graph_.size(); ++i) {
    for (std::size_t a = factor_block_begin_[i]; a < factor_block_begin_[i + 1]; ++a) {
      for (std::size_t b = factor_block_begin_[i]; b < factor_block_begin_[i + 1]; ++b) {
        const int from = factor_blocks_[a];
        const int to = factor_blocks_[b];
        if (from != to && !blocks_[from].constant && !blocks_[to].constant) {
          neighbours[from].push_back(to);
        }
      }
    }
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<int> group(blocks_.size(), -1);
  std::vector<char> taken;
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    if (blocks_[i].constant) continue;
    taken.assign(neighbours[i].size() + 1, 0);
    for (int n : neighbours[i]) {
      if (group[n] >= 0 && group[n] < static_cast<int>(taken.size())) taken[group[n]] = 1;
    }
    group[i] = static_cast<int>(std::find(taken.begin(), taken.end(), 0) - taken.begin());
    ordering->AddElementToGroup(const_cast<double*>(blockData(static_cast<int>(i))), group[i]);
  }
  return ordering;
}

ceres::Solver::Options toCeresOptions(const OptimizerOptions& options) {
  ceres::Solver::Options ceres_options;
  switch (options.linear_solver) {
    case LinearSolver::kSparseSchur:
    case LinearSolver::kGraphSchur:  // Beyond graph_schur's limits (graph/schur_solver.h).
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
  ceres_options.initial_trust_region_radius = options.initial_trust_region_radius;
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
