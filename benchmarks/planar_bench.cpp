// planar_bench: the paper's planar experiment (§4.1, Table 2) as one command.
//
// Nine photographs from OpenCV's sample data (--data-dir), three per category as in the paper
// (logos, indoor, outdoor), are each laid on a plane and viewed from an orbit above it
// (sim/planar_scene.h: homography rendering, per-pixel Gaussian intensity noise of P % of 255,
// initial poses perturbed by --init-translation / --init-rotation-deg). Every photo x noise
// P in {0, 5, 10, 15, 20} runs the whole incremental pipeline (frontend/pipeline.h, one thread)
// and its global BA. Every pipeline option is a flag named as in `curvesfm run` (`--ba-*`,
// `--local-ba-*`, ...; `--config FILE.yaml` takes run's config.yaml), so variants compare with one
// command; `--photos` and `--noise` pick a subset of the cases. The refined and the initial
// keyframe trajectories are compared with the true poses of the same keyframes after a Sim(3)
// Umeyama alignment (ATE = RMS camera-centre error, mm).
//
// A photo that is missing or unreadable is skipped with a message on stdout and stderr; no
// photo at all is an error (exit 1). A case whose pipeline throws is recorded as failed (its
// message in the table and CSV) and counts as not improved.
//
// Writes into --out: runs.csv (one row per case, per-stage timings included), paper_table2.csv
// (the paper's figures), summary.md (the table, the paper's Table 2 beside ours, stage timings),
// config.yaml (every flag in force, for --config), and through `python3 -m curvesfm_plots
// planar-bench` (when matplotlib is there) ate_ratio_vs_noise.{png,pdf} and
// ate_vs_noise.{png,pdf}. Prints the table and `key: value` headline lines; progress on stderr.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "apps/cli/cli_options.h"
#include "apps/cli/config_file.h"
#include "apps/cli/option_tables.h"
#include "apps/cli/plot_scripts.h"
#include "benchmarks/support/bench_common.h"
#include "benchmarks/support/planar_photos.h"
#include "core/errors.h"
#include "core/trajectory_evaluation.h"
#include "frontend/mapping/pipeline.h"
#include "sim/planar_scene.h"

namespace curvesfm {
namespace {

using Photo = bench::PlanarPhoto;
const std::vector<Photo>& kPhotos = bench::planarPhotos();
const std::vector<int> kNoisePercents = {0, 5, 10, 15, 20};

// The paper's Table 2 ("average position error of our method", converted from m to mm): rows
// logos, indoor, outdoor, overall; columns noise 0, 5, 10, 15, 20 %.
const std::array<std::array<double, 5>, 4> kPaperTable2Mm = {{{0.415, 0.312, 0.458, 3.5, 11.1},
                                                              {0.533, 0.533, 0.459, 1.4, 4.6},
                                                              {0.885, 1.5, 1.53, 4.2, 6.8},
                                                              {0.611, 0.798, 0.812, 3.0, 7.5}}};

struct BenchOptions {
  std::string data_dir = bench::kOpenCvSampleData;                   ///< Folder of the photos.
  std::string out = "bench_out/planar";                              ///< Output folder (created).
  int frames = 30;  ///< Rendered views per case; >= 3.
  // The initial pose error; sim/planar_scene.h's defaults, as `curvesfm synth planar`.
  InitNoiseModel init_noise_model = PlanarSceneOptions().init_noise_model;
  double init_translation_m = PlanarSceneOptions().init_noise_translation;  ///< Per axis (m).
  double init_rotation_deg = PlanarSceneOptions().init_noise_rotation_deg;  ///< Per axis (deg).
  bool quick = false;               ///< 2 photos x 2 noise levels x 10 frames.
  std::vector<std::string> photos;  ///< File names of kPhotos to run; empty runs all.
  std::vector<int> noise_percents = kNoisePercents;  ///< Intensity noise levels to run (%).
  PipelineOptions pipeline;                          ///< Every case's pipeline.
  /// Cases run at once, one thread each (each case is single-threaded); per-stage times are
  /// wall times, so more jobs than idle cores inflate them.
  int jobs = 1;
};

struct LoadedPhoto {
  Photo photo;
  int index = 0;  ///< Position in kPhotos (fixes the seeds).
  cv::Mat image;  ///< CV_8UC3: the pipeline takes colour frames.
};

// Mean per-keyframe wall time of each stage (ms), in KeyframeStats order.
struct CaseResult {
  std::string photo;
  std::string category;
  int noise_percent = 0;
  unsigned seed = 0;
  int frames = 0;
  int keyframes = 0;
  int global_curves = 0;
  double initial_ate_mm = std::nan("");
  double refined_ate_mm = std::nan("");
  KeyframeTimes stages;  ///< Per keyframe.
  double global_ba_seconds = 0.0;
  double case_seconds = 0.0;
  std::string error;  ///< Empty unless the pipeline threw.

