// strategy_bench: solver strategies, linear solvers, robust kernels and regulariser weights of
// curve bundle adjustment, compared on a fixed set of synthetic curve scenes.
//
// Every combination of strategy {joint, alternating, inner_iterations} x linear solver
// (--solvers; default {sparse_schur, dense_schur, iterative_schur}) x kernel {none, huber, cauchy}
// x (lambda1, lambda2) in {0, 1e2, 1e4} x {0, 1, 10} runs on each scene from the same perturbed
// start. Then the best configuration (lowest mean ATE over the scenes) runs again with integer edge
// positions instead of sub-pixel ones.
//
// Writes into --out: runs.csv (one row per run), summary.md (tables), and through
// `python3 -m curvesfm_plots strategy-bench` (when matplotlib is there) the figures
// error_vs_time, curve_error_vs_time, error_vs_weights and error_by_kernel (.png and .pdf).
// Prints a `key: value` summary. Errors: ATE after Sim(3) alignment (mm), mean rotation error
// (deg), curve error = mean distance of sampled curve points to the true curve after the same
// alignment (mm).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/plot_scripts.h"
#include "benchmarks/support/bench_common.h"
#include "core/errors.h"
#include "factors/curve_bundle_adjustment.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

struct NamedScene {
  std::string name;
  CurveSceneOptions options;
};

// Orbit without noise; forward walk with image noise and clutter; orbit with occlusions.
std::vector<NamedScene> benchScenes(bool quick) {
  std::vector<NamedScene> scenes;
  NamedScene orbit{"orbit_clean", {}};
  orbit.options.seed = 1;
  scenes.push_back(orbit);
  NamedScene walk{"walk_noisy", {}};
  walk.options.camera_path = CameraPath::kForwardWalk;
  walk.options.pixel_noise = 6.0;
  walk.options.num_clutter_edges = 15;
  walk.options.seed = 2;
  scenes.push_back(walk);
  NamedScene occluded{"orbit_occluded", {}};
  occluded.options.occlusion_fraction = 0.3;
  occluded.options.pixel_noise = 3.0;
  occluded.options.seed = 3;
  scenes.push_back(occluded);
  if (quick) scenes.resize(1);
  return scenes;
}

struct Config {
  Strategy strategy = Strategy::kJoint;
  LinearSolver solver = LinearSolver::kSparseSchur;
  RobustKernelType kernel = RobustKernelType::kHuber;
  double lambda1 = 100.0;
  double lambda2 = 1.0;
  bool subpixel = true;

  std::string key() const {
    std::ostringstream out;
    out << toString(strategy) << "/" << toString(solver) << "/" << toString(kernel) << "/"
        << lambda1 << "/" << lambda2 << "/" << (subpixel ? "subpixel" : "integer");
    return out.str();
  }
};

struct Run {
  std::string scene;
  Config config;
  CurveSceneErrors before;
  CurveSceneErrors after;
  int iterations = 0;
  double seconds = 0.0;
  double final_cost = 0.0;
  bool converged = false;
};

// A scene with its nearest-edge fields and the errors of its start, built once and solved many
// times.
struct PreparedScene {
  std::string name;
  CurveScene scene;
  CurveBundleAdjustmentInput input;
  CurveSceneErrors before;
};

PreparedScene prepare(const NamedScene& named) {
  PreparedScene prepared{named.name, makeCurveScene(named.options), {}, {}};
  prepared.input = makeCurveBundleAdjustmentInput(prepared.scene);
  prepared.before =
      evaluateCurveScene(prepared.scene, prepared.input.cam_from_world, prepared.input.curves);
  return prepared;
}

struct BenchOptions {
  std::string out = "bench_out/strategy";  ///< Output folder (created).
  bool quick = false;                      ///< One scene and a reduced sweep (smoke test).
  int max_iterations = 100;                ///< Ceres iterations per solve.
  bool curve_blocks = true;                ///< OptimizerOptions::curve_blocks.
  bool components_apart = false;           ///< OptimizerOptions::solve_components_apart.
  /// Linear solvers swept, by OptimizerOptions::linear_solver name.
  std::vector<std::string> solvers = {"sparse_schur", "dense_schur", "iterative_schur"};
};

