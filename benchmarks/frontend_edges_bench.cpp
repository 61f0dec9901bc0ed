// frontend_edges_bench: the first stages of the image frontend on real photographs at 640 x 480.
//
// Images: home.jpg, building.jpg and fruits.jpg from OpenCV's sample data (--data-dir), or the
// files given with --images, each resized to 640 x 480 (INTER_AREA) once, outside the timings; a
// missing photo is skipped with a message. Timed per image, on one thread (cv::setNumThreads(1)),
// default options:
//   undistort: ImageUndistorter::undistort with the TUM fr1 calibration (k1..k3 non-zero), the
//              remap a distorted camera adds per keyframe (tables built once, not timed);
//   edges:     detectEdges on the colour image (grey, blur, Sobel, automatic thresholds, Canny);
//   chains:    extractEdgeChains on that result (thinning, junctions, tracing, curvature splits);
//   field:     NearestEdgeField::build on the same edges (default reach);
// plus edges_plus_chains, the per-keyframe cost without distortion.
//
// Output: `key: value` lines after one `#` header line; times are medians over --repeats after
// one untimed run of each stage, as wall-clock time (`*_ms_*`) and as the thread's CPU time
// (`*_cpu_ms_*`). On a machine shared with other jobs the wall-clock median includes time the
// thread spent preempted; the CPU time is the figure to compare with a one-core budget.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/camera.h"
#include "core/nearest_edge_field.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/edge_detector.h"
#include "frontend/image/image_undistorter.h"

namespace curvesfm {
namespace {

using bench::Clock;
using bench::median;
using bench::print;

struct BenchOptions {
  int repeats = 21;  ///< Timed runs per stage and image; the median is reported; >= 1.
  std::string data_dir = "/usr/share/doc/opencv-doc/examples/data";  ///< Folder of the images.
  /// Images to time instead of the three photos (any size: resized to 640 x 480).
  std::vector<std::string> images;
};

// The TUM RGB-D fr1 calibration (Kinect 1 at 640 x 480), whose distortion is the strongest of
// the TUM sequences.
Camera tumFreiburg1() {
  // fx, fy, cx, cy, k1, k2, p1, p2, k3, width, height.
  return Camera(CameraIntrinsics{517.3, 516.5, 318.6, 255.3, 0.2624, -0.9531, -0.0054, 0.0026,
                                 1.1633, 640, 480});
}

double threadCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

struct StageTime {
  double wall_ms = 0.0;  ///< Median wall-clock time.
  double cpu_ms = 0.0;   ///< Median CPU time of the calling thread.
};

// Median times of `repeats` runs of `stage` after one untimed run.
template <class Stage>
StageTime timeStage(int repeats, Stage stage) {
  stage();
  std::vector<double> wall_ms;
  std::vector<double> cpu_ms;
  for (int r = 0; r < repeats; ++r) {
    const auto start = Clock::now();
    const double cpu_start = threadCpuMilliseconds();
    stage();
    cpu_ms.push_back(threadCpuMilliseconds() - cpu_start);
    wall_ms.push_back(1e3 * bench::secondsSince(start));
  }
  return {median(wall_ms), median(cpu_ms)};
}

void printStage(const std::string& stage, const std::string& image, const StageTime& time) {
  print(stage + "_ms_" + image, time.wall_ms);
  print(stage + "_cpu_ms_" + image, time.cpu_ms);
}

void runImage(const std::string& name, const cv::Mat& image, const ImageUndistorter& undistorter,
              int repeats) {
  EdgeImage edges;
  std::vector<EdgeChain> chains;
  const StageTime undistort =
      timeStage(repeats, [&] { cv::Mat out = undistorter.undistort(image); });
  const StageTime edge_time = timeStage(repeats, [&] { edges = detectEdges(image); });
  const StageTime chain_time = timeStage(repeats, [&] { chains = extractEdgeChains(edges); });
  const StageTime field_time = timeStage(repeats, [&] {
    const NearestEdgeField field = NearestEdgeField::build(edges.edges, edges.grad_x, edges.grad_y);
  });
  long long chain_pixels = 0;
  for (const EdgeChain& chain : chains) chain_pixels += static_cast<long long>(chain.pixels.size());
  const double pixels = static_cast<double>(image.total());
  printStage("undistort", name, undistort);
  printStage("edges", name, edge_time);
  printStage("chains", name, chain_time);
  printStage("field", name, field_time);
  printStage("edges_plus_chains", name,
             {edge_time.wall_ms + chain_time.wall_ms, edge_time.cpu_ms + chain_time.cpu_ms});
  print("high_threshold_" + name, edges.high_threshold);
  print("edge_fraction_" + name, cv::countNonZero(edges.edges) / pixels);
  bench::printInt("chains_" + name, static_cast<long long>(chains.size()));
  print("chain_pixel_fraction_" + name, static_cast<double>(chain_pixels) / pixels);
  std::fflush(stdout);
}

int run(const BenchOptions& bench) {
  cv::setNumThreads(1);
  std::printf(
      "# frontend_edges_bench: undistort, detectEdges, extractEdgeChains and the nearest-edge "
      "field "
      "(default options) on images resized to 640x480, one thread; medians of %d repeats\n",
      bench.repeats);
  const ImageUndistorter undistorter(tumFreiburg1());
  int measured = 0;
  std::vector<std::string> paths = bench.images;
  if (paths.empty()) {
    for (const std::string name : {"home", "building", "fruits"})
      paths.push_back(bench.data_dir + "/" + name + ".jpg");
  }
  for (const std::string& path : paths) {
    const std::string name = std::filesystem::path(path).stem().string();
    const cv::Mat photo = cv::imread(path, cv::IMREAD_COLOR);
    if (photo.empty() && !bench.images.empty()) {
      std::fprintf(stderr, "frontend_edges_bench: %s: not an image OpenCV can read\n",
                   path.c_str());
      return 1;
    }
    if (photo.empty()) {
      std::printf("# skipped %s: not found or not readable\n", path.c_str());
      continue;
    }
    cv::Mat image;
    cv::resize(photo, image, cv::Size(640, 480), 0.0, 0.0, cv::INTER_AREA);
    runImage(name, image, undistorter, bench.repeats);
    ++measured;
  }
  if (measured == 0)
    std::printf("# no image found in %s: nothing measured\n", bench.data_dir.c_str());
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions bench;
  CLI::App app{"Edges and edge chains of the image frontend on 640x480 photographs"};
  app.add_option("--repeats", bench.repeats, "Timed runs per stage and image (median reported)")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--data-dir", bench.data_dir, "Folder holding home.jpg, building.jpg, fruits.jpg")
      ->capture_default_str();
  app.add_option("--images", bench.images,
                 "Images to time instead of the three photos (resized to 640x480)")
      ->check(CLI::ExistingFile);
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(bench); });
}
