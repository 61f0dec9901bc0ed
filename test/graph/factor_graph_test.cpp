#include "graph/factor_graph.h"

#include <gtest/gtest.h>

#include "test/graph/toy_scene.h"

namespace curvesfm {
namespace {

// Enough factors for three threads, the two types interleaved (six of one, then one of the
// other), so the sums run through the type look-up at every change.
TEST(FactorGraph, CostByTypeIsTheSameOnAnyThreadCount) {
  const testing::ToyScene scene = testing::makeToyScene(200, 6, 5, 1.0);
  ASSERT_GT(scene.graph.size(), 3u * FactorGraph::kMinFactorsPerThread);
  const auto one = scene.graph.costByType(scene.start, 1);
  EXPECT_EQ(one.at("all_types").count, 1200);
  EXPECT_EQ(one.at("point_prior").count, 200);
  EXPECT_GT(one.at("all_types").cost, 0.0);
  EXPECT_NEAR(totalCost(one), scene.graph.cost(scene.start), 1e-12 * totalCost(one));
  for (const int threads : {2, 3, 64}) {
    const auto many = scene.graph.costByType(scene.start, threads);
    ASSERT_EQ(many.size(), one.size());
    for (const auto& [type, cost] : one) {
      EXPECT_EQ(many.at(type).count, cost.count) << type << ", " << threads << " threads";
      EXPECT_EQ(many.at(type).cost, cost.cost) << type << ", " << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace curvesfm
