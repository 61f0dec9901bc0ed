#include "graph/scheduler.h"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <random>
#include <set>

#include "core/so3.h"
#include "test/graph/cost_by_type_expectations.h"
#include "test/graph/test_factors.h"
#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

using testing::PointPriorFactor;

// e = cam_from_world * point - measured (3 rows): a point measured in the camera frame, as by a
// depth camera. It couples a pose and a point, so alternating needs several rounds.
class PointInCameraFactor : public NoiseModelFactorN<3, Pose3, Eigen::Vector3d> {
  using Base = NoiseModelFactorN<3, Pose3, Eigen::Vector3d>;

 public:
  PointInCameraFactor(Key pose, Key point, const Eigen::Vector3d& measured)
      : Base({pose, point}, NoiseModel{}), measured_(measured) {}

  Error evaluateError(const Pose3& cam_from_world, const Eigen::Vector3d& point_in_world,
                      Jacobian<Pose3>* H_pose, Jacobian<Eigen::Vector3d>* H_point) const override {
    Matrix36d d_cam_d_pose;
    Eigen::Matrix3d d_cam_d_point;
    const Eigen::Vector3d point_in_cam = cam_from_world.transformPoint(
        point_in_world, H_pose ? &d_cam_d_pose : nullptr, H_point ? &d_cam_d_point : nullptr);
    if (H_pose) *H_pose = d_cam_d_pose;
    if (H_point) *H_point = d_cam_d_point;
    return point_in_cam - measured_;
  }
  const char* typeName() const override { return "point_in_camera"; }

 private:
  Eigen::Vector3d measured_;
};

// The same measurement of a known world point: a pose-only factor.
class KnownLandmarkFactor : public NoiseModelFactorN<3, Pose3> {
  using Base = NoiseModelFactorN<3, Pose3>;

 public:
  KnownLandmarkFactor(Key pose, const Eigen::Vector3d& landmark, const Eigen::Vector3d& measured)
      : Base({pose}, NoiseModel{}), landmark_(landmark), measured_(measured) {}

  Error evaluateError(const Pose3& cam_from_world, Jacobian<Pose3>* H_pose) const override {
    Matrix36d d_cam_d_pose;
    const Eigen::Vector3d point_in_cam =
        cam_from_world.transformPoint(landmark_, H_pose ? &d_cam_d_pose : nullptr);
    if (H_pose) *H_pose = d_cam_d_pose;
    return point_in_cam - measured_;
  }
  const char* typeName() const override { return "known_landmark"; }

 private:
  Eigen::Vector3d landmark_;
  Eigen::Vector3d measured_;
};

constexpr int kPoses = 6;
constexpr int kPoints = 24;
constexpr int kTrack = 3;  // point l is seen by poses firstObserver(l) .. firstObserver(l) + 2

int firstObserver(int l) { return l % (kPoses - kTrack + 1); }

Eigen::Vector3d gaussian3(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  return Eigen::Vector3d(n(rng), n(rng), n(rng));
}

Pose3 perturbed(const Pose3& pose, std::mt19937& rng, double sigma) {
  Vector6d delta;
  delta << gaussian3(rng, sigma), gaussian3(rng, sigma);
  return pose.retract(delta);
}

// Poses along a line looking at points ahead; noisy measurements, so the optimum is not the
// truth; a prior on point 0 is a factor with structure only. Every pose but 0 and every point
// start perturbed.
struct Scene {
  FactorGraph graph;
  Values truth;
  Values start;
};

