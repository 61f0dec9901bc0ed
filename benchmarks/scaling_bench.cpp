// scaling_bench: how curve bundle adjustment grows with the problem. Time per Levenberg-Marquardt
// iteration and peak memory vs keyframes (10 -> 200 at 500 segments) and vs segments (100 ->
// 5,000 at 20 keyframes), on synthetic curve scenes (sim/curve_scene.h).
//
// Each configuration runs in a forked child, so that its peak resident set (ru_maxrss from
// wait4) is its own and not the high-water mark of everything measured before it. The child
// generates the scene and the nearest-edge fields, then --repeats times builds the graph and runs
// a joint solve of exactly --iterations LM iterations (tolerances no step can meet), and reports
// the solve with the median time per iteration.
// Scene generation renders images, which is not bundle-adjustment cost: it is timed apart, and
// once the fields are built the child frees the images and restarts the kernel's high-water mark
// (/proc/self/clear_refs), so "BA RSS" is the peak of what a bundle adjustment holds: fields,
// graph, values and the Ceres problem (plus the process's code and libraries).
//
// Columns: "build s" = fields + graph; "s/iteration" = Ceres' minimiser wall time / iterations
// (iteration 0's evaluation and the first symbolic factorisation included); "CPU s/iteration" =
// CPU time of the whole solve / iterations, the steadier figure on a shared machine;
// "evaluation %" and "linear solver %" = shares of the minimiser time from Ceres' FullReport;
// "final cost" = the objective after the solve (the same start and iterations must give the
// same value with every linear solver, up to the path the rough edge cost lets it take).
//
// Output: a markdown table (one row per configuration) on stdout, then `key: value` headline
// figures; one progress line per configuration on stderr; with --out, scaling.csv. Linux only
// (fork, wait4, /proc).
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/check.h"
#include "core/dense_kernels.h"
#include "core/errors.h"
#include "factors/curve_bundle_adjustment.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

using bench::Clock;

struct BenchOptions {
  std::string out;     ///< Folder for scaling.csv (created); empty writes no file.
  bool quick = false;  ///< A tiny sweep (smoke test).
  int threads = 1;     ///< Solver threads (evaluation and linear algebra); >= 1.
  std::string linear_solver = "sparse_schur";  ///< OptimizerOptions::linear_solver by name.
  int iterations = 10;                         ///< LM iterations per solve; >= 1.
  int repeats = 3;               ///< Solves per configuration; the median is reported; >= 1.
  double image_scale = 1.0;      ///< Image size relative to 640x480; in [0.25, 2].
  int segments_per_curve = 5;    ///< Cubic segments per curve; in [1, 64].
  int samples_per_segment = 10;  ///< s: s + 1 residuals per (segment, keyframe) pair; 1..64.
  int fixed_segments = 500;      ///< Segments of the keyframe sweep; >= segments_per_curve.
  int fixed_keyframes = 20;      ///< Keyframes of the segment sweep; >= 2.
  /// The sweeps' points; empty lists keep the defaults (10..200 keyframes, 100..5,000 segments).
  std::vector<int> keyframe_sweep;
  std::vector<int> segment_sweep;
  /// OptimizerOptions::curve_blocks: one solver block per curve (false: one per variable).
  bool curve_blocks = true;
  bool verbose = false;  ///< Print each solve's log (Ceres' or graph_schur's time split).
};

struct Configuration {
  std::string sweep;  ///< "keyframes" or "segments": what varies.
  int keyframes = 0;
  int segments = 0;  ///< Requested; the scene has the next multiple of segments_per_curve.
};

std::vector<Configuration> sweepConfigurations(const BenchOptions& options) {
  std::vector<int> keyframes =
      options.quick ? std::vector<int>{4, 8} : std::vector<int>{10, 25, 50, 100, 200};
  std::vector<int> segments =
      options.quick ? std::vector<int>{50, 100} : std::vector<int>{100, 500, 1000, 2500, 5000};
  if (!options.keyframe_sweep.empty()) keyframes = options.keyframe_sweep;
  if (!options.segment_sweep.empty()) segments = options.segment_sweep;
  const int fixed_segments = options.quick ? 100 : options.fixed_segments;
  const int fixed_keyframes = options.quick ? 6 : options.fixed_keyframes;
  std::vector<Configuration> configurations;
  for (int k : keyframes) configurations.push_back({"keyframes", k, fixed_segments});
  for (int s : segments) configurations.push_back({"segments", fixed_keyframes, s});
  return configurations;
}

