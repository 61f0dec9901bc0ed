// keypoint_precision_bench: how precisely descriptor keypoints are located, by their size, on a
// dataset with ground-truth poses.
//
// Each image's features are detected as the initialiser detects them (detectFeatures, default
// FeatureMatchingOptions: SIFT, 1000 features) and matched with the next --pair-gap images
// (matchFeatures: ratio test, mutual check). Where the initialiser verifies matches by RANSAC,
// the bench gates them by the true geometry instead (below). A match's error is its distance from
// the true epipolar lines (the mean of both images', in undistorted pixels) under the ground
// truth's relative pose: the component of the two keypoints' location errors across the epipolar
// line, with no fitted model in it. Matches farther than --max-distance px are taken for wrong ones
// and left out. The matches are binned by the larger of the two keypoint diameters
// (FeatureSet::sizes), half an octave a bin. The figure the hybrid graph's
// --ba-keypoint-reference-size weighs by: a keypoint detected at a coarser scale is localised less
// precisely.
//
// Output: `key: value` lines (matches, median distance overall) and one line per size bin.
#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "benchmarks/support/bench_common.h"
#include "core/camera.h"
#include "core/errors.h"
#include "core/image_sequence.h"
#include "core/pose3.h"
#include "core/so3.h"
#include "core/tum_dataset.h"
#include "frontend/image/feature_matching.h"

namespace curvesfm {
namespace {

struct KeypointBenchOptions {
  std::string dataset;
  std::string camera;
  int stride = 1;
  int max_frames = 0;
  int pair_gap = 2;
  double max_distance_px = 4.0;
  double max_dt_s = 0.02;
};

// One image: its features in undistorted pixels and its true pose.
struct PosedFeatures {
  FeatureSet features;
  std::vector<Eigen::Vector2d> undistorted;
  Pose3 cam_from_world;
};

// Distance of a match from the true epipolar lines (px, mean of both images').
double epipolarDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        const Eigen::Matrix3d& fundamental) {
  const Eigen::Vector3d xa(a.x(), a.y(), 1.0);
  const Eigen::Vector3d xb(b.x(), b.y(), 1.0);
  const Eigen::Vector3d line_b = fundamental * xa;
  const Eigen::Vector3d line_a = fundamental.transpose() * xb;
  const double e = std::abs(xb.dot(line_b));
  return 0.5 * (e / line_b.head<2>().norm() + e / line_a.head<2>().norm());
}

Eigen::Matrix3d trueFundamental(const Pose3& a, const Pose3& b, const Camera& camera) {
  const Pose3 b_from_a = b * a.inverse();
  const Eigen::Matrix3d essential = so3::hat(b_from_a.translation()) * b_from_a.rotationMatrix();
  const Eigen::Matrix3d k_inverse = camera.K().inverse();
  return k_inverse.transpose() * essential * k_inverse;
}

int run(const KeypointBenchOptions& o) {
  cv::setNumThreads(1);
  ImageSequenceOptions read;
  read.camera = o.camera;
  read.stride = o.stride;
  read.max_frames = o.max_frames;
  const ImageSequence sequence = loadImageSequence(o.dataset, read);
  if (sequence.ground_truth.empty()) throw IoError(o.dataset, "the dataset has no ground truth");
  // One pose per image, or TUM's and EuRoC's associated by timestamp.
  const std::vector<DatasetFrame> frames =
      framesWithPoses(sequence, sequence.ground_truth, o.max_dt_s, sequence.ground_truth_source);

  std::vector<PosedFeatures> images;
  const FeatureMatchingOptions matching;
  for (const DatasetFrame& frame : frames) {
    PosedFeatures p;
    const cv::Mat image = cv::imread(frame.image_path);
    if (image.empty()) throw IoError(frame.image_path, "not an image OpenCV can read");
    p.features = detectFeatures(image, matching);
    for (const Eigen::Vector2d& pixel : p.features.pixels) {
      p.undistorted.push_back(sequence.camera.undistortPixel(pixel));
    }
    p.cam_from_world = frame.initial_cam_from_world;
    images.push_back(std::move(p));
  }
  std::fprintf(stderr, "%zu posed images of %zu\n", images.size(), sequence.images.size());

  // Half-octave bins of the larger diameter, from 1.6 px (SIFT's smallest scale).
  std::map<int, std::vector<double>> by_size;
  std::vector<double> all;
  for (std::size_t i = 0; i < images.size(); ++i) {
    for (std::size_t j = i + 1; j < images.size() && j <= i + o.pair_gap; ++j) {
      const Eigen::Matrix3d f =
          trueFundamental(images[i].cam_from_world, images[j].cam_from_world, sequence.camera);
      for (const FeatureMatch& m : matchFeatures(images[i].features, images[j].features, matching)) {
        const double distance = epipolarDistance(images[i].undistorted[m.index_a],
                                                 images[j].undistorted[m.index_b], f);
        if (!(distance <= o.max_distance_px)) continue;
        const double size =
            std::max(images[i].features.sizes[m.index_a], images[j].features.sizes[m.index_b]);
        by_size[static_cast<int>(std::floor(2.0 * std::log2(size / 1.6)))].push_back(distance);
        all.push_back(distance);
      }
    }
  }
  bench::printInt("images", static_cast<long long>(images.size()));
  bench::printInt("matches", static_cast<long long>(all.size()));
  bench::print("median_epipolar_distance_px", bench::median(all));
  std::printf("# diameter from-to px | matches | median distance px\n");
  for (const auto& [bin, distances] : by_size) {
    std::printf("size %.1f-%.1f | %zu | %.3f\n", 1.6 * std::pow(2.0, bin / 2.0),
                1.6 * std::pow(2.0, (bin + 1) / 2.0), distances.size(), bench::median(distances));
  }
  return 0;
}

}  // namespace
}  // namespace curvesfm

int main(int argc, char** argv) {
  curvesfm::KeypointBenchOptions o;
  CLI::App app{"Descriptor keypoints' distance from the true epipolar lines, by keypoint size"};
  app.add_option("--dataset", o.dataset, "Dataset folder with ground truth (any layout run reads)")
      ->required();
  app.add_option("--camera", o.camera, "Intrinsics fx,fy,cx,cy[,k1,k2,p1,p2[,k3]] (px)");
  app.add_option("--stride", o.stride, "Every stride-th image")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-frames", o.max_frames, "At most this many images; 0: all")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--pair-gap", o.pair_gap, "Each image is matched with the next this many")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-distance", o.max_distance_px,
                 "Matches farther from their epipolar lines are taken as wrong (px)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--max-dt", o.max_dt_s, "Ground-truth association tolerance (s; TUM, EuRoC)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return curvesfm::bench::parseAndRun(app, argc, argv, [&] { return curvesfm::run(o); });
}