Scene makeScene() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Scene scene;
  for (int j = 0; j < kPoses; ++j) {
    scene.truth.insert(poseKey(j), Pose3(so3::exp(Eigen::Vector3d(0.05 * j, -0.04 * j, 0.02 * j)),
                                         Eigen::Vector3d(-0.5 * j, 0.1 * j, 0.0)));
  }
  for (int l = 0; l < kPoints; ++l) {
    scene.truth.insert(pointKey(l),
                       Eigen::Vector3d(2.0 * uniform(rng), uniform(rng), 4.0 + uniform(rng)));
  }
  for (int l = 0; l < kPoints; ++l) {
    const auto& point = scene.truth.at<Eigen::Vector3d>(pointKey(l));
    for (int j = firstObserver(l); j < firstObserver(l) + kTrack; ++j) {
      const Eigen::Vector3d measured =
          scene.truth.at<Pose3>(poseKey(j)) * point + gaussian3(rng, 0.02);
      scene.graph.emplace<PointInCameraFactor>(poseKey(j), pointKey(l), measured);
    }
  }
  scene.graph.emplace<PointPriorFactor>(
      pointKey(0), scene.truth.at<Eigen::Vector3d>(pointKey(0)) + gaussian3(rng, 0.02));
  scene.start = scene.truth;
  for (int j = 1; j < kPoses; ++j) {
    scene.start.update(poseKey(j), perturbed(scene.truth.at<Pose3>(poseKey(j)), rng, 0.05));
  }
  for (int l = 0; l < kPoints; ++l) {
    scene.start.update(pointKey(l), Eigen::Vector3d(scene.truth.at<Eigen::Vector3d>(pointKey(l)) +
                                                    gaussian3(rng, 0.1)));
  }
  return scene;
}

// Poses observing known landmarks only: no structure variable at all.
Scene makePoseOnlyScene(const std::vector<int>& pose_indices) {
  std::mt19937 rng(8);
  Scene scene;
  for (int j : pose_indices) {
    const Pose3 pose(so3::exp(Eigen::Vector3d(0.1, 0.02 * j, 0.0)), Eigen::Vector3d(j, 0.0, 0.0));
    scene.truth.insert(poseKey(j), pose);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d landmark(k % 2, k / 2, 5.0 + k);
      scene.graph.emplace<KnownLandmarkFactor>(poseKey(j), landmark,
                                               pose * landmark + gaussian3(rng, 0.01));
    }
  }
  scene.start = scene.truth;
  for (int j : pose_indices) {
    scene.start.update(poseKey(j), perturbed(scene.truth.at<Pose3>(poseKey(j)), rng, 0.05));
  }
  return scene;
}

SchedulerOptions tightOptions(Strategy strategy) {
  SchedulerOptions options;
  options.strategy = strategy;
  options.max_rounds = 500;
  options.round_tolerance = 1e-12;
  options.optimizer.max_iterations = 100;
  options.optimizer.function_tolerance = 1e-14;
  options.optimizer.gradient_tolerance = 1e-14;
  options.optimizer.parameter_tolerance = 1e-14;
  return options;
}

// Largest pose (translation, rotation angle) or point difference over the scene's variables.
double maxDifference(const Values& a, const Values& b) {
  double worst = 0.0;
  for (const auto& [key, variable] : a) {
    if (categoryOf(key) == VariableCategory::kPose) {
      const Pose3& pa = a.at<Pose3>(key);
      const Pose3& pb = b.at<Pose3>(key);
      worst = std::max(worst, (pa.translation() - pb.translation()).norm());
      worst = std::max(worst, pa.rotation().angularDistance(pb.rotation()));
    } else {
      worst = std::max(worst, (a.at<Eigen::Vector3d>(key) - b.at<Eigen::Vector3d>(key)).norm());
    }
  }
  return worst;
}

bool unchanged(const Values& a, const Values& b, Key key) {
  if (categoryOf(key) == VariableCategory::kPose) {
    return a.at<Pose3>(key).translation() == b.at<Pose3>(key).translation() &&
           a.at<Pose3>(key).rotation().coeffs() == b.at<Pose3>(key).rotation().coeffs();
  }
  return a.at<Eigen::Vector3d>(key) == b.at<Eigen::Vector3d>(key);
}

struct Solved {
  ScheduleReport report;
  Values values;
};

Solved solve(const Scene& scene, const SchedulerOptions& options,
             const ProblemConfig& base = ProblemConfig()) {
  Solved solved{ScheduleReport(), scene.start};
  solved.report = runSchedule(scene.graph, &solved.values, base, options);
  return solved;
}

TEST(SchedulerTestFactors, AnalyticJacobiansMatchNumerical) {
  const Scene scene = makeScene();
  for (const auto& factor : scene.graph)
    testing::expectJacobiansMatchNumerical(*factor, scene.start);
  const Scene poses = makePoseOnlyScene({0, 1});
  for (const auto& factor : poses.graph)
    testing::expectJacobiansMatchNumerical(*factor, poses.start);
}