  bool ok() const { return error.empty(); }
  bool improved() const { return ok() && refined_ate_mm < initial_ate_mm; }
  double ratio() const { return refined_ate_mm / initial_ate_mm; }
};

std::string photoNames() {
  std::string names;
  for (const Photo& photo : kPhotos) names += (names.empty() ? "" : ", ") + photo.file;
  return names;
}

std::vector<LoadedPhoto> loadPhotos(const BenchOptions& options) {
  std::vector<LoadedPhoto> loaded;
  for (std::size_t i = 0; i < kPhotos.size(); ++i) {
    if (!options.photos.empty() && std::find(options.photos.begin(), options.photos.end(),
                                             kPhotos[i].file) == options.photos.end())
      continue;
    const std::string path = options.data_dir + "/" + kPhotos[i].file;
    const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
    if (image.empty()) {
      std::printf("# skipped %s: not found or not readable\n", path.c_str());
      std::fprintf(stderr, "skipped %s: not found or not readable\n", path.c_str());
      continue;
    }
    loaded.push_back({kPhotos[i], static_cast<int>(i), image});
  }
  if (loaded.empty()) throw IoError(options.data_dir, "none of the benchmark photos is readable");
  return loaded;
}

// Runs the pipeline over the scene; fills keyframe counts, ATEs and timings of `result`.
void runPipeline(const PlanarScene& scene, const PipelineOptions& options, CaseResult* result) {
  Pipeline pipeline(*scene.camera, options);
  std::vector<KeyframeStats> keyframes;
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    const KeyframeStats stats =
        pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
    if (stats.keyframe_index >= 0) keyframes.push_back(stats);
  }
  const PipelineResult out = pipeline.finish();
  if (keyframes.size() != out.keyframe_cam_from_world.size() || keyframes.size() < 3)
    throw Error("expected >= 3 keyframes with stats, got " + std::to_string(keyframes.size()) +
                " stats for " + std::to_string(out.keyframe_cam_from_world.size()) + " poses");
  std::vector<Pose3> truth;
  for (const KeyframeStats& k : keyframes)
    truth.push_back(scene.true_cam_from_world[k.frame_index]);
  result->keyframes = static_cast<int>(keyframes.size());
  result->global_curves = static_cast<int>(out.curves.size());
  result->initial_ate_mm =
      1e3 * evaluateTrajectory(truth, out.keyframe_initial_cam_from_world).position_ate_sim3;
  result->refined_ate_mm =
      1e3 * evaluateTrajectory(truth, out.keyframe_cam_from_world).position_ate_sim3;
  result->stages = keyframeTimes(keyframes);
  result->global_ba_seconds = out.globalBaSeconds();
}

CaseResult runCase(const LoadedPhoto& photo, int noise_percent, const BenchOptions& options) {
  CaseResult result;
  result.photo = photo.photo.file;
  result.category = photo.photo.category;
  result.noise_percent = noise_percent;
  result.seed = static_cast<unsigned>(1 + 100 * photo.index + noise_percent);
  result.frames = options.frames;
  PlanarSceneOptions scene_options;
  scene_options.num_frames = options.frames;
  scene_options.intensity_noise = noise_percent / 100.0;
  scene_options.seed = result.seed;
  scene_options.init_noise_model = options.init_noise_model;
  scene_options.init_noise_translation = options.init_translation_m;
  scene_options.init_noise_rotation_deg = options.init_rotation_deg;
  const auto start = bench::Clock::now();
  try {
    runPipeline(makePlanarScene(photo.image, scene_options), options.pipeline, &result);
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  result.case_seconds = bench::secondsSince(start);
  return result;
}

void printProgress(const CaseResult& r, int done, int total) {
  if (!r.ok()) {
    std::fprintf(stderr, "[%d/%d] %s (%s) noise %d %%: FAILED: %s (%.1f s)\n", done, total,
                 r.photo.c_str(), r.category.c_str(), r.noise_percent, r.error.c_str(),
                 r.case_seconds);
    return;
  }
  std::fprintf(stderr,
               "[%d/%d] %s (%s) noise %d %%: %d kf, %d curves, ATE %.2f -> %.2f mm, frontend "
               "%.1f ms/kf, local BA %.1f ms/kf, global BA %.1f s, %.1f s\n",
               done, total, r.photo.c_str(), r.category.c_str(), r.noise_percent, r.keyframes,
               r.global_curves, r.initial_ate_mm, r.refined_ate_mm, r.stages.frontend_ms,
               r.stages.local_ba_ms, r.global_ba_seconds, r.case_seconds);
}

void writeCsv(const std::vector<CaseResult>& results, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "photo,category,noise_percent,seed,frames,keyframes,global_curves,initial_ate_mm,"
         "refined_ate_mm,ratio,improved,undistort_ms,edges_ms,field_ms,depth_ms,"
         "correspondence_ms,initialise_ms,frontend_ms,local_ba_ms,global_ba_s,case_s,error\n";
  for (const CaseResult& r : results) {
    const KeyframeTimes& s = r.stages;
    out << r.photo << "," << r.category << "," << r.noise_percent << "," << r.seed << ","
        << r.frames << "," << r.keyframes << "," << r.global_curves << "," << r.initial_ate_mm
        << "," << r.refined_ate_mm << "," << r.ratio() << "," << (r.improved() ? 1 : 0) << ","
        << s.undistort_ms << "," << s.edges_ms << "," << s.field_ms << "," << s.depth_ms << ","
        << s.correspondence_ms << "," << s.initialise_ms << "," << s.frontend_ms << ","
        << s.local_ba_ms << "," << r.global_ba_seconds << "," << r.case_seconds << ",\"" << r.error
        << "\"\n";
  }
}

std::string tableRow(const CaseResult& r) {
  char line[512];
  if (!r.ok()) {
    std::snprintf(line, sizeof(line), "| %s | %s | %d | failed: %s | | | | | | |", r.photo.c_str(),
                  r.category.c_str(), r.noise_percent, r.error.c_str());
    return line;
  }
  std::snprintf(line, sizeof(line),
                "| %s | %s | %d | %.2f | %.2f | %.2f%s | %d | %d | %.1f | %.1f |", r.photo.c_str(),
                r.category.c_str(), r.noise_percent, r.initial_ate_mm, r.refined_ate_mm, r.ratio(),
                r.improved() ? "" : " (not improved)", r.keyframes, r.global_curves,
                r.stages.frontend_ms, r.stages.local_ba_ms);
  return line;
}

std::string casesTable(const std::vector<CaseResult>& results) {
  std::ostringstream out;
  out << "| photo | category | noise % | initial ATE (mm) | refined ATE (mm) | refined / initial "
         "| keyframes | global curves | frontend ms/kf | local BA ms/kf |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const CaseResult& r : results) out << tableRow(r) << "\n";
  return out.str();
}

// Mean of `value` over the successful cases of `category` ("" for all) at `noise_percent`; NaN
// when there is none.
template <class Value>
double categoryMean(const std::vector<CaseResult>& results, const std::string& category,
                    int noise_percent, Value value) {
  double sum = 0.0;
  int count = 0;
  for (const CaseResult& r : results) {
    if (!r.ok() || r.noise_percent != noise_percent) continue;
    if (!category.empty() && r.category != category) continue;
    sum += value(r);
    ++count;
  }
  return count == 0 ? std::nan("") : sum / count;
}

std::string formatMm(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), std::isnan(value) ? "-" : "%.3g", value);
  return text;
}