// A 360 deg orbit of radius 3 m in a 12 x 3 x 12 m room (the layout CurveSceneOptions suggests
// for many curves): each keyframe sees about a third of the curves, so observations grow with
// both sweeps as they would in a real map, and the images stay readable at thousands of segments.
CurveSceneOptions sceneOptions(const Configuration& configuration, const BenchOptions& options) {
  CurveSceneOptions scene;
  scene.num_keyframes = configuration.keyframes;
  scene.arc_degrees = 360.0;
  scene.volume_half_extents = Eigen::Vector3d(6.0, 1.5, 6.0);
  scene.segments_per_curve = options.segments_per_curve;
  scene.num_curves =
      (configuration.segments + options.segments_per_curve - 1) / options.segments_per_curve;
  // Scaling the focal lengths with the image keeps the field of view, hence the observations.
  CameraIntrinsics& camera = scene.intrinsics;
  const double s = options.image_scale;
  camera.fx *= s;
  camera.fy *= s;
  camera.cx = (camera.cx + 0.5) * s - 0.5;
  camera.cy = (camera.cy + 0.5) * s - 0.5;
  camera.width = static_cast<int>(std::lround(camera.width * s));
  camera.height = static_cast<int>(std::lround(camera.height * s));
  return scene;
}

// One fixed-iteration solve, from OptimizationSummary and Ceres' FullReport.
struct SolveFigures {
  char ordering[128] = {};     ///< Schur ordering the optimiser asked for (OptimizationSummary).
  char schur_blocks[32] = {};  ///< Ceres' "e,f": eliminated and reduced parameter blocks.
  int effective_parameters = 0;
  int iterations = 0;
  /// Accepted LM steps; a rejected one evaluates residuals only and solves again.
  int successful_steps = 0;
  double setup_seconds = 0.0;          ///< Graph to Ceres problem.
  double solve_seconds = 0.0;          ///< ceres::Solve wall time (preprocessing included).
  double minimizer_seconds = 0.0;      ///< Ceres' minimiser: iteration 0 and the iterations.
  double evaluation_seconds = 0.0;     ///< Residual and Jacobian evaluation in the minimiser.
  double linear_solver_seconds = 0.0;  ///< Linear solves (Schur elimination, factorisation).
  /// CPU time of the process over the whole schedule (setup and preprocessing included): on a
  /// loaded machine the wall times above grow, this hardly does.
  double cpu_seconds = 0.0;
  /// The objective after the solve: the same start and iterations must end at the same value
  /// whichever solver ran them.
  double final_cost = 0.0;

  double secondsPerIteration() const {
    return iterations > 0 ? minimizer_seconds / iterations : 0.0;
  }
  double cpuSecondsPerIteration() const { return iterations > 0 ? cpu_seconds / iterations : 0.0; }
  double percentOfMinimizer(double seconds) const {
    return minimizer_seconds > 0.0 ? 100.0 * seconds / minimizer_seconds : 0.0;
  }
};

// What a child measures. Plain bytes, so it crosses the pipe as it is.
struct Measurement {
  bool ok = false;
  char error[512] = {};
  int keyframes = 0;
  int segments = 0;            ///< Segments of the scene's curves.
  int observed_segments = 0;   ///< Segments with at least one observation.
  int observations = 0;        ///< Curve reprojection factors.
  int samples = 0;             ///< Curve samples (residuals of those factors).
  int samples_on_field = 0;    ///< Samples within the field's reach at the start.
  int factors = 0;             ///< All factors (regularisers and gauge included).
  double scene_seconds = 0.0;  ///< makeCurveScene (rendering): not bundle-adjustment cost.
  double field_seconds = 0.0;  ///< NearestEdgeField::build over all keyframes.
  double graph_seconds = 0.0;  ///< buildCurveBundleAdjustment (median over repeats).
  SolveFigures solve;          ///< The repeat with the median time per iteration.
  double field_bytes = 0.0;    ///< NearestEdgeField::memoryBytes summed.
  double ba_peak_kib = -1.0;   ///< Peak RSS after the scene was freed; < 0 if unavailable.
  /// Peak RSS before that restart (scene generation); restarting also resets what wait4
  /// reports, so the parent needs this to know the peak of the child's whole life.
  double scene_peak_kib = 0.0;
};

