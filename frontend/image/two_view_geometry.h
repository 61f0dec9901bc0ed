#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"

namespace curvesfm {

// Two-view geometry for the point-based initialiser (issue 13): the relative motion of two frames
// of one calibrated camera from pixel matches alone, accepted only when the images decide it.
//
// Steps, each anchored in a public system (../shared/reviews/initialiser_anchors.md A.1, A.2,
// A.5 items 3 and 4):
//  1. Fit the essential matrix E and the homography H on the same matches (OpenCV USAC, seeded).
//  2. Score both ORB-SLAM's way over every match: H by symmetric transfer error, E (as the
//     fundamental matrix K^-T E K^-1) by point-to-epipolar-line distance, each direction adding
//     5.991 - chi^2 when chi^2 = d^2 / sigma^2 is below its inlier bound (5.991 for H, 3.841 for
//     E, so both are scored on one scale). A match is an inlier of a model when both its
//     directions are under the bound: both models count inliers under one noise model, whatever
//     USAC's own error measure (its mask is not used).
//  3. Select H when R_H = S_H / (S_H + S_E) > homography_score_ratio (ORB-SLAM: 0.40 in ORB2,
//     0.50 in ORB3) or when H has more than homography_inlier_ratio times E's inliers
//     (COLMAP's planar/panoramic rule, 0.8); else E.
//  4. Pure rotation: the rotation nearest to K^-1 H K (R = U V^T of its SVD) transfers at least
//     pure_rotation_fraction of the selected model's inliers within H's inlier bound (2.45 sigma,
//     step 2). Then no translation is observable (COLMAP's "panoramic"), and the pair is rejected
//     whichever model won: an initialiser must keep looking (ORB-SLAM2 #55, #262).
//  5. Decompose: E into its four (R, t) hypotheses (cv::decomposeEssentialMat), H into up to four
//     (R, t, n) (cv::decomposeHomographyMat). Each hypothesis triangulates the selected model's
//     inliers (linear DLT on normalized coordinates) and counts the points that pass the gates:
//     finite, depth > Camera::kMinDepth in both frames, reprojection error at most
//     max_reprojection_error_px in both images. The winner (most points) is refined by ten damped
//     Gauss-Newton steps on the Sampson error of its points (E = [t]x R for either model; it only
//     polishes the minimal-sample fit, two-view bundle adjustment follows in the initialiser) and
//     re-triangulated; the refinement is kept when it keeps at least as many points. The vote
//     itself compares the unrefined hypotheses.
//  6. Accept only (ORB-SLAM's CheckRT / ReconstructF / ReconstructH) when, checked in this order,
//     - the winner triangulates >= max(min_triangulated_points,
//       min_triangulated_fraction x inliers) points (ORB-SLAM: 50 and 0.9); else too_few_points;
//     - it is the one clear winner: no other hypothesis counts more than clear_winner_ratio x its
//       vote (ORB-SLAM: 0.7 for E, 0.75 for H); else ambiguous_decomposition;
//     - the parallax_rank-th largest triangulation angle is >= min_parallax_deg (ORB-SLAM: the
//       51st largest above 1 deg) and the median angle >= min_median_parallax_deg (COLMAP's
//       initial pair: 16 deg; off by default, for a pair search to set); else low_parallax.
//
// Planar scenes: a homography's decomposition leaves two solutions (the "twins") whenever every
// point lies in front of both cameras under both. Then the cheirality vote has no clear winner
// and the pair is rejected as ambiguous_decomposition, as ORB-SLAM refuses it (its winner would
// be a coin toss: in the tests the first-found twin is 12 deg off). In the tests this happens when
// the camera moves towards the plane; a sideways baseline puts about half of the points behind a
// camera under the wrong twin, and the pair is accepted with the right motion. This function never
// guesses between twins.
//
// Frames and units: pixels are undistorted pinhole pixels of `camera` (its K; distortion must
// already be removed), pixel centres at integers. cam_b_from_cam_a maps points of frame a into
// frame b, x_b = R x_a + t, with |t| = 1 (the scale is unobservable); points are in frame a in the
// same unit (the baseline is 1).

/// The model that explains the matches.
enum class TwoViewModel { kNone, kEssential, kHomography };

template <>
struct EnumNames<TwoViewModel> {
  static constexpr std::array<std::pair<TwoViewModel, const char*>, 3> kNames = {
      {{TwoViewModel::kNone, "none"},
       {TwoViewModel::kEssential, "essential"},
       {TwoViewModel::kHomography, "homography"}}};
};

/// Why a pair was not accepted.
enum class TwoViewRejection {
  kNone,                    ///< Accepted.
  kTooFewMatches,           ///< Fewer than min_matches correspondences.
  kNoModel,                 ///< Neither E nor H could be fitted (degenerate data).
  kPureRotation,            ///< A rotation alone explains the inliers: no baseline.
  kAmbiguousDecomposition,  ///< Another hypothesis counts > clear_winner_ratio x the best.
  kTooFewPoints,            ///< The winner triangulates too few of the inliers.
  kLowParallax,             ///< The triangulation angles are too small.
};

template <>
struct EnumNames<TwoViewRejection> {
  static constexpr std::array<std::pair<TwoViewRejection, const char*>, 7> kNames = {
      {{TwoViewRejection::kNone, "none"},
       {TwoViewRejection::kTooFewMatches, "too_few_matches"},
       {TwoViewRejection::kNoModel, "no_model"},
       {TwoViewRejection::kPureRotation, "pure_rotation"},
       {TwoViewRejection::kAmbiguousDecomposition, "ambiguous_decomposition"},
       {TwoViewRejection::kTooFewPoints, "too_few_points"},
       {TwoViewRejection::kLowParallax, "low_parallax"}}};
};

/// The robust score of OpenCV's USAC for both fits.
enum class TwoViewRobustScore { kMsac, kMagsac };

template <>
struct EnumNames<TwoViewRobustScore> {
  static constexpr std::array<std::pair<TwoViewRobustScore, const char*>, 2> kNames = {
      {{TwoViewRobustScore::kMsac, "msac"}, {TwoViewRobustScore::kMagsac, "magsac"}}};
};

/// Thresholds of the fits, the model selection and the acceptance (see the file comment for the
/// anchors of each default).
struct TwoViewOptions {
  /// Fewest correspondences worth fitting (count); fewer reject as too_few_matches. >= 8.
  int min_matches = 50;
  /// Robust score of both USAC fits: MSAC (truncated quadratic) or MAGSAC++ (marginalised over
  /// the noise scale).
  TwoViewRobustScore robust_score = TwoViewRobustScore::kMsac;
  /// Inlier threshold of both USAC fits (px; OpenCV's error measure for E and H). The reported
  /// inliers follow score_sigma_px. Finite, > 0.
  double ransac_threshold_px = 1.5;
  /// RANSAC confidence (probability of one all-inlier sample). In (0, 1).
  double confidence = 0.999;
  /// Most RANSAC iterations per fit (count). >= 1.
  int max_iterations = 5000;
  /// Seed of USAC's random generator: the same seed and input give the same result bit for bit.
  /// >= 0.
  int seed = 0;
  /// Standard deviation sigma of a match's pixel noise used by the ORB-SLAM scores and inliers
  /// (px; ORB-SLAM 1): E inliers within 1.96 sigma of both epipolar lines, H inliers within
  /// 2.45 sigma after transfer both ways. Finite, > 0.
  double score_sigma_px = 1.0;
  /// Select H when S_H / (S_H + S_E) exceeds this (unitless; ORB-SLAM 0.40-0.50). In [0, 1];
  /// 1 never selects H by score.
  double homography_score_ratio = 0.45;
  /// Select H when its inliers exceed this times E's (unitless; COLMAP 0.8). Finite,
  /// > 0; above 1 only a strictly better H wins.
  double homography_inlier_ratio = 0.8;
  /// Reject as pure rotation when the rotation nearest the homography transfers at least this
  /// fraction of the selected model's inliers within H's inlier bound, 2.45 score_sigma_px
  /// (unitless). In (0, 1].
  double pure_rotation_fraction = 0.9;
  /// A decomposition is ambiguous when a second hypothesis triangulates more than this fraction
  /// of the winner's points (unitless; ORB-SLAM 0.7 for E, 0.75 for H). In (0, 1).
  double clear_winner_ratio = 0.7;
  /// Fewest points the winner must triangulate (count; ORB-SLAM 50). >= 1.
  int min_triangulated_points = 50;
  /// Fewest points the winner must triangulate as a fraction of the model's inliers (unitless;
  /// ORB-SLAM 0.9). In [0, 1].
  double min_triangulated_fraction = 0.9;
  /// Largest reprojection error of a triangulated point in either image (px; ORB-SLAM 2 sigma).
  /// Finite, > 0.
  double max_reprojection_error_px = 2.0;
  /// Which largest triangulation angle the parallax gate reads (rank, 1 = the largest; ORB-SLAM
  /// 51); with fewer points, the smallest. >= 1.
  int parallax_rank = 51;
  /// Smallest accepted parallax_rank-th largest triangulation angle (deg; ORB-SLAM 1). In
  /// [0, 90).
  double min_parallax_deg = 1.0;
  /// Smallest accepted median triangulation angle (deg; COLMAP's initial pair 16, 0 = off). In
  /// [0, 90).
  double min_median_parallax_deg = 0.0;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// What estimateTwoViewGeometry found. Plain data; every field is filled, accepted or not, as far
/// as the steps went (scores and inliers after the fits, the pose and points after the
/// decomposition), so a caller can report why a pair failed.
struct TwoViewGeometry {
  bool accepted = false;                                 ///< All gates passed.
  TwoViewRejection rejection = TwoViewRejection::kNone;  ///< First failed gate; none if accepted.
  TwoViewModel model = TwoViewModel::kNone;              ///< Selected model.
  Pose3 cam_b_from_cam_a;             ///< Relative motion, unit-norm translation (see header).
  std::vector<std::uint8_t> inliers;  ///< Per match, 1 if an inlier of the selected model.
  int num_inliers = 0;                ///< Inliers of the selected model.
  int num_essential_inliers = 0;      ///< Inliers of E by its score (step 2).
  int num_homography_inliers = 0;     ///< Inliers of H by its score (step 2).
  double essential_score = 0.0;       ///< ORB-SLAM score S_E (unitless, >= 0).
  double homography_score = 0.0;      ///< ORB-SLAM score S_H (unitless, >= 0).
  std::vector<Eigen::Vector3d> points_in_cam_a;  ///< Triangulated points of the winner, frame a.
  std::vector<int> point_indices;                ///< Index of the match of each point.
  std::vector<int> hypothesis_votes;  ///< Points each decomposition hypothesis triangulates.
  double median_parallax_deg = 0.0;   ///< Median triangulation angle of the points (deg).
  double ranked_parallax_deg = 0.0;   ///< The parallax_rank-th largest angle (deg).
};

/// Relative motion of frames a and b of `camera` from matches a[i] <-> b[i] (pixels, see the
/// file comment). Never throws on degenerate data: it rejects with a reason. Throws
/// InvalidOptions for bad options and CheckError when a and b differ in size.
TwoViewGeometry estimateTwoViewGeometry(const Camera& camera, const std::vector<Eigen::Vector2d>& a,
                                        const std::vector<Eigen::Vector2d>& b,
                                        const TwoViewOptions& options);

}  // namespace curvesfm
