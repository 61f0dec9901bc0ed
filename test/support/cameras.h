#pragma once

#include <gtest/gtest.h>

#include <string>

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

/// Every field of `read` equals `given`'s to the bit (a writer and its reader round-trip);
/// `context` names the case in a failure.
inline void expectSameIntrinsics(const CameraIntrinsics& read, const CameraIntrinsics& given,
                                 const std::string& context = "") {
  EXPECT_EQ(read.fx, given.fx) << context;
  EXPECT_EQ(read.fy, given.fy) << context;
  EXPECT_EQ(read.cx, given.cx) << context;
  EXPECT_EQ(read.cy, given.cy) << context;
  EXPECT_EQ(read.k1, given.k1) << context;
  EXPECT_EQ(read.k2, given.k2) << context;
  EXPECT_EQ(read.p1, given.p1) << context;
  EXPECT_EQ(read.p2, given.p2) << context;
  EXPECT_EQ(read.k3, given.k3) << context;
  EXPECT_EQ(read.width, given.width) << context;
  EXPECT_EQ(read.height, given.height) << context;
}

}  // namespace curvesfm::testing