// Our per-category means in the layout of the paper's Table 2, each cell "ours (paper)".
std::string table2Comparison(const std::vector<CaseResult>& results) {
  std::ostringstream out;
  out << "| ATE (mm), ours (paper) | 0 % | 5 % | 10 % | 15 % | 20 % |\n|---|---|---|---|---|---|\n";
  const std::vector<std::string> rows = {"logo", "indoor", "outdoor", ""};
  for (std::size_t row = 0; row < rows.size(); ++row) {
    out << "| " << (rows[row].empty() ? "overall" : rows[row]) << " |";
    for (std::size_t col = 0; col < kNoisePercents.size(); ++col) {
      const double ours = categoryMean(results, rows[row], kNoisePercents[col],
                                       [](const CaseResult& r) { return r.refined_ate_mm; });
      out << " " << formatMm(ours) << " (" << formatMm(kPaperTable2Mm[row][col]) << ") |";
    }
    out << "\n";
  }
  return out.str();
}

std::string stageTable(const std::vector<CaseResult>& results) {
  std::ostringstream out;
  out << "| photo | noise % | undistort | edges | field | depth | correspondence | initialise | "
         "frontend | local BA | global BA (s) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const CaseResult& r : results) {
    if (!r.ok()) continue;
    const KeyframeTimes& s = r.stages;
    std::snprintf(line, sizeof(line),
                  "| %s | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f |\n",
                  r.photo.c_str(), r.noise_percent, s.undistort_ms, s.edges_ms, s.field_ms,
                  s.depth_ms, s.correspondence_ms, s.initialise_ms, s.frontend_ms, s.local_ba_ms,
                  r.global_ba_seconds);
    out << line;
  }
  return out.str();
}

