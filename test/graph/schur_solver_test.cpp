#include "graph/schur_solver.h"

#include <gtest/gtest.h>

#include <map>
#include <string>

#include "graph/levenberg_marquardt.h"
#include "graph/optimizer.h"
#include "test/graph/cost_by_type_expectations.h"
#include "test/graph/toy_scene.h"

namespace curvesfm {
namespace {

using testing::AllTypesFactor;

constexpr int kGroups = 6;
constexpr int kPoses = 4;

using Scene = testing::ToyScene;

// The toy scene off its truth, with a factor over two free poses only (the pose-pose blocks of
// the reduced system that no structure fills).
Scene makeScene() {
  Scene scene = testing::makeToyScene(kGroups, kPoses, 11, 1.0);
  scene.graph.emplace<testing::TranslationDifferenceFactor>(poseKey(3), poseKey(1),
                                                            Eigen::Vector3d(2.1, 0.9, -0.1));
  return scene;
}

ProblemConfig firstPoseHeld() {
  ProblemConfig config;
  config.setConstant(poseKey(0));
  return config;
}

OptimizerOptions tight(LinearSolver solver) {
  OptimizerOptions options;
  options.linear_solver = solver;
  options.max_iterations = 200;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  return options;
}

void expectSameVariables(const Values& a, const Values& b, double tolerance) {
  for (int g = 0; g < kGroups; ++g) {
    EXPECT_LT((a.at<Eigen::Vector3d>(pointKey(g)) - b.at<Eigen::Vector3d>(pointKey(g))).norm(),
              tolerance);
    EXPECT_LT(a.at<Direction>(directionKey(g, 0)).angleTo(b.at<Direction>(directionKey(g, 0))),
              tolerance);
    EXPECT_NEAR(a.at<double>(startLengthKey(g, 0)), b.at<double>(startLengthKey(g, 0)), tolerance);
  }
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_LT(a.at<Pose3>(poseKey(i)).localCoordinates(b.at<Pose3>(poseKey(i))).norm(), tolerance);
  }
}

TEST(GraphSchur, ReachesCeresOptimumWithPosesAndStructureFree) {
  const Scene scene = makeScene();
  Values ours = scene.start;
  Values ceres = scene.start;
  const OptimizationSummary schur =
      optimize(scene.graph, &ours, firstPoseHeld(), tight(LinearSolver::kGraphSchur));
  const OptimizationSummary sparse =
      optimize(scene.graph, &ceres, firstPoseHeld(), tight(LinearSolver::kSparseSchur));
  EXPECT_EQ(schur.linear_solver, "GRAPH_SCHUR");
  EXPECT_EQ(schur.ordering, "graph_schur (6 groups eliminated, 3 poses reduced)");
  EXPECT_EQ(schur.termination, "CONVERGENCE") << schur.message;
  EXPECT_NEAR(schur.initial_cost, sparse.initial_cost, 1e-12 * sparse.initial_cost);
  EXPECT_LT(schur.final_cost, 0.5 * schur.initial_cost);
  EXPECT_NEAR(schur.final_cost, sparse.final_cost, 1e-9 * sparse.final_cost);
  expectSameVariables(ours, ceres, 1e-6);
  EXPECT_TRUE(ours.at<Pose3>(poseKey(0)).translation() ==
              scene.start.at<Pose3>(poseKey(0)).translation());
  EXPECT_EQ(schur.num_free_variables, 3 * kGroups + kPoses - 1);
  EXPECT_EQ(schur.num_constant_variables, 1);
  EXPECT_EQ(schur.num_effective_parameters, 6 * (kPoses - 1) + 6 * kGroups);  // Free only.
  EXPECT_EQ(schur.num_residuals, sparse.num_residuals);
}

TEST(GraphSchur, TakesCeresStepsIterationForIteration) {
  // Same damping and acceptance rules: every iteration's cost, rejected steps' included, agrees
  // with Ceres' to rounding (Ceres' curve blocks would move in another chart, hence a block per
  // variable there).
  const Scene scene = makeScene();
  std::vector<double> ours_costs;
  std::vector<double> ceres_costs;
  OptimizerOptions options;  // Default tolerances: the solves also stop alike.
  options.linear_solver = LinearSolver::kGraphSchur;
  options.on_iteration = [&](const IterationProgress& p) { ours_costs.push_back(p.cost); };
  Values ours = scene.start;
  const OptimizationSummary schur = optimize(scene.graph, &ours, firstPoseHeld(), options);
  options.linear_solver = LinearSolver::kSparseSchur;
  options.curve_blocks = false;
  options.on_iteration = [&](const IterationProgress& p) { ceres_costs.push_back(p.cost); };
  Values ceres = scene.start;
  const OptimizationSummary sparse = optimize(scene.graph, &ceres, firstPoseHeld(), options);
  EXPECT_EQ(schur.iterations, sparse.iterations);
  EXPECT_EQ(schur.message.substr(0, 18), sparse.message.substr(0, 18));
  ASSERT_EQ(ours_costs.size(), ceres_costs.size());
  for (std::size_t i = 0; i < ours_costs.size(); ++i) {
    EXPECT_NEAR(ours_costs[i], ceres_costs[i], 1e-8 * ceres_costs[i]) << "iteration " << i;
  }
}

TEST(GraphSchur, StructureOnlyWithEveryPoseHeld) {
  const Scene scene = makeScene();
  ProblemConfig config;
  config.setConstant(VariableCategory::kPose);
  Values ours = scene.start;
  Values ceres = scene.start;
  const OptimizationSummary schur =
      optimize(scene.graph, &ours, config, tight(LinearSolver::kGraphSchur));
  optimize(scene.graph, &ceres, config, tight(LinearSolver::kSparseSchur));
  EXPECT_EQ(schur.ordering, "graph_schur (6 groups eliminated, 0 poses reduced)");
  expectSameVariables(ours, ceres, 1e-6);
}

// The costs per factor type come from the solve's own linearisations: the same as evaluating
// every factor at the start and at the solution, on a solve that rejects some steps.
TEST(GraphSchur, ReportsTheCostsPerTypeAtTheStartAndTheSolution) {
  const Scene scene = makeScene();
  Values values = scene.start;
  OptimizerOptions options;
  options.linear_solver = LinearSolver::kGraphSchur;
  options.initial_trust_region_radius = 1e8;  // Undamped first steps, some rejected.
  const OptimizationSummary summary = optimize(scene.graph, &values, firstPoseHeld(), options);
  ASSERT_GT(summary.iterations, 0);
  ASSERT_NE(summary.full_report.find("Unsuccessful steps "), std::string::npos);
  EXPECT_EQ(summary.full_report.find("Unsuccessful steps 0\n"), std::string::npos)
      << summary.full_report;
  testing::expectSameCostsByType(summary.initial_cost_by_type, scene.graph.costByType(scene.start),
                                 1e-12);
  testing::expectSameCostsByType(summary.final_cost_by_type, scene.graph.costByType(values), 1e-12);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
}

TEST(GraphSchur, TwoThreadsAgreeWithOneToRounding) {
  const Scene scene = makeScene();
  Values one = scene.start;
  Values two = scene.start;
  OptimizerOptions options = tight(LinearSolver::kGraphSchur);
  const OptimizationSummary a = optimize(scene.graph, &one, firstPoseHeld(), options);
  options.num_threads = 2;
  const OptimizationSummary b = optimize(scene.graph, &two, firstPoseHeld(), options);
  // Each thread sums its own share of the reduced system, so the two solves part by rounding:
  // to the same cost, and along the scene's weakly held directions (a point in the linear part
  // of its Huber prior, against its scaled direction) within 1e-6.
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-12 * a.final_cost);
  expectSameVariables(one, two, 1e-5);
}

