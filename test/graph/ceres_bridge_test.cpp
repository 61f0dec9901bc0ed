#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "core/so3.h"
#include "graph/ceres_cost_function.h"
#include "graph/ceres_manifolds.h"
#include "graph/ceres_problem.h"
#include "graph/optimizer.h"
#include "test/graph/test_factors.h"
#include "test/support/ceres_checks.h"
#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

using testing::AllTypesFactor;

using testing::PointPriorFactor;

Values randomValues(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Values values;
  values.insert(poseKey(0), Pose3(so3::exp(Eigen::Vector3d(n(rng), n(rng), n(rng))),
                                  Eigen::Vector3d(n(rng), n(rng), n(rng))));
  values.insert(pointKey(0), Eigen::Vector3d(n(rng), n(rng), n(rng)));
  values.insert(directionKey(0, 0), Direction(Eigen::Vector3d(n(rng), n(rng), n(rng))));
  values.insert(startLengthKey(0, 0), 1.0 + 0.3 * n(rng));
  return values;
}

std::shared_ptr<const AllTypesFactor> allTypesFactor(const NoiseModel& noise = {}) {
  return std::make_shared<const AllTypesFactor>(poseKey(0), pointKey(0), directionKey(0, 0),
                                                startLengthKey(0, 0),
                                                Eigen::Vector3d(0.5, -1.0, 2.0), noise);
}

TEST(NoiseModelFactorN, AnalyticJacobiansMatchNumerical) {
  std::mt19937 rng(10);
  const auto factor = allTypesFactor();
  for (int trial = 0; trial < 50; ++trial) {
    testing::expectJacobiansMatchNumerical(*factor, randomValues(rng));
  }
}

TEST(FactorCostFunction, PassesCeresGradientChecker) {
  std::mt19937 rng(11);
  const auto factor = allTypesFactor(NoiseModel{0.5, {}});
  FactorCostFunction cost(factor);
  const std::vector<const ceres::Manifold*> manifolds = {
      manifoldFor(VariableType::kPose3), nullptr, manifoldFor(VariableType::kDirection), nullptr};
  ceres::NumericDiffOptions numeric_options;
  ceres::GradientChecker checker(&cost, &manifolds, numeric_options);
  for (int trial = 0; trial < 20; ++trial) {
    testing::expectProbeAgrees(checker, testing::AmbientBlocks(*factor, randomValues(rng)), 1e-7);
  }
}

TEST(FactorCostFunction, WhitensResidualsBySigma) {
  std::mt19937 rng(12);
  const Values values = randomValues(rng);
  const auto factor = allTypesFactor(NoiseModel{0.25, {}});
  FactorCostFunction cost(factor);
  const testing::AmbientBlocks blocks(*factor, values);
  Eigen::Vector3d residual;
  ASSERT_TRUE(cost.Evaluate(blocks.pointers.data(), residual.data(), nullptr));
  EXPECT_TRUE(residual.isApprox(factor->unwhitenedError(values) / 0.25));
}

