#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <vector>

#include "graph/factor.h"
#include "graph/robust_kernel.h"

namespace curvesfm {

/// Presents a Factor to Ceres: residuals are the whitened error r / sigma, and the factor's
/// tangent Jacobians are lifted to the ambient parameter blocks (see liftToAmbient), so that
/// Ceres' product with the manifold's PlusJacobian gives back exactly the factor's Jacobian.
/// The robust kernel is not applied here; it goes to Ceres as a RobustLoss.
class FactorCostFunction : public ceres::CostFunction {
 public:
  explicit FactorCostFunction(std::shared_ptr<const Factor> factor);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  const Factor& factor() const { return *factor_; }

 private:
  std::shared_ptr<const Factor> factor_;
  std::vector<VariableType> types_;
  double inverse_sigma_;
  int max_tangent_block_ = 0;
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
