// graph_overhead_bench: what the factor-graph layer costs on top of plain Ceres.
//
// One synthetic point bundle adjustment (sim/point_scene.h) is solved two ways in one process:
//   graph:        buildPointBundleAdjustment() + optimize() + extractPoses/Points(), i.e. the
//                 path the curvesfm point-ba command takes, with analytic factor Jacobians lifted
//                 to the ambient blocks by FactorCostFunction;
//   hand-written: the same residuals written directly as ceres::AutoDiffCostFunction functors,
//                 on the same ambient layout with the same PoseManifold, the same gauge (pose 0
//                 constant, camera-distance residual between poses 0 and 1), ceres::HuberLoss
//                 and the same solver options and Schur ordering.
// Both totals run from the scene's plain data to optimised poses and points, so each includes
// its own problem building and copying results out. Then both cost functions are timed on
// residual + ambient Jacobian evaluation alone, after checking that their Jacobians agree.
//
// A third, diagnostic solve builds the Ceres problem by hand with the graph's analytic cost
// functions (FactorCostFunction) and no FactorGraph / Values / optimize(): against it,
// graph_layer_overhead_ratio shows what the layer itself costs, apart from the Jacobian method.
//
// Output: `key: value` lines after one `#` header line. Times are medians over --repeats.
#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/camera.h"
#include "core/errors.h"
#include "core/pose3.h"
#include "factors/point_bundle_adjustment.h"
#include "factors/point_reprojection_factor.h"
#include "factors/pose_prior_factor.h"
#include "graph/ceres_cost_function.h"
#include "graph/ceres_manifolds.h"
#include "graph/ceres_problem.h"
#include "graph/optimizer.h"
#include "sim/point_scene.h"

namespace curvesfm {
namespace {

using bench::Clock;
using bench::median;
using bench::print;
using bench::printInt;
using bench::printPrecise;
using bench::printText;
using bench::secondsSince;

struct BenchOptions {
  PointSceneOptions scene;  ///< Scene size via --cameras, --points, --track-length.
  int repeats = 3;          ///< Solves per variant; the median time is reported; >= 1.
  int threads = 1;          ///< Ceres threads for evaluation and linear algebra; >= 1.
  int max_iterations = 50;  ///< Ceres outer iterations; >= 0.
  /// Minimum wall time of one Jacobian timing run (s); runs repeat whole passes over all
  /// observations until this is reached.
  double jacobian_run_seconds = 0.2;
  int jacobian_runs = 5;  ///< Timing runs per cost function; the median is reported.
};

// --- the hand-written residuals ------------------------------------------------------------

// R(q) of an ambient pose [qx qy qz qw tx ty tz], row-major. The quaternion is normalised, as
// Pose3::fromAmbient does (here through the 2 / |q|^2 factor), so the ambient Jacobian has no
// component along q and equals FactorCostFunction's lifted Jacobian J_t * MinusJacobian.
template <class T>
void rotationMatrix(const T* pose, T R[9]) {
  const T& x = pose[0];
  const T& y = pose[1];
  const T& z = pose[2];
  const T& w = pose[3];
  const T s = 2.0 / (x * x + y * y + z * z + w * w);
  const T xx = s * x * x;
  const T yy = s * y * y;
  const T zz = s * z * z;
  const T xy = s * x * y;
  const T xz = s * x * z;
  const T yz = s * y * z;
  const T wx = s * w * x;
  const T wy = s * w * y;
  const T wz = s * w * z;
  R[0] = 1.0 - (yy + zz);
  R[1] = xy - wz;
  R[2] = xz + wy;
  R[3] = xy + wz;
  R[4] = 1.0 - (xx + zz);
  R[5] = yz - wx;
  R[6] = xz - wy;
  R[7] = yz + wx;
  R[8] = 1.0 - (xx + yy);
}

// Camera::project's model: pinhole with radial-tangential distortion (k1, k2, p1, p2, k3), and
// PointReprojectionFactor's behind-camera rule (constant error, zero Jacobian).
struct ReprojectionFunctor {
  ReprojectionFunctor(const CameraIntrinsics& intrinsics, const Eigen::Vector2d& measured,
                      double sigma)
      : c(intrinsics), measured(measured), inverse_sigma(1.0 / sigma) {}

