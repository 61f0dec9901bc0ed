#include "frontend/image/feature_matching.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/dense_kernels.h"
#include "core/errors.h"

namespace curvesfm {

void FeatureMatchingOptions::validate() const {
  const OptionCheck require("FeatureMatchingOptions");
  require(kind == FeatureKind::kSift || kind == FeatureKind::kOrb, "kind", static_cast<int>(kind),
          "one of " + enumNameList<FeatureKind>());
  require(max_features >= 1 && max_features <= 100000, "max_features", max_features,
          "in [1, 100000]");
  require(detection_scale > 0.0 && detection_scale <= 1.0, "detection_scale", detection_scale,
          "in (0, 1]");
  require(ratio > 0.0 && ratio <= 1.0, "ratio", ratio, "in (0, 1]");
}

namespace {

cv::Mat toGrey(const cv::Mat& image) {
  CURVESFM_CHECK(!image.empty()) << "detectFeatures needs an image, got an empty one";
  CURVESFM_CHECK(image.type() == CV_8UC1 || image.type() == CV_8UC3)
      << "detectFeatures takes 8-bit grey (CV_8UC1) or BGR (CV_8UC3) images, got type "
      << image.type() << " with " << image.channels() << " channel(s)";
  if (image.type() == CV_8UC1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Mat resizedForDetection(const cv::Mat& grey, double scale) {
  if (scale == 1.0) return grey;
  cv::Mat resized;
  cv::resize(grey, resized,
             cv::Size(std::max(1, static_cast<int>(std::lround(grey.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(grey.rows * scale)))),
             0.0, 0.0, cv::INTER_AREA);
  return resized;
}

constexpr float kOrbScaleFactor = 1.2f;  // OpenCV's default, spelled out for orbPixel.

cv::Ptr<cv::Feature2D> makeDetector(const FeatureMatchingOptions& o) {
  if (o.kind == FeatureKind::kOrb) return cv::ORB::create(o.max_features, kOrbScaleFactor);
  return cv::SIFT::create(o.max_features);
}

// OpenCV 4.6's SIFT starts its scale space at the image doubled by a linear resize, which puts
// the doubled image's pixel u at u / 2 - 0.25 of the image, and reports u / 2: every keypoint lies
// 0.25 px right of and below its feature, at every octave (OpenCV issue 23123; the keypoints of
// the image turned by 180 deg, mapped back, lie 0.5 px from the image's own along each axis:
// test/frontend/image/feature_matching_test.cpp).
// Uncorrected, SIFT's observations disagree with KLT's within one track, and on stills the
// cameras turn to absorb the shift.
constexpr double kSiftDoublingBiasPx = 0.25;

// ORB scales a keypoint of pyramid level l by 1.2^l, but the level is the image resized to
// round(size / 1.2^l) pixels, whose pixel p lies at (p + 0.5) size / level_size - 0.5 of the image:
// at 640 px, 0.5 px off at level 1 and 1-2 px at the coarsest levels. The arithmetic is OpenCV
// 4.6's own (a float scale from a double power, sizes rounded from size * (1 / scale)), so that
// the level sizes agree where round(size / scale) would tie differently (513 px at level 1).
Eigen::Vector2d orbPixel(const cv::KeyPoint& k, const cv::Size& image_size) {
  const float level_scale = static_cast<float>(std::pow(double{kOrbScaleFactor}, k.octave));
  const float inverse_scale = 1.0f / level_scale;
  const Eigen::Array2d level_pixel(k.pt.x / level_scale, k.pt.y / level_scale);
  const Eigen::Array2d level_size(cvRound(image_size.width * inverse_scale),
                                  cvRound(image_size.height * inverse_scale));
  const Eigen::Array2d size(image_size.width, image_size.height);
  return (level_pixel + 0.5) * size / level_size - 0.5;
}

// The keypoint's position in the image it was detected in, pixel centres at integers.
Eigen::Vector2d keypointPixel(const cv::KeyPoint& k, FeatureKind kind, const cv::Size& image_size) {
  if (kind == FeatureKind::kOrb) return orbPixel(k, image_size);
  return Eigen::Vector2d(k.pt.x - kSiftDoublingBiasPx, k.pt.y - kSiftDoublingBiasPx);
}

// Strongest first, ties broken by position, size and angle: a total order on distinct keypoints,
// so the kept set and its order never depend on how the detector's threads finished.
bool stronger(const cv::KeyPoint& p, const cv::KeyPoint& q) {
  if (p.response != q.response) return p.response > q.response;
  if (p.pt.y != q.pt.y) return p.pt.y < q.pt.y;
  if (p.pt.x != q.pt.x) return p.pt.x < q.pt.x;
  if (p.size != q.size) return p.size < q.size;
  if (p.angle != q.angle) return p.angle < q.angle;
  return p.octave < q.octave;
}

#if defined(__x86_64__) || defined(__i386__)
// Hamming distances (bits) between the rows of two CV_8U descriptor sets, as CV_32F, 64 bits at
// a time with the popcnt instruction (words loaded by memcpy: the rows are bytes).
__attribute__((target("popcnt"))) void hammingRowsPopcnt(const cv::Mat& a, const cv::Mat& b,
                                                         cv::Mat& out) {
  const int words = a.cols / 8;
  std::vector<std::uint64_t> x(static_cast<std::size_t>(words));
  std::vector<std::uint64_t> y(static_cast<std::size_t>(b.rows) * words);
  for (int j = 0; j < b.rows; ++j) std::memcpy(&y[std::size_t(j) * words], b.ptr(j), a.cols);
  for (int i = 0; i < a.rows; ++i) {
    std::memcpy(x.data(), a.ptr(i), a.cols);
    float* row = out.ptr<float>(i);
    for (int j = 0; j < b.rows; ++j) {
      const std::uint64_t* yj = &y[std::size_t(j) * words];
      int bits = 0;
      for (int w = 0; w < words; ++w) bits += __builtin_popcountll(x[w] ^ yj[w]);
      row[j] = static_cast<float>(bits);
    }
  }
}

bool hasPopcnt() { return __builtin_cpu_supports("popcnt"); }
#else
void hammingRowsPopcnt(const cv::Mat&, const cv::Mat&, cv::Mat&) {}
bool hasPopcnt() { return false; }
#endif

cv::Mat hammingDistances(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat out(a.rows, b.rows, CV_32F);
  if (a.cols % 8 == 0 && hasPopcnt()) {
    hammingRowsPopcnt(a, b, out);
    return out;
  }
  cv::Mat bits;
  cv::batchDistance(a, b, bits, CV_32S, cv::noArray(), cv::NORM_HAMMING);
  bits.convertTo(out, CV_32F);
  return out;
}

// Squared Euclidean distances between the rows of two CV_32F descriptor sets, as CV_32F: |x|^2 +
// |y|^2 - 2 x.y with the dot products in one matrix product, clamped at 0 against rounding.
// OpenCV's SIFT descriptors hold whole numbers up to 255, so every dot product and norm is an
// integer below 2^24 and exact in single precision, whatever the product's order of additions:
// the AVX2 product of core/dense_kernels.h gives the distances BLAS gave, to the bit, at a third
// of its time. Squared: square roots keep their order (but where two round to one float), so
// only the two nearest of a row need one.
cv::Mat squaredEuclideanDistances(const cv::Mat& a_in, const cv::Mat& b_in) {
  const cv::Mat a = a_in.isContinuous() ? a_in : a_in.clone();
  const cv::Mat b = b_in.isContinuous() ? b_in : b_in.clone();
  cv::Mat dot(a.rows, b.rows, CV_32F);
  dense::productTransposedFloat(a.ptr<float>(), a.rows, b.ptr<float>(), b.rows, a.cols,
                                dot.ptr<float>());
  cv::Mat a_squared;
  cv::Mat b_squared;
  cv::reduce(a.mul(a), a_squared, 1, cv::REDUCE_SUM);
  cv::reduce(b.mul(b), b_squared, 1, cv::REDUCE_SUM);
  const float* y_squared = b_squared.ptr<float>();
  for (int i = 0; i < dot.rows; ++i) {
    float* row = dot.ptr<float>(i);
    const float x_squared = a_squared.at<float>(i);
    for (int j = 0; j < dot.cols; ++j) {
      row[j] = std::max(0.0f, -2.0f * row[j] + x_squared + y_squared[j]);
    }
  }
  return dot;
}

struct TwoNearest {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  double second_distance = std::numeric_limits<double>::infinity();
};

// The nearest and second-nearest column of a row; ties go to the lower column.
TwoNearest twoNearestInRow(const cv::Mat& distances, int i) {
  TwoNearest n;
  const float* row = distances.ptr<float>(i);
  for (int j = 0; j < distances.cols; ++j) {
    if (row[j] < n.best_distance) {
      n.second_distance = n.best_distance;
      n.best_distance = row[j];
      n.best = j;
    } else if (row[j] < n.second_distance) {
      n.second_distance = row[j];
    }
  }
  return n;
}

// For every column, the row nearest to it; ties go to the lower row.
std::vector<int> nearestRowPerColumn(const cv::Mat& distances) {
  std::vector<int> nearest(static_cast<std::size_t>(distances.cols), -1);
  std::vector<float> best(static_cast<std::size_t>(distances.cols),
                          std::numeric_limits<float>::infinity());
  for (int i = 0; i < distances.rows; ++i) {
    const float* row = distances.ptr<float>(i);
    for (int j = 0; j < distances.cols; ++j) {
      if (row[j] < best[static_cast<std::size_t>(j)]) {
        best[static_cast<std::size_t>(j)] = row[j];
        nearest[static_cast<std::size_t>(j)] = i;
      }
    }
  }
  return nearest;
}

}  // namespace

FeatureSet detectFeatures(const cv::Mat& image, const FeatureMatchingOptions& options) {
  options.validate();
  const cv::Mat grey = resizedForDetection(toGrey(image), options.detection_scale);
  const cv::Ptr<cv::Feature2D> detector = makeDetector(options);

  // One pass: detect() then compute() would build SIFT's scale space twice (60 % more time). The
  // detector keeps its max_features strongest; compute may drop keypoints whose descriptor window
  // leaves the image (ORB), so rows follow the returned keypoints.
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  detector->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
  std::vector<int> order(keypoints.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int p, int q) { return stronger(keypoints[p], keypoints[q]); });
  if (static_cast<int>(order.size()) > options.max_features) {
    order.resize(static_cast<std::size_t>(options.max_features));
  }

  FeatureSet set;
  set.kind = options.kind;
  if (order.empty()) return set;
  const Eigen::Array2d scale(static_cast<double>(grey.cols) / image.cols,
                             static_cast<double>(grey.rows) / image.rows);
  set.descriptors.create(static_cast<int>(order.size()), descriptors.cols, descriptors.type());
  set.pixels.reserve(order.size());
  set.sizes.reserve(order.size());
  for (std::size_t row = 0; row < order.size(); ++row) {
    const cv::KeyPoint& k = keypoints[static_cast<std::size_t>(order[row])];
    // Pixel centres at integers in both images: x = (x' + 0.5) / s - 0.5.
    const Eigen::Vector2d detected = keypointPixel(k, options.kind, grey.size());
    set.pixels.push_back((detected.array() + 0.5) / scale - 0.5);
    set.sizes.push_back(k.size / scale.x());
    descriptors.row(order[row]).copyTo(set.descriptors.row(static_cast<int>(row)));
  }
  return set;
}

std::vector<FeatureMatch> matchFeatures(const FeatureSet& a, const FeatureSet& b,
                                        const FeatureMatchingOptions& options) {
  options.validate();
  std::vector<FeatureMatch> matches;
  if (a.size() == 0 || b.size() == 0) return matches;
  CURVESFM_CHECK(a.kind == b.kind && a.descriptors.type() == b.descriptors.type() &&
                 a.descriptors.cols == b.descriptors.cols)
      << "matchFeatures: the sets hold different descriptors (" << toString(a.kind) << ", "
      << a.descriptors.cols << " columns of type " << a.descriptors.type() << " vs "
      << toString(b.kind) << ", " << b.descriptors.cols << " columns of type "
      << b.descriptors.type() << ")";
  CURVESFM_CHECK(a.descriptors.rows == a.size() && b.descriptors.rows == b.size())
      << "matchFeatures: a set needs one descriptor row per keypoint, got " << a.descriptors.rows
      << " rows for " << a.size() << " and " << b.descriptors.rows << " rows for " << b.size();

  // One distance matrix serves both directions: the ratio test reads a's rows, the mutual check
  // b's columns. OpenCV's BFMatcher searched twice and, for Hamming, paid a call per pair
  // (7-Scenes, 1750 features a side: SIFT 80 -> 30 ms, ORB 80 -> 10 ms on one core).
  const bool squared = a.kind != FeatureKind::kOrb;
  const cv::Mat distances = squared ? squaredEuclideanDistances(a.descriptors, b.descriptors)
                                    : hammingDistances(a.descriptors, b.descriptors);
  const std::vector<int> nearest_in_a =
      options.mutual_check ? nearestRowPerColumn(distances) : std::vector<int>();
  for (int i = 0; i < distances.rows; ++i) {
    TwoNearest nearest = twoNearestInRow(distances, i);
    if (squared) {
      nearest.best_distance = std::sqrt(static_cast<float>(nearest.best_distance));
      nearest.second_distance = std::sqrt(static_cast<float>(nearest.second_distance));
    }
    // With a single feature in b there is no second neighbour, and nothing to be confused with.
    if (!(nearest.best_distance < options.ratio * nearest.second_distance)) continue;
    if (options.mutual_check && nearest_in_a[static_cast<std::size_t>(nearest.best)] != i) continue;
    matches.push_back({i, nearest.best, a.pixels[static_cast<std::size_t>(i)],
                       b.pixels[static_cast<std::size_t>(nearest.best)], nearest.best_distance});
  }
  return matches;
}

}  // namespace curvesfm
