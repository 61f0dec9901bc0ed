#include "graph/component_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <unordered_map>

#include "core/clock.h"
#include "core/parallel.h"
#include "graph/levenberg_marquardt.h"
#include "graph/variable_slots.h"

namespace curvesfm {
namespace {

// A factor's key as a component sees it: a free variable (its index in the component) or a
// constant one (its slot).
struct FactorKey {
  int variable = -1;  // Index in Component::variables, or -1 when constant.
  int slot = -1;
};

struct Component {
  std::vector<int> factors;    // Graph indices.
  std::vector<int> variables;  // Slot indices of its free variables.
};

struct ComponentResult {
  int iterations = 0;
  int rejected = 0;  // Iterations whose step was not kept.
  bool converged = false;
};

// Every variable the factors use, their start values, and the independent components.
struct Setup : VariableSlots {
  std::vector<Component> components;  // Factors without a free variable are in none.
};

Setup makeSetup(const FactorGraph& graph, const Values& values, const ProblemConfig& config) {
  Setup setup;
  static_cast<VariableSlots&>(setup) = collectVariableSlots(graph, values, config);
  int num_components = 0;
  const std::vector<int> component_of = connectedSets(
      setup, [&](int s) { return setup.slots[s].free; }, &num_components);
  setup.components.resize(num_components);
  for (std::size_t s = 0; s < setup.slots.size(); ++s) {
    if (component_of[s] >= 0) setup.components[component_of[s]].variables.push_back(int(s));
  }
  for (std::size_t f = 0; f < graph.size(); ++f) {
    const auto free_slot = std::find_if(setup.factor_slots[f].begin(), setup.factor_slots[f].end(),
                                        [&](int s) { return setup.slots[s].free; });
    if (free_slot != setup.factor_slots[f].end()) {
      setup.components[component_of[*free_slot]].factors.push_back(static_cast<int>(f));
    }
  }
  return setup;
}

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One component's least-squares problem: cost, gradient and Gauss-Newton matrix at a point given
// by the ambient values of its free variables.
class ComponentProblem {
 public:
  ComponentProblem(const FactorGraph& graph, const Setup& setup, const Component& component)
      : graph_(graph), setup_(setup), component_(component) {
    std::unordered_map<int, int> variable_of_slot;
    for (const int s : component.variables) {
      variable_of_slot[s] = static_cast<int>(ambient_offset_.size());
      const VariableType type = setup.slots[s].type;
      ambient_offset_.push_back(ambient_size_);
      tangent_offset_.push_back(tangent_size_);
      ambient_size_ += ambientDim(type);
      tangent_size_ += tangentDim(type);
    }
    for (const int f : component.factors) {
      std::vector<FactorKey> keys;
      for (const int s : setup.factor_slots[f]) {
        const auto it = variable_of_slot.find(s);
        keys.push_back({it == variable_of_slot.end() ? -1 : it->second, s});
      }
      factor_keys_.push_back(std::move(keys));
    }
  }

  int tangentSize() const { return tangent_size_; }

  std::vector<double> startValues() const {
    std::vector<double> x(ambient_size_);
    for (std::size_t v = 0; v < component_.variables.size(); ++v) {
      const VariableSlot& slot = setup_.slots[component_.variables[v]];
      std::copy_n(setup_.ambient.begin() + slot.ambient, ambientDim(slot.type),
                  x.begin() + ambient_offset_[v]);
    }
    return x;
  }

  void writeBack(const std::vector<double>& x, std::vector<double>* ambient) const {
    for (std::size_t v = 0; v < component_.variables.size(); ++v) {
      const VariableSlot& slot = setup_.slots[component_.variables[v]];
      std::copy_n(x.begin() + ambient_offset_[v], ambientDim(slot.type),
                  ambient->begin() + slot.ambient);
    }
  }

  void retract(const std::vector<double>& x, const Eigen::VectorXd& delta,
               std::vector<double>* out) const {
    out->resize(x.size());
    for (std::size_t v = 0; v < component_.variables.size(); ++v) {
      retractAmbient(setup_.slots[component_.variables[v]].type, x.data() + ambient_offset_[v],
                     delta.data() + tangent_offset_[v], out->data() + ambient_offset_[v]);
    }
  }

