#include "frontend/image/edge_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// Histogram resolution of the automatic thresholds: 1/16 grey level per pixel is far below the
// noise of any real image, and the largest L2 gradient of an 8-bit image (255 sqrt(2) / 2 = 180
// grey levels per px, with either aperture) stays below kHistogramBins / kBinsPerGreyLevel.
constexpr double kBinsPerGreyLevel = 16.0;
constexpr int kHistogramBins = 4096;

double sobelGain(int aperture) { return aperture == 3 ? 8.0 : 128.0; }

cv::Mat toGrey(const cv::Mat& image) {
  CURVESFM_CHECK(!image.empty()) << "detectEdges needs a non-empty image";
  CURVESFM_CHECK(image.type() == CV_8UC1 || image.type() == CV_8UC3 || image.type() == CV_8UC4)
      << "detectEdges needs a CV_8UC1, CV_8UC3 (BGR) or CV_8UC4 (BGRA) image, got type "
      << image.type();
  if (image.type() == CV_8UC1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.type() == CV_8UC3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  return grey;
}

void gradients(const cv::Mat& grey, const EdgeDetectorOptions& options, EdgeImage* result) {
  // A new matrix: blurring into a header of `grey` would write into the caller's image.
  cv::Mat blurred;
  if (options.blur_sigma_px > 0.0) {
    cv::GaussianBlur(grey, blurred, cv::Size(0, 0), options.blur_sigma_px, options.blur_sigma_px);
  } else {
    blurred = grey;
  }
  result->blurred = blurred;
  if (options.sobel_aperture == 3) {
    // One pass for both derivatives: about half the time of two cv::Sobel calls.
    cv::spatialGradient(blurred, result->grad_x, result->grad_y, 3);
  } else {
    cv::Sobel(blurred, result->grad_x, CV_16S, 1, 0, options.sobel_aperture);
    cv::Sobel(blurred, result->grad_y, CV_16S, 0, 1, options.sobel_aperture);
  }
}

// Histogram of the L2 gradient magnitude over the pixels the mask admits, in bins of
// 1 / kBinsPerGreyLevel grey levels per pixel; returns the number of pixels counted. Every
// second pixel of every second row is enough (76 800 samples at 640 x 480 put the median and the
// 90 % quantile within a fraction of a bin) and a quarter of the cost.
long long magnitudeHistogram(const EdgeImage& result, const cv::Mat& valid_mask,
                             std::vector<int>* histogram) {
  histogram->assign(kHistogramBins, 0);
  int* bins = histogram->data();
  const float scale = static_cast<float>(kBinsPerGreyLevel / result.gain);
  long long counted = 0;
  for (int r = 0; r < result.grad_x.rows; r += 2) {
    const std::int16_t* gx = result.grad_x.ptr<std::int16_t>(r);
    const std::int16_t* gy = result.grad_y.ptr<std::int16_t>(r);
    const std::uint8_t* mask = valid_mask.empty() ? nullptr : valid_mask.ptr<std::uint8_t>(r);
    for (int c = 0; c < result.grad_x.cols; c += 2) {
      if (mask != nullptr && mask[c] == 0) continue;
      const float x = gx[c];
      const float y = gy[c];
      const int bin = static_cast<int>(std::sqrt(x * x + y * y) * scale);
      ++bins[std::min(bin, kHistogramBins - 1)];
      ++counted;
    }
  }
  return counted;
}

// The magnitude (grey levels / px) below which a fraction q of the counted pixels lie,
// interpolated linearly inside its bin.
double histogramQuantile(const std::vector<int>& histogram, long long counted, double q) {
  const double target = q * static_cast<double>(counted);
  double below = 0.0;
  for (int bin = 0; bin < kHistogramBins; ++bin) {
    const double in_bin = histogram[bin];
    if (below + in_bin >= target && in_bin > 0.0) {
      return (bin + (target - below) / in_bin) / kBinsPerGreyLevel;
    }
    below += in_bin;
  }
  return kHistogramBins / kBinsPerGreyLevel;
}

double automaticHighThreshold(const EdgeImage& result, const cv::Mat& valid_mask,
                              const EdgeDetectorOptions& options) {
  std::vector<int> histogram;
  const long long counted = magnitudeHistogram(result, valid_mask, &histogram);
  if (counted == 0) return options.auto_min_high_threshold;
  // Median of a Rayleigh distribution = sigma * sqrt(2 ln 2).
  const double noise_sigma =
      histogramQuantile(histogram, counted, 0.5) / std::sqrt(2.0 * std::log(2.0));
  const double seed_cap =
      histogramQuantile(histogram, counted, 1.0 - options.auto_max_seed_fraction);
  return std::max(
      {options.auto_noise_factor * noise_sigma, seed_cap, options.auto_min_high_threshold});
}

void chooseThresholds(const cv::Mat& valid_mask, const EdgeDetectorOptions& options,
                      EdgeImage* result) {
  double high = options.canny_high_threshold;
  if (high <= 0.0) {
    // A given low threshold above the automatic high one wins: the user asked for it.
    high =
        std::max(automaticHighThreshold(*result, valid_mask, options), options.canny_low_threshold);
  }
  result->high_threshold = high;
  result->low_threshold = options.canny_low_threshold > 0.0 ? options.canny_low_threshold
                                                            : options.auto_low_ratio * high;
}

void applyMask(const cv::Mat& valid_mask, cv::Mat* edges) {
  if (valid_mask.empty()) return;
  for (int r = 0; r < edges->rows; ++r) {
    std::uint8_t* edge = edges->ptr<std::uint8_t>(r);
    const std::uint8_t* mask = valid_mask.ptr<std::uint8_t>(r);
    for (int c = 0; c < edges->cols; ++c) edge[c] = mask[c] == 0 ? 0 : edge[c];
  }
}

}  // namespace

