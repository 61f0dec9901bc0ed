#pragma once

#include <Eigen/Core>

namespace curvesfm {

/// One image measurement of a 3D point: point `point_index` seen by camera `camera_index` at
/// `pixel` (distorted pixel coordinates, pixel centres at integers).
struct PointObservation {
  int camera_index = 0;
  int point_index = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  /// Detected in its image on its own (a descriptor keypoint), not followed from another image.
  bool keypoint = false;
  /// The keypoint's diameter (px), the scale it was detected at; 0 when not a keypoint.
  double keypoint_size = 0.0;
};

}  // namespace curvesfm