void writeSummary(const std::vector<CaseResult>& results, const BenchOptions& options,
                  const std::string& command, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "# Planar experiment (paper §4.1, Table 2)\n\nCommand: `" << command << "`\n\n"
      << "Each photo lies on a plane viewed from " << options.frames
      << " frames of an orbit (640x480, sim/planar_scene.h defaults); per-pixel Gaussian "
         "intensity noise of P % of 255; initial poses perturbed by "
      << options.init_translation_m << " m / " << options.init_rotation_deg << " deg per axis "
      << (options.init_noise_model == InitNoiseModel::kDrift
              ? "per step between frames (drift: the errors accumulate as a visual odometry's)"
              : "per pose (independent errors)")
      << ". The pipeline runs on one thread with the options in config.yaml beside this file. "
         "ATE: RMS "
         "camera-centre error of the keyframes after a Sim(3) Umeyama alignment to their true "
         "poses.\n\n## Every case\n\n"
      << casesTable(results)
      << "\n## Beside the paper's Table 2\n\nMean refined ATE per category; in brackets the "
         "paper's Table 2 (\"average position error of our method\", converted to mm). The "
         "comparison is loose: the paper used other photos (TUM RGB-D indoor, KITTI outdoor, "
         "unnamed logos), and it does not give its orbit, image size, initial pose error, "
         "number of views or its error statistic; a '-' is a category without a successful "
         "case.\n\n"
      << table2Comparison(results)
      << "\n## Per-stage wall time per keyframe (ms, means over keyframes)\n\n"
      << stageTable(results);
}

// The paper's Table 2 as data beside runs.csv, for the figure that sets ours against it.
void writePaperTable(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw IoError(path.string(), "cannot open for writing");
  out << "category,noise_percent,ate_mm\n";
  const std::vector<std::string> rows = {"logo", "indoor", "outdoor", "overall"};
  for (std::size_t row = 0; row < rows.size(); ++row) {
    for (std::size_t col = 0; col < kNoisePercents.size(); ++col) {
      out << rows[row] << "," << kNoisePercents[col] << "," << kPaperTable2Mm[row][col] << "\n";
    }
  }
}

