#pragma once

#include <Eigen/Core>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "graph/key.h"
#include "graph/robust_kernel.h"
#include "graph/values.h"
#include "graph/variable_traits.h"

namespace curvesfm {

/// Error and tangent-space Jacobians of a factor at some Values (for tests and tools).
struct Linearization {
  Eigen::VectorXd error;                 ///< Unwhitened error.
  std::vector<Eigen::MatrixXd> jacobians;  ///< One per key: rows x tangentDim(key).
};

/// A residual over a few variables, in GTSAM's style. The solver-facing interface is
/// evaluateRaw(); concrete factors derive from NoiseModelFactorN below and implement a typed
/// evaluateError(). The noise model (sigma + robust kernel) is applied by the solver bridge and
/// by cost(); errors and Jacobians here are unwhitened.
class Factor {
 public:
  Factor(std::vector<Key> keys, NoiseModel noise_model);
  virtual ~Factor() = default;

  const std::vector<Key>& keys() const { return keys_; }
  const NoiseModel& noiseModel() const { return noise_model_; }
  /// Number of residual rows.
  virtual int residualDimension() const = 0;
  /// Short name of the residual kind for reports, e.g. "point_reprojection".
  virtual const char* typeName() const = 0;
  /// Expected variable type of each key, in key order.
  virtual std::vector<VariableType> variableTypes() const = 0;

  /// Unwhitened error at variables given in ambient coordinates (`ambient[i]` for keys()[i]).
  /// Fills `tangent_jacobians[i]` (row-major, rows x tangentDim) when non-null.
  /// Must be thread-safe and allocation-free; never throws.
  virtual void evaluateRaw(const double* const* ambient, double* error,
                           double* const* tangent_jacobians) const = 0;

  /// Unwhitened error at `values` (allocates; not for hot loops).
  Eigen::VectorXd unwhitenedError(const Values& values) const;
  /// Error and all tangent Jacobians at `values` (allocates; not for hot loops).
  Linearization linearize(const Values& values) const;
  /// 0.5 * rho(|error / sigma|^2), the factor's share of the Ceres cost.
  double cost(const Values& values) const;

 private:
  std::vector<Key> keys_;
  NoiseModel noise_model_;
};

/// Base of factors over the typed variables Ts... with `kRows` residual rows (or Eigen::Dynamic
/// rows bounded by kMaxRows, which keeps evaluation on the stack).
/// Derived classes implement
///   Error evaluateError(const Ts&... x, Jacobian<Ts>*... H) const;
/// returning the unwhitened error and filling each H (rows x tangent dim of the type) only when
/// it is non-null. Use NoiseModelFactorN for a fixed number of rows.
template <int kRows, int kMaxRows, class... Ts>
class NoiseModelFactorBase : public Factor {
 public:
  static constexpr int kNumKeys = sizeof...(Ts);
  using Error = Eigen::Matrix<double, kRows, 1, Eigen::ColMajor, kMaxRows, 1>;
  template <class T>
  using Jacobian = Eigen::Matrix<double, kRows, VariableTraits<T>::kTangentDim,
                                 VariableTraits<T>::kTangentDim == 1 ? Eigen::ColMajor
                                                                     : Eigen::RowMajor,
                                 kMaxRows, VariableTraits<T>::kTangentDim>;

  /// `rows` only matters for kRows == Eigen::Dynamic.
  NoiseModelFactorBase(std::vector<Key> keys, NoiseModel noise_model, int rows = kRows)
      : Factor(std::move(keys), std::move(noise_model)), rows_(rows) {}

  int residualDimension() const override { return rows_; }
  std::vector<VariableType> variableTypes() const override {
    return {VariableTraits<Ts>::kType...};
  }

  virtual Error evaluateError(const Ts&... x, Jacobian<Ts>*... H) const = 0;

  void evaluateRaw(const double* const* ambient, double* error,
                   double* const* tangent_jacobians) const override {
    evaluateRawImpl(std::index_sequence_for<Ts...>{}, ambient, error, tangent_jacobians);
  }

 private:
  template <std::size_t... I>
  void evaluateRawImpl(std::index_sequence<I...>, const double* const* ambient, double* error,
                       double* const* tangent_jacobians) const {
    std::tuple<Jacobian<Ts>...> H;
    const Error e = evaluateError(VariableTraits<Ts>::fromAmbient(ambient[I])...,
                                  (tangent_jacobians[I] ? &std::get<I>(H) : nullptr)...);
    Eigen::Map<Eigen::VectorXd>(error, rows_) = e;
    (copyJacobian<Ts>(std::get<I>(H), tangent_jacobians[I]), ...);
  }

  template <class T>
  void copyJacobian(const Jacobian<T>& H, double* out) const {
    if (!out) return;
    Eigen::Map<Eigen::Matrix<double, kRows, VariableTraits<T>::kTangentDim,
                              Jacobian<T>::IsRowMajor ? Eigen::RowMajor : Eigen::ColMajor>>(
        out, rows_, VariableTraits<T>::kTangentDim) = H;
  }

  int rows_;
};

/// A factor with a fixed number of residual rows over variables Ts...
template <int kRows, class... Ts>
using NoiseModelFactorN = NoiseModelFactorBase<kRows, kRows, Ts...>;

}  // namespace curvesfm
