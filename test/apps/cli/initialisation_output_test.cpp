// What `run` takes from the initialiser into the hybrid graph: each registered frame's sightings
// keep whether the observation is a descriptor keypoint and its keypoint's size, which the
// keypoint weights (--ba-keypoint-sigma, --ba-keypoint-reference-size) read.
#include "apps/cli/initialisation_output.h"

#include <gtest/gtest.h>

namespace curvesfm {
namespace {

TEST(InitialisedSightings, KeepTheKeypointsAndTheirSizesPerRegisteredFrame) {
  PointInitialisation result;
  result.frames.resize(3);
  result.frames[0].cam_from_world = Pose3();
  result.frames[2].cam_from_world = Pose3();  // Frame 1 is not registered.
  InitialisedPoint point;
  point.observations.push_back({0, Eigen::Vector2d(10.0, 20.0)});
  point.observations.push_back({2, Eigen::Vector2d(30.0, 40.0), /*keypoint=*/true, 6.5});
  result.points = {InitialisedPoint(), point};

  const std::vector<std::vector<PointSighting>> sightings = initialisedSightings(result);
  ASSERT_EQ(sightings.size(), 2u);  // One per registered frame.
  ASSERT_EQ(sightings[0].size(), 1u);
  EXPECT_EQ(sightings[0][0].point, 1);
  EXPECT_FALSE(sightings[0][0].keypoint);
  EXPECT_EQ(sightings[0][0].keypoint_size, 0.0);
  ASSERT_EQ(sightings[1].size(), 1u);
  EXPECT_EQ(sightings[1][0].pixel, Eigen::Vector2d(30.0, 40.0));
  EXPECT_TRUE(sightings[1][0].keypoint);
  EXPECT_EQ(sightings[1][0].keypoint_size, 6.5);
}

}  // namespace
}  // namespace curvesfm
