#include "frontend/image/feature_matching.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {

void FeatureMatchingOptions::validate() const {
  const OptionCheck require("FeatureMatchingOptions");
  require(kind == FeatureKind::kSift || kind == FeatureKind::kOrb, "kind", static_cast<int>(kind),
          "one of " + enumNameList<FeatureKind>());
  require(max_features >= 1 && max_features <= 100000, "max_features", max_features,
          "in [1, 100000]");
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

cv::Ptr<cv::Feature2D> makeDetector(const FeatureMatchingOptions& o) {
  if (o.kind == FeatureKind::kOrb) return cv::ORB::create(o.max_features);
  return cv::SIFT::create(o.max_features);
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

}  // namespace

FeatureSet detectFeatures(const cv::Mat& image, const FeatureMatchingOptions& options) {
  options.validate();
  const cv::Mat grey = toGrey(image);
  const cv::Ptr<cv::Feature2D> detector = makeDetector(options);

  std::vector<cv::KeyPoint> keypoints;
  detector->detect(grey, keypoints);
  std::sort(keypoints.begin(), keypoints.end(), stronger);
  if (static_cast<int>(keypoints.size()) > options.max_features) {
    keypoints.resize(static_cast<std::size_t>(options.max_features));
  }

  FeatureSet set;
  set.kind = options.kind;
  if (keypoints.empty()) return set;
  // compute() may drop keypoints whose descriptor window leaves the image (ORB); it returns the
  // kept ones, in order, with their rows.
  detector->compute(grey, keypoints, set.descriptors);
  set.pixels.reserve(keypoints.size());
  for (const cv::KeyPoint& k : keypoints) set.pixels.emplace_back(k.pt.x, k.pt.y);
  if (set.pixels.empty()) set.descriptors = cv::Mat();
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

  const int norm = a.kind == FeatureKind::kOrb ? cv::NORM_HAMMING : cv::NORM_L2;
  cv::BFMatcher matcher(norm);
  std::vector<std::vector<cv::DMatch>> a_to_b;
  matcher.knnMatch(a.descriptors, b.descriptors, a_to_b, 2);
  std::vector<std::vector<cv::DMatch>> b_to_a;
  if (options.mutual_check) matcher.knnMatch(b.descriptors, a.descriptors, b_to_a, 1);

  for (const std::vector<cv::DMatch>& nearest : a_to_b) {
    if (nearest.empty()) continue;
    const cv::DMatch& best = nearest[0];
    // With a single feature in b there is no second neighbour, and nothing to be confused with.
    const double second =
        nearest.size() > 1 ? nearest[1].distance : std::numeric_limits<double>::infinity();
    if (!(best.distance < options.ratio * second)) continue;
    if (options.mutual_check) {
      const std::vector<cv::DMatch>& back = b_to_a[static_cast<std::size_t>(best.trainIdx)];
      if (back.empty() || back[0].trainIdx != best.queryIdx) continue;
    }
    matches.push_back({best.queryIdx, best.trainIdx,
                       a.pixels[static_cast<std::size_t>(best.queryIdx)],
                       b.pixels[static_cast<std::size_t>(best.trainIdx)], best.distance});
  }
  return matches;
}

}  // namespace curvesfm
