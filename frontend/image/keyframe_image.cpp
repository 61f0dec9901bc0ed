#include "frontend/image/keyframe_image.h"

#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/clock.h"

namespace curvesfm {

KeyframeImage prepareKeyframeImage(const cv::Mat& image_bgr, const ImageUndistorter& undistorter,
                                   const EdgeDetectorOptions& edges, const EdgeChainOptions& chains,
                                   const NearestEdgeFieldOptions& field) {
  CURVESFM_CHECK(image_bgr.type() == CV_8UC3)
      << "expected a CV_8UC3 BGR image, found type " << image_bgr.type() << " ("
      << image_bgr.channels() << " channels)";
  KeyframeImage prepared;
  Clock::time_point start = Clock::now();
  // A copy: undistort() returns its input unchanged when the camera has no distortion, and the
  // caller's buffer must not be shared with the map.
  prepared.image_bgr = undistorter.undistort(image_bgr).clone();
  cv::Mat grey;
  cv::cvtColor(prepared.image_bgr, grey, cv::COLOR_BGR2GRAY);
  prepared.undistort_seconds = secondsSince(start);

  start = Clock::now();
  const EdgeImage edge_image = detectEdges(grey, edges, undistorter.validMask());
  prepared.chains = extractEdgeChains(edge_image, chains);
  prepared.edges = edge_image.edges;
  prepared.canny_low_threshold = edge_image.low_threshold;
  prepared.canny_high_threshold = edge_image.high_threshold;
  edge_image.blurred.convertTo(prepared.grey_float, CV_32F);
  prepared.edges_seconds = secondsSince(start);

  start = Clock::now();
  prepared.field = std::make_shared<const NearestEdgeField>(
      NearestEdgeField::build(edge_image.edges, edge_image.grad_x, edge_image.grad_y, field));
  prepared.field_seconds = secondsSince(start);
  return prepared;
}

}  // namespace curvesfm