  template <class T>
  bool operator()(const T* pose, const T* point, T* residual) const {
    T R[9];
    rotationMatrix(pose, R);
    const T pz = R[6] * point[0] + R[7] * point[1] + R[8] * point[2] + pose[6];
    if (!(pz > T(Camera::kMinDepth))) {
      residual[0] = T(PointReprojectionFactor::kBehindCameraError * inverse_sigma);
      residual[1] = T(PointReprojectionFactor::kBehindCameraError * inverse_sigma);
      return true;
    }
    const T px = R[0] * point[0] + R[1] * point[1] + R[2] * point[2] + pose[4];
    const T py = R[3] * point[0] + R[4] * point[1] + R[5] * point[2] + pose[5];
    const T inverse_z = 1.0 / pz;
    const T x = px * inverse_z;
    const T y = py * inverse_z;
    const T xx = x * x;
    const T yy = y * y;
    const T xy = x * y;
    const T r2 = xx + yy;
    const T radial = 1.0 + r2 * (c.k1 + r2 * (c.k2 + r2 * c.k3));
    const T xd = x * radial + (2.0 * c.p1) * xy + c.p2 * (r2 + 2.0 * xx);
    const T yd = y * radial + c.p1 * (r2 + 2.0 * yy) + (2.0 * c.p2) * xy;
    residual[0] = (c.fx * xd + c.cx - measured.x()) * inverse_sigma;
    residual[1] = (c.fy * yd + c.cy - measured.y()) * inverse_sigma;
    return true;
  }

  CameraIntrinsics c;
  Eigen::Vector2d measured;
  double inverse_sigma;
};

// CameraDistanceFactor: e = |c_j - c_i| - distance with c = -R^T t; the same degenerate rule.
struct CameraDistanceFunctor {
  CameraDistanceFunctor(double distance, double sigma)
      : distance(distance), inverse_sigma(1.0 / sigma) {}

  template <class T>
  static void centre(const T* pose, T c[3]) {
    T R[9];
    rotationMatrix(pose, R);
    for (int k = 0; k < 3; ++k) {
      c[k] = -(R[k] * pose[4] + R[3 + k] * pose[5] + R[6 + k] * pose[6]);
    }
  }

  template <class T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    using std::sqrt;
    T c_i[3];
    T c_j[3];
    centre(pose_i, c_i);
    centre(pose_j, c_j);
    const T d0 = c_j[0] - c_i[0];
    const T d1 = c_j[1] - c_i[1];
    const T d2 = c_j[2] - c_i[2];
    const T squared = d0 * d0 + d1 * d1 + d2 * d2;
    if (!(squared > T(1e-24))) {
      residual[0] = T(-distance * inverse_sigma);
      return true;
    }
    residual[0] = (sqrt(squared) - distance) * inverse_sigma;
    return true;
  }