void copyText(const std::string& text, char* buffer, std::size_t size) {
  std::snprintf(buffer, size, "%s", text.c_str());
}

// "VmHWM" (peak) or "VmRSS" (current) of this process in KiB, from /proc/self/status; -1 if
// absent.
double procStatusKib(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  }
  return -1.0;
}

// Gives freed memory back to the kernel and restarts its high-water mark at the current RSS
// (Linux >= 4.0); false if the kernel refuses.
bool restartPeakRss() {
  malloc_trim(0);
  std::ofstream clear_refs("/proc/self/clear_refs");
  clear_refs << "5";
  clear_refs.close();
  return static_cast<bool>(clear_refs);
}

double processCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// The words after `label` on its line of Ceres' FullReport; `label` starts with the newline
// and the indentation, which tell the timing "  Linear solver   0.123 (5)" from the setting
// "Linear solver   SPARSE_SCHUR ..."; empty if absent.
std::vector<std::string> reportWords(const std::string& full_report, const std::string& label) {
  const std::size_t at = full_report.find(label);
  if (at == std::string::npos) return {};
  const std::size_t begin = at + label.size();
  std::istringstream line(full_report.substr(begin, full_report.find('\n', begin) - begin));
  std::vector<std::string> words;
  for (std::string word; line >> word;) words.push_back(word);
  return words;
}

double reportNumber(const std::string& full_report, const std::string& label) {
  const std::vector<std::string> words = reportWords(full_report, label);
  return words.empty() ? 0.0 : std::atof(words.front().c_str());
}

std::vector<std::shared_ptr<const NearestEdgeField>> buildFields(const CurveScene& scene,
                                                                 double* bytes) {
  std::vector<std::shared_ptr<const NearestEdgeField>> fields = buildKeyframeFields(scene);
  *bytes = 0.0;
  for (const auto& field : fields) *bytes += static_cast<double>(field->memoryBytes());
  return fields;
}

void countScene(const CurveScene& scene, Measurement* m) {
  m->keyframes = static_cast<int>(scene.keyframes.size());
  for (const PolyBezier& curve : scene.true_curves) m->segments += curve.numSegments();
  std::set<std::pair<int, int>> observed;
  for (const CurveObservation& obs : scene.observations) {
    observed.emplace(obs.curve_index, obs.segment_index);
  }
  m->observed_segments = static_cast<int>(observed.size());
}

void countProblem(const CurveBundleAdjustmentProblem& problem, Measurement* m) {
  m->factors = static_cast<int>(problem.graph.size());
  for (const auto& factor : problem.graph) {
    if (std::strcmp(factor->typeName(), "curve_reprojection") == 0) ++m->observations;
  }
  const CurveSampleCounts samples = countCurveSamples(problem.graph, problem.values);
  m->samples = samples.total();
  m->samples_on_field = samples.on_field;
}

// Exactly `iterations` LM iterations: tolerances no real step can meet.
SchedulerOptions fixedIterationSolve(const BenchOptions& options) {
  SchedulerOptions scheduler;
  scheduler.strategy = Strategy::kJoint;
  OptimizerOptions& optimizer = scheduler.optimizer;
  optimizer.linear_solver =
      parseEnumName<LinearSolver>(options.linear_solver, "OptimizerOptions", "linear_solver");
  optimizer.max_iterations = options.iterations;
  optimizer.num_threads = options.threads;
  optimizer.curve_blocks = options.curve_blocks;
  optimizer.verbose = options.verbose;
  optimizer.function_tolerance = 1e-300;
  optimizer.gradient_tolerance = 1e-300;
  optimizer.parameter_tolerance = 1e-300;
  return scheduler;
}

