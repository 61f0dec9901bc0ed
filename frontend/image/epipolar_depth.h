#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera.h"
#include "core/enum_names.h"
#include "core/pose3.h"
#include "frontend/image/edge_chains.h"

namespace curvesfm {

/// How estimateChainDepths() finds the depth of edge pixels by epipolar search (paper §2.3, a
/// variant of Engel et al., "Semi-dense visual odometry for a monocular camera", ICCV 2013).
///
/// Depths are z in the keyframe camera (along the principal axis, as Camera::unproject); the
/// search and all variances work in inverse depth rho = 1 / z, in which the epipolar geometry is
/// linear and image noise is close to Gaussian.
///
/// Lengths are in the unit of the poses given to the functions (metres for these defaults).
/// The pipeline works in multiples of its scene scale instead (PipelineOptions::scene_scale), so
/// its defaults differ: defaultPipelineDepthOptions().
struct EpipolarDepthOptions {
  /// Nearest depth searched (length unit of the poses); finite, > 0.
  double min_depth = 0.2;
  /// Farthest depth searched (length unit of the poses); > min_depth, may be +infinity (the
  /// search then reaches the vanishing point of the pixel's ray).
  double max_depth = 20.0;

  /// A reference frame is eligible only if its baseline b subtends at least this angle at the
  /// mid-range depth: atan(b * rho_mid) >= min_parallax_deg with
  /// rho_mid = (1 / min_depth + 1 / max_depth) / 2 (deg). In [0, 90).
  double min_parallax_deg = 0.5;
  /// ... and only if its optical axis is within this angle of the keyframe's (deg): beyond it the
  /// patches change too much between the views. In (0, 180].
  double max_optical_axis_angle_deg = 30.0;
  /// A reference frame serves a pixel only if the pixel's image gradient is within this angle of
  /// the epipolar line through it (deg). Near 90 deg the edge runs along the epipolar line and
  /// the match slides along it. In [0, 90).
  double max_gradient_epipolar_angle_deg = 70.0;

  /// Half size h of the 1D patch: 2h + 1 samples 1 px apart along the keyframe's epipolar line,
  /// matched against samples along the reference's at the local scale between the views
  /// (samples). 3 (7 samples) halves the median error of 2 on textured planes. In [1, 10].
  int patch_half_size_1d = 3;
  /// Half size of the square 2D patch that disambiguates the 1D minima (px). In [1, 10].
  int patch_half_size_2d = 3;
  /// Number of best local minima of the 1D cost kept for the 2D check (paper: three). In [1, 8].
  int max_candidates = 3;
  /// Compare patches after subtracting their means, which makes the costs insensitive to an
  /// exposure change between the frames.
  bool subtract_patch_mean = true;
  /// A candidate is kept only if its 1D patch, and the match only if its 2D patch too, differ by
  /// at most this root mean square at the refined position (grey levels). In (0, 255].
  double max_patch_rms_grey = 16.0;
  /// A match is ambiguous, and rejected, unless its 2D cost is at most this fraction of the next
  /// best candidate's (unitless). In (0, 1]; 1 keeps every unique best.
  double max_ambiguity_ratio = 0.8;

  /// Standard deviation of the image noise (grey levels); turns the curvature of the matching
  /// cost into a disparity variance. In (0, 255].
  double image_noise_sigma_grey = 2.0;
  /// Standard deviation of the epipolar line's position due to pose error (px); divided by the
  /// cosine of the gradient-epipolar angle it gives the geometric disparity variance. In (0, 100].
  double epipolar_sigma_px = 0.5;
  /// A depth is rejected if its standard deviation in inverse depth exceeds this fraction of the
  /// inverse depth (unitless): too little parallax across the edge. In (0, 10].
  double max_relative_inverse_depth_sigma = 0.1;

