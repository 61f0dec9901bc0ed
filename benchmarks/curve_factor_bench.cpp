// curve_factor_bench: what one curve residual costs next to one point observation.
//
// Both are evaluated the way Ceres evaluates them during a solve: FactorCostFunction::Evaluate
// with the residuals and every ambient Jacobian block requested, at the ground truth of a
// synthetic scene (so every curve sample projects onto the field and takes the full path).
//   curve: every CurveReprojectionFactor of a curve scene (sim/curve_scene.h), per sample
//          (s + 1 samples per factor): Bézier point and its Jacobians, pose, distortion,
//          nearest-edge look-up, projection onto the gradient;
//   point: every PointReprojectionFactor of the point scene of graph_overhead_bench, per
//          observation (2 rows).
// curve_sample_vs_point_obs_ratio = ns per curve sample / ns per point observation; the target
// of issue 3 is <= 1.0.
//
// Output: `key: value` lines after one `#` header line. Times are medians over --runs.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <unordered_map>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/errors.h"
#include "factors/curve_bundle_adjustment.h"
#include "factors/point_bundle_adjustment.h"
#include "graph/ceres_cost_function.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"
#include "sim/point_scene.h"

namespace curvesfm {
namespace {

using bench::Clock;

// Cost functions with their ambient parameter blocks, ready to evaluate.
class EvaluationSet {
 public:
  EvaluationSet(const FactorGraph& graph, const Values& values, const char* type_name) {
    for (const auto& factor : graph) {
      if (std::string(factor->typeName()) != type_name) continue;
      std::vector<const double*> blocks;
      for (Key key : factor->keys()) blocks.push_back(ambientOf(values, key));
      functions_.push_back(std::make_unique<FactorCostFunction>(factor));
      parameters_.push_back(std::move(blocks));
      rows_ += factor->residualDimension();
      max_rows_ = std::max(max_rows_, factor->residualDimension());
    }
  }

  std::size_t size() const { return functions_.size(); }
  long long rows() const { return rows_; }

  // Nanoseconds per evaluation of every function in turn, repeated for at least `min_seconds`.
  double nanosecondsPerPass(double min_seconds, double* checksum) const {
    std::vector<double> residuals(max_rows_);
    std::vector<std::vector<double>> jacobians(8, std::vector<double>(max_rows_ * 7));
    std::vector<double*> jacobian_pointers;
    for (auto& jacobian : jacobians) jacobian_pointers.push_back(jacobian.data());
    long long passes = 0;
    const auto start = Clock::now();
    double elapsed = 0.0;
    do {
      for (std::size_t k = 0; k < functions_.size(); ++k) {
        functions_[k]->Evaluate(parameters_[k].data(), residuals.data(), jacobian_pointers.data());
        *checksum += residuals[0] + jacobians[0][0];
      }
      ++passes;
      elapsed = bench::secondsSince(start);
    } while (elapsed < min_seconds);
    return 1e9 * elapsed / static_cast<double>(passes);
  }

 private:
  const double* ambientOf(const Values& values, Key key) {
    auto [it, inserted] = ambient_.try_emplace(key);
    if (inserted) {
      it->second.resize(ambientDim(values.type(key)));
      values.toAmbient(key, it->second.data());
    }
    return it->second.data();
  }

  std::unordered_map<Key, std::vector<double>> ambient_;
  std::vector<std::unique_ptr<FactorCostFunction>> functions_;
  std::vector<std::vector<const double*>> parameters_;
  long long rows_ = 0;
  int max_rows_ = 0;
};

struct BenchOptions {
  CurveSceneOptions curve_scene;
  PointSceneOptions point_scene;
  CurveBundleAdjustmentOptions curve_ba;
  int runs = 5;              ///< Timed runs; the median is reported; >= 1.
  double run_seconds = 0.5;  ///< Minimum duration of one timed run (s); > 0.
};

EvaluationSet curveFactorsAtTruth(const BenchOptions& options) {
  const CurveScene scene = makeCurveScene(options.curve_scene);
  const CurveBundleAdjustmentInput input =
      makeCurveBundleAdjustmentInput(scene, SceneStart::kTruth);
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, options.curve_ba);
  const CurveSampleCounts counts = countCurveSamples(problem.graph, problem.values);
  bench::printInt("curve_samples", counts.total());
  bench::print("curve_samples_on_field_fraction",
               static_cast<double>(counts.on_field) / std::max(1, counts.total()));
  return EvaluationSet(problem.graph, problem.values, "curve_reprojection");
}

EvaluationSet pointFactorsAtTruth(const BenchOptions& options) {
  const PointScene scene = makePointScene(options.point_scene);
  PointBundleAdjustmentInput input;
  input.camera = scene.camera;
  input.cam_from_world = scene.true_cam_from_world;
  input.points = scene.true_points;
  input.observations = scene.observations;
  const PointBundleAdjustmentProblem problem =
      buildPointBundleAdjustment(input, PointBundleAdjustmentOptions{});
  return EvaluationSet(problem.graph, problem.values, "point_reprojection");
}

int run(const BenchOptions& options) {
  std::printf(
      "# curve_factor_bench: residual + ambient Jacobians per curve sample vs per point "
      "observation\n");
  const EvaluationSet curves = curveFactorsAtTruth(options);
  const EvaluationSet points = pointFactorsAtTruth(options);
  const long long samples = curves.rows();
  const long long observations = points.rows() / 2;
  bench::printInt("curve_factors", static_cast<long long>(curves.size()));
  bench::printInt("samples_per_factor", options.curve_ba.samples_per_segment + 1);
  bench::printInt("point_observations", observations);

  double checksum = 0.0;
  std::vector<double> curve_ns;
  std::vector<double> point_ns;
  for (int r = 0; r < options.runs; ++r) {
    curve_ns.push_back(curves.nanosecondsPerPass(options.run_seconds, &checksum) / samples);
    point_ns.push_back(points.nanosecondsPerPass(options.run_seconds, &checksum) / observations);
  }
  const double curve_sample_ns = bench::median(curve_ns);
  const double point_obs_ns = bench::median(point_ns);
  bench::print("curve_ns_per_factor", curve_sample_ns * (options.curve_ba.samples_per_segment + 1));
  bench::print("curve_ns_per_sample", curve_sample_ns);
  bench::print("point_ns_per_obs", point_obs_ns);
  bench::print("curve_sample_vs_point_obs_ratio", curve_sample_ns / point_obs_ns);
  // Printed so the timing loops' results are used; the value itself means nothing.
  bench::print("checksum", checksum);
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions options;
  options.curve_scene.num_keyframes = 20;
  options.curve_scene.num_curves = 30;
  CLI::App app{"Cost of one curve-residual sample vs one point observation (with Jacobians)"};
  app.add_option("--keyframes", options.curve_scene.num_keyframes, "Keyframes of the curve scene")
      ->capture_default_str();
  app.add_option("--curves", options.curve_scene.num_curves, "Curves of the curve scene")
      ->capture_default_str();
  app.add_option("--samples", options.curve_ba.samples_per_segment,
                 "s: samples per segment and keyframe are s + 1")
      ->capture_default_str();
  app.add_option("--runs", options.runs, "Timed runs (median reported)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--run-seconds", options.run_seconds, "Minimum duration of one timed run")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(options); });
}