SolveFigures solveFigures(const OptimizationSummary& summary) {
  SolveFigures f;
  const std::string& report = summary.full_report;
  copyText(summary.ordering, f.ordering, sizeof(f.ordering));
  const std::vector<std::string> ordering = reportWords(report, "\nLinear solver ordering");
  if (!ordering.empty()) copyText(ordering.back(), f.schur_blocks, sizeof(f.schur_blocks));
  f.effective_parameters = summary.num_effective_parameters;
  f.iterations = summary.iterations;
  f.final_cost = summary.final_cost;
  // Ceres counts iteration 0, the starting point, as a successful step.
  f.successful_steps =
      std::max(0, static_cast<int>(reportNumber(report, "\nSuccessful steps")) - 1);
  f.setup_seconds = summary.setup_seconds;
  f.solve_seconds = summary.solve_seconds;
  f.minimizer_seconds = summary.minimizer_seconds;
  f.evaluation_seconds = reportNumber(report, "\n  Residual only evaluation") +
                         reportNumber(report, "\n  Jacobian & residual evaluation");
  f.linear_solver_seconds = reportNumber(report, "\n  Linear solver");
  return f;
}

// `repeats` solves from the same start, each on a freshly built problem (so the graph's build
// is timed as often); returns the solve with the median time per iteration, whose figures stay
// consistent with each other.
SolveFigures medianSolve(const CurveBundleAdjustmentInput& input, const BenchOptions& options,
                         Measurement* m) {
  CurveBundleAdjustmentOptions ba;
  ba.samples_per_segment = options.samples_per_segment;
  std::vector<SolveFigures> solves;
  std::vector<double> build_seconds;
  for (int r = 0; r < options.repeats; ++r) {
    const auto start = Clock::now();
    CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, ba);
    build_seconds.push_back(bench::secondsSince(start));
    if (r == 0) countProblem(problem, m);
    const double cpu_start = processCpuSeconds();
    const ScheduleReport report =
        runSchedule(problem.graph, &problem.values, problem.config, fixedIterationSolve(options));
    const double cpu_seconds = processCpuSeconds() - cpu_start;
    if (report.rounds.empty()) throw std::runtime_error("the schedule ran no solve");
    solves.push_back(solveFigures(report.rounds.front().summary));
    solves.back().cpu_seconds = cpu_seconds;
  }
  m->graph_seconds = bench::median(build_seconds);
  std::sort(solves.begin(), solves.end(), [](const SolveFigures& a, const SolveFigures& b) {
    return a.secondsPerIteration() < b.secondsPerIteration();
  });
  return solves[solves.size() / 2];
}

// The child's work. The scene is a local that dies, images and all, before the peak restarts.
Measurement measure(const Configuration& configuration, const BenchOptions& options) {
  Measurement m;
  CurveBundleAdjustmentInput input;
  {
    auto start = Clock::now();
    const CurveScene scene = makeCurveScene(sceneOptions(configuration, options));
    m.scene_seconds = bench::secondsSince(start);
    countScene(scene, &m);
    start = Clock::now();
    input = makeCurveBundleAdjustmentInput(scene, buildFields(scene, &m.field_bytes));
    m.field_seconds = bench::secondsSince(start);
  }
  m.scene_peak_kib = procStatusKib("VmHWM");
  const bool peak_restarted = restartPeakRss();
  m.solve = medianSolve(input, options, &m);
  if (peak_restarted) m.ba_peak_kib = procStatusKib("VmHWM");
  m.ok = true;
  return m;
}

void writeAll(int fd, const void* data, std::size_t size) {
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = write(fd, bytes, size);
    if (n <= 0) return;  // The parent reports the short read.
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
}

