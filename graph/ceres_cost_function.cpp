#include "graph/ceres_cost_function.h"

#include <algorithm>

#include "graph/ceres_manifolds.h"

namespace curvesfm {

FactorCostFunction::FactorCostFunction(std::shared_ptr<const Factor> factor)
    : factor_(std::move(factor)),
      types_(factor_->variableTypes()),
      inverse_sigma_(1.0 / factor_->noiseModel().sigma) {
  set_num_residuals(factor_->residualDimension());
  for (VariableType type : types_) {
    mutable_parameter_block_sizes()->push_back(ambientDim(type));
    max_tangent_block_ = std::max(max_tangent_block_, tangentDim(type));
  }
}

bool FactorCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const int rows = num_residuals();
  const std::size_t num_blocks = types_.size();
  // Per-thread scratch for the tangent Jacobians: grows once, then no allocation per call.
  thread_local std::vector<double> scratch;
  thread_local std::vector<double*> tangent;
  tangent.assign(num_blocks, nullptr);
  if (jacobians) {
    scratch.resize(std::max(scratch.size(), num_blocks * rows * max_tangent_block_));
    for (std::size_t i = 0; i < num_blocks; ++i) {
      if (jacobians[i]) tangent[i] = scratch.data() + i * rows * max_tangent_block_;
    }
  }
  factor_->evaluateRaw(parameters, residuals, tangent.data());
  for (int r = 0; r < rows; ++r) residuals[r] *= inverse_sigma_;
  if (!jacobians) return true;
  for (std::size_t i = 0; i < num_blocks; ++i) {
    if (!jacobians[i]) continue;
    const int size = rows * tangentDim(types_[i]);
    for (int k = 0; k < size; ++k) tangent[i][k] *= inverse_sigma_;
    liftToAmbient(types_[i], parameters[i], tangent[i], rows, jacobians[i]);
  }
  return true;
}

}  // namespace curvesfm
