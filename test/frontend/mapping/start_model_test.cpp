#include "frontend/mapping/start_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/point_triangulation.h"
#include "core/so3.h"
#include "sim/point_scene.h"

namespace curvesfm {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;

// Cameras on an arc around a cube of points, undistorted, half a pixel of noise.
PointScene scene() {
  PointSceneOptions o;
  o.num_cameras = 40;
  o.num_points = 1500;
  o.track_length = 8;
  o.pixel_noise = 0.5;
  o.intrinsics.k1 = o.intrinsics.k2 = 0.0;
  return makePointScene(o);
}

// The true poses, each rotated about its own centre by its rotation vector (deg).
std::vector<Pose3> rotated(const PointScene& s, const std::vector<Eigen::Vector3d>& degrees) {
  std::vector<Pose3> poses;
  for (std::size_t i = 0; i < s.true_cam_from_world.size(); ++i) {
    const Pose3& truth = s.true_cam_from_world[i];
    const Eigen::Quaterniond turn = so3::exp(degrees[i] * kRadiansPerDegree);
    const Eigen::Quaterniond rotation = turn * truth.rotation();
    // Same centre c: t = -R c.
    poses.emplace_back(rotation, -(rotation * truth.inverseTranslation()));
  }
  return poses;
}

std::vector<Eigen::Vector3d> independentTurns(int n, double sigma_deg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_deg);
  std::vector<Eigen::Vector3d> turns(n);
  for (Eigen::Vector3d& t : turns) t = {noise(rng), noise(rng), noise(rng)};
  return turns;
}

// A random walk: every step turns by sigma_deg per axis more.
std::vector<Eigen::Vector3d> driftingTurns(int n, double step_deg, unsigned seed) {
  std::vector<Eigen::Vector3d> steps = independentTurns(n, step_deg, seed);
  for (int i = 1; i < n; ++i) steps[i] += steps[i - 1];
  return steps;
}

// What finishAtPoses hands the run: the given poses and the tracks triangulated at them.
PointInitialisation atPoses(const PointScene& s, const std::vector<Pose3>& given) {
  PointInitialisation init;
  init.frames.resize(given.size());
  for (std::size_t i = 0; i < given.size(); ++i) init.frames[i].cam_from_world = given[i];
  std::vector<std::vector<TrackObservation>> tracks(s.true_points.size());
  for (const PointObservation& o : s.observations) {
    tracks[o.point_index].push_back({o.camera_index, o.pixel});
  }
  for (const std::vector<TrackObservation>& track : tracks) {
    if (track.size() < 2) continue;
    std::vector<Pose3> poses;
    std::vector<Eigen::Vector2d> normalized;
    for (const TrackObservation& o : track) {
      poses.push_back(given[o.frame]);
      normalized.push_back(s.camera->pixelToNormalized(o.pixel));
    }
    InitialisedPoint point;
    if (!triangulateDlt(poses, normalized, &point.position)) continue;
    point.observations = track;
    init.points.push_back(point);
  }
  return init;
}

TEST(StartModel, AStartAtTheTruthAgreesWithTheImages) {
  const PointScene s = scene();
  const StartModelEstimate e = estimateStartModel(*s.camera, atPoses(s, s.true_cam_from_world));
  EXPECT_EQ(e.model, StartModel::kConsistent);
  EXPECT_EQ(e.frames_measured, 40);
  EXPECT_LT(e.rotation_rms_deg, 0.03);
}

TEST(StartModel, PosesOffEachOnItsOwnAreCalledPerPoseAtAboutTheirNoise) {
  const PointScene s = scene();
  const std::vector<Pose3> given = rotated(s, independentTurns(40, 0.2, 7));
  const StartModelEstimate e = estimateStartModel(*s.camera, atPoses(s, given));
  EXPECT_EQ(e.model, StartModel::kPerPose);
  // The points share each frame's error over their tracks, so a little less than the noise.
  EXPECT_GT(e.rotation_rms_deg, 0.12);
  EXPECT_LT(e.rotation_rms_deg, 0.22);
  EXPECT_LT(e.variogram_growth, 1.3);
}

