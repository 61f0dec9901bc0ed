#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "graph/factor.h"
#include "graph/values.h"

namespace curvesfm {

/// Cost of all factors of one type.
struct FactorTypeCost {
  int count = 0;      ///< Number of factors of this type.
  double cost = 0.0;  ///< Sum of 0.5 * rho(|r / sigma|^2) over them (Ceres' convention).
};

/// The sum of the per-type costs (FactorGraph::costByType's total).
double totalCost(const std::map<std::string, FactorTypeCost>& by_type);

/// A list of factors sharing variables by key. Factors are immutable and shared, so a graph is
/// cheap to copy and a solver may hold them while the graph changes.
class FactorGraph {
 public:
  /// Below this many factors a thread of costByType costs more to hand the work to than it saves.
  static constexpr int kMinFactorsPerThread = 256;

  using FactorPtr = std::shared_ptr<const Factor>;

  void add(FactorPtr factor);
  template <class F, class... Args>
  void emplace(Args&&... args) {
    add(std::make_shared<const F>(std::forward<Args>(args)...));
  }

  std::size_t size() const { return factors_.size(); }
  bool empty() const { return factors_.empty(); }
  const FactorPtr& operator[](std::size_t i) const { return factors_[i]; }
  auto begin() const { return factors_.begin(); }
  auto end() const { return factors_.end(); }

  /// Total cost 0.5 * sum rho(|r_i / sigma_i|^2) at `values`.
  double cost(const Values& values) const;
  /// Cost per factor typeName() at `values`, the factors evaluated on up to `num_threads`
  /// threads (the result does not depend on their number).
  std::map<std::string, FactorTypeCost> costByType(const Values& values, int num_threads = 1) const;
  /// The per-type sums of `costs`, factor i's cost at costs[i] (size()), added in the factors'
  /// order as costByType does: a solver that evaluated every factor already need not again.
  std::map<std::string, FactorTypeCost> sumByType(const std::vector<double>& costs) const;

 private:
  std::vector<FactorPtr> factors_;
};

}  // namespace curvesfm