// The factor over one curve's point, direction and length, as CeresProblem binds them when a
// curve gets one block: the pose in a block of its own, the curve as offsets from anchors.
TEST(FactorCostFunction, CurveBlockOffsetsFromAnchorsPassCeresGradientChecker) {
  std::mt19937 rng(14);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto factor = std::make_shared<const AllTypesFactor>(
      poseKey(0), curvePointKey(0, 0), directionKey(0, 0), startLengthKey(0, 0),
      Eigen::Vector3d(0.5, -1.0, 2.0), NoiseModel{0.5, {}});
  // Offsets from tiny (the series branch of the direction's chart) to about a radian.
  for (double reach : {0.0, 1e-3, 0.05, 1.0}) {
    const Values values = randomValues(rng);
    std::vector<double> anchors(7);
    values.toAmbient(pointKey(0), anchors.data());
    values.toAmbient(directionKey(0, 0), anchors.data() + 3);
    values.toAmbient(startLengthKey(0, 0), anchors.data() + 6);
    const std::vector<VariableBinding> bindings = {{VariableType::kPose3, 0, nullptr, 0},
                                                   {VariableType::kPoint3, 1, &anchors[0], 0},
                                                   {VariableType::kDirection, 1, &anchors[3], 3},
                                                   {VariableType::kScalar, 1, &anchors[6], 5}};
    FactorCostFunction cost(factor, bindings, {7, 6});
    const std::vector<const ceres::Manifold*> manifolds = {manifoldFor(VariableType::kPose3),
                                                           nullptr};
    ceres::NumericDiffOptions numeric_options;
    ceres::GradientChecker checker(&cost, &manifolds, numeric_options);
    testing::AmbientBlocks blocks(*allTypesFactor(), values);
    blocks.storage.resize(2);
    blocks.storage[1].resize(6);
    for (double& offset : blocks.storage[1]) offset = reach * n(rng);
    blocks.pointers = {blocks.storage[0].data(), blocks.storage[1].data()};
    testing::expectProbeAgrees(checker, blocks, 1e-7);
  }
}

// Pose, point, direction and scale pinned by enough factors to have a unique optimum.
struct ToyProblem {
  FactorGraph graph;
  Values truth;
  Values start;
};

ToyProblem makeToyProblem() {
  std::mt19937 rng(13);
  ToyProblem toy;
  toy.truth = randomValues(rng);
  const Pose3& pose = toy.truth.at<Pose3>(poseKey(0));
  const auto& point = toy.truth.at<Eigen::Vector3d>(pointKey(0));
  const auto& direction = toy.truth.at<Direction>(directionKey(0, 0));
  const double scale = toy.truth.at<double>(startLengthKey(0, 0));
  // The same point, direction and scale seen through several pose-like observations.
  for (int i = 0; i < 4; ++i) {
    const Key pose_key = poseKey(i + 1);
    const Pose3 other =
        Pose3(so3::exp(Eigen::Vector3d(0.3 * i, -0.2, 0.1 * i)), Eigen::Vector3d(i, 1.0 - i, 0.5));
    toy.truth.insert(pose_key, other);
    toy.graph.emplace<AllTypesFactor>(pose_key, pointKey(0), directionKey(0, 0),
                                      startLengthKey(0, 0),
                                      other * (point + scale * direction.vector()));
  }
  toy.graph.emplace<AllTypesFactor>(poseKey(0), pointKey(0), directionKey(0, 0),
                                    startLengthKey(0, 0),
                                    pose * (point + scale * direction.vector()));
  toy.graph.emplace<PointPriorFactor>(pointKey(0), point);
  toy.start = toy.truth;
  toy.start.update(pointKey(0), Eigen::Vector3d(point + Eigen::Vector3d(0.2, -0.1, 0.1)));
  toy.start.update(directionKey(0, 0), direction.retract(Eigen::Vector2d(0.2, -0.1)));
  toy.start.update(startLengthKey(0, 0), scale * 1.2);
  return toy;
}

ProblemConfig posesConstant() {
  ProblemConfig config;
  config.setConstant(VariableCategory::kPose);
  return config;
}

