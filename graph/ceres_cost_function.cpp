#include "graph/ceres_cost_function.h"

#include <algorithm>

#include "graph/ceres_manifolds.h"

namespace curvesfm {
namespace {

std::vector<VariableBinding> ownBlocks(const Factor& factor) {
  std::vector<VariableBinding> bindings;
  const std::vector<VariableType> types = factor.variableTypes();
  for (std::size_t i = 0; i < types.size(); ++i) {
    bindings.push_back({types[i], static_cast<int>(i), nullptr, 0});
  }
  return bindings;
}

std::vector<int> ambientSizes(const Factor& factor) {
  std::vector<int> sizes;
  for (VariableType type : factor.variableTypes()) sizes.push_back(ambientDim(type));
  return sizes;
}

}  // namespace

FactorCostFunction::FactorCostFunction(std::shared_ptr<const Factor> factor)
    : FactorCostFunction(factor, ownBlocks(*factor), ambientSizes(*factor)) {}

FactorCostFunction::FactorCostFunction(std::shared_ptr<const Factor> factor,
                                       std::vector<VariableBinding> bindings,
                                       const std::vector<int>& block_sizes)
    : factor_(std::move(factor)),
      bindings_(std::move(bindings)),
      shared_block_(block_sizes.size(), 0),
      inverse_sigma_(1.0 / factor_->noiseModel().sigma) {
  set_num_residuals(factor_->residualDimension());
  *mutable_parameter_block_sizes() = block_sizes;
  for (const VariableBinding& binding : bindings_) {
    max_tangent_block_ = std::max(max_tangent_block_, tangentDim(binding.type));
    if (binding.ownBlock()) continue;
    shared_block_[binding.block] = 1;
    shared_ambient_size_ += ambientDim(binding.type);
  }
}

void FactorCostFunction::gatherAmbient(double const* const* parameters, const double** ambient,
                                       double* buffer) const {
  for (std::size_t i = 0; i < bindings_.size(); ++i) {
    const VariableBinding& binding = bindings_[i];
    if (binding.ownBlock()) {
      ambient[i] = parameters[binding.block];
    } else if (binding.heldAtAnchor()) {
      ambient[i] = binding.anchor;
    } else {
      retractAnchored(binding.type, binding.anchor, parameters[binding.block] + binding.column,
                      buffer);
      ambient[i] = buffer;
      buffer += ambientDim(binding.type);
    }
  }
}

void FactorCostFunction::evaluateError(double const* const* parameters, double* error) const {
  thread_local std::vector<const double*> ambient;
  thread_local std::vector<double> buffer;
  thread_local std::vector<double*> no_jacobians;
  ambient.resize(bindings_.size());
  buffer.resize(std::max<std::size_t>(buffer.size(), shared_ambient_size_));
  no_jacobians.assign(bindings_.size(), nullptr);
  gatherAmbient(parameters, ambient.data(), buffer.data());
  factor_->evaluateRaw(ambient.data(), error, no_jacobians.data());
}

bool FactorCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const int rows = num_residuals();
  const std::size_t num_keys = bindings_.size();
  // Per-thread scratch: grows once, then no allocation per call.
  thread_local std::vector<const double*> ambient;
  thread_local std::vector<double> buffer;
  thread_local std::vector<double> scratch;
  thread_local std::vector<double*> tangent;
  ambient.resize(num_keys);
  buffer.resize(std::max<std::size_t>(buffer.size(), shared_ambient_size_));
  tangent.assign(num_keys, nullptr);
  if (jacobians) {
    scratch.resize(std::max(scratch.size(), num_keys * rows * max_tangent_block_));
    for (std::size_t i = 0; i < num_keys; ++i) {
      const VariableBinding& binding = bindings_[i];
      if (jacobians[binding.block] && !binding.heldAtAnchor()) {
        tangent[i] = scratch.data() + i * rows * max_tangent_block_;
      }
    }
  }
  gatherAmbient(parameters, ambient.data(), buffer.data());
  factor_->evaluateRaw(ambient.data(), residuals, tangent.data());
  for (int r = 0; r < rows; ++r) residuals[r] *= inverse_sigma_;
  if (!jacobians) return true;
  // A shared block's columns of variables this factor does not touch stay zero.
  for (std::size_t b = 0; b < shared_block_.size(); ++b) {
    if (shared_block_[b] && jacobians[b]) {
      std::fill_n(jacobians[b], rows * parameter_block_sizes()[b], 0.0);
    }
  }
  for (std::size_t i = 0; i < num_keys; ++i) {
    if (!tangent[i]) continue;
    const VariableBinding& binding = bindings_[i];
    const int size = rows * tangentDim(binding.type);
    for (int k = 0; k < size; ++k) tangent[i][k] *= inverse_sigma_;
    if (binding.ownBlock()) {
      liftToAmbient(binding.type, parameters[binding.block], tangent[i], rows,
                    jacobians[binding.block]);
    } else {
      writeAnchoredJacobian(binding.type, binding.anchor,
                            parameters[binding.block] + binding.column, ambient[i], tangent[i],
                            rows, jacobians[binding.block], parameter_block_sizes()[binding.block],
                            binding.column);
    }
  }
  return true;
}

}  // namespace curvesfm
