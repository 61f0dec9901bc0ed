#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "graph/robust_kernel.h"

namespace curvesfm {

// The parts of Ceres' Levenberg-Marquardt (TrustRegionMinimizer with the
// LevenbergMarquardtStrategy) that our own minimisers (graph/component_solver.h,
// graph/schur_solver.h) share, so that their objective, damping and step acceptance are Ceres'
// and only the linear algebra differs.

/// Ceres' defaults for what OptimizerOptions does not expose.
constexpr double kMinRelativeDecrease = 1e-3;  ///< Keep a step achieving this share of the model's.
constexpr double kMinDiagonal = 1e-6;          ///< Clamp of Marquardt's diagonal.
constexpr double kMaxDiagonal = 1e32;

/// The trust region: Marquardt's damping is diag(H) / radius. After a kept step the radius grows
/// by 1 / max(1/3, 1 - (2 q - 1)^3) (q: the step's quality, actual over model decrease); after a
/// rejected one it is divided by a factor that doubles with every rejection in a row.
class TrustRegionRadius {
 public:
  explicit TrustRegionRadius(double initial) : radius_(initial) {}
  /// The factor on the clamped diagonal of H.
  double damping() const { return 1.0 / radius_; }
  void accept(double step_quality) {
    radius_ = std::min(kMaxRadius,
                       radius_ / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * step_quality - 1.0, 3)));
    decrease_factor_ = 2.0;
  }
  void reject() {
    radius_ /= decrease_factor_;
    decrease_factor_ *= 2.0;
  }
  /// Ceres stops when the radius falls below its minimum.
  bool collapsed() const { return radius_ < kMinRadius; }

 private:
  static constexpr double kMaxRadius = 1e16;
  static constexpr double kMinRadius = 1e-32;
  double radius_;
  double decrease_factor_ = 2.0;
};

/// OptimizerOptions::stall_iterations: true once the lowest cost so far fell by less than
/// `tolerance` of itself over the last `window` iterations. window 0 never stalls. The window
/// opens at the first step that lowers the cost: the rejected steps before it shrink the trust
/// region from its first radius (global BA's 1e4 takes five of them to reach 0.3), a search for
/// the step's scale rather than a stall, and a solve ended there would never have moved.
class StallTest {
 public:
  StallTest(int window, double tolerance, double start_cost)
      : window_(window), tolerance_(tolerance), lowest_(1, start_cost) {}
  /// After each iteration, with the cost it ended at.
  bool stalled(double cost) {
    if (window_ <= 0) return false;
    if (lowest_.size() == 1 && !(cost < lowest_.back())) return false;  // No step kept yet.
    lowest_.push_back(std::min(lowest_.back(), cost));
    const std::size_t n = lowest_.size() - 1;  // Iterations so far.
    if (n < static_cast<std::size_t>(window_)) return false;
    return lowest_[n - window_] - lowest_[n] <= tolerance_ * std::abs(lowest_[n]);
  }

 private:
  int window_;
  double tolerance_;
  std::vector<double> lowest_;  // After each iteration, the start first.
};

/// Marquardt's diagonal of H as Ceres clamps it.
inline Eigen::VectorXd marquardtDiagonal(const Eigen::Ref<const Eigen::VectorXd>& diagonal) {
  return diagonal.cwiseMax(kMinDiagonal).cwiseMin(kMaxDiagonal);
}

/// Turns a factor's unwhitened error `r` and Jacobian `J` (its free columns side by side) into
/// the rows a Gauss-Newton step sees, as Ceres' Corrector does: whitened by sigma, then scaled by
/// sqrt(rho') with Triggs' correction, so the kernel's curvature enters the model. `s` is
/// |r / sigma|^2 and `rho` the kernel's rho, rho', rho'' at s.
inline void whitenAndCorrect(double sigma, double s, const double rho[3], Eigen::MatrixXd* J,
                             Eigen::VectorXd* r) {
  *r /= sigma;
  const double sqrt_rho1 = std::sqrt(std::max(rho[1], 0.0));
  if (s > 0.0 && rho[2] > 0.0 && rho[1] > 0.0) {
    const double alpha = 1.0 - std::sqrt(std::max(1.0 + 2.0 * s * rho[2] / rho[1], 0.0));
    for (Eigen::Index c = 0; c < J->cols(); ++c) {  // J -= (alpha / s) r (r^T J), allocation-free
      J->col(c) -= (alpha / s * r->dot(J->col(c))) * *r;
    }
    *J *= sqrt_rho1 / sigma;
    *r *= sqrt_rho1 / (1.0 - alpha);
  } else {
    *J *= sqrt_rho1 / sigma;
    *r *= sqrt_rho1;
  }
}

}  // namespace curvesfm