TEST(GraphSchur, BeyondItsReducedSystemLimitCeresSolves) {
  // One point seen by more free poses than the dense reduced system takes.
  const int poses = kGraphSchurMaxReducedDimension / 6 + 1;
  FactorGraph graph;
  Values values;
  values.insert(pointKey(0), Eigen::Vector3d(0.0, 0.0, 1.0));
  values.insert(directionKey(0, 0), Direction(Eigen::Vector3d::UnitX()));
  values.insert(startLengthKey(0, 0), 1.0);
  for (int i = 0; i < poses; ++i) {
    values.insert(poseKey(i), Pose3());
    graph.emplace<AllTypesFactor>(poseKey(i), pointKey(0), directionKey(0, 0), startLengthKey(0, 0),
                                  Eigen::Vector3d(1.0, 0.0, 1.0));
  }
  OptimizerOptions options;
  options.linear_solver = LinearSolver::kGraphSchur;
  options.max_iterations = 1;
  const OptimizationSummary summary = optimize(graph, &values, ProblemConfig{}, options);
  EXPECT_EQ(summary.linear_solver, "SPARSE_SCHUR");
  EXPECT_NE(summary.ordering.find("Ceres instead of graph_schur: " + std::to_string(poses) +
                                  " free poses (at most " +
                                  std::to_string(kGraphSchurMaxReducedDimension / 6) + ")"),
            std::string::npos)
      << summary.ordering;
}