TEST(Optimize, RecoversTheOptimumWithPosesConstant) {
  ToyProblem toy = makeToyProblem();
  Values values = toy.start;
  OptimizerOptions options;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.linear_solver = LinearSolver::kDenseSchur;
  const OptimizationSummary summary = optimize(toy.graph, &values, posesConstant(), options);
  EXPECT_TRUE(summary.usable) << summary.message;
  EXPECT_LT(summary.final_cost, 1e-16);
  EXPECT_GT(summary.initial_cost, 1e-3);
  EXPECT_LT(
      (values.at<Eigen::Vector3d>(pointKey(0)) - toy.truth.at<Eigen::Vector3d>(pointKey(0))).norm(),
      1e-8);
  EXPECT_LT(
      values.at<Direction>(directionKey(0, 0)).angleTo(toy.truth.at<Direction>(directionKey(0, 0))),
      1e-8);
  EXPECT_NEAR(values.at<double>(startLengthKey(0, 0)), toy.truth.at<double>(startLengthKey(0, 0)),
              1e-8);
  for (int i = 0; i < 5; ++i) {
    EXPECT_TRUE(values.at<Pose3>(poseKey(i)).translation() ==
                toy.truth.at<Pose3>(poseKey(i)).translation());
  }
  EXPECT_EQ(summary.num_constant_variables, 5);
  EXPECT_EQ(summary.num_free_variables, 3);
}

TEST(Optimize, ReportsCostsInCeresConventionPerType) {
  ToyProblem toy = makeToyProblem();
  Values values = toy.start;
  const double start_cost = toy.graph.cost(values);
  const OptimizationSummary summary =
      optimize(toy.graph, &values, posesConstant(), OptimizerOptions());
  EXPECT_NEAR(summary.initial_cost, start_cost, 1e-12 * start_cost);
  ASSERT_EQ(summary.initial_cost_by_type.size(), 2u);
  EXPECT_EQ(summary.initial_cost_by_type.at("all_types").count, 5);
  EXPECT_EQ(summary.initial_cost_by_type.at("point_prior").count, 1);
  double sum = 0;
  for (const auto& entry : summary.final_cost_by_type) sum += entry.second.cost;
  EXPECT_NEAR(sum, summary.final_cost, 1e-9 + 1e-9 * summary.final_cost);
  EXPECT_NE(summary.toString().find("all_types"), std::string::npos);
}

TEST(Optimize, HandsEveryIterationToTheHookWithTheCostsOfTheSummary) {
  ToyProblem toy = makeToyProblem();
  Values values = toy.start;
  std::vector<IterationProgress> seen;
  OptimizerOptions options;
  options.on_iteration = [&seen](const IterationProgress& p) { seen.push_back(p); };
  const OptimizationSummary summary = optimize(toy.graph, &values, posesConstant(), options);
  ASSERT_GE(summary.iterations, 1);
  // Iteration 0 (the start), then one call per iteration, in order and in time.
  ASSERT_EQ(seen.size(), static_cast<std::size_t>(summary.iterations) + 1);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].iteration, static_cast<int>(i));
    if (i > 0) {
      EXPECT_GE(seen[i].seconds, seen[i - 1].seconds);
    }
  }
  EXPECT_NEAR(seen.front().cost, summary.initial_cost, 1e-9 * summary.initial_cost);
  EXPECT_TRUE(std::any_of(seen.begin() + 1, seen.end(),
                          [](const IterationProgress& p) { return p.step_accepted; }));
  EXPECT_NEAR(seen.back().cost, summary.final_cost, 1e-9 + 1e-9 * summary.final_cost);
}

TEST(Optimize, RobustLossIsTheKernelOfTheNoiseModel) {
  Values values;
  values.insert(pointKey(0), Eigen::Vector3d(10, 0, 0));
  FactorGraph graph;
  const NoiseModel huber{1.0, RobustKernel(RobustKernelType::kHuber, 1.0)};
  graph.emplace<PointPriorFactor>(pointKey(0), Eigen::Vector3d::Zero(), huber);
  OptimizerOptions options;
  options.max_iterations = 0;
  const OptimizationSummary summary = optimize(graph, &values, ProblemConfig(), options);
  EXPECT_NEAR(summary.initial_cost, 0.5 * (2 * 10.0 - 1.0), 1e-12);
}

