#include "graph/factor_graph.h"

#include <algorithm>

#include "core/check.h"
#include "core/parallel.h"

namespace curvesfm {

double totalCost(const std::map<std::string, FactorTypeCost>& by_type) {
  double total = 0.0;
  for (const auto& [type, cost] : by_type) total += cost.cost;
  return total;
}

void FactorGraph::add(FactorPtr factor) {
  CURVESFM_CHECK(factor != nullptr) << "FactorGraph::add: null factor";
  factors_.push_back(std::move(factor));
}

double FactorGraph::cost(const Values& values) const {
  double total = 0.0;
  for (const auto& factor : factors_) total += factor->cost(values);
  return total;
}

std::map<std::string, FactorTypeCost> FactorGraph::costByType(const Values& values,
                                                              int num_threads) const {
  // Each factor's cost on the threads, then the sums in the factors' order: the same bits on
  // any thread count. Ceres' and the component solver's summaries call this before and after
  // every solve (graph_schur sums the costs of its own linearisations, sumByType).
  const int n = static_cast<int>(factors_.size());
  std::vector<double> costs(n);
  const int threads = std::clamp(n / kMinFactorsPerThread, 1, std::max(1, num_threads));
  runInParallel(threads, [&](int t) {
    for (int i = n * t / threads; i < n * (t + 1) / threads; ++i) {
      costs[i] = factors_[i]->cost(values);
    }
  });
  return sumByType(costs);
}

std::map<std::string, FactorTypeCost> FactorGraph::sumByType(
    const std::vector<double>& costs) const {
  const int n = static_cast<int>(factors_.size());
  CURVESFM_CHECK(costs.size() == factors_.size())
      << "FactorGraph::sumByType: " << costs.size() << " costs for " << n << " factors";
  std::map<std::string, FactorTypeCost> by_type;
  const char* type = nullptr;
  FactorTypeCost* entry = nullptr;
  for (int i = 0; i < n; ++i) {
    if (factors_[i]->typeName() != type) {  // Factors of one type mostly come in runs.
      type = factors_[i]->typeName();
      entry = &by_type[type];
    }
    ++entry->count;
    entry->cost += costs[i];
  }
  return by_type;
}

}  // namespace curvesfm