  // Cost 0.5 * sum rho(|r / sigma|^2) at x; with H and g, also the Gauss-Newton matrix and the
  // gradient of the robustified problem (Triggs' correction, as Ceres' Corrector).
  double evaluate(const std::vector<double>& x, Eigen::MatrixXd* H, Eigen::VectorXd* g) {
    if (H) {
      H->setZero(tangent_size_, tangent_size_);
      g->setZero(tangent_size_);
    }
    double cost = 0.0;
    for (std::size_t i = 0; i < component_.factors.size(); ++i) {
      cost += evaluateFactor(x, i, H, g);
    }
    return cost;
  }

 private:
  double evaluateFactor(const std::vector<double>& x, std::size_t i, Eigen::MatrixXd* H,
                        Eigen::VectorXd* g) {
    const Factor& factor = *graph_[component_.factors[i]];
    const std::vector<FactorKey>& keys = factor_keys_[i];
    const int rows = factor.residualDimension();
    ambient_.resize(keys.size());
    jacobians_.resize(keys.size());
    columns_ = 0;
    for (std::size_t k = 0; k < keys.size(); ++k) {
      const FactorKey& key = keys[k];
      ambient_[k] = key.variable >= 0 ? x.data() + ambient_offset_[key.variable]
                                      : setup_.ambient.data() + setup_.slots[key.slot].ambient;
      jacobians_[k] = nullptr;
      if (H && key.variable >= 0) columns_ += tangentDim(setup_.slots[key.slot].type);
    }
    error_.resize(rows);
    if (H) {
      jacobian_storage_.resize(static_cast<std::size_t>(rows) * columns_);
      int column = 0;
      for (std::size_t k = 0; k < keys.size(); ++k) {
        if (keys[k].variable < 0) continue;
        jacobians_[k] = jacobian_storage_.data() + static_cast<std::size_t>(rows) * column;
        column += tangentDim(setup_.slots[keys[k].slot].type);
      }
    }
    factor.evaluateRaw(ambient_.data(), error_.data(), jacobians_.data());

    const NoiseModel& noise = factor.noiseModel();
    const Eigen::Map<const Eigen::VectorXd> e(error_.data(), rows);
    const double s = e.squaredNorm() / (noise.sigma * noise.sigma);
    double rho[3];
    noise.kernel.evaluate(s, rho);
    if (H) accumulate(keys, rows, noise.sigma, s, rho, H, g);
    return 0.5 * rho[0];
  }

  // Adds the factor's corrected J^T J and J^T r (Triggs' correction, as Ceres' Corrector: the
  // kernel's curvature enters the Gauss-Newton model); the whitened Jacobian is J / sigma.
  void accumulate(const std::vector<FactorKey>& keys, int rows, double sigma, double s,
                  const double rho[3], Eigen::MatrixXd* H, Eigen::VectorXd* g) {
    // Gather the free keys' Jacobian blocks side by side (each stored row-major rows x dim).
    J_.resize(rows, columns_);
    int column = 0;
    blocks_.clear();
    for (std::size_t k = 0; k < keys.size(); ++k) {
      if (!jacobians_[k]) continue;
      const int dim = tangentDim(setup_.slots[keys[k].slot].type);
      J_.middleCols(column, dim) = Eigen::Map<const RowMajorMatrix>(jacobians_[k], rows, dim);
      blocks_.push_back({column, tangent_offset_[keys[k].variable], dim});
      column += dim;
    }
    r_ = Eigen::Map<const Eigen::VectorXd>(error_.data(), rows);
    whitenAndCorrect(sigma, s, rho, &J_, &r_);
    // Products of a few dozen columns: lazy (coefficient-wise) products skip the blocked GEMM's
    // packing, which dominated this function's profile.
    JtJ_.noalias() = J_.transpose().lazyProduct(J_);
    Jtr_.noalias() = J_.transpose().lazyProduct(r_);
    for (const Block& a : blocks_) {
      g->segment(a.tangent, a.dim) += Jtr_.segment(a.column, a.dim);
      for (const Block& b : blocks_) {
        H->block(a.tangent, b.tangent, a.dim, b.dim) +=
            JtJ_.block(a.column, b.column, a.dim, b.dim);
      }
    }
  }