TEST(GraphSchur, TheHookSeesEveryIteration) {
  const Scene scene = makeScene();
  Values values = scene.start;
  std::vector<IterationProgress> seen;
  OptimizerOptions options;
  options.linear_solver = LinearSolver::kGraphSchur;
  options.on_iteration = [&seen](const IterationProgress& p) { seen.push_back(p); };
  const OptimizationSummary summary = optimize(scene.graph, &values, firstPoseHeld(), options);
  ASSERT_EQ(static_cast<int>(seen.size()), summary.iterations + 1);
  EXPECT_EQ(seen.front().iteration, 0);
  EXPECT_NEAR(seen.front().cost, summary.initial_cost, 1e-9 * summary.initial_cost);
  EXPECT_NEAR(seen.back().cost, summary.final_cost, 1e-9 * summary.final_cost);
}

// The stall test ends a solve whose lowest cost fell by less than the tolerance over the
// window, in both Levenberg-Marquardt implementations; the toy scene's cost falls by orders of
// magnitude at first, so a loose tolerance ends it early and the same tolerance ends both alike.
TEST(GraphSchur, AStalledCostEndsTheSolveAsInCeres) {
  const Scene scene = makeScene();
  for (const LinearSolver solver : {LinearSolver::kGraphSchur, LinearSolver::kSparseSchur}) {
    Values full = scene.start;
    Values stalled = scene.start;
    OptimizerOptions options = tight(solver);
    const OptimizationSummary to_the_end = optimize(scene.graph, &full, firstPoseHeld(), options);
    options.stall_iterations = 2;
    options.stall_tolerance = 0.5;
    const OptimizationSummary stopped = optimize(scene.graph, &stalled, firstPoseHeld(), options);
    EXPECT_GE(stopped.iterations, 2);
    EXPECT_LT(stopped.iterations, to_the_end.iterations);
    EXPECT_GT(stopped.final_cost, to_the_end.final_cost);
    EXPECT_EQ(stopped.termination, "CONVERGENCE");
    EXPECT_EQ(stopped.message, "Cost stalled.");
  }
}

// StallTest counts the window over iterations, kept or rejected, against the lowest cost.
TEST(StallTest, ComparesTheLowestCostAcrossTheWindow) {
  StallTest off(0, 0.1, 100.0);
  EXPECT_FALSE(off.stalled(100.0));
  StallTest stall(2, 0.1, 100.0);
  EXPECT_FALSE(stall.stalled(50.0));  // One iteration: the window is not full.
  EXPECT_FALSE(stall.stalled(45.0));  // 100 -> 45 over two.
  EXPECT_FALSE(stall.stalled(60.0));  // A rejected step: the lowest stays 45; 50 -> 45 is 11 %.
  EXPECT_TRUE(stall.stalled(44.0));   // 45 -> 44 over two.
}

// Rejected steps before the first kept one search the trust region's scale: the window opens
// at the first step that lowers the cost, so a solve is not ended before it has moved.
TEST(StallTest, OpensItsWindowAtTheFirstStepThatLowersTheCost) {
  StallTest stall(2, 0.1, 100.0);
  for (int rejected = 0; rejected < 6; ++rejected) EXPECT_FALSE(stall.stalled(130.0));
  EXPECT_FALSE(stall.stalled(100.0));  // Equal is not lower: still searching.
  EXPECT_FALSE(stall.stalled(60.0));   // The first kept step: one iteration in the window.
  EXPECT_FALSE(stall.stalled(59.0));   // 100 -> 59 over two.
  EXPECT_TRUE(stall.stalled(58.0));    // 60 -> 58 over two.
}

}  // namespace
}  // namespace curvesfm
