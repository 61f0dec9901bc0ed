#include "frontend/mapping/keyframe_selector.h"

#include <gtest/gtest.h>

#include <cmath>

namespace curvesfm {
namespace {

TEST(KeyframeSelector, SelectsByTranslationOrRotation) {
  CurveMapOptions options;
  options.min_keyframe_translation = 0.01;
  options.min_keyframe_rotation_deg = 2.0;
  KeyframeSelector selector(options);
  const Pose3 origin;
  EXPECT_TRUE(selector.isKeyframe(origin));
  EXPECT_FALSE(selector.isKeyframe(Pose3(Eigen::Matrix3d::Identity(), {0.005, 0, 0})));
  EXPECT_TRUE(selector.isKeyframe(Pose3(Eigen::Matrix3d::Identity(), {0.0135, 0, 0})));
  // Measured from the last keyframe (x = 0.0135), not the first.
  EXPECT_FALSE(selector.isKeyframe(Pose3(Eigen::Matrix3d::Identity(), {0.02, 0, 0})));
  const Eigen::Matrix3d turned =
      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_TRUE(selector.isKeyframe(Pose3(turned, {0.0135, 0, 0})));
}

TEST(KeyframeSelector, ZeroThresholdsTakeEveryFrame) {
  CurveMapOptions options;
  options.min_keyframe_translation = 0.0;
  options.min_keyframe_rotation_deg = 0.0;
  KeyframeSelector selector(options);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(selector.isKeyframe(Pose3()));
}

}  // namespace
}  // namespace curvesfm
