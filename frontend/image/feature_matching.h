#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "core/enum_names.h"

namespace curvesfm {

// Descriptor matching between keyframes, the second half of the point-based initialiser's
// correspondences (issue 13): where KLT (point_tracks.h) follows points between consecutive
// frames, descriptors re-find points between frames far apart and bridge the frames where KLT
// loses them (../shared/reviews/initialiser_anchors.md A.5 item 1: COLMAP's sequential matcher,
// SIFT with ratio 0.8 and a mutual check).
//
// Steps:
//  1. detectFeatures: keypoints and descriptors of one image (SIFT or ORB, OpenCV features2d).
//  2. matchFeatures: brute-force k-nearest-neighbours (k = 2; L2 for SIFT, Hamming for ORB) from
//     a to b; Lowe's ratio test keeps a's feature only when its nearest descriptor in b is closer
//     than ratio x the second nearest (a unique match); the mutual (cross) check then also
//     requires a's feature to be the nearest in a of its match in b.
// Plain data in (8-bit images), plain data out (pixels, indices, distances); no randomness, so the
// same images always give the same matches.
//
// Pixels: centres at integers, (0, 0) the centre of the top-left pixel (as Camera::project and
// OpenCV's keypoints).

/// The descriptor that is detected and matched.
enum class FeatureKind {
  kSift,  ///< SIFT (128 floats, L2 distance): scale and rotation invariant, the reference.
  kOrb,   ///< ORB (256 bits, Hamming distance): faster, less distinctive.
};

template <>
struct EnumNames<FeatureKind> {
  static constexpr std::array<std::pair<FeatureKind, const char*>, 2> kNames = {
      {{FeatureKind::kSift, "sift"}, {FeatureKind::kOrb, "orb"}}};
};

/// How features are detected and matched. Defaults follow COLMAP's sequential matcher.
struct FeatureMatchingOptions {
  /// Descriptor detected and matched: sift (L2) or orb (Hamming). Measured on one core at
  /// 640x360 (Pavilion), 1000 features: SIFT 43 ms to detect per image, ORB 5 ms; matching a pair
  /// 3-4 ms either way. ORB's matches registered fewer frames and gave a worse ATE on every real
  /// set but 7-Scenes (docs/benchmarks.md).
  FeatureKind kind = FeatureKind::kSift;
  /// Most features kept per image, the strongest first (SIFT: by contrast response; ORB: by
  /// Harris score). Matching costs its square. 1000 rather than 2000 lowered the initialiser's
  /// ATE on 7-Scenes, Pavilion and fountain-P11 and left KITTI, templeRing and templeSparseRing
  /// (which has fewer) unchanged (docs/benchmarks.md). In [1, 100000].
  int max_features = 1000;
  /// Features are detected on the image resized by this factor and their pixels mapped back
  /// (unitless; 1: full resolution). SIFT's scale space starts at twice the image size, so 0.5
  /// starts it at full size: about 4x faster, without SIFT's finest scale, and a quarter of the
  /// features on Pavilion; at 0.5 the initialiser registered 8 of templeSparseRing's 16 stills
  /// and 56 of Pavilion's 100 frames (0.75: 13 of 16). In (0, 1].
  double detection_scale = 1.0;
  /// Lowe's ratio: a match is kept when its descriptor distance is below this fraction of the
  /// distance to the second nearest descriptor (unitless; smaller is stricter: fewer, surer
  /// matches). In (0, 1].
  double ratio = 0.8;
  /// Keep a match a -> b only when a's feature is also the nearest in a to b's feature (the
  /// mutual or cross check): removes many-to-one matches onto one look-alike.
  bool mutual_check = true;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// The features of one image: keypoint i has descriptor row i.
struct FeatureSet {
  /// Keypoint positions (px, pixel centres at integers), corrected for where OpenCV's detectors
  /// put them off their features (SIFT: 0.25 px right and down; ORB: its coarser levels).
  std::vector<Eigen::Vector2d> pixels;
  /// Keypoint diameters (px of the image given; OpenCV's KeyPoint::size): the scale each was
  /// detected at. A keypoint found at a coarser scale is localised less precisely.
  std::vector<double> sizes;
  /// One row per keypoint: CV_32F with 128 columns (SIFT) or CV_8U with 32 columns (ORB); empty
  /// when no feature was found.
  cv::Mat descriptors;
  FeatureKind kind = FeatureKind::kSift;  ///< The descriptor of `descriptors`.

  int size() const { return static_cast<int>(pixels.size()); }
};

/// One descriptor match between two feature sets.
struct FeatureMatch {
  int index_a = -1;                                   ///< Feature in set a.
  int index_b = -1;                                   ///< Feature in set b.
  Eigen::Vector2d pixel_a = Eigen::Vector2d::Zero();  ///< Its position in image a (px).
  Eigen::Vector2d pixel_b = Eigen::Vector2d::Zero();  ///< Its position in image b (px).
  /// Descriptor distance: L2 (SIFT) or Hamming bits (ORB).
  double distance = 0.0;
};

/// Detects keypoints and computes descriptors of `image` (CV_8UC1 grey, or CV_8UC3 BGR,
/// converted to grey), at most options.max_features, ordered as the detector returns them.
/// A featureless image (constant) gives an empty set. Throws InvalidOptions for invalid options,
/// CheckError for an empty image or another type.
FeatureSet detectFeatures(const cv::Mat& image, const FeatureMatchingOptions& options = {});

/// Matches a's features to b's: nearest neighbours by brute force, Lowe's ratio test, and the
/// mutual check when options.mutual_check. Matches are ordered by index_a; each index_b appears at
/// most once when the mutual check is on. An empty set on either side gives no matches. Throws
/// InvalidOptions for invalid options, CheckError when the two sets hold different descriptors
/// (kind or descriptor length).
std::vector<FeatureMatch> matchFeatures(const FeatureSet& a, const FeatureSet& b,
                                        const FeatureMatchingOptions& options = {});

}  // namespace curvesfm
