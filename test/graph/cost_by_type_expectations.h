#pragma once

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "graph/factor_graph.h"

namespace curvesfm::testing {

/// Expects the same factor types with the same counts, and each type's cost within
/// `relative_tolerance` of the expected one's.
inline void expectSameCostsByType(const std::map<std::string, FactorTypeCost>& actual,
                                  const std::map<std::string, FactorTypeCost>& expected,
                                  double relative_tolerance) {
  ASSERT_EQ(actual.size(), expected.size());
  for (const auto& [type, cost] : expected) {
    ASSERT_EQ(actual.count(type), 1u) << type;
    EXPECT_EQ(actual.at(type).count, cost.count) << type;
    EXPECT_NEAR(actual.at(type).cost, cost.cost, relative_tolerance * cost.cost) << type;
  }
}

}  // namespace curvesfm::testing
