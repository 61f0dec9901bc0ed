#include "graph/factor_graph.h"

#include "core/check.h"

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

std::map<std::string, FactorTypeCost> FactorGraph::costByType(const Values& values) const {
  std::map<std::string, FactorTypeCost> by_type;
  for (const auto& factor : factors_) {
    FactorTypeCost& entry = by_type[factor->typeName()];
    ++entry.count;
    entry.cost += factor->cost(values);
  }
  return by_type;
}

}  // namespace curvesfm
