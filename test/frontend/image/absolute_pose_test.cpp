#include "frontend/image/absolute_pose.h"

#include <gtest/gtest.h>

#include <random>

#include "core/angles.h"
#include "core/errors.h"
#include "core/so3.h"

namespace curvesfm {
namespace {

struct Correspondences {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
};

const Camera& testCamera() {
  static const Camera camera{CameraIntrinsics{}};  // 525 px, 640 x 480.
  return camera;
}

// Points in front of `pose` seen at their projections with 0.5 px noise, a fraction replaced by
// uniform pixels (outliers).
Correspondences makeCorrespondences(const Pose3& cam_from_world, int n, double outliers) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 639), v(0, 479), depth(2, 6), unit(0, 1);
  std::normal_distribution<double> noise(0, 0.5);
  Correspondences c;
  const Pose3 world_from_cam = cam_from_world.inverse();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d pixel(u(rng), v(rng));
    c.points.push_back(world_from_cam * testCamera().unproject(pixel, depth(rng)));
    c.pixels.push_back(unit(rng) < outliers ? Eigen::Vector2d(u(rng), v(rng))
                                            : pixel + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  return c;
}

Pose3 truePose() { return Pose3(so3::exp(Eigen::Vector3d(0.1, -0.2, 0.05)), {0.3, -0.1, 0.5}); }

TEST(AbsolutePose, RegistersThroughAThirdOfOutliers) {
  const Correspondences c = makeCorrespondences(truePose(), 200, 0.3);
  const AbsolutePose result = estimateAbsolutePose(testCamera(), c.points, c.pixels, {});
  ASSERT_TRUE(result.accepted) << toString(result.rejection);
  EXPECT_LT((result.cam_from_world.translation() - truePose().translation()).norm(), 0.01);
  EXPECT_LT(kRadToDeg * result.cam_from_world.rotation().angularDistance(truePose().rotation()),
            0.1);
  EXPECT_GT(result.num_inliers, 120);
  EXPECT_LT(result.num_inliers, 160);
}

TEST(AbsolutePose, IsDeterministic) {
  const Correspondences c = makeCorrespondences(truePose(), 100, 0.4);
  const AbsolutePose a = estimateAbsolutePose(testCamera(), c.points, c.pixels, {});
  const AbsolutePose b = estimateAbsolutePose(testCamera(), c.points, c.pixels, {});
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.cam_from_world.translation(), b.cam_from_world.translation());
}

TEST(AbsolutePose, RejectsTooFewCorrespondencesAndPureNoise) {
  const Correspondences few = makeCorrespondences(truePose(), 20, 0.0);
  EXPECT_EQ(estimateAbsolutePose(testCamera(), few.points, few.pixels, {}).rejection,
            AbsolutePoseRejection::kTooFewMatches);
  const Correspondences noise = makeCorrespondences(truePose(), 200, 1.0);
  const AbsolutePose result = estimateAbsolutePose(testCamera(), noise.points, noise.pixels, {});
  EXPECT_FALSE(result.accepted);
}

TEST(AbsolutePose, RejectsBadOptionsAndMismatchedSizes) {
  AbsolutePoseOptions options;
  options.min_inliers = 3;
  EXPECT_THROW(estimateAbsolutePose(testCamera(), {}, {}, options), InvalidOptions);
  EXPECT_THROW(estimateAbsolutePose(testCamera(), {Eigen::Vector3d::Zero()}, {}, {}), CheckError);
}

}  // namespace
}  // namespace curvesfm
