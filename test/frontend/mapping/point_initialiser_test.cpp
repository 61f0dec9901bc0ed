#include "frontend/mapping/point_initialiser.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "factors/point_bundle_adjustment.h"
#include "sim/point_scene.h"

namespace curvesfm {
namespace {

// Noise-free observations of a cube of points from an arc of undistorted cameras, as an
// initialisation at the true poses whose observations are moved by `shift` (px).
struct ShiftedScene {
  PointScene scene;
  PointInitialisation result;
};

ShiftedScene atTruth(const Eigen::Vector2d& shift) {
  PointSceneOptions o;
  o.num_cameras = 8;
  o.num_points = 300;
  o.track_length = 4;
  o.pixel_noise = 0.0;
  o.intrinsics.k1 = o.intrinsics.k2 = 0.0;
  ShiftedScene s{makePointScene(o), {}};
  s.result.frames.resize(s.scene.true_cam_from_world.size());
  for (std::size_t i = 0; i < s.result.frames.size(); ++i) {
    s.result.frames[i].cam_from_world = s.scene.true_cam_from_world[i];
  }
  s.result.points.resize(s.scene.true_points.size());
  for (std::size_t p = 0; p < s.result.points.size(); ++p) {
    s.result.points[p].position = s.scene.true_points[p];
  }
  for (const PointObservation& obs : s.scene.observations) {
    s.result.points[obs.point_index].observations.push_back(
        {obs.camera_index, obs.pixel + shift});
  }
  return s;
}

TEST(ReprojectionSummary, TrueNoiseFreeObservationsHaveNoResidual) {
  const ShiftedScene s = atTruth(Eigen::Vector2d::Zero());
  const ReprojectionSummary r = reprojectionSummary(*s.scene.camera, s.result);
  EXPECT_EQ(r.observations, static_cast<int>(s.scene.observations.size()));
  EXPECT_LT(r.mean_px.norm(), 1e-9);
  EXPECT_LT(r.rms_px, 1e-9);
}

TEST(ReprojectionSummary, AShiftOfEveryObservationIsTheMeanResidual) {
  const ShiftedScene s = atTruth(Eigen::Vector2d(0.3, -0.2));
  const ReprojectionSummary r = reprojectionSummary(*s.scene.camera, s.result);
  EXPECT_NEAR(r.mean_px.x(), 0.3, 1e-9);
  EXPECT_NEAR(r.mean_px.y(), -0.2, 1e-9);
  EXPECT_NEAR(r.rms_px, std::hypot(0.3, 0.2), 1e-9);
}

TEST(ReprojectionSummary, SkipsUnposedFramesAndPointsBehindTheCamera) {
  ShiftedScene s = atTruth(Eigen::Vector2d(1.0, 1.0));
  int in_frame_0 = 0;
  for (const PointObservation& obs : s.scene.observations) in_frame_0 += obs.camera_index == 0;
  ASSERT_GT(in_frame_0, 0);
  s.result.frames[0].cam_from_world.reset();
  // A point seen in another frame too, mirrored through that frame's camera centre: behind it.
  InitialisedPoint* behind = nullptr;
  int other_frame = -1;
  for (InitialisedPoint& point : s.result.points) {
    for (const TrackObservation& o : point.observations) {
      if (o.frame != 0) {
        behind = &point;
        other_frame = o.frame;
        break;
      }
    }
    if (behind) break;
  }
  ASSERT_NE(behind, nullptr);
  const Eigen::Vector3d centre = s.scene.true_cam_from_world[other_frame].inverse().translation();
  behind->position = 2.0 * centre - behind->position;
  int behind_elsewhere = 0;
  for (const TrackObservation& o : behind->observations) behind_elsewhere += o.frame != 0;
  const ReprojectionSummary r = reprojectionSummary(*s.scene.camera, s.result);
  EXPECT_EQ(r.observations,
            static_cast<int>(s.scene.observations.size()) - in_frame_0 - behind_elsewhere);
}

TEST(ReprojectionSummary, NothingObservedGivesZeros) {
  const ReprojectionSummary r = reprojectionSummary(Camera(CameraIntrinsics{}), {});
  EXPECT_EQ(r.observations, 0);
  EXPECT_EQ(r.mean_px, Eigen::Vector2d::Zero());
  EXPECT_EQ(r.rms_px, 0.0);
}

// The result's frames as the factor layer's cameras: the posed ones in frame order, the
// observations in unposed frames left out. Here frame 0 unposed: cameras 1-7 of the scene, whose
// observations are all 0.3, -0.2 px off (a noise the residuals tell).
TEST(CentrePrecision, CoversThePosedFramesOnly) {
  ShiftedScene s = atTruth(Eigen::Vector2d(0.3, -0.2));
  s.result.frames[0].cam_from_world.reset();
  PointBundleAdjustmentInput posed{
      s.scene.camera,
      {s.scene.true_cam_from_world.begin() + 1, s.scene.true_cam_from_world.end()},
      s.scene.true_points,
      {}};
  for (const PointObservation& o : s.scene.observations) {
    if (o.camera_index > 0) {
      posed.observations.push_back(
          {o.camera_index - 1, o.point_index, o.pixel + Eigen::Vector2d(0.3, -0.2)});
    }
  }
  const double sigma = estimatedPixelSigma(posed, false);
  const double expected = predictedCentreAte(posed, sigma);
  EXPECT_GT(expected, 0.0);
  const std::optional<CentrePrecision> precision =
      centrePrecision(*s.scene.camera, s.result, false);
  ASSERT_TRUE(precision.has_value());
  EXPECT_NEAR(precision->pixel_sigma, sigma, 1e-12 * sigma);
  EXPECT_NEAR(precision->predicted_ate, expected, 1e-12 * expected);
}

TEST(CentrePrecision, NoneWhereTheResidualsTellNoNoise) {
  const ShiftedScene s = atTruth(Eigen::Vector2d::Zero());
  EXPECT_FALSE(centrePrecision(*s.scene.camera, s.result, true).has_value());
}

}  // namespace
}  // namespace curvesfm