TEST(Optimize, EverySolverChoiceConverges) {
  for (LinearSolver solver : {LinearSolver::kSparseSchur, LinearSolver::kDenseSchur,
                              LinearSolver::kIterativeSchur, LinearSolver::kSparseNormalCholesky}) {
    for (TrustRegion region : {TrustRegion::kLevenbergMarquardt, TrustRegion::kDogleg}) {
      ToyProblem toy = makeToyProblem();
      Values values = toy.start;
      OptimizerOptions options;
      options.linear_solver = solver;
      options.trust_region = region;
      ProblemConfig config;
      config.setConstant(poseKey(0));
      const OptimizationSummary summary = optimize(toy.graph, &values, config, options);
      EXPECT_LT(summary.final_cost, 1e-8) << toString(solver) << " " << toString(region);
    }
  }
}

TEST(Optimize, WithEveryPoseHeldSchurSolversGiveWayToSparseCholesky) {
  ToyProblem toy = makeToyProblem();
  Values values = toy.start;
  const OptimizationSummary summary =
      optimize(toy.graph, &values, posesConstant(), OptimizerOptions());
  EXPECT_EQ(summary.linear_solver, "SPARSE_NORMAL_CHOLESKY");
  EXPECT_EQ(summary.ordering, "none (no free pose: sparse normal Cholesky)");
}

TEST(Optimize, FallsBackToAutomaticOrderingWhenStructureIsCoupled) {
  ToyProblem toy = makeToyProblem();
  Values values = toy.start;
  ProblemConfig config;
  config.setConstant(poseKey(0));
  const OptimizationSummary summary = optimize(toy.graph, &values, config, OptimizerOptions());
  // AllTypesFactor ties the point to the curve block of the direction and scale.
  EXPECT_EQ(summary.ordering, "automatic (factor all_types couples two structure blocks)");
}

// The toy problem with its point a curve point: point, direction and length are one curve.
ToyProblem makeToyCurve() {
  ToyProblem toy = makeToyProblem();
  FactorGraph graph;
  for (const auto& factor : toy.graph) {
    const auto* all_types = dynamic_cast<const AllTypesFactor*>(factor.get());
    if (!all_types) continue;
    graph.add(std::make_shared<AllTypesFactor>(factor->keys()[0], curvePointKey(0, 0),
                                               directionKey(0, 0), startLengthKey(0, 0),
                                               all_types->target()));
  }
  for (Values* values : {&toy.truth, &toy.start}) {
    values->insert(curvePointKey(0, 0), values->at<Eigen::Vector3d>(pointKey(0)));
    values->erase(pointKey(0));
  }
  graph.emplace<PointPriorFactor>(curvePointKey(0, 0),
                                  toy.truth.at<Eigen::Vector3d>(curvePointKey(0, 0)));
  toy.graph = graph;
  return toy;
}

OptimizerOptions tightOptions(bool curve_blocks) {
  OptimizerOptions options;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.curve_blocks = curve_blocks;
  return options;
}

TEST(Optimize, ACurveBlockIsEliminatedAndReachesTheSameOptimum) {
  const ToyProblem toy = makeToyCurve();
  ProblemConfig config;
  config.setConstant(poseKey(0));
  Values per_variable = toy.start;
  const OptimizationSummary a = optimize(toy.graph, &per_variable, config, tightOptions(false));
  Values per_curve = toy.start;
  const OptimizationSummary b = optimize(toy.graph, &per_curve, config, tightOptions(true));
  EXPECT_EQ(a.ordering, "automatic (factor all_types couples two structure blocks)");
  EXPECT_EQ(b.ordering, "structure_first (1 eliminated, 4 reduced blocks)");
  EXPECT_EQ(b.num_curve_blocks, 1);
  EXPECT_EQ(b.num_free_variables, a.num_free_variables);
  EXPECT_EQ(b.num_effective_parameters, a.num_effective_parameters);
  EXPECT_NEAR(b.initial_cost, a.initial_cost, 1e-12 * a.initial_cost);
  EXPECT_LT(a.final_cost, 1e-16);
  EXPECT_LT(b.final_cost, 1e-16);
  for (int i = 1; i < 5; ++i) {
    const Pose3& x = per_variable.at<Pose3>(poseKey(i));
    const Pose3& y = per_curve.at<Pose3>(poseKey(i));
    EXPECT_LT(x.localCoordinates(y).norm(), 1e-8) << "pose " << i;
  }
  EXPECT_LT((per_variable.at<Eigen::Vector3d>(curvePointKey(0, 0)) -
             per_curve.at<Eigen::Vector3d>(curvePointKey(0, 0)))
                .norm(),
            1e-8);
  EXPECT_LT(per_variable.at<Direction>(directionKey(0, 0))
                .angleTo(per_curve.at<Direction>(directionKey(0, 0))),
            1e-8);
  EXPECT_NEAR(per_variable.at<double>(startLengthKey(0, 0)),
              per_curve.at<double>(startLengthKey(0, 0)), 1e-8);
}