  double distance;
  double inverse_sigma;
};

using ReprojectionCost = ceres::AutoDiffCostFunction<ReprojectionFunctor, 2, 7, 3>;
using CameraDistanceCost = ceres::AutoDiffCostFunction<CameraDistanceFunctor, 1, 7, 7>;

// --- the solves ------------------------------------------------------------------------------

struct SolveResult {
  double total_seconds = 0.0;  ///< Scene data in, optimised poses and points out.
  double build_seconds = 0.0;  ///< Building the problem (graph: graph + Values + bridge).
  double solve_seconds = 0.0;  ///< ceres::Solve wall time.
  /// The rest of the total: results out (graph: write-back, final costs), freeing the problem.
  double finish_seconds = 0.0;
  // Graph only: buildPointBundleAdjustment(), optimize()'s setup (initial per-type costs,
  // CeresProblem, ordering) and its write-back (Values update, final per-type costs).
  double graph_construction_seconds = 0.0;
  double bridge_setup_seconds = 0.0;
  double writeback_seconds = 0.0;
  double minimizer_seconds = 0.0;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  std::string termination;
  std::vector<Pose3> poses;
  std::vector<Eigen::Vector3d> points;
};

PointBundleAdjustmentInput baInput(const PointScene& scene) {
  PointBundleAdjustmentInput input;
  input.camera = scene.camera;
  input.cam_from_world = scene.initial_cam_from_world;
  input.points = scene.initial_points;
  input.observations = scene.observations;
  input.scale_distance = scene.trueScaleDistance();
  return input;
}

SolveResult solveWithGraph(const PointScene& scene, const PointBundleAdjustmentOptions& ba,
                           const OptimizerOptions& optimizer) {
  SolveResult result;
  const auto start = Clock::now();
  auto problem = std::make_unique<PointBundleAdjustmentProblem>(
      buildPointBundleAdjustment(baInput(scene), ba));
  const double graph_seconds = secondsSince(start);
  const OptimizationSummary summary =
      optimize(problem->graph, &problem->values, problem->config, optimizer);
  result.poses = extractPoses(problem->values, scene.initial_cam_from_world.size());
  result.points = extractPoints(problem->values, scene.initial_points.size());
  // Freeing the graph counts, as freeing the ceres::Problem does on the other side.
  problem.reset();
  result.total_seconds = secondsSince(start);
  result.build_seconds = graph_seconds + summary.setup_seconds;
  result.solve_seconds = summary.solve_seconds;
  result.finish_seconds = result.total_seconds - result.build_seconds - result.solve_seconds;
  result.graph_construction_seconds = graph_seconds;
  result.bridge_setup_seconds = summary.setup_seconds;
  result.writeback_seconds = summary.writeback_seconds;
  result.minimizer_seconds = summary.minimizer_seconds;
  result.iterations = summary.iterations;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.termination = summary.termination;
  return result;
}

// Cost functions of a hand-built problem: the autodiff functors above (the baseline), or, as a
// diagnostic that isolates the graph layer's own overhead, our analytic factors in
// FactorCostFunction without FactorGraph, Values or optimize().
enum class Differentiation { kAutodiff, kAnalytic };

ceres::CostFunction* reprojectionCost(Differentiation kind, const PointScene& scene,
                                      const PointObservation& obs,
                                      const PointBundleAdjustmentOptions& ba) {
  if (kind == Differentiation::kAutodiff) {
    return new ReprojectionCost(
        new ReprojectionFunctor(scene.camera->intrinsics(), obs.pixel, ba.pixel_sigma));
  }
  // The loss goes to Ceres separately (ceres::HuberLoss); the factor's kernel is not used here.
  return new FactorCostFunction(std::make_shared<const PointReprojectionFactor>(
      poseKey(obs.camera_index), pointKey(obs.point_index), obs.pixel, scene.camera,
      NoiseModel{ba.pixel_sigma, {}}));
}

ceres::CostFunction* cameraDistanceCost(Differentiation kind, double distance,
                                        const PointBundleAdjustmentOptions& ba) {
  if (kind == Differentiation::kAutodiff) {
    return new CameraDistanceCost(new CameraDistanceFunctor(distance, ba.scale_sigma));
  }
  return new FactorCostFunction(std::make_shared<const CameraDistanceFactor>(
      poseKey(0), poseKey(1), distance, NoiseModel{ba.scale_sigma, {}}));
}

SolveResult solveHandwritten(const PointScene& scene, const PointBundleAdjustmentOptions& ba,
                             const OptimizerOptions& optimizer, Differentiation kind) {
  SolveResult result;
  const auto start = Clock::now();
  const std::size_t num_cameras = scene.initial_cam_from_world.size();
  const std::size_t num_points = scene.initial_points.size();
  std::vector<double> poses(7 * num_cameras);
  std::vector<double> points(3 * num_points);
  for (std::size_t i = 0; i < num_cameras; ++i) {
    scene.initial_cam_from_world[i].toAmbient(&poses[7 * i]);
  }
  for (std::size_t p = 0; p < num_points; ++p) {
    Eigen::Vector3d::Map(&points[3 * p]) = scene.initial_points[p];
  }

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto problem = std::make_unique<ceres::Problem>(problem_options);
  PoseManifold pose_manifold;
  ceres::HuberLoss huber(ba.kernel_width);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  // Blocks are added in first-use order, as the graph bridge does, so that both programs list
  // their parameter blocks identically.
  std::vector<bool> pose_added(num_cameras, false);
  std::vector<bool> point_added(num_points, false);
  auto addPose = [&](int i) {
    double* block = &poses[7 * i];
    if (pose_added[i]) return block;
    pose_added[i] = true;
    problem->AddParameterBlock(block, 7, &pose_manifold);
    ordering->AddElementToGroup(block, 1);
    return block;
  };
  for (const PointObservation& obs : scene.observations) {
    double* pose = addPose(obs.camera_index);
    double* point = &points[3 * obs.point_index];
    if (!point_added[obs.point_index]) {
      point_added[obs.point_index] = true;
      problem->AddParameterBlock(point, 3);
      ordering->AddElementToGroup(point, 0);
    }
    problem->AddResidualBlock(reprojectionCost(kind, scene, obs, ba), &huber, pose, point);
  }
  problem->AddResidualBlock(cameraDistanceCost(kind, scene.trueScaleDistance(), ba), nullptr,
                            addPose(0), addPose(1));
  problem->SetParameterBlockConstant(&poses[0]);

  // The solver settings come from the same mapping the graph uses, so they cannot drift apart;
  // only the problem is hand-written.
  ceres::Solver::Options options = toCeresOptions(optimizer);
  options.linear_solver_ordering = ordering;
  result.build_seconds = secondsSince(start);

  const auto solve_start = Clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem.get(), &summary);
  result.solve_seconds = secondsSince(solve_start);

