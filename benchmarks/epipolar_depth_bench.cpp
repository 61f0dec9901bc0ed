// epipolar_depth_bench: semi-dense depth of the edge pixels of one 640x480 keyframe.
//
// Scene: a texture on the plane z = 0 (sim/planar_scene.h), seen from 1.5 m by a keyframe and
// two references 12 cm to the side and 10 cm up (all slightly tilted, so the depth varies by
// about 10 % over the image). Textures: the photograph --photo (default OpenCV's building.jpg,
// skipped if missing) and a synthetic one (smoothed random noise quantised into blobs of 5 grey
// levels), both at about one texel per pixel.
//
// Not in the timings: rendering, and detectEdges + extractEdgeChains (each run once, their times
// printed for the frontend budget). Timed, on one thread: estimateChainDepths with the default
// options but the depth range --min-depth .. --max-depth (0.5 - 5 m), for pixel_step 1 and 2,
// as wall time and as this thread's CPU time (on a shared machine the wall time also counts
// waiting for a core). The time grows with the searched segment, about f * baseline *
// (1 / min_depth - 1 / max_depth) px (here 113 px for the side reference). Accuracy lines compare
// the valid depths with the plane.
//
// Output: `key: value` lines after one `#` header line; times are medians over --repeats.
#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/camera.h"
#include "core/pose3.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/edge_detector.h"
#include "frontend/image/epipolar_depth.h"
#include "sim/planar_scene.h"

