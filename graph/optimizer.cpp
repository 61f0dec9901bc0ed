#include "graph/optimizer.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/errors.h"

namespace curvesfm {
void OptimizerOptions::validate() const {
  const OptionCheck require("OptimizerOptions");
  require(max_iterations >= 0, "max_iterations", max_iterations, "must be >= 0");
  require(num_threads >= 1, "num_threads", num_threads, "must be >= 1");
  require.positive("initial_trust_region_radius", initial_trust_region_radius);
  require.positive("function_tolerance", function_tolerance);
  require.positive("gradient_tolerance", gradient_tolerance);
  require.positive("parameter_tolerance", parameter_tolerance);
  require(stall_iterations >= 0, "stall_iterations", stall_iterations, "must be >= 0");
  require.positive("stall_tolerance", stall_tolerance);
  require(max_curve_block_size >= 1, "max_curve_block_size", max_curve_block_size, "must be >= 1");
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