bool readAll(int fd, void* data, std::size_t size) {
  char* bytes = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = read(fd, bytes, size);
    if (n <= 0) return false;
    bytes += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Runs in the child and never returns: an exception must not unwind into the parent's sweep.
[[noreturn]] void childMain(int fd, const Configuration& configuration,
                            const BenchOptions& options) {
  Measurement m;
  try {
    m = measure(configuration, options);
  } catch (const std::exception& e) {
    copyText(e.what(), m.error, sizeof(m.error));
  } catch (...) {
    copyText("unknown exception", m.error, sizeof(m.error));
  }
  writeAll(fd, &m, sizeof(m));
  std::fflush(stdout);  // _exit drops buffered output: --verbose's logs when stdout is a file.
  _exit(0);  // Skips destructors of large problems and the parent's atexit handlers.
}

struct Row {
  Configuration configuration;
  Measurement m;
  double peak_rss_kib = 0.0;  ///< Peak RSS of the child's whole life, scene included.
};

std::string describe(const Configuration& c) {
  return c.sweep + " sweep, " + std::to_string(c.keyframes) + " keyframes, " +
         std::to_string(c.segments) + " segments";
}

Row runIsolated(const Configuration& configuration, const BenchOptions& options) {
  std::fflush(stdout);  // Or the child would flush the parent's buffered output again.
  std::fflush(stderr);
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe: " + std::string(std::strerror(errno)));
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork: " + std::string(std::strerror(errno)));
  if (pid == 0) {
    close(fds[0]);
    childMain(fds[1], configuration, options);
  }
  close(fds[1]);
  Row row{configuration, {}, 0.0};
  const bool complete = readAll(fds[0], &row.m, sizeof(row.m));
  close(fds[0]);
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) {
    throw std::runtime_error("wait4: " + std::string(std::strerror(errno)));
  }
  if (!complete || !WIFEXITED(status)) {
    const std::string how = WIFSIGNALED(status)
                                ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                : "ended without a result";
    throw std::runtime_error(describe(configuration) + ": the child " + how);
  }
  if (!row.m.ok) throw std::runtime_error(describe(configuration) + ": " + row.m.error);
  // ru_maxrss (KiB on Linux) covers what followed the child's restart of its high-water mark.
  row.peak_rss_kib = std::max(static_cast<double>(usage.ru_maxrss), row.m.scene_peak_kib);
  return row;
}

double mib(double kib) { return kib / 1024.0; }

constexpr const char* kTableHeader =
    "| sweep | keyframes | segments | observations | samples | scene s | build s | s/iteration | "
    "CPU s/iteration | "
    "evaluation % | linear solver % | peak RSS MiB | BA RSS MiB | fields MiB | final cost |\n"
    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";

std::string tableRow(const Row& row) {
  const Measurement& m = row.m;
  const SolveFigures& solve = m.solve;
  char ba_rss[32] = "n/a";
  if (m.ba_peak_kib >= 0.0) std::snprintf(ba_rss, sizeof(ba_rss), "%.0f", mib(m.ba_peak_kib));
  char line[512];
  std::snprintf(
      line, sizeof(line),
      "| %s | %d | %d | %d | %d | %.2f | %.2f | %.3f | %.3f | %.0f | %.0f | %.0f | %s | %.0f | "
      "%.6g |",
      row.configuration.sweep.c_str(), m.keyframes, m.segments, m.observations, m.samples,
      m.scene_seconds, m.field_seconds + m.graph_seconds, solve.secondsPerIteration(),
      solve.cpuSecondsPerIteration(), solve.percentOfMinimizer(solve.evaluation_seconds),
      solve.percentOfMinimizer(solve.linear_solver_seconds), mib(row.peak_rss_kib), ba_rss,
      mib(m.field_bytes / 1024.0), solve.final_cost);
  return line;
}