  for (std::size_t i = 0; i < num_cameras; ++i) {
    result.poses.push_back(Pose3::fromAmbient(&poses[7 * i]));
  }
  for (std::size_t p = 0; p < num_points; ++p) {
    result.points.push_back(Eigen::Vector3d::Map(&points[3 * p]));
  }
  // optimize() frees its bridge's ceres::Problem before it returns; do the same here.
  problem.reset();
  result.total_seconds = secondsSince(start);
  result.finish_seconds = result.total_seconds - result.build_seconds - result.solve_seconds;
  result.minimizer_seconds = summary.minimizer_time_in_seconds;
  result.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  return result;
}

// --- Jacobian evaluation ---------------------------------------------------------------------

// Residual + both ambient Jacobians of every cost function at its parameters.
struct EvaluationSet {
  std::vector<std::unique_ptr<ceres::CostFunction>> functions;
  std::vector<std::array<const double*, 2>> parameters;
};

struct Evaluation {
  std::array<double, 2> residual{};
  std::array<double, 14> H_pose{};
  std::array<double, 6> H_point{};

  void run(const ceres::CostFunction& function, const double* const* parameters) {
    double* jacobians[2] = {H_pose.data(), H_point.data()};
    function.Evaluate(parameters, residual.data(), jacobians);
  }
};

// Nanoseconds per evaluation: whole passes over all cost functions until `min_seconds`.
double nanosecondsPerEvaluation(const EvaluationSet& set, double min_seconds, double* checksum) {
  Evaluation evaluation;
  std::size_t evaluations = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  do {
    for (std::size_t k = 0; k < set.functions.size(); ++k) {
      evaluation.run(*set.functions[k], set.parameters[k].data());
      // Consumed so that no evaluation can be dropped as dead code.
      *checksum += evaluation.residual[0] + evaluation.H_pose[0] + evaluation.H_point[5];
    }
    evaluations += set.functions.size();
    elapsed = secondsSince(start);
  } while (elapsed < min_seconds);
  return 1e9 * elapsed / static_cast<double>(evaluations);
}

