#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace curvesfm {

/// Per pixel of a keyframe, the depth of the nearest curve whose projection passes within
/// `half_width` px of it (a square), +infinity where none. Re-association asks it whether a
/// segment lies behind another curve (an occluder, nearer) or on a duplicate at its own depth
/// (PipelineOptions::reassociation_skip_occluded).
class NearestCurveDepths {
 public:
  /// `occluder_depth_ratio` in (0, 1]: a curve hides a point whose depth exceeds its own by more
  /// than 1 / ratio.
  NearestCurveDepths(int width, int height, int half_width, double occluder_depth_ratio);

  /// Adds a projected curve: pixel vertices with their depths, linear in between. Pieces are
  /// clipped to the image and its band, so a projection that runs far outside costs nothing there.
  void add(const std::vector<cv::Point>& polyline, const std::vector<double>& depths);

  /// Fraction of the vertices that lie behind a curve nearer than the ratio times their own depth
  /// (vertices outside the image are never hidden); 0 for an empty polyline.
  double fractionOccluded(const std::vector<cv::Point>& polyline,
                          const std::vector<double>& depths) const;

  /// The nearest depth at a pixel inside the image (+infinity where no curve passes).
  float depthAt(const cv::Point& pixel) const { return depth_(pixel); }

 private:
  void stamp(const cv::Point& centre, float depth);

  cv::Mat1f depth_;
  int half_width_;
  double occluder_depth_ratio_;
};

}  // namespace curvesfm
