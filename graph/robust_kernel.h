#pragma once

#include <string>

#include "core/enum_names.h"

namespace curvesfm {

enum class RobustKernelType { kNone, kHuber, kCauchy, kTukey };

template <>
struct EnumNames<RobustKernelType> {
  static constexpr std::array<std::pair<RobustKernelType, const char*>, 4> kNames = {{
      {RobustKernelType::kNone, "none"},
      {RobustKernelType::kHuber, "huber"},
      {RobustKernelType::kCauchy, "cauchy"},
      {RobustKernelType::kTukey, "tukey"},
  }};
};

/// A robust kernel rho(s) of the squared whitened residual norm s = |r/sigma|^2, in Ceres'
/// convention: the cost of a residual block is 0.5 * rho(s); rho(s) = s without a kernel.
/// `width` a (> 0, in whitened units, i.e. sigmas) is where the kernel departs from s:
///   Huber:  rho = s                          for s <= a^2, else 2 a sqrt(s) - a^2
///   Cauchy: rho = a^2 log(1 + s / a^2)
///   Tukey:  rho = a^2/3 (1 - (1 - s/a^2)^3)  for s <= a^2, else a^2/3
class RobustKernel {
 public:
  /// No kernel (plain least squares).
  RobustKernel() = default;
  /// Throws InvalidOptions unless width > 0 and finite (any width is accepted with kNone).
  RobustKernel(RobustKernelType type, double width);

  RobustKernelType type() const { return type_; }
  double width() const { return width_; }

  /// rho(s), rho'(s), rho''(s) for s >= 0 into out[0..2].
  void evaluate(double s, double out[3]) const;
  double rho(double s) const;

  /// e.g. "huber(1)" or "none".
  std::string toString() const;

 private:
  RobustKernelType type_ = RobustKernelType::kNone;
  double width_ = 1.0;
};

/// How a factor's error is weighted: whitened error r / sigma, then the robust kernel.
/// The information weight is 1 / sigma^2. Isotropic: one sigma for every residual row.
struct NoiseModel {
  double sigma = 1.0;   ///< Standard deviation of every residual row, in the residual's unit; > 0.
  RobustKernel kernel;  ///< Robust kernel on the whitened squared norm; none by default.

  /// Throws InvalidOptions unless sigma > 0 and finite.
  void validate() const;
  /// 0.5 * rho(|error / sigma|^2): the Ceres cost of one residual block.
  double cost(double squared_unwhitened_norm) const {
    return 0.5 * kernel.rho(squared_unwhitened_norm / (sigma * sigma));
  }
};

}  // namespace curvesfm
