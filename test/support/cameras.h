#pragma once

#include "core/camera.h"

namespace curvesfm::testing {

/// A distortion-free camera of `width` x `height` px with focal length `focal_px` on both axes
/// and the principal point at the image centre.
inline Camera centredPinhole(double focal_px, int width, int height) {
  CameraIntrinsics k;
  k.fx = k.fy = focal_px;
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  k.width = width;
  k.height = height;
  return Camera(k);
}

}  // namespace curvesfm::testing