TEST(CeresProblem, ACurvesConstantVariablesWaitAtTheirStartBesideItsFreeOnes) {
  const ToyProblem toy = makeToyCurve();
  ProblemConfig config;
  config.setConstant(poseKey(0));
  config.setConstant(startLengthKey(0, 0));
  Values values = toy.start;
  values.update(startLengthKey(0, 0), toy.truth.at<double>(startLengthKey(0, 0)));
  const OptimizationSummary summary = optimize(toy.graph, &values, config, tightOptions(true));
  EXPECT_EQ(summary.num_curve_blocks, 1);
  // Ceres counts constant blocks too: the five poses' 30 and the curve block's 5, without the
  // length, which waits at its anchor outside every block.
  EXPECT_EQ(summary.num_effective_parameters, 35);
  EXPECT_EQ(values.at<double>(startLengthKey(0, 0)), toy.truth.at<double>(startLengthKey(0, 0)));
  EXPECT_LT((values.at<Eigen::Vector3d>(curvePointKey(0, 0)) -
             toy.truth.at<Eigen::Vector3d>(curvePointKey(0, 0)))
                .norm(),
            1e-8);
  EXPECT_LT(
      values.at<Direction>(directionKey(0, 0)).angleTo(toy.truth.at<Direction>(directionKey(0, 0))),
      1e-8);
}

TEST(CeresProblem, WithEveryPoseHeldCurvesKeepABlockPerVariable) {
  const ToyProblem toy = makeToyCurve();
  CeresProblem bridge(toy.graph, toy.start, posesConstant(), OptimizerOptions());
  EXPECT_EQ(bridge.numCurveBlocks(), 0);
  EXPECT_NE(bridge.block(curvePointKey(0, 0)), bridge.block(directionKey(0, 0)));
}

TEST(CeresProblem, WithInnerIterationsCurvesKeepABlockPerVariable) {
  const ToyProblem toy = makeToyCurve();
  OptimizerOptions options;
  options.use_inner_iterations = true;
  CeresProblem bridge(toy.graph, toy.start, ProblemConfig(), options);
  EXPECT_EQ(bridge.numCurveBlocks(), 0);
}

TEST(CeresProblem, ACurveWiderThanTheLimitKeepsABlockPerVariable) {
  const ToyProblem toy = makeToyCurve();
  OptimizerOptions options;
  options.max_curve_block_size = 5;  // the curve has 3 + 2 + 1 free dimensions
  CeresProblem narrow(toy.graph, toy.start, ProblemConfig(), options);
  EXPECT_EQ(narrow.numCurveBlocks(), 0);
  EXPECT_NE(narrow.block(curvePointKey(0, 0)), narrow.block(directionKey(0, 0)));
  options.max_curve_block_size = 6;
  CeresProblem wide(toy.graph, toy.start, ProblemConfig(), options);
  EXPECT_EQ(wide.numCurveBlocks(), 1);
  EXPECT_EQ(wide.block(curvePointKey(0, 0)), wide.block(directionKey(0, 0)));
}