namespace curvesfm {
namespace {

using bench::Clock;
using bench::median;
using bench::print;

constexpr double kViewingDistance = 1.5;  // m
constexpr double kFocal = 525.0;          // px, CameraIntrinsics' default.

struct BenchOptions {
  int repeats = 7;  ///< Timed runs per case (median reported); >= 1.
  std::string photo = "/usr/share/doc/opencv-doc/examples/data/building.jpg";  ///< Texture.
  unsigned seed = 1;       ///< Seed of the synthetic texture.
  double min_depth = 0.5;  ///< EpipolarDepthOptions::min_depth (m); the plane is at ~1.5 m.
  double max_depth = 5.0;  ///< EpipolarDepthOptions::max_depth (m); > min_depth.
};

double millisecondsSince(Clock::time_point start) { return 1e3 * bench::secondsSince(start); }

// CPU time of this thread (ms): on a shared machine the wall time also counts waiting for a core.
double threadCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

// Smoothed uniform noise cut into 5 grey levels: blobs with edges in every direction.
cv::Mat blobTexture(unsigned seed) {
  cv::Mat noise(900, 1200, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 9.0);
  cv::normalize(noise, noise, 0.0, 4.999, cv::NORM_MINMAX);
  cv::Mat levels;
  noise.convertTo(levels, CV_8UC1, 1.0, -0.5);  // Rounds to 0..4.
  levels = levels * 50 + 20;
  cv::GaussianBlur(levels, levels, cv::Size(0, 0), 0.8);
  return levels;
}

// Looking down at the plane from `centre`, image x along world x, tilted about world x and y.
Pose3 viewFrom(const Eigen::Vector3d& centre, double tilt_x_deg, double tilt_y_deg) {
  const double rad = 3.14159265358979323846 / 180.0;
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(tilt_x_deg * rad, Eigen::Vector3d::UnitX()) *
                                    Eigen::AngleAxisd(tilt_y_deg * rad, Eigen::Vector3d::UnitY()))
                                       .toRotationMatrix() *
                                   Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  return Pose3(rotation, centre).inverse();
}

struct Keyframe {
  Camera camera{CameraIntrinsics{}};
  Pose3 pose;
  cv::Mat image;
  std::vector<EdgeChain> chains;
  std::vector<DepthReferenceView> references;
  int edge_pixels = 0;
};

Keyframe makeKeyframe(const cv::Mat& texture, const std::string& name) {
  Keyframe key;
  const double width = std::max(texture.cols, texture.rows) * kViewingDistance / kFocal;
  key.pose = viewFrom({0.0, 0.0, kViewingDistance}, 4.0, -3.0);
  key.image = renderPlanarView(texture, width, key.camera, key.pose);
  for (const Pose3& pose : {viewFrom({0.12, 0.0, kViewingDistance}, 4.0, -1.0),
                            viewFrom({0.0, 0.10, kViewingDistance - 0.05}, 5.0, -3.0)}) {
    key.references.push_back({renderPlanarView(texture, width, key.camera, pose), pose});
  }
  auto start = Clock::now();
  const EdgeImage edges = detectEdges(key.image);
  print("edges_ms_" + name, millisecondsSince(start));
  start = Clock::now();
  key.chains = extractEdgeChains(edges);
  print("chains_ms_" + name, millisecondsSince(start));
  for (const EdgeChain& chain : key.chains)
    key.edge_pixels += static_cast<int>(chain.pixels.size());
  print("chain_pixels_" + name, key.edge_pixels);
  return key;
}

// Median |depth - plane depth| / plane depth over the valid pixels.
double medianRelativeError(const Keyframe& key, const ChainDepths& depths) {
  const Pose3 world_from_cam = key.pose.inverse();
  std::vector<double> errors;
  for (std::size_t c = 0; c < key.chains.size(); ++c) {
    for (std::size_t i = 0; i < key.chains[c].pixels.size(); ++i) {
      if (!depths.chains[c][i].valid()) continue;
      const Eigen::Vector3d ray = world_from_cam.rotationMatrix() *
                                  key.camera.unproject(key.chains[c].pixels[i].cast<double>(), 1.0);
      const double truth = -world_from_cam.translation().z() / ray.z();
      errors.push_back(std::abs(depths.chains[c][i].depth - truth) / truth);
    }
  }
  return median(errors);
}

void runCase(const Keyframe& key, int pixel_step, const std::string& name,
             const BenchOptions& bench) {
  EpipolarDepthOptions options;
  options.min_depth = bench.min_depth;
  options.max_depth = bench.max_depth;
  options.pixel_step = pixel_step;
  if (pixel_step > 1) options.min_window_support = 2;
  std::vector<double> wall_ms;
  std::vector<double> cpu_ms;
  ChainDepths depths;
  for (int r = 0; r < bench.repeats; ++r) {
    const auto start = Clock::now();
    const double cpu_start = threadCpuMilliseconds();
    depths =
        estimateChainDepths(key.image, key.pose, key.chains, key.references, key.camera, options);
    cpu_ms.push_back(threadCpuMilliseconds() - cpu_start);
    wall_ms.push_back(millisecondsSince(start));
  }
  const double cpu = median(cpu_ms);
  const std::string suffix = name + "_step" + std::to_string(pixel_step);
  print("depth_ms_" + suffix, median(wall_ms));
  print("depth_cpu_ms_" + suffix, cpu);
  print("pixels_per_cpu_s_" + suffix, 1e3 * key.edge_pixels / cpu);
  print("valid_fraction_" + suffix,
        static_cast<double>(depths.counts.valid()) / std::max(1, depths.counts.total()));
  print("median_relative_error_" + suffix, medianRelativeError(key, depths));
  for (int s = 1; s < kNumDepthStatuses; ++s) {
    const DepthStatus status = static_cast<DepthStatus>(s);
    bench::printInt("rejected_" + toString(status) + "_" + suffix, depths.counts.count(status));
  }
  std::fflush(stdout);
}

int run(const BenchOptions& bench) {
  cv::setNumThreads(1);
  std::printf(
      "# epipolar_depth_bench: estimateChainDepths per 640x480 keyframe, two references, one "
      "thread; medians of %d repeats\n",
      bench.repeats);
  print("min_depth", bench.min_depth);
  print("max_depth", bench.max_depth);
  std::vector<std::pair<std::string, cv::Mat>> textures = {{"blobs", blobTexture(bench.seed)}};
  const cv::Mat photo = cv::imread(bench.photo, cv::IMREAD_GRAYSCALE);
  if (!photo.empty()) textures.emplace_back("photo", photo);
  bench::printText("photo", photo.empty() ? "missing, skipped" : bench.photo);
  for (const auto& [name, texture] : textures) {
    const Keyframe key = makeKeyframe(texture, name);
    for (const int step : {1, 2}) runCase(key, step, name, bench);
  }
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::BenchOptions bench;
  CLI::App app{"Semi-dense epipolar depth of the edge pixels of one keyframe"};
  app.add_option("--repeats", bench.repeats, "Timed runs per case (median reported)")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--photo", bench.photo, "Photograph laid on the plane (skipped if missing)")
      ->capture_default_str();
  app.add_option("--seed", bench.seed, "Seed of the synthetic texture")->capture_default_str();
  app.add_option("--min-depth", bench.min_depth, "Nearest depth searched (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-depth", bench.max_depth, "Farthest depth searched (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(bench); });
}