TEST(RunSchedule, JointReachesTheOptimum) {
  const Scene scene = makeScene();
  const Solved joint = solve(scene, tightOptions(Strategy::kJoint));
  const ScheduleReport& report = joint.report;
  EXPECT_TRUE(report.converged) << report.toString();
  ASSERT_EQ(report.rounds.size(), 1u);
  EXPECT_EQ(report.rounds[0].phase, "joint");
  EXPECT_EQ(report.num_rounds, 1);
  EXPECT_EQ(report.num_active_factors, static_cast<int>(scene.graph.size()));
  EXPECT_EQ(report.initial_cost, report.rounds[0].summary.initial_cost);
  EXPECT_EQ(report.final_cost, report.rounds[0].summary.final_cost);
  EXPECT_NEAR(report.final_cost, scene.graph.cost(joint.values), 1e-12);
  // The noisy optimum fits the measurements at least as well as the truth does, lies near it
  // (the far poses drift by a few lever-arm-amplified noise levels) and a second solve from it
  // finds nothing better.
  EXPECT_LE(report.final_cost, scene.graph.cost(scene.truth));
  EXPECT_GT(report.initial_cost, 10.0 * report.final_cost);
  EXPECT_LT(maxDifference(joint.values, scene.truth), 0.3);
  Values again = joint.values;
  const ScheduleReport second =
      runSchedule(scene.graph, &again, ProblemConfig(), tightOptions(Strategy::kJoint));
  EXPECT_GT(second.final_cost, report.final_cost * (1.0 - 1e-12));
  EXPECT_LT(maxDifference(again, joint.values), 1e-7);
  EXPECT_TRUE(report.warnings.empty());
}

TEST(RunSchedule, AlternatingReachesTheJointOptimumWithFallingRoundCosts) {
  const Scene scene = makeScene();
  const Solved joint = solve(scene, tightOptions(Strategy::kJoint));
  const Solved alternating = solve(scene, tightOptions(Strategy::kAlternating));
  const ScheduleReport& report = alternating.report;
  EXPECT_TRUE(report.converged) << report.toString();
  EXPECT_GE(report.num_rounds, 3) << "poses and structure are coupled";
  ASSERT_EQ(report.rounds.size(), 2u * report.num_rounds);
  EXPECT_NEAR(report.final_cost, joint.report.final_cost, 1e-8 * joint.report.final_cost);
  EXPECT_LT(maxDifference(alternating.values, joint.values), 1e-5);
  double previous_round_end = report.initial_cost;
  for (std::size_t i = 0; i < report.rounds.size(); ++i) {
    const ScheduleRound& entry = report.rounds[i];
    EXPECT_EQ(entry.round, static_cast<int>(i / 2) + 1);
    EXPECT_EQ(entry.phase, i % 2 == 0 ? "poses" : "structure");
    ASSERT_FALSE(entry.skipped);
    // Every phase reports the cost of all factors, so each starts where the last one ended.
    EXPECT_NEAR(entry.summary.initial_cost, previous_round_end, 1e-12 * previous_round_end);
    EXPECT_LE(entry.summary.final_cost, entry.summary.initial_cost);
    previous_round_end = entry.summary.final_cost;
  }
  EXPECT_TRUE(report.warnings.empty());
}