void EdgeDetectorOptions::validate() const {
  const OptionCheck require("EdgeDetectorOptions");
  require(blur_sigma_px >= 0.0 && blur_sigma_px <= 10.0, "blur_sigma_px", blur_sigma_px,
          "in [0, 10]");
  require(sobel_aperture == 3 || sobel_aperture == 5, "sobel_aperture", sobel_aperture,
          "must be 3 or 5");
  require(canny_low_threshold >= 0.0 && canny_low_threshold <= 1e6, "canny_low_threshold",
          canny_low_threshold, "in [0, 1e6]");
  require(canny_high_threshold >= 0.0 && canny_high_threshold <= 1e6, "canny_high_threshold",
          canny_high_threshold, "in [0, 1e6]");
  require(canny_high_threshold == 0.0 || canny_low_threshold <= canny_high_threshold,
          "canny_low_threshold", canny_low_threshold,
          "must be <= canny_high_threshold = " + formatOptionValue(canny_high_threshold));
  require(auto_noise_factor > 0.0 && auto_noise_factor <= 100.0, "auto_noise_factor",
          auto_noise_factor, "in (0, 100]");
  require(auto_max_seed_fraction > 0.0 && auto_max_seed_fraction <= 1.0, "auto_max_seed_fraction",
          auto_max_seed_fraction, "in (0, 1]");
  require(auto_min_high_threshold >= 0.0 && auto_min_high_threshold <= 255.0,
          "auto_min_high_threshold", auto_min_high_threshold, "in [0, 255]");
  require(auto_low_ratio > 0.0 && auto_low_ratio <= 1.0, "auto_low_ratio", auto_low_ratio,
          "in (0, 1]");
}

EdgeImage detectEdges(const cv::Mat& image, const EdgeDetectorOptions& options,
                      const cv::Mat& valid_mask) {
  options.validate();
  const cv::Mat grey = toGrey(image);
  CURVESFM_CHECK(valid_mask.empty() ||
                 (valid_mask.type() == CV_8UC1 && valid_mask.size() == image.size()))
      << "valid_mask must be empty or CV_8UC1 of the image size " << image.size() << ", got type "
      << valid_mask.type() << " size " << valid_mask.size();

  EdgeImage result;
  result.gain = sobelGain(options.sobel_aperture);
  gradients(grey, options, &result);
  chooseThresholds(valid_mask, options, &result);
  cv::Canny(result.grad_x, result.grad_y, result.edges, result.low_threshold * result.gain,
            result.high_threshold * result.gain, /*L2gradient=*/true);
  applyMask(valid_mask, &result.edges);
  return result;
}

}  // namespace curvesfm