TEST(CeresProblem, InnerIterationOrderingHoldsEveryFreeBlockInIndependentSets) {
  ToyProblem toy = makeToyProblem();
  ProblemConfig config;
  config.setConstant(poseKey(0));
  OptimizerOptions per_variable;
  per_variable.curve_blocks = false;
  CeresProblem bridge(toy.graph, toy.start, config, per_variable);
  const auto ordering = bridge.innerIterationOrdering();
  // Free: poses 1..4, the point, the direction and the length; pose 0 is constant.
  EXPECT_EQ(ordering->NumElements(), 7);
  EXPECT_FALSE(ordering->IsMember(bridge.block(poseKey(0))));
  // The point, direction and length share every factor, so each needs a group of its own; the
  // poses share factors with those three only, so they fit in one more.
  EXPECT_EQ(ordering->NumGroups(), 4);
  for (const auto& factor : toy.graph) {
    std::set<int> groups;
    int members = 0;
    for (Key key : factor->keys()) {
      if (!ordering->IsMember(bridge.block(key))) continue;
      ++members;
      groups.insert(ordering->GroupId(bridge.block(key)));
    }
    EXPECT_EQ(static_cast<int>(groups.size()), members) << "two blocks of one factor share a group";
  }
}

TEST(Optimize, MissingOrMistypedVariablesThrowBeforeSolving) {
  ToyProblem toy = makeToyProblem();
  Values missing = toy.start;
  missing.erase(pointKey(0));
  EXPECT_THROW(optimize(toy.graph, &missing, ProblemConfig(), OptimizerOptions()), KeyDoesNotExist);
  Values mistyped = toy.start;
  mistyped.erase(startLengthKey(0, 0));
  mistyped.insert(startLengthKey(0, 0), Eigen::Vector3d::Zero());
  EXPECT_THROW(optimize(toy.graph, &mistyped, ProblemConfig(), OptimizerOptions()), IncorrectType);
  // The same with every pose held, in the component solver.
  OptimizerOptions apart;
  apart.solve_components_apart = true;
  EXPECT_THROW(optimize(toy.graph, &missing, posesConstant(), apart), KeyDoesNotExist);
  EXPECT_THROW(optimize(toy.graph, &mistyped, posesConstant(), apart), IncorrectType);
}

TEST(OptimizerOptions, ValidateNamesFieldAndValue) {
  OptimizerOptions options;
  options.num_threads = 0;
  try {
    options.validate();
    FAIL();
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("OptimizerOptions.num_threads = 0"), std::string::npos)
        << e.what();
  }
  options = OptimizerOptions();
  options.function_tolerance = -1;
  EXPECT_THROW(options.validate(), InvalidOptions);
  const auto expectRefused = [](const OptimizerOptions& bad, const std::string& field) {
    try {
      bad.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const InvalidOptions& e) {
      EXPECT_NE(std::string(e.what()).find("OptimizerOptions." + field), std::string::npos)
          << e.what();
    }
  };
  options = OptimizerOptions();
  options.max_curve_block_size = 0;
  expectRefused(options, "max_curve_block_size = 0");
  options = OptimizerOptions();
  options.initial_trust_region_radius = 0.0;
  expectRefused(options, "initial_trust_region_radius = 0");
  EXPECT_EQ(parseEnumName<LinearSolver>("iterative_schur", "OptimizerOptions", "x"),
            LinearSolver::kIterativeSchur);
  EXPECT_THROW(parseEnumName<LinearSolver>("cholesky", "OptimizerOptions", "linear_solver"),
               InvalidOptions);
  EXPECT_EQ(parseEnumName<TrustRegion>("dogleg", "OptimizerOptions", "x"), TrustRegion::kDogleg);
}

}  // namespace
}  // namespace curvesfm