  /// Search every k-th pixel of a chain (px), for a k-fold speed-up. The others get the robust
  /// average of their window (marked interpolated), or status kNotSearched when smoothing is off
  /// or unsupported; only about (2 * smoothing_half_window + 1) / k searched depths fall in a
  /// window, so lower min_window_support accordingly. In [1, 16].
  int pixel_step = 1;
  /// Half size of the window along the chain used for the robust average (chain pixels); 0 turns
  /// smoothing and its outlier rejection off. In [0, 15].
  int smoothing_half_window = 3;
  /// A pixel keeps its depth only if its window holds at least this many searched depths within
  /// outlier_sigmas of the window's median, its own included (count).
  /// In [1, 2 * smoothing_half_window + 1].
  int min_window_support = 3;
  /// A depth further than this many of its standard deviations from its window's median (in
  /// inverse depth) is an outlier (unitless). In (0, 100].
  double outlier_sigmas = 3.0;
  /// Threads the chains are split over (count; the result does not depend on it: each chain is
  /// searched on one thread). In [1, 64].
  int num_threads = 1;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// One reference view for the epipolar search.
struct DepthReferenceView {
  /// Grey image, undistorted (ImageUndistorter), of the camera's size: CV_8UC1, or CV_32FC1 of
  /// the same grey levels, which the search then samples without converting it.
  cv::Mat image;
  /// The view's pose (world to camera).
  Pose3 cam_from_world;
};

/// The outcome of one chain pixel; everything but kValid is a rejection.
enum class DepthStatus : std::uint8_t {
  kValid = 0,          ///< depth and variances are set.
  kNotSearched,        ///< skipped by pixel_step and not filled by its window.
  kAtImageBorder,      ///< a patch would leave the keyframe or the reference image.
  kNoReference,        ///< no reference frame is eligible (baseline, optical axis angle).
  kOutOfView,          ///< the depth range projects outside, behind or (at the epipole) onto a
                       ///< point in every eligible reference.
  kEdgeAlongEpipolar,  ///< in every reference that sees it the edge runs along the epipolar line.
  kNoMinimum,          ///< the 1D cost has no local minimum inside the searched segment.
  kAmbiguous,          ///< the 2D check does not single out one of the candidate minima.
  kHighCost,           ///< the best match differs too much (max_patch_rms_grey).
  kHighVariance,       ///< too little parallax across the edge for the precision asked.
  kOutlier,            ///< inconsistent with the robust average of its window.
  kUnsupported,        ///< too few depths in its window (min_window_support).
};
constexpr int kNumDepthStatuses = 12;

template <>
struct EnumNames<DepthStatus> {
  static constexpr std::array<std::pair<DepthStatus, const char*>, 12> kNames = {{
      {DepthStatus::kValid, "valid"},
      {DepthStatus::kNotSearched, "not_searched"},
      {DepthStatus::kAtImageBorder, "at_image_border"},
      {DepthStatus::kNoReference, "no_reference"},
      {DepthStatus::kOutOfView, "out_of_view"},
      {DepthStatus::kEdgeAlongEpipolar, "edge_along_epipolar"},
      {DepthStatus::kNoMinimum, "no_minimum"},
      {DepthStatus::kAmbiguous, "ambiguous"},
      {DepthStatus::kHighCost, "high_cost"},
      {DepthStatus::kHighVariance, "high_variance"},
      {DepthStatus::kOutlier, "outlier"},
      {DepthStatus::kUnsupported, "unsupported"},
  }};
};
static_assert(EnumNames<DepthStatus>::kNames.size() == kNumDepthStatuses,
              "every DepthStatus needs a name");

/// The depth of one chain pixel.
struct PixelDepth {
  /// z of the point in the keyframe camera (length unit of the poses); 0 unless valid.
  double depth = 0.0;
  /// Variance of the inverse depth (m^-2): the disparity variance, photometric
  /// (4 image_noise_sigma_grey^2 / C'', C'' the curvature of the 1D cost at its minimum) plus
  /// geometric ((epipolar_sigma_px / cos(gradient-epipolar angle))^2), over the squared rate of
  /// disparity per inverse depth. 0 unless valid.
  double inverse_depth_variance = 0.0;
  /// Variance of the depth to first order, inverse_depth_variance * depth^4 (m^2).
  double depth_variance = 0.0;
  /// Index into `references` of the view matched against; -1 if none was searched.
  int reference = -1;
  DepthStatus status = DepthStatus::kNotSearched;
  /// True if the pixel was not searched (pixel_step) and its depth is its window's average.
  bool interpolated = false;

  bool valid() const { return status == DepthStatus::kValid; }
};

/// Number of chain pixels per final status.
struct DepthCounts {
  std::array<int, kNumDepthStatuses> by_status{};