TEST(RunSchedule, PhaseCostsIncludeFactorsWhoseVariablesAreAllConstant) {
  const Scene scene = makeScene();
  SchedulerOptions options = tightOptions(Strategy::kAlternating);
  options.max_rounds = 1;
  const Solved solved = solve(scene, options);
  ASSERT_EQ(solved.report.rounds.size(), 2u);
  const OptimizationSummary& poses = solved.report.rounds[0].summary;
  // In the poses phase the point prior touches only constant variables, yet it is counted.
  EXPECT_EQ(poses.initial_cost_by_type.at("point_prior").count, 1);
  EXPECT_EQ(poses.num_factors, static_cast<int>(scene.graph.size()));
  double by_type = 0.0;
  for (const auto& [type, cost] : poses.initial_cost_by_type) by_type += cost.cost;
  EXPECT_NEAR(poses.initial_cost, by_type, 1e-12 * by_type);
  EXPECT_NEAR(poses.initial_cost, scene.graph.cost(scene.start), 1e-12 * by_type);
  EXPECT_EQ(poses.num_free_variables, kPoses - 1);
  EXPECT_EQ(poses.num_constant_variables, 1 + kPoints);
  const OptimizationSummary& structure = solved.report.rounds[1].summary;
  EXPECT_EQ(structure.num_free_variables, kPoints);
  EXPECT_EQ(structure.num_constant_variables, kPoses);
}

TEST(RunSchedule, InnerIterationsReachTheJointOptimum) {
  const Scene scene = makeScene();
  const Solved joint = solve(scene, tightOptions(Strategy::kJoint));
  const Solved inner = solve(scene, tightOptions(Strategy::kInnerIterations));
  EXPECT_TRUE(inner.report.converged) << inner.report.toString();
  EXPECT_EQ(inner.report.strategy, Strategy::kInnerIterations);
  EXPECT_NEAR(inner.report.final_cost, joint.report.final_cost, 1e-8 * joint.report.final_cost);
  EXPECT_LT(maxDifference(inner.values, joint.values), 1e-5);
}

TEST(RunSchedule, AlternatingStopsAtMaxRounds) {
  const Scene scene = makeScene();
  SchedulerOptions options = tightOptions(Strategy::kAlternating);
  options.max_rounds = 2;
  options.round_tolerance = 0.0;
  const Solved solved = solve(scene, options);
  EXPECT_FALSE(solved.report.converged);
  EXPECT_EQ(solved.report.num_rounds, 2);
  EXPECT_EQ(solved.report.rounds.size(), 4u);
  EXPECT_NE(solved.report.stop_reason.find("max_rounds = 2"), std::string::npos)
      << solved.report.stop_reason;
}

TEST(RunSchedule, FixFirstPoseHoldsItInEveryStrategy) {
  Scene scene = makeScene();
  std::mt19937 rng(9);
  scene.start.update(poseKey(0), perturbed(scene.truth.at<Pose3>(poseKey(0)), rng, 0.05));
  for (Strategy strategy : {Strategy::kJoint, Strategy::kAlternating, Strategy::kInnerIterations}) {
    SchedulerOptions options = tightOptions(strategy);
    options.max_rounds = 5;  // enough to move every other variable
    const Solved fixed = solve(scene, options);
    EXPECT_TRUE(unchanged(fixed.values, scene.start, poseKey(0))) << toString(strategy);
    EXPECT_FALSE(unchanged(fixed.values, scene.start, poseKey(1))) << toString(strategy);
  }
  SchedulerOptions free_gauge = tightOptions(Strategy::kJoint);
  free_gauge.fix_first_pose = false;
  const Solved free = solve(scene, free_gauge);
  EXPECT_FALSE(unchanged(free.values, scene.start, poseKey(0)));
  EXPECT_EQ(free.report.rounds[0].summary.num_constant_variables, 0);
}

TEST(RunSchedule, TheFirstPoseIsTheSmallestIndexTheGraphUses) {
  const Scene scene = makePoseOnlyScene({9, 7});
  const Solved solved = solve(scene, tightOptions(Strategy::kJoint));
  EXPECT_TRUE(unchanged(solved.values, scene.start, poseKey(7)));
  EXPECT_FALSE(unchanged(solved.values, scene.start, poseKey(9)));
  EXPECT_EQ(solved.report.rounds[0].summary.num_free_variables, 1);
  EXPECT_EQ(solved.report.rounds[0].summary.num_constant_variables, 1);
}

TEST(RunSchedule, BaseConstantsStayConstant) {
  const Scene scene = makeScene();
  ProblemConfig base;
  base.setConstant(pointKey(5));
  base.setConstant(poseKey(3));
  const Solved solved = solve(scene, tightOptions(Strategy::kAlternating), base);
  EXPECT_TRUE(unchanged(solved.values, scene.start, pointKey(5)));
  EXPECT_TRUE(unchanged(solved.values, scene.start, poseKey(3)));
  EXPECT_FALSE(unchanged(solved.values, scene.start, pointKey(6)));
}