Run solve(const PreparedScene& prepared, const Config& config, const BenchOptions& options) {
  CurveBundleAdjustmentOptions ba;
  ba.kernel = config.kernel;
  ba.lambda1 = config.lambda1;
  ba.lambda2 = config.lambda2;
  ba.use_subpixel_edges = config.subpixel;
  SchedulerOptions scheduler;
  scheduler.strategy = config.strategy;
  scheduler.optimizer.linear_solver = config.solver;
  scheduler.optimizer.max_iterations = options.max_iterations;
  scheduler.optimizer.curve_blocks = options.curve_blocks;
  scheduler.optimizer.solve_components_apart = options.components_apart;

  const auto start = bench::Clock::now();
  CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(prepared.input, ba);
  const ScheduleReport report =
      runSchedule(problem.graph, &problem.values, problem.config, scheduler);
  Run run;
  run.seconds = bench::secondsSince(start);
  run.scene = prepared.name;
  run.config = config;
  run.before = prepared.before;
  run.after = evaluateCurveScene(prepared.scene,
                                 extractPoses(problem.values, prepared.input.cam_from_world.size()),
                                 extractCurves(problem.values, prepared.input.curves));
  run.iterations = report.total_iterations;
  run.final_cost = report.final_cost;
  run.converged = report.converged;
  return run;
}

std::vector<Config> sweepConfigs(const std::vector<LinearSolver>& solvers) {
  std::vector<Config> configs;
  for (Strategy strategy : {Strategy::kJoint, Strategy::kAlternating, Strategy::kInnerIterations}) {
    for (LinearSolver solver : solvers) {
      for (RobustKernelType kernel :
           {RobustKernelType::kNone, RobustKernelType::kHuber, RobustKernelType::kCauchy}) {
        for (double lambda1 : {0.0, 1e2, 1e4}) {
          for (double lambda2 : {0.0, 1.0, 10.0}) {
            configs.push_back({strategy, solver, kernel, lambda1, lambda2, true});
          }
        }
      }
    }
  }
  return configs;
}

// Means over the scenes of one configuration.
struct Aggregate {
  Config config;
  int runs = 0;
  double ate_mm = 0.0;
  double rotation_deg = 0.0;
  double curve_mm = 0.0;
  double seconds = 0.0;
  double iterations = 0.0;
};

std::vector<Aggregate> aggregate(const std::vector<Run>& runs) {
  std::map<std::string, Aggregate> by_key;
  std::vector<std::string> order;
  for (const Run& run : runs) {
    auto [it, inserted] = by_key.try_emplace(run.config.key());
    if (inserted) order.push_back(run.config.key());
    Aggregate& a = it->second;
    a.config = run.config;
    ++a.runs;
    a.ate_mm += 1e3 * run.after.position_ate_sim3;
    a.rotation_deg += run.after.rotation_mean_deg;
    a.curve_mm += 1e3 * run.after.curve_mean_error_aligned;
    a.seconds += run.seconds;
    a.iterations += run.iterations;
  }
  std::vector<Aggregate> result;
  for (const std::string& key : order) {
    Aggregate a = by_key[key];
    a.ate_mm /= a.runs;
    a.rotation_deg /= a.runs;
    a.curve_mm /= a.runs;
    a.seconds /= a.runs;
    a.iterations /= a.runs;
    result.push_back(a);
  }
  return result;
}

void writeCsv(const std::vector<Run>& runs, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "scene,strategy,linear_solver,kernel,lambda1,lambda2,edges,ate_before_mm,ate_after_mm,"
         "rotation_before_deg,rotation_after_deg,curve_before_mm,curve_after_mm,iterations,"
         "seconds,final_cost,converged\n";
  for (const Run& r : runs) {
    out << r.scene << "," << toString(r.config.strategy) << "," << toString(r.config.solver) << ","
        << toString(r.config.kernel) << "," << r.config.lambda1 << "," << r.config.lambda2 << ","
        << (r.config.subpixel ? "subpixel" : "integer") << "," << 1e3 * r.before.position_ate_sim3
        << "," << 1e3 * r.after.position_ate_sim3 << "," << r.before.rotation_mean_deg << ","
        << r.after.rotation_mean_deg << "," << 1e3 * r.before.curve_mean_error_aligned << ","
        << 1e3 * r.after.curve_mean_error_aligned << "," << r.iterations << "," << r.seconds << ","
        << r.final_cost << "," << (r.converged ? 1 : 0) << "\n";
  }
}

std::string row(const Aggregate& a) {
  char line[256];
  std::snprintf(line, sizeof(line), "| %s | %s | %s | %g | %g | %.2f | %.3f | %.2f | %.1f | %.3f |",
                toString(a.config.strategy).c_str(), toString(a.config.solver).c_str(),
                toString(a.config.kernel).c_str(), a.config.lambda1, a.config.lambda2, a.ate_mm,
                a.rotation_deg, a.curve_mm, a.iterations, a.seconds);
  return line;
}

constexpr const char* kTableHeader =
    "| strategy | linear solver | kernel | lambda1 | lambda2 | ATE (mm) | rotation (deg) | "
    "curve (mm) | iterations | time (s) |\n|---|---|---|---|---|---|---|---|---|---|\n";

