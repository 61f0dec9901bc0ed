#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace curvesfm::testing {

/// Draws `count` filled rectangles with sides in [min_side, max_side) px at random places of
/// `texture`, in random grey levels.
inline void drawRandomRectangles(cv::Mat* texture, cv::RNG* rng, int count, int min_side,
                                 int max_side) {
  for (int i = 0; i < count; ++i) {
    const cv::Point a(rng->uniform(0, texture->cols), rng->uniform(0, texture->rows));
    const cv::Point b(a.x + rng->uniform(min_side, max_side),
                      a.y + rng->uniform(min_side, max_side));
    cv::rectangle(*texture, a, b, cv::Scalar(rng->uniform(0, 256)), cv::FILLED);
  }
}

/// A 640x480 grey texture of many small filled rectangles and discs in random grey levels (fixed
/// seed) on a mid-grey ground: corners and blobs everywhere, so that every grid cell of a view has
/// something to track and SIFT and ORB find features all over it.
inline cv::Mat denseTexture() {
  cv::Mat texture(480, 640, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(11);
  drawRandomRectangles(&texture, &rng, 400, 8, 40);
  for (int i = 0; i < 150; ++i) {
    cv::circle(texture, {rng.uniform(0, 640), rng.uniform(0, 480)}, rng.uniform(4, 20),
               cv::Scalar(rng.uniform(0, 256)), cv::FILLED, cv::LINE_AA);
  }
  return texture;
}

}  // namespace curvesfm::testing
