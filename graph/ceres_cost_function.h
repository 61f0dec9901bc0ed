#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <vector>

#include "graph/factor.h"
#include "graph/robust_kernel.h"

namespace curvesfm {

/// Where the solver keeps one variable of a factor: in a parameter block of its own (ambient
/// coordinates, with the type's manifold), or inside a shared block as the tangent offset from
/// an anchor (see retractAnchored), or held at its anchor.
struct VariableBinding {
  VariableType type = VariableType::kPoint3;
  int block = 0;  ///< Index into the cost function's parameter blocks.
  /// Shared blocks only: the variable's anchor (ambient); nullptr for a block of its own.
  const double* anchor = nullptr;
  /// Shared blocks only: first column of the variable's offset in the block, or -1 if the
  /// variable is held at its anchor (a constant beside free variables of the same curve).
  int column = 0;

  bool ownBlock() const { return anchor == nullptr; }
  bool heldAtAnchor() const { return anchor != nullptr && column < 0; }
};

/// Presents a Factor to Ceres: residuals are the whitened error r / sigma. A variable with a
/// block of its own gets the factor's tangent Jacobian lifted to ambient coordinates (see
/// liftToAmbient), so that Ceres' product with the manifold's PlusJacobian gives it back; a
/// variable in a shared block gets it through its anchored chart (writeAnchoredJacobian), into
/// its columns of that block. The robust kernel is not applied here; it goes to Ceres as a
/// RobustLoss.
class FactorCostFunction : public ceres::CostFunction {
 public:
  /// A block of its own per key, in key order.
  explicit FactorCostFunction(std::shared_ptr<const Factor> factor);
  /// One binding per key of `factor`; `block_sizes` are the parameter blocks' sizes (ambient for
  /// a block of its own, tangent columns for a shared one).
  FactorCostFunction(std::shared_ptr<const Factor> factor, std::vector<VariableBinding> bindings,
                     const std::vector<int>& block_sizes);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  /// The unwhitened error at `parameters` (no Jacobians, nothing allocated after the first call
  /// on a thread).
  void evaluateError(double const* const* parameters, double* error) const;

  const Factor& factor() const { return *factor_; }

 private:
  /// Points `ambient` at each variable's value, retracting shared-block variables into
  /// `buffer` (sum of their ambient sizes).
  void gatherAmbient(double const* const* parameters, const double** ambient, double* buffer) const;

  std::shared_ptr<const Factor> factor_;
  std::vector<VariableBinding> bindings_;
  std::vector<char> shared_block_;  ///< Per parameter block: does it hold shared variables?
  double inverse_sigma_;
  int max_tangent_block_ = 0;
  int shared_ambient_size_ = 0;
};

/// Our RobustKernel as a Ceres loss function, so the cost Ceres minimises is the one
/// FactorGraph::cost() reports.
class RobustLoss : public ceres::LossFunction {
 public:
  explicit RobustLoss(const RobustKernel& kernel) : kernel_(kernel) {}
  void Evaluate(double s, double rho[3]) const override { kernel_.evaluate(s, rho); }
  const RobustKernel& kernel() const { return kernel_; }

 private:
  RobustKernel kernel_;
};

}  // namespace curvesfm