void writeSummary(const std::vector<Aggregate>& sweep, const std::vector<Run>& edge_runs,
                  const std::vector<NamedScene>& scenes, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "# Curve bundle adjustment: strategy bench\n\nScenes:";
  for (const NamedScene& scene : scenes) out << " " << scene.name;
  out << ". Values are means over the scenes, after BA from the perturbed start.\n\n";
  std::vector<Aggregate> sorted = sweep;
  std::sort(sorted.begin(), sorted.end(),
            [](const Aggregate& a, const Aggregate& b) { return a.ate_mm < b.ate_mm; });
  out << "## All configurations, best ATE first\n\n" << kTableHeader;
  for (const Aggregate& a : sorted) out << row(a) << "\n";
  out << "\n## Integer vs sub-pixel edges (best configuration)\n\n" << kTableHeader;
  for (const Aggregate& a : aggregate(edge_runs)) {
    out << row(a) << (a.config.subpixel ? " sub-pixel" : " integer") << "\n";
  }
}

int run(const BenchOptions& options) {
  const auto start = bench::Clock::now();
  const std::filesystem::path out(options.out);
  std::filesystem::create_directories(out);
  const std::vector<NamedScene> named = benchScenes(options.quick);
  std::vector<PreparedScene> scenes;
  for (const NamedScene& scene : named) scenes.push_back(prepare(scene));

  std::vector<LinearSolver> solvers;
  for (const std::string& name : options.solvers) {
    solvers.push_back(parseEnumName<LinearSolver>(name, "OptimizerOptions", "linear_solver"));
  }
  std::vector<Config> configs = sweepConfigs(solvers);
  if (options.quick) configs.resize(configs.size() / 9);
  std::vector<Run> runs;
  int done = 0;
  const int total = static_cast<int>(configs.size() * scenes.size());
  for (const Config& config : configs) {
    for (const PreparedScene& scene : scenes) {
      runs.push_back(solve(scene, config, options));
      if (++done % 20 == 0 || done == total) {
        std::fprintf(stderr, "\r%d / %d runs, %.0f s", done, total, bench::secondsSince(start));
      }
    }
  }
  std::fprintf(stderr, "\n");
  const std::vector<Aggregate> sweep = aggregate(runs);
  const Aggregate best =
      *std::min_element(sweep.begin(), sweep.end(),
                        [](const Aggregate& a, const Aggregate& b) { return a.ate_mm < b.ate_mm; });

  std::vector<Run> edge_runs;
  for (bool subpixel : {false, true}) {
    Config config = best.config;
    config.subpixel = subpixel;
    for (const PreparedScene& scene : scenes) {
      edge_runs.push_back(solve(scene, config, options));
    }
  }

  writeCsv(runs, out / "runs.csv");
  writeSummary(sweep, edge_runs, named, out / "summary.md");

  std::printf("# strategy_bench: %d runs on %zu scenes, %s, %s\n", total, scenes.size(),
              options.curve_blocks ? "a solver block per curve" : "a solver block per variable",
              options.components_apart ? "structure-only steps per component"
                                       : "structure-only steps in one Ceres solve");
  double ate_before = 0.0;
  for (const Run& run : runs) ate_before += 1e3 * run.before.position_ate_sim3;
  bench::print("ate_before_mm_mean", ate_before / runs.size());
  bench::printText("best_config", best.config.key());
  bench::print("best_ate_mm", best.ate_mm);
  bench::print("best_rotation_deg", best.rotation_deg);
  bench::print("best_curve_mm", best.curve_mm);
  for (const Aggregate& a : aggregate(edge_runs)) {
    const std::string prefix = a.config.subpixel ? "subpixel_" : "integer_";
    bench::print(prefix + "ate_mm", a.ate_mm);
    bench::print(prefix + "curve_mm", a.curve_mm);
  }
  bench::print("total_seconds", bench::secondsSince(start));
  bench::printText("outputs", (out / "{runs.csv,summary.md}").string());
  // The figures come last: the data above stands without them.
  drawFiguresIfPossible({"strategy-bench", out.string()});
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions options;
  CLI::App app{"Curve BA strategies x linear solvers x kernels x weights on synthetic scenes"};
  app.add_option("--out", options.out, "Output folder for CSV, table and plots")
      ->capture_default_str();
  app.add_flag("--quick", options.quick, "One scene and a ninth of the sweep (smoke test)");
  app.add_option("--max-iterations", options.max_iterations, "Ceres iterations per solve")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--curve-blocks", options.curve_blocks,
                 "One solver block per curve (false: one per variable)")
      ->capture_default_str();
  app.add_option("--solvers", options.solvers,
                 "Linear solvers swept (graph_schur: our own Schur complement)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--components-apart", options.components_apart,
                 "With every pose held (alternating's structure step), solve each curve alone "
                 "(false: one Ceres solve)")
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(options); });
}