struct JacobianComparison {
  double max_relative_difference = 0.0;  ///< max |J_a - J_b| / max |J_b| per observation.
  double max_residual_difference = 0.0;  ///< max |r_a - r_b| (whitened).
};

JacobianComparison compareJacobians(const EvaluationSet& analytic, const EvaluationSet& autodiff) {
  JacobianComparison comparison;
  Evaluation a;
  Evaluation b;
  for (std::size_t k = 0; k < analytic.functions.size(); ++k) {
    a.run(*analytic.functions[k], analytic.parameters[k].data());
    b.run(*autodiff.functions[k], autodiff.parameters[k].data());
    double difference = 0.0;
    double scale = 0.0;
    for (std::size_t i = 0; i < a.H_pose.size(); ++i) {
      difference = std::max(difference, std::abs(a.H_pose[i] - b.H_pose[i]));
      scale = std::max(scale, std::abs(b.H_pose[i]));
    }
    for (std::size_t i = 0; i < a.H_point.size(); ++i) {
      difference = std::max(difference, std::abs(a.H_point[i] - b.H_point[i]));
      scale = std::max(scale, std::abs(b.H_point[i]));
    }
    comparison.max_relative_difference =
        std::max(comparison.max_relative_difference, difference / std::max(scale, 1e-300));
    for (int r = 0; r < 2; ++r) {
      comparison.max_residual_difference =
          std::max(comparison.max_residual_difference, std::abs(a.residual[r] - b.residual[r]));
    }
  }
  return comparison;
}

// --- output ----------------------------------------------------------------------------------

