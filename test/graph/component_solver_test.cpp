#include "graph/component_solver.h"

#include <gtest/gtest.h>

#include "graph/optimizer.h"
#include "test/graph/toy_scene.h"

namespace curvesfm {
namespace {

constexpr int kGroups = 6;
constexpr int kPoses = 4;

using Scene = testing::ToyScene;

Scene makeScene() { return testing::makeToyScene(kGroups, kPoses, 7, 0.0); }

ProblemConfig posesHeld() {
  ProblemConfig config;
  config.setConstant(VariableCategory::kPose);
  return config;
}

OptimizerOptions tight(bool apart) {
  OptimizerOptions options;
  options.solve_components_apart = apart;
  options.max_iterations = 200;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  return options;
}

TEST(OptimizeComponents, ReachesCeresOptimumOneComponentPerStructure) {
  const Scene scene = makeScene();
  Values ours = scene.start;
  Values ceres = scene.start;
  const OptimizationSummary apart = optimize(scene.graph, &ours, posesHeld(), tight(true));
  const OptimizationSummary joint = optimize(scene.graph, &ceres, posesHeld(), tight(false));
  EXPECT_EQ(apart.ordering, "components (6 solved apart)");
  EXPECT_EQ(apart.linear_solver, "dense_cholesky_per_component");
  EXPECT_EQ(apart.termination, "CONVERGENCE") << apart.message;
  EXPECT_EQ(joint.linear_solver, "SPARSE_NORMAL_CHOLESKY");
  EXPECT_NEAR(apart.initial_cost, joint.initial_cost, 1e-12 * joint.initial_cost);
  EXPECT_GT(apart.final_cost, 1e-3);  // The noisy targets leave a cost at the optimum.
  EXPECT_NEAR(apart.final_cost, joint.final_cost, 1e-9 * joint.final_cost);
  double sum = 0.0;
  for (const auto& [type, cost] : apart.final_cost_by_type) sum += cost.cost;
  EXPECT_NEAR(sum, apart.final_cost, 1e-9 * apart.final_cost);
  for (int g = 0; g < kGroups; ++g) {
    EXPECT_LT(
        (ours.at<Eigen::Vector3d>(pointKey(g)) - ceres.at<Eigen::Vector3d>(pointKey(g))).norm(),
        1e-7);
    EXPECT_LT(
        ours.at<Direction>(directionKey(g, 0)).angleTo(ceres.at<Direction>(directionKey(g, 0))),
        1e-7);
    EXPECT_NEAR(ours.at<double>(startLengthKey(g, 0)), ceres.at<double>(startLengthKey(g, 0)),
                1e-7);
  }
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_TRUE(ours.at<Pose3>(poseKey(i)).translation() ==
                scene.start.at<Pose3>(poseKey(i)).translation());
  }
  EXPECT_EQ(apart.num_free_variables, 3 * kGroups);
  EXPECT_EQ(apart.num_constant_variables, kPoses);
  EXPECT_EQ(apart.num_effective_parameters, 6 * kGroups);
  EXPECT_EQ(apart.num_residuals, joint.num_residuals);
}

TEST(OptimizeComponents, TheResultDoesNotDependOnTheThreadCount) {
  const Scene scene = makeScene();
  Values one = scene.start;
  Values two = scene.start;
  OptimizerOptions options;
  options.solve_components_apart = true;
  optimize(scene.graph, &one, posesHeld(), options);
  options.num_threads = 2;
  optimize(scene.graph, &two, posesHeld(), options);
  for (int g = 0; g < kGroups; ++g) {
    EXPECT_TRUE(one.at<Eigen::Vector3d>(pointKey(g)) == two.at<Eigen::Vector3d>(pointKey(g)));
    EXPECT_EQ(one.at<double>(startLengthKey(g, 0)), two.at<double>(startLengthKey(g, 0)));
  }
}

TEST(OptimizeComponents, MaxIterationsCountsPerComponent) {
  const Scene scene = makeScene();
  Values values = scene.start;
  OptimizerOptions options = tight(true);
  options.max_iterations = 1;
  const OptimizationSummary summary = optimize(scene.graph, &values, posesHeld(), options);
  EXPECT_EQ(summary.iterations, 1);
  EXPECT_EQ(summary.termination, "NO_CONVERGENCE");
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  EXPECT_NE(summary.message.find("6 stopped at 1 iterations"), std::string::npos)
      << summary.message;
}

// The stall test (OptimizerOptions::stall_iterations) ends each component's solve as it ends
// the joint solvers': a loose tolerance stops every component early, as converged.
TEST(OptimizeComponents, AStalledCostEndsEachComponent) {
  const Scene scene = makeScene();
  Values full = scene.start;
  Values stalled = scene.start;
  OptimizerOptions options = tight(true);
  const OptimizationSummary to_the_end = optimize(scene.graph, &full, posesHeld(), options);
  options.stall_iterations = 2;
  options.stall_tolerance = 0.5;
  const OptimizationSummary stopped = optimize(scene.graph, &stalled, posesHeld(), options);
  EXPECT_EQ(stopped.termination, "CONVERGENCE") << stopped.message;
  EXPECT_GE(stopped.iterations, 2);
  EXPECT_LT(stopped.iterations, to_the_end.iterations);
  EXPECT_GT(stopped.final_cost, to_the_end.final_cost);
}

TEST(OptimizeComponents, AFreePoseJoinsItsStructureIntoOneComponent) {
  const Scene scene = makeScene();
  Values values = scene.start;
  ProblemConfig config;
  for (int i = 1; i < kPoses; ++i) config.setConstant(poseKey(i));
  // optimize() hands a free pose to Ceres; the component solver itself takes it as one component.
  EXPECT_TRUE(hasFreePose(scene.graph, config));
  EXPECT_FALSE(hasFreePose(scene.graph, posesHeld()));
  const OptimizationSummary summary = optimizeComponents(scene.graph, &values, config, tight(true));
  EXPECT_EQ(summary.ordering, "components (1 solved apart)");
  EXPECT_EQ(summary.termination, "CONVERGENCE") << summary.message;
  EXPECT_LT(summary.final_cost, summary.initial_cost);
}

TEST(OptimizeComponents, TheHookSeesTheStartAndTheEnd) {
  const Scene scene = makeScene();
  Values values = scene.start;
  std::vector<IterationProgress> seen;
  OptimizerOptions options;
  options.solve_components_apart = true;
  options.on_iteration = [&seen](const IterationProgress& p) { seen.push_back(p); };
  const OptimizationSummary summary = optimize(scene.graph, &values, posesHeld(), options);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0].iteration, 0);
  EXPECT_NEAR(seen[0].cost, summary.initial_cost, 1e-9 * summary.initial_cost);
  EXPECT_EQ(seen[1].iteration, summary.iterations);
  EXPECT_NEAR(seen[1].cost, summary.final_cost, 1e-9 * summary.final_cost);
}

