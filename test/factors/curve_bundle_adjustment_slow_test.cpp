// Curve bundle adjustments solved to the end on synthetic scenes (ctest label "slow").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "factors/curve_bundle_adjustment.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

struct Solved {
  CurveSceneErrors before;
  CurveSceneErrors after;
  ScheduleReport report;
};

Solved solve(const CurveScene& scene, Strategy strategy,
             const CurveBundleAdjustmentOptions& ba = {}, bool curve_blocks = true,
             LinearSolver solver = LinearSolver::kSparseSchur) {
  const CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, ba);
  SchedulerOptions scheduler;
  scheduler.strategy = strategy;
  scheduler.optimizer.max_iterations = 100;
  scheduler.optimizer.curve_blocks = curve_blocks;
  scheduler.optimizer.linear_solver = solver;
  Solved solved;
  solved.before = evaluateCurveScene(scene, input.cam_from_world, input.curves);
  solved.report = runSchedule(problem.graph, &problem.values, problem.config, scheduler);
  solved.after =
      evaluateCurveScene(scene, extractPoses(problem.values, input.cam_from_world.size()),
                         extractCurves(problem.values, input.curves));
  return solved;
}

// The protocol: poses perturbed by ~2 cm / 1 deg, curves by ~2 cm, noise-free images.
CurveSceneOptions perturbedScene() { return CurveSceneOptions{}; }

// A small start error, so that two solvers' step sequences end in the same basin.
CurveScene slightlyPerturbedScene() {
  CurveSceneOptions options;
  options.pose_noise_translation = 0.005;
  options.pose_noise_rotation_deg = 0.2;
  options.curve_point_noise = 0.005;
  return makeCurveScene(options);
}

TEST(CurveBundleAdjustment, JointRecoversPosesAndCurvesFromAPerturbedStart) {
  const Solved solved = solve(makeCurveScene(perturbedScene()), Strategy::kJoint);
  // Measured (seed 42): ATE 30 -> 2.8 mm, rotation 1.71 -> 0.065 deg, aligned curve error
  // 27.5 -> 10.0 mm with the parabola sub-pixel fit; ATE 4.6 mm with the Gaussian fit now in
  // NearestEdgeField. The result is sensitive to such details (docs/benchmarks.md, "Curve bundle
  // adjustment"), hence the loose bounds. The curve figure is the weak one: a straight line can
  // slide along itself, which the edge residual does not see.
  EXPECT_LT(solved.after.position_ate_sim3, 0.25 * solved.before.position_ate_sim3);
  EXPECT_LT(solved.after.rotation_mean_deg, 0.1 * solved.before.rotation_mean_deg);
  EXPECT_LT(solved.after.curve_mean_error_aligned, 0.5 * solved.before.curve_mean_error_aligned);
  EXPECT_LT(solved.report.final_cost, 0.1 * solved.report.initial_cost);
}

TEST(CurveBundleAdjustment, ABlockPerCurveReachesTheOptimumOfABlockPerVariable) {
  const CurveScene scene = slightlyPerturbedScene();
  const Solved per_variable = solve(scene, Strategy::kJoint, {}, false);
  const Solved per_curve = solve(scene, Strategy::kJoint, {}, true);
  const OptimizationSummary& a = per_variable.report.rounds.front().summary;
  const OptimizationSummary& b = per_curve.report.rounds.front().summary;
  EXPECT_EQ(a.ordering.rfind("automatic", 0), 0u) << a.ordering;
  EXPECT_EQ(b.ordering.rfind("structure_first", 0), 0u) << b.ordering;
  EXPECT_EQ(b.num_curve_blocks, static_cast<int>(scene.true_curves.size()));
  EXPECT_NEAR(b.initial_cost, a.initial_cost, 1e-9 * a.initial_cost);
  EXPECT_NEAR(b.final_cost, a.final_cost, 0.01 * a.final_cost);
  EXPECT_NEAR(per_curve.after.position_ate_sim3, per_variable.after.position_ate_sim3, 2e-4);
  EXPECT_NEAR(per_curve.after.curve_mean_error_aligned, per_variable.after.curve_mean_error_aligned,
              5e-4);
}