// The expected local problem, worked out from the scene's track layout.
struct LocalExpectation {
  std::set<Key> free;      // window poses and the points they see
  std::set<Key> constant;  // other variables of the active factors
  int active_factors = 0;
};

LocalExpectation expectLocal(int window) {
  LocalExpectation expected;
  const int first_window_pose = kPoses - window;
  for (int j = first_window_pose; j < kPoses; ++j) expected.free.insert(poseKey(j));
  for (int l = 0; l < kPoints; ++l) {
    if (firstObserver(l) + kTrack - 1 < first_window_pose) continue;
    expected.free.insert(pointKey(l));
    for (int j = firstObserver(l); j < firstObserver(l) + kTrack; ++j) {
      if (j < first_window_pose) expected.constant.insert(poseKey(j));
    }
    expected.active_factors += kTrack;
  }
  return expected;
}

TEST(RunSchedule, LocalScopeFreesTheLastPosesAndTheStructureTheySee) {
  const Scene scene = makeScene();
  const LocalExpectation expected = expectLocal(2);
  ASSERT_EQ(expected.free.size(), 2u + kPoints / 2);  // points first seen by poses 2 and 3
  ASSERT_EQ(expected.constant.size(), 2u);            // poses 2 and 3
  SchedulerOptions options = tightOptions(Strategy::kJoint);
  options.scope = Scope::kLocal;
  options.local_window = 2;
  const Solved solved = solve(scene, options);
  const ScheduleReport& report = solved.report;
  EXPECT_TRUE(report.converged) << report.toString();
  EXPECT_EQ(report.num_active_factors, expected.active_factors);
  EXPECT_EQ(report.num_factors, static_cast<int>(scene.graph.size()));
  const OptimizationSummary& summary = report.rounds.at(0).summary;
  EXPECT_EQ(summary.num_factors, expected.active_factors);
  EXPECT_EQ(summary.num_free_variables, static_cast<int>(expected.free.size()));
  EXPECT_EQ(summary.num_constant_variables, static_cast<int>(expected.constant.size()));
  EXPECT_EQ(summary.initial_cost_by_type.count("point_prior"), 0u) << "point 0 is not free";
  for (const auto& [key, variable] : scene.start) {
    EXPECT_EQ(unchanged(solved.values, scene.start, key), expected.free.count(key) == 0) << key;
  }
  EXPECT_LT(report.final_cost, report.initial_cost);
}

TEST(RunSchedule, LocalAlternatingSplitsTheWindowIntoPosesAndStructure) {
  const Scene scene = makeScene();
  const LocalExpectation expected = expectLocal(3);
  const int window_points = static_cast<int>(expected.free.size()) - 3;
  const int fixed_poses = static_cast<int>(expected.constant.size());
  SchedulerOptions options = tightOptions(Strategy::kAlternating);
  options.scope = Scope::kLocal;
  options.local_window = 3;
  options.max_rounds = 3;
  const Solved solved = solve(scene, options);
  ASSERT_EQ(solved.report.rounds.size(), 6u) << solved.report.toString();
  for (const ScheduleRound& entry : solved.report.rounds) {
    const bool poses = entry.phase == "poses";
    EXPECT_EQ(entry.summary.num_free_variables, poses ? 3 : window_points);
    EXPECT_EQ(entry.summary.num_constant_variables,
              poses ? fixed_poses + window_points : fixed_poses + 3);
  }
  for (const auto& [key, variable] : scene.start) {
    EXPECT_EQ(unchanged(solved.values, scene.start, key), expected.free.count(key) == 0) << key;
  }
}

TEST(RunSchedule, LocalWindowWiderThanTheTrajectoryIsGlobal) {
  const Scene scene = makeScene();
  SchedulerOptions options = tightOptions(Strategy::kJoint);
  options.scope = Scope::kLocal;
  options.local_window = 100;
  const Solved local = solve(scene, options);
  const Solved global = solve(scene, tightOptions(Strategy::kJoint));
  EXPECT_EQ(local.report.num_active_factors, static_cast<int>(scene.graph.size()));
  EXPECT_EQ(local.report.rounds[0].summary.num_free_variables, kPoses - 1 + kPoints);
  EXPECT_NEAR(local.report.final_cost, global.report.final_cost, 1e-12);
}