  // A free key's columns in J_ and its place in the component's tangent vector.
  struct Block {
    int column = 0;
    int tangent = 0;
    int dim = 0;
  };

  const FactorGraph& graph_;
  const Setup& setup_;
  const Component& component_;
  std::vector<int> ambient_offset_;
  std::vector<int> tangent_offset_;
  int ambient_size_ = 0;
  int tangent_size_ = 0;
  std::vector<std::vector<FactorKey>> factor_keys_;
  // Scratch of one factor evaluation.
  std::vector<const double*> ambient_;
  std::vector<double*> jacobians_;
  std::vector<double> jacobian_storage_;
  std::vector<double> error_;
  int columns_ = 0;
  Eigen::MatrixXd J_;
  Eigen::VectorXd r_;
  Eigen::MatrixXd JtJ_;
  Eigen::VectorXd Jtr_;
  std::vector<Block> blocks_;
};

double ambientNorm(const std::vector<double>& x) {
  return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())).norm();
}

// Levenberg-Marquardt with Ceres' trust-region rules (TrustRegionMinimizer with the
// LevenbergMarquardtStrategy): Marquardt's damping diag(H) / radius, a step kept when it achieves
// at least kMinRelativeDecrease of the model's decrease, the radius grown by
// 1 / max(1/3, 1 - (2 rho - 1)^3) after a kept step and divided by a doubling factor after a
// rejected one.
ComponentResult minimise(ComponentProblem* problem, std::vector<double>* x,
                         const OptimizerOptions& options) {
  ComponentResult result;
  const int n = problem->tangentSize();
  Eigen::MatrixXd H(n, n);
  Eigen::VectorXd g(n);
  double cost = problem->evaluate(*x, &H, &g);
  TrustRegionRadius radius(options.initial_trust_region_radius);
  StallTest stall(options.stall_iterations, options.stall_tolerance, cost);
  std::vector<double> candidate;
  result.converged = g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance;
  while (!result.converged && result.iterations < options.max_iterations) {
    ++result.iterations;
    Eigen::MatrixXd A = H;
    A.diagonal() += marquardtDiagonal(H.diagonal()) * radius.damping();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
    const Eigen::VectorXd step = -ldlt.solve(g);
    const bool solved = ldlt.info() == Eigen::Success && step.allFinite();
    const double x_norm = ambientNorm(*x);
    if (solved &&
        step.norm() <= (x_norm + options.parameter_tolerance) * options.parameter_tolerance) {
      result.converged = true;
      --result.iterations;  // As Ceres, the stopping iteration is not counted.
      break;
    }
    const double model_decrease = solved ? -(g.dot(step) + 0.5 * step.dot(H * step)) : 0.0;
    double new_cost = cost;
    if (model_decrease > 0.0) {
      problem->retract(*x, step, &candidate);
      new_cost = problem->evaluate(candidate, nullptr, nullptr);
    }
    const double change = cost - new_cost;
    // As Ceres: a step changing the cost too little ends the solve, kept or not (a rough cost
    // near its minimum would otherwise reject step after step until the radius collapses).
    if (model_decrease > 0.0 && std::abs(change) <= options.function_tolerance * cost) {
      result.converged = true;
      --result.iterations;
      break;
    }
    if (model_decrease > 0.0 && std::isfinite(new_cost) &&
        change > kMinRelativeDecrease * model_decrease) {
      const double ratio = change / model_decrease;
      x->swap(candidate);
      cost = problem->evaluate(*x, &H, &g);
      radius.accept(ratio);
      // The check above let through only steps changing the cost by more than the tolerance.
      result.converged = g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance;
    } else {
      ++result.rejected;
      radius.reject();
      result.converged = radius.collapsed();
    }
    result.converged = result.converged || stall.stalled(cost);
  }
  return result;
}

}  // namespace

