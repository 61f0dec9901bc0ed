#include "frontend/image/image_undistorter.h"

#include <opencv2/imgproc.hpp>
#include <string>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// For every pixel of the pinhole image, where its ray meets the distorted source image.
void sourcePositions(const Camera& source, cv::Mat* map_x, cv::Mat* map_y) {
  const int width = source.width();
  const int height = source.height();
  map_x->create(height, width, CV_32FC1);
  map_y->create(height, width, CV_32FC1);
  for (int v = 0; v < height; ++v) {
    float* x = map_x->ptr<float>(v);
    float* y = map_y->ptr<float>(v);
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector2d normalized((u - source.cx()) / source.fx(),
                                       (v - source.cy()) / source.fy());
      const Eigen::Vector2d distorted = source.distortNormalized(normalized);
      x[u] = static_cast<float>(source.fx() * distorted.x() + source.cx());
      y[u] = static_cast<float>(source.fy() * distorted.y() + source.cy());
    }
  }
}

// 255 where the source position lies inside the source image, shrunk by `margin` px; the outer
// border of the output counts as valid, since there the image itself ends.
cv::Mat validRegion(const cv::Mat& map_x, const cv::Mat& map_y, int margin) {
  const float max_x = static_cast<float>(map_x.cols - 1);
  const float max_y = static_cast<float>(map_x.rows - 1);
  cv::Mat mask(map_x.size(), CV_8UC1);
  for (int v = 0; v < mask.rows; ++v) {
    const float* x = map_x.ptr<float>(v);
    const float* y = map_y.ptr<float>(v);
    std::uint8_t* m = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < mask.cols; ++u) {
      m[u] = x[u] >= 0.0f && y[u] >= 0.0f && x[u] <= max_x && y[u] <= max_y ? 255 : 0;
    }
  }
  if (margin > 0) {
    const cv::Mat disc =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin + 1, 2 * margin + 1));
    cv::erode(mask, mask, disc, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(255));
  }
  return mask;
}

}  // namespace

void ImageUndistorterOptions::validate() const {
  const OptionCheck require("ImageUndistorterOptions");
  require(valid_margin_px >= 0 && valid_margin_px <= 100, "valid_margin_px", valid_margin_px,
          "in [0, 100]");
}

ImageUndistorter::ImageUndistorter(const Camera& distorted_camera,
                                   const ImageUndistorterOptions& options)
    : source_(distorted_camera), pinhole_(distorted_camera.withoutDistortion()) {
  options.validate();
  if (isIdentity()) {
    valid_mask_ = cv::Mat(source_.height(), source_.width(), CV_8UC1, cv::Scalar(255));
    return;
  }
  cv::Mat map_x;
  cv::Mat map_y;
  sourcePositions(source_, &map_x, &map_y);
  valid_mask_ = validRegion(map_x, map_y, options.valid_margin_px);
  // Fixed-point tables (1/32 px) make remap about twice as fast as float ones.
  cv::convertMaps(map_x, map_y, map_xy_, map_frac_, CV_16SC2);
}

cv::Mat ImageUndistorter::undistort(const cv::Mat& image) const {
  CURVESFM_CHECK(image.cols == source_.width() && image.rows == source_.height())
      << "image of size " << image.size() << " for a camera of " << source_.width() << " x "
      << source_.height();
  if (isIdentity()) return image;
  cv::Mat undistorted;
  cv::remap(image, undistorted, map_xy_, map_frac_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return undistorted;
}

}  // namespace curvesfm