  int count(DepthStatus status) const { return by_status[static_cast<int>(status)]; }
  int valid() const { return count(DepthStatus::kValid); }
  int total() const;
};

/// Depths of all chain pixels of one keyframe.
struct ChainDepths {
  /// chains[c][i] belongs to chains[c].pixels[i] of the input.
  std::vector<std::vector<PixelDepth>> chains;
  DepthCounts counts;
};

/// How well a candidate frame serves as the reference of a keyframe's edge pixels.
struct ReferenceCandidate {
  int index = -1;             ///< Index into the candidate list.
  double baseline = 0.0;      ///< Distance between the camera centres (length unit of the poses).
  double parallax_deg = 0.0;  ///< atan(baseline * rho_mid) (deg), see min_parallax_deg.
  double optical_axis_angle_deg = 0.0;  ///< Angle between the optical axes (deg).
  /// Eligible by min_parallax_deg and max_optical_axis_angle_deg.
  bool eligible = false;
  /// Mean over (up to 1024 evenly spread) chain pixels of the cross-edge parallax
  /// cos(angle(gradient, epipolar line)) * |d disparity / d rho| * rho_mid (px), the rate taken
  /// in the middle of the visible part of the pixel's segment: about how far a point at the
  /// mid-range depth moves across its edge between the views, i.e. the depth resolution the
  /// frame offers there. A pixel contributes 0 if its depth range projects outside the frame or
  /// its gradient is beyond max_gradient_epipolar_angle_deg. 0 for ineligible frames.
  double score = 0.0;
};

/// Ranks `candidate_cam_from_world` as reference frames for a keyframe (paper §2.3: "considering
/// the length of the baseline and the parallelism between the epipolar direction and the local
/// image gradient"): eligible frames first, by decreasing score (see ReferenceCandidate), then
/// the ineligible ones in input order. `camera` must have no distortion (undistorted images).
/// Throws InvalidOptions on bad options, CheckError on a distorted camera or malformed chains.
std::vector<ReferenceCandidate> rankReferenceFrames(
    const Pose3& keyframe_cam_from_world, const std::vector<Pose3>& candidate_cam_from_world,
    const Camera& camera, const std::vector<EdgeChain>& chains,
    const EpipolarDepthOptions& options = {});

/// Semi-dense depth of the chain pixels of a keyframe with known poses (paper §2.3). Per pixel:
///  1. Reference: among the eligible `references`, those where the pixel's depth range projects
///     into the image and the gradient-epipolar angle is small enough; the one with the largest
///     cross-edge parallax (ReferenceCandidate::score, evaluated at this pixel) wins.
///  2. 1D search: the mean-free SSD of 2h + 1 samples along the keyframe's epipolar line against
///     the reference's epipolar segment of [min_depth, max_depth], sampled at the local
///     scale between the views so that patches correspond.
///  3. The max_candidates best local minima (non-maximum suppressed within h samples), each
///     refined to sub-pixel by a parabola through its cost and its neighbours'; those whose 1D
///     cost exceeds max_patch_rms_grey are dropped.
///  4. Disambiguation: the 2D patch around the pixel against each refined candidate, warped by
///     the local affine map of the fronto-parallel plane at its depth; the best must beat the
///     runner-up by max_ambiguity_ratio and pass max_patch_rms_grey too.
///  5. Variance: the parabola's curvature gives the photometric disparity variance, the
///     gradient-epipolar angle the geometric one (see PixelDepth); too imprecise depths are
///     rejected (max_relative_inverse_depth_sigma).
///  6. Along each chain: a robust average in inverse depth over a window (median, then the
///     inverse-variance weighted mean of the depths within outlier_sigmas of it); pixels far from
///     the median, or with too little support, are rejected (see EpipolarDepthOptions).
/// The variance kept is the harmonic mean of the window's inlier variances: neighbours share the
/// pose error and overlapping 2D patches, so averaging them is not assumed to reduce it.
///
/// `keyframe_image` and every reference image: grey, undistorted, of the camera's size, CV_8UC1
/// or CV_32FC1 (as DepthReferenceView::image);
/// `camera` without distortion (ImageUndistorter::camera()); each chain's normals are the unit
/// image gradients of the keyframe at its pixels (extractEdgeChains). Chain pixels outside the
/// image are rejected as kAtImageBorder. Chains split over options.num_threads threads, no
/// allocation per pixel. The time per
/// searched pixel grows with its segment, about f * baseline * (1 / min_depth - 1 / max_depth)
/// px: epipolar_depth_bench measures about 2 us per pixel for 100 px segments (pixel_step halves
/// the total).
/// Throws InvalidOptions on bad options, CheckError on bad images, cameras or chains.
ChainDepths estimateChainDepths(const cv::Mat& keyframe_image, const Pose3& keyframe_cam_from_world,
                                const std::vector<EdgeChain>& chains,
                                const std::vector<DepthReferenceView>& references,
                                const Camera& camera, const EpipolarDepthOptions& options = {});

}  // namespace curvesfm