int run(const BenchOptions& bench) {
  const PointScene scene = makePointScene(bench.scene);
  const PointBundleAdjustmentOptions ba;  // sigma 1 px, Huber width 1, pose 0 + scale fixed.
  OptimizerOptions optimizer;             // sparse Schur (SuiteSparse), LM, structure first.
  optimizer.max_iterations = bench.max_iterations;
  optimizer.num_threads = bench.threads;
  optimizer.validate();

  std::printf(
      "# graph_overhead_bench: point BA via factor graph (analytic) vs hand-written Ceres "
      "(autodiff); times are medians of %d repeats\n",
      bench.repeats);
  printInt("cameras", static_cast<long long>(scene.initial_cam_from_world.size()));
  printInt("points", static_cast<long long>(scene.initial_points.size()));
  printInt("observations", static_cast<long long>(scene.observations.size()));
  printInt("threads", bench.threads);
  printInt("max_iterations", bench.max_iterations);
  printInt("repeats", bench.repeats);
  std::fflush(stdout);

  // Alternate the variants so that drifts in machine load hit both alike.
  std::vector<SolveResult> graph_runs;
  std::vector<SolveResult> handwritten_runs;
  std::vector<SolveResult> direct_runs;
  for (int r = 0; r < bench.repeats; ++r) {
    graph_runs.push_back(solveWithGraph(scene, ba, optimizer));
    handwritten_runs.push_back(solveHandwritten(scene, ba, optimizer, Differentiation::kAutodiff));
    direct_runs.push_back(solveHandwritten(scene, ba, optimizer, Differentiation::kAnalytic));
  }
  auto medianOf = [](const std::vector<SolveResult>& runs, double SolveResult::*field) {
    std::vector<double> samples;
    for (const SolveResult& run : runs) samples.push_back(run.*field);
    return median(samples);
  };
  const SolveResult& graph = graph_runs.front();
  const SolveResult& handwritten = handwritten_runs.front();
  const double graph_total = medianOf(graph_runs, &SolveResult::total_seconds);
  const double handwritten_total = medianOf(handwritten_runs, &SolveResult::total_seconds);
  const int graph_iterations = std::max(graph.iterations, 1);
  const int handwritten_iterations = std::max(handwritten.iterations, 1);

  printInt("iterations_graph", graph.iterations);
  printInt("iterations_handwritten", handwritten.iterations);
  printText("termination_graph", graph.termination);
  printText("termination_handwritten", handwritten.termination);
  printPrecise("initial_cost_graph", graph.initial_cost);
  printPrecise("initial_cost_handwritten", handwritten.initial_cost);
  printPrecise("final_cost_graph", graph.final_cost);
  printPrecise("final_cost_handwritten", handwritten.final_cost);
  print("final_cost_relative_difference", std::abs(graph.final_cost - handwritten.final_cost) /
                                              std::max(std::abs(handwritten.final_cost), 1e-300));
  const PointSceneErrors graph_errors = evaluatePointScene(scene, graph.poses, graph.points);
  const PointSceneErrors handwritten_errors =
      evaluatePointScene(scene, handwritten.poses, handwritten.points);
  print("reprojection_rmse_px_graph", graph_errors.reprojection_rmse_px);
  print("reprojection_rmse_px_handwritten", handwritten_errors.reprojection_rmse_px);
  print("seconds_total_graph", graph_total);
  print("seconds_total_handwritten", handwritten_total);
  print("seconds_build_graph", medianOf(graph_runs, &SolveResult::build_seconds));
  print("seconds_build_handwritten", medianOf(handwritten_runs, &SolveResult::build_seconds));
  print("seconds_finish_graph", medianOf(graph_runs, &SolveResult::finish_seconds));
  print("seconds_finish_handwritten", medianOf(handwritten_runs, &SolveResult::finish_seconds));
  print("seconds_solve_graph", medianOf(graph_runs, &SolveResult::solve_seconds));
  print("seconds_solve_handwritten", medianOf(handwritten_runs, &SolveResult::solve_seconds));
  print("seconds_minimizer_graph", medianOf(graph_runs, &SolveResult::minimizer_seconds));
  print("seconds_minimizer_handwritten",
        medianOf(handwritten_runs, &SolveResult::minimizer_seconds));
  print("seconds_graph_construction",
        medianOf(graph_runs, &SolveResult::graph_construction_seconds));
  print("seconds_graph_bridge_setup", medianOf(graph_runs, &SolveResult::bridge_setup_seconds));
  print("seconds_graph_writeback", medianOf(graph_runs, &SolveResult::writeback_seconds));
  const double graph_per_iteration = graph_total / graph_iterations;
  const double handwritten_per_iteration = handwritten_total / handwritten_iterations;
  print("seconds_per_iteration_graph", graph_per_iteration);
  print("seconds_per_iteration_handwritten", handwritten_per_iteration);
  print("graph_overhead_ratio", graph_per_iteration / handwritten_per_iteration);
  // Diagnostic: the hand-built problem with the graph's analytic cost functions. Against it the
  // ratio measures only what FactorGraph, Values and optimize() add, not the Jacobian method.
  const SolveResult& direct = direct_runs.front();
  const double direct_total = medianOf(direct_runs, &SolveResult::total_seconds);
  const double direct_per_iteration = direct_total / std::max(direct.iterations, 1);
  printInt("iterations_direct_analytic", direct.iterations);
  printPrecise("final_cost_direct_analytic", direct.final_cost);
  print("seconds_total_direct_analytic", direct_total);
  print("seconds_build_direct_analytic", medianOf(direct_runs, &SolveResult::build_seconds));
  print("seconds_solve_direct_analytic", medianOf(direct_runs, &SolveResult::solve_seconds));
  print("seconds_finish_direct_analytic", medianOf(direct_runs, &SolveResult::finish_seconds));
  print("seconds_per_iteration_direct_analytic", direct_per_iteration);
  print("graph_layer_overhead_ratio", graph_per_iteration / direct_per_iteration);
  std::fflush(stdout);

  // Both cost function kinds at the starting values, one per observation. The graph lists the
  // reprojection factors first, in observation order.
  const PointBundleAdjustmentProblem problem = buildPointBundleAdjustment(baInput(scene), ba);
  std::vector<double> poses(7 * scene.initial_cam_from_world.size());
  std::vector<double> points(3 * scene.initial_points.size());
  for (std::size_t i = 0; i < scene.initial_cam_from_world.size(); ++i) {
    scene.initial_cam_from_world[i].toAmbient(&poses[7 * i]);
  }
  for (std::size_t p = 0; p < scene.initial_points.size(); ++p) {
    Eigen::Vector3d::Map(&points[3 * p]) = scene.initial_points[p];
  }
  EvaluationSet analytic;
  EvaluationSet autodiff;
  for (std::size_t k = 0; k < scene.observations.size(); ++k) {
    const PointObservation& obs = scene.observations[k];
    const std::array<const double*, 2> parameters = {&poses[7 * obs.camera_index],
                                                     &points[3 * obs.point_index]};
    analytic.functions.push_back(std::make_unique<FactorCostFunction>(problem.graph[k]));
    analytic.parameters.push_back(parameters);
    autodiff.functions.push_back(std::make_unique<ReprojectionCost>(
        new ReprojectionFunctor(scene.camera->intrinsics(), obs.pixel, ba.pixel_sigma)));
    autodiff.parameters.push_back(parameters);
  }
  const JacobianComparison comparison = compareJacobians(analytic, autodiff);

  // optimize() evaluates FactorGraph::costByType() twice (before and after) outside Ceres.
  std::vector<double> cost_by_type_seconds;
  for (int r = 0; r < bench.repeats; ++r) {
    const auto start = Clock::now();
    const auto costs = problem.graph.costByType(problem.values);
    cost_by_type_seconds.push_back(secondsSince(start));
  }
  print("seconds_cost_by_type", median(cost_by_type_seconds));

  double checksum = 0.0;
  std::vector<double> analytic_ns;
  std::vector<double> autodiff_ns;
  for (int r = 0; r < bench.jacobian_runs; ++r) {
    analytic_ns.push_back(
        nanosecondsPerEvaluation(analytic, bench.jacobian_run_seconds, &checksum));
    autodiff_ns.push_back(
        nanosecondsPerEvaluation(autodiff, bench.jacobian_run_seconds, &checksum));
  }
  const double analytic_median = median(analytic_ns);
  const double autodiff_median = median(autodiff_ns);
  print("jacobian_ns_per_obs_analytic", analytic_median);
  print("jacobian_ns_per_obs_autodiff", autodiff_median);
  print("jacobian_speedup", autodiff_median / analytic_median);
  printInt("jacobian_check_observations", static_cast<long long>(scene.observations.size()));
  print("max_jacobian_difference", comparison.max_relative_difference);
  print("max_residual_difference", comparison.max_residual_difference);
  printText("jacobian_check", comparison.max_relative_difference <= 1e-6 ? "ok" : "FAILED");
  // Printed so the timing loops' results are used; the value itself means nothing.
  print("checksum", checksum);
  return comparison.max_relative_difference <= 1e-6 ? 0 : 1;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions bench;
  CLI::App app{"Factor-graph layer vs hand-written Ceres on one point bundle adjustment"};
  app.add_option("--cameras", bench.scene.num_cameras, "Cameras on the arc")->capture_default_str();
  app.add_option("--points", bench.scene.num_points, "Points in the cube")->capture_default_str();
  app.add_option("--track-length", bench.scene.track_length,
                 "Consecutive cameras that observe each point")
      ->capture_default_str();
  app.add_option("--repeats", bench.repeats, "Solves per variant (median reported)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--threads", bench.threads, "Ceres threads")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--max-iterations", bench.max_iterations, "Ceres outer iterations")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(bench); });
}
