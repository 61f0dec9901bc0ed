#pragma once

#include <opencv2/core.hpp>

#include "core/camera.h"

namespace curvesfm {

/// How ImageUndistorter marks the pixels that have no source data.
struct ImageUndistorterOptions {
  /// Width of the band along the border of the valid region that validMask() also excludes
  /// (px): there the blur and Sobel kernels of edge detection read replicated border pixels.
  /// In [0, 100].
  int valid_margin_px = 3;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// Removes lens distortion from the images of one camera, so that the rest of the pipeline sees
/// a pinhole camera.
///
/// Why images and not edge pixels: the nearest-edge field, the chains, the depth search along
/// epipolar lines and the appearance checks all work on the pixel grid, and an undistorted edge
/// pixel would fall between grid points. Undistorting each image once (a table look-up per
/// pixel, about 2 ms for a BGR image at 640 x 480 on one core) gives every later stage one model:
/// camera(), a pinhole camera with the source camera's K and size and no distortion. Keeping K
/// (rather than a rescaled "optimal" matrix) keeps the scale of pixels, so thresholds in px mean
/// the same with or without distortion. The price: with barrel distortion (k1 < 0) the rim of the
/// source image falls outside the output and is lost; with pincushion distortion (k1 > 0) output
/// pixels near the corners have no source data. Those are filled by replicating the nearest border
/// pixel, which creates no strong artificial step, and validMask() marks them so that
/// detectEdges() ignores them.
///
/// The tables are built once from Camera::distortNormalized, i.e. from exactly the model that
/// Camera::project uses, so the undistorted image of a point lands where camera().project() puts
/// it (to the 1/32 px of OpenCV's fixed-point tables plus the bilinear interpolation). Immutable
/// after construction; undistort() is thread-safe.
class ImageUndistorter {
 public:
  /// Throws InvalidOptions on bad options.
  explicit ImageUndistorter(const Camera& distorted_camera,
                            const ImageUndistorterOptions& options = {});

  /// The camera the input images come from.
  const Camera& sourceCamera() const { return source_; }
  /// The pinhole camera (same K and size, no distortion) of the undistorted images: the one to
  /// use for everything downstream of undistort().
  const Camera& camera() const { return pinhole_; }
  /// True if the source camera has no distortion; undistort() then returns its input unchanged.
  bool isIdentity() const { return !source_.hasDistortion(); }

  /// CV_8UC1 of the image size: 255 where the undistorted image holds data at least
  /// valid_margin_px away from the border of the data, 0 elsewhere (all 255 without distortion).
  const cv::Mat& validMask() const { return valid_mask_; }

  /// The undistorted image (bilinear interpolation). `image` must have the camera's size; any
  /// OpenCV depth and channel count remap accepts. Without distortion returns `image` itself (no
  /// copy). Throws CheckError on a size mismatch.
  cv::Mat undistort(const cv::Mat& image) const;

 private:
  Camera source_;
  Camera pinhole_;
  cv::Mat map_xy_;    // CV_16SC2 integer source positions (fixed-point tables of cv::remap).
  cv::Mat map_frac_;  // CV_16UC1 interpolation table indices.
  cv::Mat valid_mask_;
};

}  // namespace curvesfm
