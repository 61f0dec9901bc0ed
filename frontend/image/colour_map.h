#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace curvesfm {

/// The overlays' fixed colour map, OpenCV's COLORMAP_TURBO (dark blue, cyan, green, yellow, dark
/// red), at `fraction` of its length: 0 gives its first colour, 1 its last, in 256 steps. Values
/// outside [0, 1] are clipped to the nearer end and NaN gives the first colour, so that a
/// statistic mapped through a fixed range always has a colour. BGR, 0-255 each.
cv::Scalar colourMapBgr(double fraction);

/// What a legend of colourMapBgr says: the bar runs from fraction 0 (left) to 1 (right).
struct ColourLegend {
  std::string title;       ///< The statistic and its unit, e.g. "residual rms (px)". ASCII.
  std::string low_label;   ///< The value at the left end, e.g. "0". ASCII.
  std::string high_label;  ///< The value at the right end, e.g. ">=3". ASCII.
};

/// Draws `legend` in the top-left corner of `image_bgr` (CV_8UC3; CheckError otherwise): the
/// title, the colour bar and its end labels on a darkened box, sized with the image width (the
/// same for every keyframe of a run). Parts beyond a small image's border are cut off. Returns
/// the box, clipped to the image.
cv::Rect drawColourLegend(cv::Mat* image_bgr, const ColourLegend& legend);

}  // namespace curvesfm
