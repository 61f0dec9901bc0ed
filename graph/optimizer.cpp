#include "graph/optimizer.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/errors.h"

namespace curvesfm {
namespace {

template <class Enum>
Enum parseEnum(const std::string& name, const std::string& field, const char* struct_name,
               std::initializer_list<Enum> all) {
  std::string accepted;
  for (Enum value : all) {
    if (name == toString(value)) return value;
    accepted += (accepted.empty() ? "" : ", ") + toString(value);
  }
  throw InvalidOptions(struct_name, field, "\"" + name + "\"", "expected one of " + accepted);
}

void requirePositive(double value, const char* field) {
  if (!(value > 0.0 && std::isfinite(value))) {
    throw InvalidOptions("OptimizerOptions", field, std::to_string(value),
                         "must be > 0 and finite");
  }
}

}  // namespace

std::string toString(LinearSolver solver) {
  switch (solver) {
    case LinearSolver::kSparseSchur: return "sparse_schur";
    case LinearSolver::kDenseSchur: return "dense_schur";
    case LinearSolver::kIterativeSchur: return "iterative_schur";
    case LinearSolver::kSparseNormalCholesky: return "sparse_normal_cholesky";
  }
  return "unknown";
}

std::string toString(TrustRegion strategy) {
  switch (strategy) {
    case TrustRegion::kLevenbergMarquardt: return "levenberg_marquardt";
    case TrustRegion::kDogleg: return "dogleg";
  }
  return "unknown";
}

LinearSolver parseLinearSolver(const std::string& name, const std::string& field) {
  return parseEnum(name, field, "OptimizerOptions",
                   {LinearSolver::kSparseSchur, LinearSolver::kDenseSchur,
                    LinearSolver::kIterativeSchur, LinearSolver::kSparseNormalCholesky});
}

TrustRegion parseTrustRegion(const std::string& name, const std::string& field) {
  return parseEnum(name, field, "OptimizerOptions",
                   {TrustRegion::kLevenbergMarquardt, TrustRegion::kDogleg});
}

void OptimizerOptions::validate() const {
  if (max_iterations < 0) {
    throw InvalidOptions("OptimizerOptions", "max_iterations", std::to_string(max_iterations),
                         "must be >= 0");
  }
  if (num_threads < 1) {
    throw InvalidOptions("OptimizerOptions", "num_threads", std::to_string(num_threads),
                         "must be >= 1");
  }
  requirePositive(function_tolerance, "function_tolerance");
  requirePositive(gradient_tolerance, "gradient_tolerance");
  requirePositive(parameter_tolerance, "parameter_tolerance");
}

std::string OptimizationSummary::toString() const {
  std::ostringstream os;
  os << std::setprecision(6);
  os << "  cost (0.5*sum rho): " << initial_cost << " -> " << final_cost << "  [" << termination
     << ", " << iterations << " iterations, " << linear_solver << ", ordering " << ordering
     << "]\n";
  for (const auto& [type, initial] : initial_cost_by_type) {
    const auto it = final_cost_by_type.find(type);
    const double final_value = it == final_cost_by_type.end() ? 0.0 : it->second.cost;
    os << "    " << std::left << std::setw(24) << type << std::right << std::setw(8)
       << initial.count << " factors  " << initial.cost << " -> " << final_value << "\n";
  }
  os << "  problem: " << num_factors << " factors, " << num_free_variables << " free / "
     << num_constant_variables << " constant variables, " << num_residuals << " residuals, "
     << num_effective_parameters << " parameters\n";
  os << std::fixed << std::setprecision(3) << "  time (s): setup " << setup_seconds << ", solve "
     << solve_seconds << " (minimiser " << minimizer_seconds << "), write-back "
     << writeback_seconds << ", total " << total_seconds;
  return os.str();
}

}  // namespace curvesfm