void writeCsv(const std::vector<Row>& rows, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "sweep,keyframes,segments,observed_segments,observations,samples,samples_on_field,"
         "factors,effective_parameters,schur_blocks,iterations,successful_steps,scene_seconds,"
         "field_seconds,graph_seconds,setup_seconds,solve_seconds,minimizer_seconds,"
         "seconds_per_iteration,cpu_seconds,evaluation_seconds,linear_solver_seconds,peak_rss_mib,"
         "ba_peak_rss_mib,field_mib,final_cost,ordering\n";
  for (const Row& row : rows) {
    const Measurement& m = row.m;
    const SolveFigures& solve = m.solve;
    out << row.configuration.sweep << "," << m.keyframes << "," << m.segments << ","
        << m.observed_segments << "," << m.observations << "," << m.samples << ","
        << m.samples_on_field << "," << m.factors << "," << solve.effective_parameters << ",\""
        << solve.schur_blocks << "\"," << solve.iterations << "," << solve.successful_steps << ","
        << m.scene_seconds << "," << m.field_seconds << "," << m.graph_seconds << ","
        << solve.setup_seconds << "," << solve.solve_seconds << "," << solve.minimizer_seconds
        << "," << solve.secondsPerIteration() << "," << solve.cpu_seconds << ","
        << solve.evaluation_seconds << "," << solve.linear_solver_seconds << ","
        << mib(row.peak_rss_kib) << "," << mib(m.ba_peak_kib) << "," << mib(m.field_bytes / 1024.0)
        << "," << solve.final_cost << ",\"" << solve.ordering << "\"\n";
  }
}

// Least-squares slope of y over x; NaN for fewer than two distinct x.
double slope(const std::vector<std::pair<double, double>>& points) {
  double mean_x = 0.0;
  double mean_y = 0.0;
  for (const auto& [x, y] : points) {
    mean_x += x / points.size();
    mean_y += y / points.size();
  }
  double covariance = 0.0;
  double variance = 0.0;
  for (const auto& [x, y] : points) {
    covariance += (x - mean_x) * (y - mean_y);
    variance += (x - mean_x) * (x - mean_x);
  }
  return variance > 0.0 ? covariance / variance : std::numeric_limits<double>::quiet_NaN();
}

// Slope of log(CPU s/iteration) over log(keyframes or segments) within one sweep: 1 is linear.
// CPU time, because wall times on a shared machine swing with the load.
double cpuTimeExponent(const std::vector<Row>& rows, const std::string& sweep) {
  std::vector<std::pair<double, double>> points;
  for (const Row& row : rows) {
    const double x = sweep == "keyframes" ? row.m.keyframes : row.m.segments;
    const double y = row.m.solve.cpuSecondsPerIteration();
    if (row.configuration.sweep == sweep && y > 0.0) {
      points.emplace_back(std::log(x), std::log(y));
    }
  }
  return slope(points);
}

// Memory beyond the fields per curve observation (KiB): the slope of BA RSS minus the fields
// over the observation count, all rows; the constant part (code, libraries) drops out.
double kibPerObservation(const std::vector<Row>& rows) {
  std::vector<std::pair<double, double>> points;
  for (const Row& row : rows) {
    if (row.m.ba_peak_kib < 0.0) continue;
    points.emplace_back(row.m.observations, row.m.ba_peak_kib - row.m.field_bytes / 1024.0);
  }
  return slope(points);
}

// The last row of a sweep is its largest configuration.
const Row& largest(const std::vector<Row>& rows, const std::string& sweep) {
  const Row* last = nullptr;
  for (const Row& row : rows) {
    if (row.configuration.sweep == sweep) last = &row;
  }
  CURVESFM_CHECK(last != nullptr) << "no row in the " << sweep << " sweep";
  return *last;
}

void printHeadline(const std::vector<Row>& rows) {
  for (const std::string sweep : {"keyframes", "segments"}) {
    const Row& row = largest(rows, sweep);
    const SolveFigures& solve = row.m.solve;
    bench::print("time_per_iteration_s_max_" + sweep, solve.secondsPerIteration());
    bench::print("us_per_sample_iteration_max_" + sweep,
                 1e6 * solve.secondsPerIteration() / std::max(1, row.m.samples));
    bench::print("peak_rss_mib_max_" + sweep, mib(row.peak_rss_kib));
    bench::print("ba_peak_rss_mib_max_" + sweep, mib(row.m.ba_peak_kib));
    bench::printText("schur_blocks_max_" + sweep, solve.schur_blocks);
    bench::print("cpu_time_per_iteration_s_max_" + sweep, solve.cpuSecondsPerIteration());
    bench::print("cpu_time_per_iteration_exponent_vs_" + sweep, cpuTimeExponent(rows, sweep));
    bench::print("final_cost_max_" + sweep, solve.final_cost);
  }
  bench::print("ba_kib_per_observation_beyond_fields", kibPerObservation(rows));
  bench::printText("ordering", rows.back().m.solve.ordering);
}

