#pragma once

#include <opencv2/core.hpp>

namespace curvesfm {

/// How detectEdges() finds Canny edges. Gradient thresholds are in grey levels per pixel of the
/// blurred image (the Sobel response divided by its gain on a unit ramp, 8 for aperture 3 and
/// 128 for aperture 5), so they do not change with the aperture: OpenCV's customary 50 / 150
/// with aperture 3 and an L2 gradient are 6.25 / 18.75 here.
///
/// Automatic thresholds (canny_high_threshold = 0): at least half the pixels of a frame see no
/// edge, and there the gradient is noise whose magnitude is Rayleigh distributed with scale
/// sigma = median(|g|) / sqrt(2 ln 2). The high threshold is
///   high = max(auto_noise_factor * sigma, quantile(|g|, 1 - auto_max_seed_fraction),
///              auto_min_high_threshold)
/// and the low one auto_low_ratio * high (the ratio MATLAB's edge() uses). With the defaults a
/// noise pixel exceeds the high threshold (6 sigma) with probability exp(-18) and the low one
/// (2.4 sigma) with 0.056, too rarely for noise maxima to link into chains; the quantile caps
/// the fraction of pixels that may seed an edge in a textured frame (on real 640 x 480 photos it
/// usually decides, giving 5-8 % edge pixels), and the floor keeps a noise-free rendering
/// (median 0) from turning quantisation steps into edges.
struct EdgeDetectorOptions {
  /// Standard deviation of the Gaussian blur before differentiation (px); 0 disables the blur.
  /// In [0, 10].
  double blur_sigma_px = 1.0;
  /// Aperture of the Sobel operator (px): 3 or 5 (7 would overflow the CV_16S gradients).
  int sobel_aperture = 3;
  /// Canny hysteresis low threshold (grey levels / px); 0 = auto_low_ratio * high. >= 0, and
  /// <= canny_high_threshold when both are set.
  double canny_low_threshold = 0.0;
  /// Canny hysteresis high threshold (grey levels / px); 0 = automatic (see the struct comment).
  /// >= 0.
  double canny_high_threshold = 0.0;
  /// Automatic high threshold in noise standard deviations of the gradient (unitless);
  /// in (0, 100].
  double auto_noise_factor = 6.0;
  /// Largest fraction of the pixels whose gradient may exceed the automatic high threshold;
  /// in (0, 1].
  double auto_max_seed_fraction = 0.1;
  /// Floor of the automatic high threshold (grey levels / px); in [0, 255].
  double auto_min_high_threshold = 2.0;
  /// Automatic low threshold as a fraction of the high one (unitless); in (0, 1].
  double auto_low_ratio = 0.4;

  /// Throws InvalidOptions naming the first field outside its range.
  void validate() const;
};

/// Canny edges of one image with the gradients they came from, ready for
/// NearestEdgeField::build(edges, grad_x, grad_y) and extractEdgeChains().
struct EdgeImage {
  /// CV_8UC1: 255 at edge pixels (one pixel wide after non-maximum suppression), 0 elsewhere.
  cv::Mat edges;
  /// CV_16SC1 Sobel derivative d/dx of the blurred grey image (raw Sobel units, see `gain`);
  /// (grad_x, grad_y) points from dark to bright.
  cv::Mat grad_x;
  /// CV_16SC1 Sobel derivative d/dy (y down) of the blurred grey image.
  cv::Mat grad_y;
  /// Raw Sobel units per grey level per pixel: 8 (aperture 3) or 128 (aperture 5).
  double gain = 8.0;
  /// Hysteresis thresholds actually applied (grey levels / px), automatic or given.
  double low_threshold = 0.0;
  double high_threshold = 0.0;
  /// CV_8UC1: the grey image the gradients were taken of, after the Gaussian blur (the grey image
  /// itself, shared, when blur_sigma_px is 0).
  cv::Mat blurred;
};

/// Canny edge detection (paper §2.3): grey conversion, Gaussian blur, Sobel gradients, hysteresis
/// thresholds (given or automatic, see EdgeDetectorOptions) with the L2 gradient magnitude.
///
/// `image`: CV_8UC1 grey, CV_8UC3 BGR or CV_8UC4 BGRA, not empty. Distortion is not handled here:
/// pass an image undistorted by ImageUndistorter so that every edge pixel obeys its pinhole camera.
/// `valid_mask` (optional): CV_8UC1 of the image size; pixels where it is 0 carry no edge and do
/// not enter the automatic thresholds (e.g. ImageUndistorter::validMask()).
/// Throws InvalidOptions on bad options, CheckError on a bad image or mask. Allocates the result;
/// everything per pixel runs without allocation.
EdgeImage detectEdges(const cv::Mat& image, const EdgeDetectorOptions& options = {},
                      const cv::Mat& valid_mask = cv::Mat());

}  // namespace curvesfm