bool hasFreePose(const FactorGraph& graph, const ProblemConfig& config) {
  for (const auto& factor : graph) {
    for (const Key key : factor->keys()) {
      if (categoryOf(key) == VariableCategory::kPose && !config.isConstant(key)) return true;
    }
  }
  return false;
}

OptimizationSummary optimizeComponents(const FactorGraph& graph, Values* values,
                                       const ProblemConfig& config,
                                       const OptimizerOptions& options) {
  options.validate();
  const auto start = Clock::now();
  OptimizationSummary summary;
  summary.num_factors = static_cast<int>(graph.size());
  summary.initial_cost_by_type = graph.costByType(*values, options.num_threads);
  Setup setup = makeSetup(graph, *values, config);
  for (const VariableSlot& slot : setup.slots) {
    (slot.free ? summary.num_free_variables : summary.num_constant_variables) += 1;
    if (slot.free) summary.num_effective_parameters += tangentDim(slot.type);
  }
  for (const auto& factor : graph) summary.num_residuals += factor->residualDimension();
  summary.setup_seconds = secondsSince(start);

  const auto solve_start = Clock::now();
  const int num_components = static_cast<int>(setup.components.size());
  std::vector<ComponentResult> results(num_components);
  std::vector<double> solved_ambient = setup.ambient;
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int c = next++; c < num_components; c = next++) {
      ComponentProblem problem(graph, setup, setup.components[c]);
      std::vector<double> x = problem.startValues();
      results[c] = minimise(&problem, &x, options);
      problem.writeBack(x, &solved_ambient);  // Disjoint slots: no two components share one.
    }
  };
  if (options.on_iteration) {
    options.on_iteration({0, totalCost(summary.initial_cost_by_type), secondsSince(start), false});
  }
  const int num_threads = std::min(options.num_threads, std::max(1, num_components));
  runInParallel(num_threads, [&](int) { work(); });
  summary.solve_seconds = secondsSince(solve_start);
  summary.minimizer_seconds = summary.solve_seconds;

  const auto writeback_start = Clock::now();
  for (const VariableSlot& slot : setup.slots) {
    if (slot.free) values->setFromAmbient(slot.key, solved_ambient.data() + slot.ambient);
  }
  summary.final_cost_by_type = graph.costByType(*values, options.num_threads);
  summary.writeback_seconds = secondsSince(writeback_start);

  int converged = 0;
  long total_iterations = 0;
  long rejected = 0;
  // Every factor's cost, those without a free variable included, as Ceres counts them.
  summary.initial_cost = totalCost(summary.initial_cost_by_type);
  summary.final_cost = totalCost(summary.final_cost_by_type);
  for (const ComponentResult& r : results) {
    summary.iterations = std::max(summary.iterations, r.iterations);
    converged += r.converged ? 1 : 0;
    total_iterations += r.iterations;
    rejected += r.rejected;
  }
  summary.usable = std::isfinite(summary.final_cost);
  summary.termination = converged == num_components ? "CONVERGENCE" : "NO_CONVERGENCE";
  std::ostringstream message;
  message << num_components << " components solved apart, " << converged << " converged, "
          << num_components - converged << " stopped at " << options.max_iterations
          << " iterations";
  summary.message = message.str();
  summary.linear_solver = "dense_cholesky_per_component";
  summary.ordering = "components (" + std::to_string(num_components) + " solved apart)";
  message << "; " << total_iterations << " iterations in all (" << rejected << " rejected steps)";
  summary.full_report = message.str();
  if (options.verbose) std::printf("%s\n", summary.full_report.c_str());
  summary.total_seconds = secondsSince(start);
  if (options.on_iteration) {
    options.on_iteration({summary.iterations, summary.final_cost, summary.total_seconds, true});
  }
  return summary;
}

}  // namespace curvesfm