void printSettings(const BenchOptions& options) {
  const CurveSceneOptions scene = sceneOptions({"keyframes", 2, 1}, options);
  std::printf(
      "# scaling_bench: images %dx%d, 360 deg orbit (r = 3 m) in a 12 x 3 x 12 m room, %d "
      "segments per curve, %d samples per observation; joint solves of %d LM iterations (median of "
      "%d), %s, %d solver thread(s), %s, dense kernels %s; each configuration in its own "
      "process\n\n",
      scene.intrinsics.width, scene.intrinsics.height, options.segments_per_curve,
      options.samples_per_segment + 1, options.iterations, options.repeats,
      options.linear_solver.c_str(), options.threads,
      options.curve_blocks ? "a block per curve" : "a block per variable", dense::kernelVariant());
}

int run(const BenchOptions& options) {
  // Bad flags and an unwritable --out fail before the first fork, not minutes later.
  fixedIterationSolve(options).validate();
  const std::filesystem::path csv = std::filesystem::path(options.out) / "scaling.csv";
  if (!options.out.empty()) std::filesystem::create_directories(options.out);
  const auto start = Clock::now();
  printSettings(options);
  std::printf("%s", kTableHeader);
  std::vector<Row> rows;
  const std::vector<Configuration> configurations = sweepConfigurations(options);
  for (const Configuration& configuration : configurations) {
    rows.push_back(runIsolated(configuration, options));
    const Row& row = rows.back();
    std::printf("%s\n", tableRow(row).c_str());
    std::fprintf(stderr, "[%zu/%zu] %s: %.3f s/iteration, peak RSS %.0f MiB, %.0f s so far\n",
                 rows.size(), configurations.size(), describe(configuration).c_str(),
                 row.m.solve.secondsPerIteration(), mib(row.peak_rss_kib),
                 bench::secondsSince(start));
  }
  std::printf("\n");
  printHeadline(rows);
  if (!options.out.empty()) {
    writeCsv(rows, csv);
    bench::printText("csv", csv.string());
  }
  bench::print("total_seconds", bench::secondsSince(start));
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions options;
  CLI::App app{"Curve BA scaling: time per LM iteration and peak memory vs keyframes and segments"};
  app.add_option("--out", options.out, "Folder for scaling.csv (none if empty)");
  app.add_flag("--quick", options.quick, "A tiny sweep (smoke test)");
  app.add_option("--threads", options.threads, "Solver threads")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option(
         "--linear-solver", options.linear_solver,
         "sparse_schur, dense_schur, iterative_schur, sparse_normal_cholesky or graph_schur "
         "(our own Schur complement)")
      ->capture_default_str();
  app.add_option("--iterations", options.iterations, "LM iterations per solve")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--repeats", options.repeats, "Solves per configuration (median reported)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--image-scale", options.image_scale, "Image size relative to 640x480")
      ->check(CLI::Range(0.25, 2.0))
      ->capture_default_str();
  app.add_option("--segments-per-curve", options.segments_per_curve, "Cubic segments per curve")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--samples-per-segment", options.samples_per_segment,
                 "s: s + 1 residuals per observation")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--fixed-segments", options.fixed_segments, "Segments of the keyframe sweep")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--fixed-keyframes", options.fixed_keyframes, "Keyframes of the segment sweep")
      ->check(CLI::Range(2, 10000))
      ->capture_default_str();
  app.add_option("--keyframe-sweep", options.keyframe_sweep,
                 "Keyframe counts of the keyframe sweep (default 10 25 50 100 200)")
      ->check(CLI::Range(2, 10000));
  app.add_option("--segment-sweep", options.segment_sweep,
                 "Segment counts of the segment sweep (default 100 500 1000 2500 5000)")
      ->check(CLI::Range(1, 100000));
  app.add_flag("--verbose", options.verbose, "Print each solve's log and time split");
  app.add_option("--curve-blocks", options.curve_blocks,
                 "One solver block per curve (false: one per variable, the old layout)")
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(options); });
}