void printHeadlines(const std::vector<CaseResult>& results) {
  int improved = 0;
  std::vector<double> frontend_ms;
  std::vector<double> local_ba_ms;
  for (const CaseResult& r : results) {
    improved += r.improved() ? 1 : 0;
    if (!r.ok()) continue;
    frontend_ms.push_back(r.stages.frontend_ms);
    local_ba_ms.push_back(r.stages.local_ba_ms);
  }
  std::printf("planar_cases_improved: %d of %zu\n", improved, results.size());
  bench::printInt("planar_cases_failed",
                  static_cast<long long>(results.size() - frontend_ms.size()));
  const double max_ms =
      frontend_ms.empty() ? 0.0 : *std::max_element(frontend_ms.begin(), frontend_ms.end());
  bench::print("frontend_ms_per_keyframe_max", max_ms);
  bench::print("frontend_ms_per_keyframe_median", bench::median(frontend_ms));
  bench::print("local_ba_ms_per_keyframe_median", bench::median(local_ba_ms));
}

// The stages' medians over the cases, so the budget can be read per stage.
void printStageMedians(const std::vector<CaseResult>& results) {
  const std::vector<std::pair<std::string, double KeyframeTimes::*>> stages = {
      {"undistort", &KeyframeTimes::undistort_ms},
      {"edges", &KeyframeTimes::edges_ms},
      {"field", &KeyframeTimes::field_ms},
      {"depth", &KeyframeTimes::depth_ms},
      {"correspondence", &KeyframeTimes::correspondence_ms},
      {"initialise", &KeyframeTimes::initialise_ms}};
  for (const auto& [name, member] : stages) {
    std::vector<double> ms;
    for (const CaseResult& r : results) {
      if (r.ok()) ms.push_back(r.stages.*member);
    }
    bench::print(name + "_ms_per_keyframe_median", bench::median(ms));
  }
}

// "all" or photo file names of kPhotos; throws CLI::ValidationError naming the flag.
std::vector<std::string> parsePhotoList(const std::string& list) {
  if (list == "all") return {};
  std::vector<std::string> photos = bench::splitAtCommas(list, "--photos");
  for (const std::string& photo : photos) {
    const auto known = [&](const Photo& p) { return p.file == photo; };
    if (std::none_of(kPhotos.begin(), kPhotos.end(), known)) {
      throw CLI::ValidationError("--photos",
                                 "'" + photo + "' is not a benchmark photo (" + photoNames() + ")");
    }
  }
  return photos;
}

// Noise levels in [0, 100] %; throws CLI::ValidationError naming the flag.
std::vector<int> parseNoiseList(const std::string& list) {
  std::vector<int> levels;
  for (const std::string& item : bench::splitAtCommas(list, "--noise")) {
    std::size_t used = 0;
    int level = -1;
    try {
      level = std::stoi(item, &used);
    } catch (const std::exception&) {
    }
    if (used != item.size() || level < 0 || level > 100) {
      throw CLI::ValidationError("--noise", "'" + item + "' is not a percentage in [0, 100]");
    }
    levels.push_back(level);
  }
  return levels;
}

void writeText(const std::string& text, const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!(out << text)) throw IoError(path.string(), "cannot write");
}