TEST(StartModel, ADriftingStartIsNotCalledPerPose) {
  const PointScene s = scene();
  // 0.1 deg per step: after 40 frames the orientation is off by about 0.6 deg per axis.
  const std::vector<Pose3> given = rotated(s, driftingTurns(40, 0.1, 11));
  const StartModelEstimate e = estimateStartModel(*s.camera, atPoses(s, given));
  EXPECT_NE(e.model, StartModel::kPerPose);
  EXPECT_NE(e.model, StartModel::kNotMeasured);
}

TEST(StartModel, EveryStartThatMovesIsTiedPerPoseUnlessADriftIsLeftToTheMotionPrior) {
  StartModelOptions o;
  StartModelEstimate e;
  const auto ties = [&](StartModel model) {
    e.model = model;
    return tiesEachPose(e, o);
  };
  EXPECT_TRUE(ties(StartModel::kPerPose));
  EXPECT_TRUE(ties(StartModel::kDrifting));
  EXPECT_FALSE(ties(StartModel::kConsistent));
  EXPECT_FALSE(ties(StartModel::kNotMeasured));
  o.tie_drifting_per_pose = false;
  EXPECT_TRUE(ties(StartModel::kPerPose));
  EXPECT_FALSE(ties(StartModel::kDrifting));
}

TEST(StartModel, TheStartIsReadOnTheTwoViewPointsWhereTheBAKeepsOthers) {
  const PointScene s = scene();
  const std::vector<Pose3> given = rotated(s, independentTurns(40, 0.1, 11));
  const PointInitialisation two_view = atPoses(s, given);
  // Points at the truth share none of the start's error: read against them, the start moves by
  // all of it (0.105 deg per axis for 0.1 when written); against points triangulated at it, by
  // less (0.096).
  PointInitialisation both = two_view;
  both.points = atPoses(s, s.true_cam_from_world).points;
  both.two_view_points = two_view.points;
  StartModelOptions others;
  others.two_view_points = false;
  const StartModelEstimate expected = estimateStartModel(*s.camera, two_view);
  const StartModelEstimate read = estimateStartModel(*s.camera, both);
  const StartModelEstimate against_others = estimateStartModel(*s.camera, both, others);
  EXPECT_EQ(read.rotation_rms_deg, expected.rotation_rms_deg);
  EXPECT_EQ(read.centre_rms_spacings, expected.centre_rms_spacings);
  EXPECT_NEAR(against_others.rotation_rms_deg, 0.1, 0.015);
  EXPECT_GT(against_others.rotation_rms_deg, read.rotation_rms_deg);
}

TEST(StartModel, TooFewFramesGiveNoVerdict) {
  const PointScene s = scene();
  StartModelOptions o;
  o.min_frames = 41;  // The scene has 40.
  EXPECT_EQ(estimateStartModel(*s.camera, atPoses(s, s.true_cam_from_world), o).model,
            StartModel::kNotMeasured);
}

TEST(StartModel, FramesWithoutNeighboursGiveNoVerdictOnTheKind) {
  const PointScene s = scene();
  PointInitialisation init = atPoses(s, rotated(s, independentTurns(40, 0.2, 7)));
  // Every other frame unposed: no two measured frames are one apart.
  for (std::size_t f = 1; f < init.frames.size(); f += 2) init.frames[f].cam_from_world.reset();
  StartModelOptions o;
  o.min_frames = 10;
  const StartModelEstimate e = estimateStartModel(*s.camera, init, o);
  EXPECT_EQ(e.frames_measured, 20);
  EXPECT_GT(e.rotation_rms_deg, 0.1);  // Measured all the same.
  EXPECT_EQ(e.model, StartModel::kNotMeasured);
}

TEST(StartModel, BadOptionsNameTheField) {
  const auto expectRejected = [](const StartModelOptions& o, const std::string& field) {
    EXPECT_THAT([&] { o.validate(); },
                testing::ThrowsMessage<InvalidOptions>(testing::HasSubstr(field)));
  };
  StartModelOptions o;
  o.max_variogram_growth = 0.0;
  expectRejected(o, "max_variogram_growth");
  o = StartModelOptions();
  o.relift_passes = -1;
  expectRejected(o, "relift_passes");
  o = StartModelOptions();
  o.rotation_prior_sigma_scale = 0.0;
  expectRejected(o, "rotation_prior_sigma_scale");
  o = StartModelOptions();
  o.reassociation_rounds = -2;
  expectRejected(o, "reassociation_rounds");
}

}  // namespace
}  // namespace curvesfm