// e = point - target, its x row shifted by +/- jump on either side of x = 0: a residual that
// jumps, as the nearest-edge residual does between pixels, with its minimum at the jump.
class SteppedPriorFactor : public NoiseModelFactorN<3, Eigen::Vector3d> {
  using Base = NoiseModelFactorN<3, Eigen::Vector3d>;

 public:
  SteppedPriorFactor(Key point, double jump) : Base({point}, NoiseModel{}), jump_(jump) {}
  Error evaluateError(const Eigen::Vector3d& point, Jacobian<Eigen::Vector3d>* H) const override {
    if (H) H->setIdentity();
    Error e = point;
    e.x() += point.x() >= 0.0 ? jump_ : -jump_;
    return e;
  }
  const char* typeName() const override { return "stepped_prior"; }

 private:
  double jump_;
};

TEST(OptimizeComponents, AStepThatBarelyChangesTheCostEndsTheSolveAsInTheJointSolver) {
  // From x = 2 the first step lands at x = -0.5 and the next one jumps to +0.5 at the same
  // cost. Ceres (and graph_schur) stop there; a solver that only rejected that step would crawl
  // towards the jump with ever smaller steps until max_iterations.
  FactorGraph graph;
  graph.add(std::make_shared<SteppedPriorFactor>(pointKey(0), 0.5));
  Values start;
  start.insert(pointKey(0), Eigen::Vector3d(2.0, 1.0, -1.0));
  OptimizerOptions options;
  options.initial_trust_region_radius = 1e16;  // Gauss-Newton's steps, to know where they land.
  options.max_iterations = 50;
  Values apart = start, joint = start;
  options.solve_components_apart = true;
  const OptimizationSummary a = optimize(graph, &apart, ProblemConfig{}, options);
  options.solve_components_apart = false;
  options.linear_solver = LinearSolver::kGraphSchur;
  const OptimizationSummary j = optimize(graph, &joint, ProblemConfig{}, options);
  EXPECT_EQ(a.termination, "CONVERGENCE") << a.message;
  EXPECT_EQ(a.iterations, j.iterations) << j.message;
  EXPECT_LT(a.iterations, 5);
  EXPECT_NEAR(apart.at<Eigen::Vector3d>(pointKey(0)).x(), -0.5, 1e-9);
  EXPECT_NEAR(a.final_cost, j.final_cost, 1e-12);
}

}  // namespace
}  // namespace curvesfm
