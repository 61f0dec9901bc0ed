#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/nearest_edge_field.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/edge_detector.h"
#include "frontend/image/image_undistorter.h"

namespace curvesfm {

/// The image stage of a keyframe (paper §2.1-2.3): the undistorted image, its Canny edges, their
/// chains and the nearest-edge field. It depends on the image alone, never on a pose or the map,
/// so a caller may prepare a later keyframe's on another thread while bundle adjustment runs
/// (issue 15: the frontend overlapped with BA).
struct KeyframeImage {
  cv::Mat image_bgr;  ///< Undistorted, CV_8UC3.
  /// What the depth search samples: the undistorted grey image after the edge detector's blur
  /// (EdgeImage::blurred), CV_32FC1, converted once here, ahead, instead of for every keyframe that
  /// takes this one as a depth reference.
  cv::Mat grey_float;
  cv::Mat edges;      ///< CV_8UC1, 255 at edge pixels (EdgeImage::edges).
  /// Canny hysteresis thresholds applied (grey levels / px), automatic or given.
  double canny_low_threshold = 0.0;
  double canny_high_threshold = 0.0;
  std::vector<EdgeChain> chains;
  std::shared_ptr<const NearestEdgeField> field;
  // Wall time of each part (s), on whichever thread prepared it.
  double undistort_seconds = 0.0;  ///< Undistortion and grey conversion.
  double edges_seconds = 0.0;      ///< detectEdges, extractEdgeChains, grey_float.
  double field_seconds = 0.0;
};

/// Runs the image stage on a distorted CV_8UC3 BGR image of the undistorter's source camera.
/// Thread-safe: it reads its arguments only. Throws CheckError for an image of another type.
KeyframeImage prepareKeyframeImage(const cv::Mat& image_bgr, const ImageUndistorter& undistorter,
                                   const EdgeDetectorOptions& edges, const EdgeChainOptions& chains,
                                   const NearestEdgeFieldOptions& field);

}  // namespace curvesfm
