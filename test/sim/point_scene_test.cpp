#include "sim/point_scene.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace curvesfm {
namespace {

std::string validationMessage(const PointSceneOptions& options) {
  try {
    options.validate();
  } catch (const InvalidOptions& e) {
    return e.what();
  }
  return "valid";
}

TEST(PointSceneOptions, RejectionNamesFieldValueAndConstraint) {
  PointSceneOptions options;
  options.track_length = options.num_cameras + 1;
  EXPECT_NE(validationMessage(options).find("PointSceneOptions.track_length = 51"),
            std::string::npos)
      << validationMessage(options);
  options = PointSceneOptions();
  options.cube_half_size = options.orbit_radius;
  EXPECT_NE(validationMessage(options).find("cube_half_size"), std::string::npos);
  options = PointSceneOptions();
  options.pixel_noise = -1.0;
  EXPECT_NE(validationMessage(options).find("pixel_noise"), std::string::npos);
  EXPECT_EQ(validationMessage(PointSceneOptions()), "valid");
}

TEST(PointScene, SameSeedSameSceneAndObservationsInsideTheImage) {
  PointSceneOptions options;
  options.num_cameras = 6;
  options.num_points = 50;
  options.track_length = 3;
  const PointScene a = makePointScene(options);
  const PointScene b = makePointScene(options);
  ASSERT_EQ(a.observations.size(), b.observations.size());
  EXPECT_EQ(a.observations.front().pixel, b.observations.front().pixel);
  for (const PointObservation& obs : a.observations) {
    EXPECT_TRUE(a.camera->isInImage(obs.pixel));
  }
  // Camera 0 is the gauge: it starts at its true pose.
  EXPECT_EQ(a.initial_cam_from_world[0].translation(), a.true_cam_from_world[0].translation());
}

}  // namespace
}  // namespace curvesfm