TEST(RunSchedule, EmptyGraphIsNotAnError) {
  for (Strategy strategy : {Strategy::kJoint, Strategy::kAlternating, Strategy::kInnerIterations}) {
    for (Scope scope : {Scope::kGlobal, Scope::kLocal}) {
      Values values;
      values.insert(poseKey(0), Pose3());
      SchedulerOptions options;
      options.strategy = strategy;
      options.scope = scope;
      const ScheduleReport report = runSchedule(FactorGraph(), &values, ProblemConfig(), options);
      EXPECT_TRUE(report.converged);
      EXPECT_TRUE(report.rounds.empty());
      EXPECT_EQ(report.num_rounds, 0);
      EXPECT_EQ(report.initial_cost, 0.0);
      EXPECT_EQ(report.final_cost, 0.0);
      EXPECT_EQ(report.stop_reason, "empty graph");
      EXPECT_NE(report.toString().find("empty graph"), std::string::npos);
    }
  }
}

TEST(RunSchedule, WithoutStructureTheStructurePhaseIsSkipped) {
  const Scene scene = makePoseOnlyScene({0, 1, 2, 3});
  const Solved joint = solve(scene, tightOptions(Strategy::kJoint));
  const Solved alternating = solve(scene, tightOptions(Strategy::kAlternating));
  const ScheduleReport& report = alternating.report;
  EXPECT_TRUE(report.converged) << report.toString();
  EXPECT_EQ(report.num_rounds, 1) << "one round already solves every free variable";
  ASSERT_EQ(report.rounds.size(), 2u);
  EXPECT_FALSE(report.rounds[0].skipped);
  EXPECT_EQ(report.rounds[1].phase, "structure");
  EXPECT_TRUE(report.rounds[1].skipped);
  EXPECT_NE(report.toString().find("skipped"), std::string::npos);
  EXPECT_NEAR(report.final_cost, joint.report.final_cost, 1e-10);
  EXPECT_EQ(report.final_cost, report.rounds[0].summary.final_cost);
}

TEST(RunSchedule, NothingFreeIsNotAnError) {
  const Scene scene = makeScene();
  ProblemConfig base;
  base.setConstant(VariableCategory::kPoint);
  base.setConstant(VariableCategory::kPose);
  for (Strategy strategy : {Strategy::kJoint, Strategy::kAlternating}) {
    const Solved solved = solve(scene, tightOptions(strategy), base);
    EXPECT_TRUE(solved.report.converged);
    EXPECT_EQ(solved.report.total_iterations, 0);
    for (const ScheduleRound& entry : solved.report.rounds) EXPECT_TRUE(entry.skipped);
    EXPECT_NEAR(solved.report.initial_cost, scene.graph.cost(scene.start), 1e-12);
    EXPECT_EQ(solved.report.final_cost, solved.report.initial_cost);
    for (const auto& [key, variable] : scene.start) {
      EXPECT_TRUE(unchanged(solved.values, scene.start, key)) << key;
    }
  }
}

TEST(RunSchedule, LocalScopeWithoutPosesFreesNothing) {
  FactorGraph graph;
  graph.emplace<PointPriorFactor>(pointKey(0), Eigen::Vector3d(1.0, 2.0, 3.0));
  Values values;
  values.insert(pointKey(0), Eigen::Vector3d::Zero());
  SchedulerOptions options;
  options.scope = Scope::kLocal;
  const ScheduleReport report = runSchedule(graph, &values, ProblemConfig(), options);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.stop_reason, "no factor touches a free variable");
  EXPECT_EQ(report.num_active_factors, 0);
  EXPECT_EQ(report.final_cost, 0.0) << "the cost of the (empty) active graph";
  EXPECT_EQ(values.at<Eigen::Vector3d>(pointKey(0)), Eigen::Vector3d::Zero());
}