TEST(CurveBundleAdjustment, OurOwnSchurComplementReachesTheOptimumOfCeres) {
  const CurveScene scene = slightlyPerturbedScene();
  const Solved ceres = solve(scene, Strategy::kJoint, {}, false);
  const Solved ours = solve(scene, Strategy::kJoint, {}, true, LinearSolver::kGraphSchur);
  const OptimizationSummary& a = ceres.report.rounds.front().summary;
  const OptimizationSummary& b = ours.report.rounds.front().summary;
  EXPECT_EQ(b.linear_solver, "GRAPH_SCHUR");
  EXPECT_EQ(b.ordering,
            "graph_schur (" + std::to_string(scene.true_curves.size()) + " groups eliminated, " +
                std::to_string(scene.true_cam_from_world.size() - 1) + " poses reduced)");
  EXPECT_NEAR(b.initial_cost, a.initial_cost, 1e-9 * a.initial_cost);
  EXPECT_NEAR(b.final_cost, a.final_cost, 0.01 * a.final_cost);
  EXPECT_NEAR(ours.after.position_ate_sim3, ceres.after.position_ate_sim3, 2e-4);
  EXPECT_NEAR(ours.after.curve_mean_error_aligned, ceres.after.curve_mean_error_aligned, 5e-4);
  EXPECT_LT(ours.after.position_ate_sim3, 0.5 * ours.before.position_ate_sim3);
}

TEST(CurveBundleAdjustment, AlternatingReachesTheCostOfJointAndImprovesAsMuch) {
  const CurveScene scene = makeCurveScene(perturbedScene());
  const Solved joint = solve(scene, Strategy::kJoint);
  const Solved alternating = solve(scene, Strategy::kAlternating);
  // Both are local minima of the same objective; alternating's is not worse. Measured: cost
  // 17663 -> 813 (joint), -> 78 (alternating); its poses stall in the flat valley of a global
  // rotation about the fixed keyframe (rotation error 0.23 deg vs joint's 0.065 deg).
  EXPECT_LE(alternating.report.final_cost, 1.05 * joint.report.final_cost);
  EXPECT_LT(alternating.after.position_ate_sim3, 0.3 * alternating.before.position_ate_sim3);
  EXPECT_LT(alternating.after.rotation_mean_deg, 0.2 * alternating.before.rotation_mean_deg);
  EXPECT_LT(alternating.after.curve_mean_error_aligned,
            0.5 * alternating.before.curve_mean_error_aligned);
  // Each round may only lower the cost.
  double previous = alternating.report.initial_cost;
  for (const ScheduleRound& round : alternating.report.rounds) {
    if (round.skipped) continue;
    EXPECT_LE(round.summary.final_cost, previous * (1 + 1e-9)) << round.phase << round.round;
    previous = round.summary.final_cost;
  }
}

TEST(CurveBundleAdjustment, PartlyHiddenCurvesAreNotBiasedWithTheOrientationCheck) {
  // Start at the truth with a contiguous 30-50% of a curve hidden in half of the (curve,
  // keyframe) pairs. Hidden samples within the reach of the visible end match that end, where
  // the gradient runs along the curve and pulls them towards the visible part. Measured
  // (seed 42): aligned curve error 7.5 mm, ATE 4.9 mm with every match accepted; 0.8 mm /
  // 1.6 mm with matches limited to edges within 20 deg of the curve normal; 1.4 mm / 1.1 mm
  // with nothing hidden.
  CurveSceneOptions options;
  options.pose_noise_translation = 0.0;
  options.pose_noise_rotation_deg = 0.0;
  options.curve_point_noise = 0.0;
  options.curve_tangent_noise_deg = 0.0;
  options.curve_length_noise = 0.0;
  options.occlusion_fraction = 0.5;
  const CurveScene scene = makeCurveScene(options);
  int partly_hidden = 0;
  for (const CurveObservation& obs : scene.observations) partly_hidden += obs.partlyHidden();
  ASSERT_GT(partly_hidden, static_cast<int>(scene.observations.size()) / 8);

  const Solved unchecked = solve(scene, Strategy::kJoint);
  CurveBundleAdjustmentOptions ba;
  ba.max_normal_angle_deg = 20.0;
  const Solved checked = solve(scene, Strategy::kJoint, ba);
  EXPECT_LT(checked.after.curve_mean_error_aligned, 0.002);
  EXPECT_LT(checked.after.position_ate_sim3, 0.003);
  EXPECT_LT(checked.after.curve_mean_error_aligned, 0.3 * unchecked.after.curve_mean_error_aligned);
}

// The perturbed scene's poses after a joint solve with the truth as the priors' trajectory.
std::vector<Pose3> posesWithPriorsAtTheTruth(const CurveScene& scene,
                                             const CurveBundleAdjustmentOptions& ba) {
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  input.motion_prior_cam_from_world = scene.true_cam_from_world;
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, ba);
  SchedulerOptions scheduler;
  scheduler.optimizer.max_iterations = 100;
  runSchedule(problem.graph, &problem.values, problem.config, scheduler);
  return extractPoses(problem.values, input.cam_from_world.size());
}