int run(const BenchOptions& options, const std::string& command, const std::string& config_yaml) {
  cv::setNumThreads(1);
  const auto start = bench::Clock::now();
  const std::filesystem::path out(options.out);
  std::filesystem::create_directories(out);
  const std::vector<LoadedPhoto> photos = loadPhotos(options);
  const std::vector<int>& noises = options.noise_percents;
  std::printf("# planar_bench: %zu photos x %zu noise levels, %d frames each\n", photos.size(),
              noises.size(), options.frames);
  for (const LoadedPhoto& p : photos)
    std::printf("# photo %s: %s\n", p.photo.file.c_str(), p.photo.category.c_str());

  std::vector<std::pair<const LoadedPhoto*, int>> cases;
  for (const LoadedPhoto& photo : photos) {
    for (int noise : noises) cases.emplace_back(&photo, noise);
  }
  std::vector<CaseResult> results(cases.size());
  std::atomic<std::size_t> next{0};
  int done = 0;
  std::mutex progress;
  const auto worker = [&]() {
    for (std::size_t i = next++; i < cases.size(); i = next++) {
      results[i] = runCase(*cases[i].first, cases[i].second, options);
      const std::lock_guard<std::mutex> lock(progress);
      printProgress(results[i], ++done, static_cast<int>(cases.size()));
    }
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < options.jobs; ++j) threads.emplace_back(worker);
  worker();
  for (std::thread& thread : threads) thread.join();

  writeCsv(results, out / "runs.csv");
  writeSummary(results, options, command, out / "summary.md");
  writeText("# planar_bench: the options in force; rerun with --config " +
                (out / "config.yaml").string() + "\n" + config_yaml,
            out / "config.yaml");
  writePaperTable(out / "paper_table2.csv");
  std::printf("\n%s\n%s\n", casesTable(results).c_str(), table2Comparison(results).c_str());
  printHeadlines(results);
  printStageMedians(results);
  bench::print("total_seconds", bench::secondsSince(start));
  bench::printText("outputs",
                   (out / "{runs.csv,paper_table2.csv,summary.md,config.yaml}").string());
  // The figures come last: the data above stands without them.
  drawFiguresIfPossible({"planar-bench", out.string()});
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions options;
  CLI::App app{"The paper's planar experiment: 9 photos x 5 noise levels through the pipeline"};
  app.name("planar_bench");  // For the usage line: parsing a vector does not read argv[0].
  // A flag given in the config file and again on the command line: the last one wins.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--data-dir", options.data_dir, "Folder of OpenCV's sample photos")
      ->capture_default_str();
  app.add_option("--out", options.out, "Output folder for CSV, table and plots")
      ->capture_default_str();
  app.add_option("--frames", options.frames, "Rendered views per case")
      ->check(CLI::Range(3, 1000))
      ->capture_default_str();
  app.add_option_function<std::string>(
         "--init-noise-model",
         [&options](const std::string& name) {
           options.init_noise_model = curvesfm::parseEnumName<curvesfm::InitNoiseModel>(
               name, "PlanarSceneOptions", "init_noise_model");
         },
         "Initial pose error: drift (per step, accumulating) or independent (per pose)")
      ->check(CLI::IsMember({"drift", "independent"}))
      ->default_str(curvesfm::toString(options.init_noise_model));
  app.add_option("--init-translation", options.init_translation_m,
                 "Std dev of the initial camera-centre error (m), per step or per pose")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--init-rotation-deg", options.init_rotation_deg,
                 "Std dev per axis of the initial rotation error (deg), per step or per pose")
      ->check(CLI::Range(0.0, 45.0))
      ->capture_default_str();
  // Lists are one comma-separated value, so that the last flag wins over --config as for every
  // other flag, and config.yaml echoes them as one scalar.
  app.add_option_function<std::string>(
         "--photos",
         [&options](const std::string& list) { options.photos = curvesfm::parsePhotoList(list); },
         "Comma-separated photo file names to run, or all")
      ->default_str("all");
  app.add_option_function<std::string>(
         "--noise",
         [&options](const std::string& list) {
           options.noise_percents = curvesfm::parseNoiseList(list);
         },
         "Comma-separated intensity noise levels to run (%)")
      ->default_str("0,5,10,15,20");
  app.add_flag("--quick", options.quick,
               "LinuxLogo and building x noise 0, 10 % x 10 frames (smoke test)");
  app.add_option("--jobs", options.jobs,
                 "Cases run at once (one thread each; stage times are wall times)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  curvesfm::addConfigFlag(&app);
  curvesfm::OptionsTable table;
  curvesfm::addPipelineOptions(&table, &options.pipeline, "/pipeline");
  table.addFlags(&app);
  const std::string command = curvesfm::bench::commandLine(argc, argv);
  const auto parse = [&] {
    curvesfm::parseCommandLine(&app, std::vector<std::string>(argv + 1, argv + argc));
  };
  return curvesfm::bench::parseWithAndRun(app, parse, [&] {
    if (options.quick) {
      options.photos = {"LinuxLogo.jpg", "building.jpg"};
      options.noise_percents = {0, 10};
      options.frames = std::min(options.frames, 10);
    }
    table.validate();
    return curvesfm::run(options, command, curvesfm::effectiveOptionsYaml(app));
  });
}