TEST(ScheduleReport, TableListsEveryPhaseAndFactorType) {
  const Scene scene = makeScene();
  SchedulerOptions options = tightOptions(Strategy::kAlternating);
  options.max_rounds = 2;
  const std::string table = solve(scene, options).report.toString();
  for (const char* expected :
       {"schedule alternating, global scope: 2 rounds", "cost before", "poses", "structure",
        "point_in_camera", "point_prior", "max_rounds = 2"}) {
    EXPECT_NE(table.find(expected), std::string::npos) << expected << " in\n" << table;
  }
}

// The scheduler reports optimize()'s per-type costs, which the bridge computes from its own
// parameter blocks: they must be FactorGraph::costByType's, robust kernels included.
TEST(Optimize, CostsByTypeAreTheFactorGraphsBeforeAndAfterTheSolve) {
  Scene scene = makeScene();
  const NoiseModel huber{0.5, RobustKernel(RobustKernelType::kHuber, 1.0)};
  const NoiseModel cauchy{2.0, RobustKernel(RobustKernelType::kCauchy, 0.5)};
  scene.graph.emplace<PointPriorFactor>(pointKey(1), Eigen::Vector3d(0.0, 0.0, 5.0), huber);
  scene.graph.emplace<PointPriorFactor>(pointKey(2), Eigen::Vector3d(1.0, 0.0, 5.0), cauchy);
  Values values = scene.start;
  const auto before = scene.graph.costByType(values);
  ProblemConfig config;
  config.setConstant(poseKey(0));
  const OptimizationSummary summary = optimize(scene.graph, &values, config, OptimizerOptions());
  testing::expectSameCostsByType(summary.initial_cost_by_type, before, 1e-14);
  testing::expectSameCostsByType(summary.final_cost_by_type, scene.graph.costByType(values), 1e-14);
  EXPECT_EQ(summary.initial_cost_by_type.at("point_prior").count, 3);
  EXPECT_LT(summary.final_cost_by_type.at("point_in_camera").cost,
            before.at("point_in_camera").cost);
}

void expectInvalid(const SchedulerOptions& options, const std::string& expected) {
  try {
    options.validate();
    FAIL() << "accepted " << expected;
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

TEST(SchedulerOptions, ValidateNamesFieldAndValue) {
  EXPECT_NO_THROW(SchedulerOptions().validate());
  SchedulerOptions options;
  options.local_window = 0;
  expectInvalid(options, "SchedulerOptions.local_window = 0: must be >= 1");
  options = SchedulerOptions();
  options.max_rounds = -2;
  expectInvalid(options, "SchedulerOptions.max_rounds = -2");
  options = SchedulerOptions();
  options.round_tolerance = -1e-3;
  expectInvalid(options, "SchedulerOptions.round_tolerance = -0.001");
  options.round_tolerance = std::numeric_limits<double>::quiet_NaN();
  expectInvalid(options, "SchedulerOptions.round_tolerance");
  options = SchedulerOptions();
  options.optimizer.max_iterations = -1;
  expectInvalid(options, "OptimizerOptions.max_iterations = -1");
  Values values;
  EXPECT_THROW(runSchedule(FactorGraph(), &values, ProblemConfig(), options), InvalidOptions);
}

TEST(SchedulerOptions, ParseInvertsToString) {
  for (Strategy strategy : {Strategy::kJoint, Strategy::kAlternating, Strategy::kInnerIterations}) {
    EXPECT_EQ(parseEnumName<Strategy>(toString(strategy), "SchedulerOptions", "strategy"),
              strategy);
  }
  for (Scope scope : {Scope::kGlobal, Scope::kLocal}) {
    EXPECT_EQ(parseEnumName<Scope>(toString(scope), "SchedulerOptions", "scope"), scope);
  }
  EXPECT_EQ(toString(Strategy::kInnerIterations), "inner_iterations");
  try {
    parseEnumName<Strategy>("gauss_seidel", "SchedulerOptions", "strategy");
    FAIL();
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("SchedulerOptions.strategy = \"gauss_seidel\": expected "
                                         "one of joint, alternating, inner_iterations"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(parseEnumName<Scope>("window", "SchedulerOptions", "scope"), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