TEST(CurveBundleAdjustment, ATightMotionPriorKeepsThePriorsRelativeMotions) {
  const CurveScene scene = makeCurveScene(perturbedScene());
  CurveBundleAdjustmentOptions ba;
  ba.motion_prior_rotation_sigma_deg = 1e-4;
  ba.motion_prior_translation_sigma_rel = 1e-6;
  const std::vector<Pose3> poses = posesWithPriorsAtTheTruth(scene, ba);
  for (std::size_t j = 1; j < poses.size(); ++j) {
    const Pose3 motion = poses[j] * poses[j - 1].inverse();
    const Pose3 truth = scene.true_cam_from_world[j] * scene.true_cam_from_world[j - 1].inverse();
    // The start is ~2 cm / 1 deg off per pose; the prior pins each motion to ~1e-6.
    EXPECT_LT(truth.localCoordinates(motion).norm(), 1e-4) << "keyframes " << j - 1 << ", " << j;
  }
}

// The same start in a world whose origin lies `shift` away: poses and curves moved with it.
CurveBundleAdjustmentInput shiftedWorld(CurveBundleAdjustmentInput input,
                                        const Eigen::Vector3d& shift) {
  const Pose3 world_from_shifted(Eigen::Quaterniond::Identity(), -shift);
  for (Pose3& pose : input.cam_from_world) pose = pose * world_from_shifted;
  for (PolyBezier& curve : input.curves) {
    for (int i = 0; i < curve.numPoints(); ++i) curve.setPoint(i, curve.points()[i] + shift);
  }
  return input;
}

std::vector<Pose3> posesAfterIterations(const CurveBundleAdjustmentInput& input, int iterations) {
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, {});
  SchedulerOptions scheduler;
  scheduler.strategy = Strategy::kJoint;
  scheduler.optimizer.max_iterations = iterations;
  runSchedule(problem.graph, &problem.values, problem.config, scheduler);
  return extractPoses(problem.values, input.cam_from_world.size());
}

// The pose chart turns a camera about its own centre, so where the world's origin lies does not
// change a single step (with a chart that turned it about the origin, a start 50 scene units away
// took other steps and ended in other minima on real scenes: docs/benchmarks.md).
TEST(CurveBundleAdjustment, StepsDoNotDependOnWhereTheWorldOriginLies) {
  const CurveScene scene = makeCurveScene(perturbedScene());
  const CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  const Eigen::Vector3d shift(30.0, -20.0, 40.0);
  const std::vector<Pose3> here = posesAfterIterations(input, 3);
  const std::vector<Pose3> there = posesAfterIterations(shiftedWorld(input, shift), 3);
  const Pose3 shifted_from_world(Eigen::Quaterniond::Identity(), shift);
  double moved = 0.0;
  for (std::size_t j = 0; j < here.size(); ++j) {
    moved = std::max(moved, cameraCentreDistance(here[j], input.cam_from_world[j]));
    EXPECT_LT(cameraCentreDistance(there[j] * shifted_from_world, here[j]), 1e-9)
        << "keyframe " << j;
    EXPECT_LT(there[j].rotation().angularDistance(here[j].rotation()), 1e-10) << "keyframe " << j;
  }
  EXPECT_GT(moved, 1e-3);  // Three iterations moved the poses: the comparison means something.
}

TEST(CurveBundleAdjustment, ATightStartPriorKeepsEveryCentreAndOrientation) {
  const CurveScene scene = makeCurveScene(perturbedScene());
  CurveBundleAdjustmentOptions ba;
  ba.motion_prior = false;
  ba.fix_first_pose = false;
  ba.start_prior = true;
  ba.start_prior_rotation_sigma_deg = 1e-4;
  ba.start_prior_centre_sigma_rel = 1e-6;
  const std::vector<Pose3> poses = posesWithPriorsAtTheTruth(scene, ba);
  for (std::size_t j = 0; j < poses.size(); ++j) {
    // The start is ~2 cm / 1 deg off per pose; the prior pins each pose to its truth.
    const Pose3& truth = scene.true_cam_from_world[j];
    EXPECT_LT(cameraCentreDistance(poses[j], truth), 1e-4) << "keyframe " << j;
    EXPECT_LT(poses[j].rotation().angularDistance(truth.rotation()), 1e-5) << "keyframe " << j;
  }
}

}  // namespace
}  // namespace curvesfm
