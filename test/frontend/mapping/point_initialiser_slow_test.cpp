#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/errors.h"
#include "core/so3.h"
#include "core/trajectory_evaluation.h"
#include "frontend/mapping/point_initialiser.h"
#include "sim/planar_scene.h"
#include "test/support/textures.h"

namespace curvesfm {
namespace {

// A textured plane seen from the planar protocol's orbit (3 deg of arc between frames): the
// initialiser must find its own pair, register every frame and recover the orbit up to Sim(3).
PlanarScene orbitScene(int frames) {
  PlanarSceneOptions options;
  options.num_frames = frames;
  options.arc_degrees = 3.0 * (frames - 1);
  options.intensity_noise = 0.01;
  return makePlanarScene(testing::denseTexture(), options);
}

PointInitialisation initialise(const PlanarScene& scene, const PointInitialiserOptions& options) {
  PointInitialiser initialiser(*scene.camera, options);
  for (const cv::Mat& image : scene.images) initialiser.addFrame(image);
  return initialiser.finish();
}

std::vector<Pose3> registeredPoses(const PointInitialisation& result) {
  std::vector<Pose3> poses;
  for (const InitialisedFrame& f : result.frames) poses.push_back(*f.cam_from_world);
  return poses;
}

// The initialiser's BAs solve on graph_schur (deterministic for a thread count); its global
// BAs end when their cost stalls, its local BAs run to their tolerances.
TEST(PointInitialiserOptions, GlobalBaEndsWhenItsCostStalls) {
  const PointInitialiserOptions options;
  EXPECT_EQ(options.global_ba.linear_solver, LinearSolver::kGraphSchur);
  EXPECT_EQ(options.local_ba.linear_solver, LinearSolver::kGraphSchur);
  EXPECT_EQ(options.global_ba.stall_iterations, 5);
  EXPECT_EQ(options.local_ba.stall_iterations, 0);
}

TEST(PointInitialiser, RecoversThePlanarOrbitUpToSimilarity) {
  const PlanarScene scene = orbitScene(16);
  const PointInitialisation result = initialise(scene, {});
  ASSERT_EQ(result.registeredFrames(), 16) << result.failure;
  EXPECT_EQ(result.models, 1);
  const TrajectoryErrors errors =
      evaluateTrajectory(scene.true_cam_from_world, registeredPoses(result));
  // The orbit spans about 0.2 m; its poses must come back within a millimetre.
  EXPECT_LT(errors.position_ate_sim3, 1e-3);  // 0.23 mm when written.
  EXPECT_GT(result.points.size(), 200u);
  int observations = 0;
  for (const InitialisedPoint& p : result.points) {
    EXPECT_GE(p.observations.size(), 2u);
    observations += static_cast<int>(p.observations.size());
  }
  // Every observation is in front of its camera, and BA leaves the tracks' own noise.
  EXPECT_EQ(result.reprojection.observations, observations);
  EXPECT_LT(result.reprojection.rms_px, 1.0);
  EXPECT_LT(result.reprojection.mean_px.norm(), 0.1);
  // The points fix the 16 centres (a finite floor) at a noise above what BA left (it fitted the
  // poses and points to the observations); with a bound below the posed frames none is computed.
  ASSERT_TRUE(result.reprojection.precision.has_value());
  EXPECT_GT(result.reprojection.precision->pixel_sigma,
            result.reprojection.rms_px / std::sqrt(2.0));
  EXPECT_GT(result.reprojection.precision->predicted_ate, 0.0);
  EXPECT_TRUE(std::isfinite(result.reprojection.precision->predicted_ate));
  PointInitialiserOptions bounded;
  bounded.precision_max_frames = 16;
  EXPECT_TRUE(initialise(scene, bounded).reprojection.precision.has_value());
  bounded.precision_max_frames = 15;
  EXPECT_FALSE(initialise(scene, bounded).reprojection.precision.has_value());
}

// A camera looking down at a long textured floor flies 0.9 m along it and back, 3 cm to the
// side: the floor's start leaves the view on the way out and comes back on the way home, where
// KLT follows new tracks and the matching window pairs only recent frames, so nothing ties the
// return to the start but loop matches.
struct Corridor {
  std::shared_ptr<const Camera> camera;
  std::vector<cv::Mat> images;
  std::vector<Pose3> true_cam_from_world;
};

Corridor corridorThereAndBack() {
  cv::Mat floor(500, 1600, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(5);
  testing::drawRandomRectangles(&floor, &rng, 1500, 6, 30);
  Corridor c;
  CameraIntrinsics intrinsics;
  intrinsics.width = 320;
  intrinsics.height = 240;
  intrinsics.fx = intrinsics.fy = 262.5;
  intrinsics.cx = 159.5;
  intrinsics.cy = 119.5;
  c.camera = std::make_shared<Camera>(intrinsics);
  const Eigen::Matrix3d down = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  const auto view = [&](double x, double y) {
    const Eigen::Vector3d centre(x, y, 0.5);
    const Pose3 pose(down, -down * centre);
    c.images.push_back(renderPlanarView(floor, 2.0, *c.camera, pose));
    c.true_cam_from_world.push_back(pose);
  };
  for (int i = 0; i <= 18; ++i) view(-0.45 + 0.05 * i, 0.0);
  for (int i = 18; i >= 0; --i) view(-0.45 + 0.05 * i, 0.03);
  return c;
}

int pointsSeenAtBothEnds(const PointInitialisation& result, int frames) {
  int count = 0;
  for (const InitialisedPoint& p : result.points) {
    const auto at_start = [](const TrackObservation& o) { return o.frame < 3; };
    const auto at_end = [frames](const TrackObservation& o) { return o.frame >= frames - 3; };
    count += std::any_of(p.observations.begin(), p.observations.end(), at_start) &&
             std::any_of(p.observations.begin(), p.observations.end(), at_end);
  }
  return count;
}

TEST(PointInitialiser, LoopMatchesTieTheReturnToTheStart) {
  const Corridor corridor = corridorThereAndBack();
  const int frames = static_cast<int>(corridor.images.size());
  const auto initialise = [&corridor](const PointInitialiserOptions& options) {
    PointInitialiser initialiser(*corridor.camera, options);
    for (const cv::Mat& image : corridor.images) initialiser.addFrame(image);
    return initialiser.finish();
  };
  PointInitialiserOptions without;
  without.loops.enabled = false;
  const PointInitialisation plain = initialise(without);
  const PointInitialisation looped = initialise({});
  ASSERT_EQ(plain.registeredFrames(), frames) << plain.failure;
  ASSERT_EQ(looped.registeredFrames(), frames) << looped.failure;
  EXPECT_EQ(pointsSeenAtBothEnds(plain, frames), 0);
  EXPECT_GT(looped.loops.merges, 100);                   // 411 when written.
  EXPECT_GT(pointsSeenAtBothEnds(looped, frames), 100);  // 259 when written.
  // The corridor spans 0.9 m; both come back within a millimetre (0.27 and 0.33 mm when
  // written: rendered views do not drift, so the loop has nothing to take out here).
  EXPECT_LT(
      evaluateTrajectory(corridor.true_cam_from_world, registeredPoses(looped)).position_ate_sim3,
      1e-3);
}

TEST(PointInitialiser, FallbackThresholdRegistersWhatTheFirstRefuses) {
  // PnP's own threshold refuses every frame; the fallback's accepts them all.
  const PlanarScene scene = orbitScene(8);
  PointInitialiserOptions options;
  options.registration.min_inliers = 100000;
  options.max_models = 1;
  EXPECT_EQ(initialise(scene, options).registeredFrames(), 8);
  options.fallback_min_inliers = options.registration.min_inliers;  // No second try.
  EXPECT_EQ(initialise(scene, options).registeredFrames(), 2);
}

// The orbit rendered with the scene's camera, initialised with its focal lengths 5 % too long:
// global BA with a free focal length finds the true one within 0.4 %; held, the camera stays as
// given. (A plane's orbit bends little under the wrong focal length: both trajectories come
// back within a fraction of a millimetre.)
TEST(PointInitialiser, RefinesAFocalLengthGivenRoughly) {
  const PlanarScene scene = orbitScene(16);
  const Camera rough = scene.camera->withFocalScale(1.05);
  const auto initialiseWith = [&](bool refine_focal) {
    PointInitialiserOptions options;
    options.ba.refine_focal = refine_focal;
    PointInitialiser initialiser(rough, options);
    for (const cv::Mat& image : scene.images) initialiser.addFrame(image);
    PointInitialisation result = initialiser.finish();
    EXPECT_NEAR(initialiser.undistortedCamera().fx(), result.focal_scale * rough.fx(), 1e-9);
    return result;
  };
  const PointInitialisation refined = initialiseWith(true);
  const PointInitialisation held = initialiseWith(false);
  ASSERT_EQ(refined.registeredFrames(), 16) << refined.failure;
  ASSERT_EQ(held.registeredFrames(), 16) << held.failure;
  EXPECT_NEAR(refined.focal_scale, 1.0 / 1.05, 0.005);  // 0.9561 when written.
  EXPECT_EQ(held.focal_scale, 1.0);
  EXPECT_LT(
      evaluateTrajectory(scene.true_cam_from_world, registeredPoses(refined)).position_ate_sim3,
      1e-3);
}

// Two orbits over unrelated textures, one after the other: two models that share no point, so
// nothing merges and the longer, first one is written. With a free focal length the second
// model's global BA moves the camera after the first's; the written model must have been refined
// last, under the camera that is written with it.
TEST(PointInitialiser, TheWrittenModelIsRefinedUnderTheWrittenFocalLength) {
  cv::Mat other(480, 640, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(23);
  testing::drawRandomRectangles(&other, &rng, 500, 8, 40);
  PlanarSceneOptions scene_options;
  scene_options.intensity_noise = 0.01;
  scene_options.num_frames = 10;
  scene_options.arc_degrees = 27.0;
  const PlanarScene first = makePlanarScene(testing::denseTexture(), scene_options);
  scene_options.num_frames = 6;
  scene_options.arc_degrees = 15.0;
  const PlanarScene second = makePlanarScene(other, scene_options);
  PointInitialiserOptions options;
  options.ba.refine_focal = true;
  options.loops.enabled = false;  // Its global BAs refine the written model too.
  PointInitialiser initialiser(first.camera->withFocalScale(1.05), options);
  for (const PlanarScene* scene : {&first, &second}) {
    for (const cv::Mat& image : scene->images) initialiser.addFrame(image);
  }
  const PointInitialisation result = initialiser.finish();
  ASSERT_EQ(result.models, 2) << result.failure;
  EXPECT_EQ(result.merged_models, 1);
  EXPECT_EQ(result.registeredFrames(), 10);
  const auto last_global =
      std::find_if(result.bundle_adjustments.rbegin(), result.bundle_adjustments.rend(),
                   [](const InitialiserBundleAdjustment& ba) { return ba.scope == "global"; });
  ASSERT_NE(last_global, result.bundle_adjustments.rend());
  EXPECT_EQ(last_global->model, 0);
  EXPECT_EQ(last_global->frames, 10);
}

TEST(PointInitialiser, ScaleConventionIsMedianDepthOneInThePairsFirstFrame) {
  const PlanarScene scene = orbitScene(10);
  const PointInitialisation result = initialise(scene, {});
  ASSERT_GE(result.registeredFrames(), 2) << result.failure;
  const Pose3& first = *result.frames[result.initial_pair.first].cam_from_world;
  std::vector<double> depths;
  for (const InitialisedPoint& p : result.points) depths.push_back((first * p.position).z());
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  // Set after two-view BA; later BAs move it a little, never far.
  EXPECT_NEAR(depths[depths.size() / 2], 1.0, 0.1);
}

// The true poses of `scene`, each turned about its own centre by a rotation of `sigma_deg` per
// axis, independent per pose (a start off per pose by a few pixels).
std::vector<std::optional<Pose3>> turnedPoses(const PlanarScene& scene, double sigma_deg) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, sigma_deg * M_PI / 180.0);
  std::vector<std::optional<Pose3>> poses;
  for (const Pose3& truth : scene.true_cam_from_world) {
    const Eigen::Quaterniond rotation =
        so3::exp(Eigen::Vector3d(noise(rng), noise(rng), noise(rng))) * truth.rotation();
    poses.emplace_back(Pose3(rotation, -(rotation * truth.inverseTranslation())));
  }
  return poses;
}

PointInitialisation atPoses(const PlanarScene& scene,
                            const std::vector<std::optional<Pose3>>& poses,
                            const PointInitialiserOptions& options) {
  PointInitialiser initialiser(*scene.camera, options);
  for (const cv::Mat& image : scene.images) initialiser.addFrame(image);
  return initialiser.finishAtPoses(poses);
}

TEST(PointInitialiser, TriangulatesTheTracksAtGivenPosesWithoutMovingThem) {
  const PlanarScene scene = orbitScene(8);
  std::vector<std::optional<Pose3>> poses(scene.true_cam_from_world.begin(),
                                          scene.true_cam_from_world.end());
  poses[3].reset();  // A frame without a given pose stays out.
  const PointInitialisation result = atPoses(scene, poses, {});
  EXPECT_EQ(result.registeredFrames(), 7);
  EXPECT_FALSE(result.frames[3].cam_from_world.has_value());
  EXPECT_EQ(result.frames[4].cam_from_world->translation(),
            scene.true_cam_from_world[4].translation());
  EXPECT_EQ(result.frames[4].cam_from_world->rotation().coeffs(),
            scene.true_cam_from_world[4].rotation().coeffs());
  ASSERT_GT(result.points.size(), 200u);
  // The texture lies on the plane z = 0 of the orbit's world (metres, 0.6 m below the cameras):
  // the points must come back on it, in the given poses' unit. Without BA a track of a few 3-deg
  // steps triangulates to a few mm (3.2 mm median when written); a pose misread would be off by
  // the scene's size.
  std::vector<double> heights;
  for (const InitialisedPoint& p : result.points) {
    heights.push_back(std::abs(p.position.z()));
    for (const TrackObservation& o : p.observations) EXPECT_NE(o.frame, 3);
  }
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  EXPECT_LT(heights[heights.size() / 2], 1e-2);
  EXPECT_EQ(result.scale_convention, "the given poses' unit");
  // At the true poses the points fit their tracks; reprojectionSummary itself is tested in
  // point_initialiser_test.cpp.
  EXPECT_GT(result.reprojection.observations, 400);
  EXPECT_LT(result.reprojection.rms_px, 1.0);
}

TEST(PointInitialiser, AtGivenPosesEachPointIsRefinedOverItsViews) {
  const PlanarScene scene = orbitScene(8);
  const std::vector<std::optional<Pose3>> poses = turnedPoses(scene, 0.4);
  PointInitialiserOptions refine;
  refine.refine_at_given_poses = true;
  const PointInitialisation pair = atPoses(scene, poses, {});
  const PointInitialisation refined = atPoses(scene, poses, refine);
  // A point placed by two views carries their errors into every other view's residual; the
  // least squares over all of them fits at least as many observations within the same 4 px, and
  // closer (1.75 against 1.87 px rms when written: the orbit's tracks are 3-4 views long).
  EXPECT_EQ(refined.given_poses_gate_px, 4.0);
  EXPECT_GE(refined.reprojection.observations, pair.reprojection.observations);
  EXPECT_LT(refined.reprojection.rms_px, 0.95 * pair.reprojection.rms_px);
  // The start model's points are the two-view ones, whatever the BA keeps.
  EXPECT_TRUE(pair.two_view_points.empty());
  ASSERT_EQ(refined.two_view_points.size(), pair.points.size());
  for (std::size_t i = 0; i < pair.points.size(); ++i) {
    EXPECT_EQ(refined.two_view_points[i].position, pair.points[i].position);
    EXPECT_EQ(refined.two_view_points[i].observations.size(), pair.points[i].observations.size());
  }
}

TEST(PointInitialiser, TheGateAtGivenPosesFollowsTheirResiduals) {
  const PlanarScene scene = orbitScene(8);
  PointInitialiserOptions options;
  options.refine_at_given_poses = true;
  options.given_poses_gate_scale = 3.0;
  const std::vector<std::optional<Pose3>> truth(scene.true_cam_from_world.begin(),
                                                scene.true_cam_from_world.end());
  const PointInitialisation at_truth = atPoses(scene, truth, options);
  EXPECT_GT(at_truth.given_poses_median_error_px, 0.0);
  EXPECT_LT(at_truth.given_poses_median_error_px, 0.5);
  EXPECT_EQ(at_truth.given_poses_gate_px, options.max_reprojection_error_px);

  const std::vector<std::optional<Pose3>> turned = turnedPoses(scene, 0.6);
  PointInitialiserOptions fixed_gate;
  fixed_gate.refine_at_given_poses = true;
  const PointInitialisation fixed = atPoses(scene, turned, fixed_gate);
  const PointInitialisation following = atPoses(scene, turned, options);
  EXPECT_GT(following.given_poses_gate_px, options.max_reprojection_error_px);
  EXPECT_LE(following.given_poses_gate_px, options.given_poses_max_gate_px);
  EXPECT_NEAR(following.given_poses_gate_px, 3.0 * following.given_poses_median_error_px, 1e-9);
  EXPECT_GT(following.reprojection.observations, fixed.reprojection.observations * 11 / 10);
}

TEST(PointInitialiserOptions, AGivenPosesGateOutOfItsRangeIsRefusedByName) {
  PointInitialiserOptions options;
  options.given_poses_max_gate_px = 3.0;
  EXPECT_THAT([&] { options.validate(); }, ::testing::ThrowsMessage<InvalidOptions>(
                                               ::testing::HasSubstr("given_poses_max_gate_px")));
  options = {};
  options.refine_at_given_poses = true;
  options.given_poses_gate_scale = -1.0;
  EXPECT_THAT([&] { options.validate(); }, ::testing::ThrowsMessage<InvalidOptions>(
                                               ::testing::HasSubstr("given_poses_gate_scale")));
  // The gate follows the refined points' residuals: without them it has none to follow.
  options = {};
  options.given_poses_gate_scale = 3.0;
  EXPECT_THAT([&] { options.validate(); },
              ::testing::ThrowsMessage<InvalidOptions>(
                  ::testing::HasSubstr("0 unless refine_at_given_poses")));
}

TEST(PointInitialiserOptions, ALoopMergeBoundOfZeroIsRefusedByName) {
  PointInitialiserOptions options;
  options.loops.max_merge_error_px = 0.0;
  EXPECT_THAT([&] { options.validate(); },
              ::testing::ThrowsMessage<InvalidOptions>(::testing::HasSubstr("max_merge_error_px")));
}

TEST(PointInitialiserOptions, ANegativePrecisionFrameBoundIsRefusedByName) {
  PointInitialiserOptions options;
  options.precision_max_frames = -1;
  EXPECT_THAT([&] { options.validate(); }, ::testing::ThrowsMessage<InvalidOptions>(
                                               ::testing::HasSubstr("precision_max_frames")));
}

TEST(PointInitialiserOptions, ANegativeTrackingThreadCountIsRefusedByName) {
  PointInitialiserOptions options;
  options.tracking_threads = -1;
  EXPECT_THAT([&] { options.validate(); },
              ::testing::ThrowsMessage<InvalidOptions>(::testing::HasSubstr("tracking_threads")));
}

TEST(PointInitialiser, ATexturelessSequenceFailsWithAReason) {
  PlanarSceneOptions options;
  options.num_frames = 6;
  const PlanarScene scene = makePlanarScene(cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), options);
  const PointInitialisation result = initialise(scene, {});
  EXPECT_EQ(result.registeredFrames(), 0);
  EXPECT_EQ(result.models, 0);
  EXPECT_THAT(result.failure, ::testing::HasSubstr("no initial pair"));
  for (const InitialisedFrame& f : result.frames) {
    EXPECT_NE(f.status, FrameRegistration::kRegistered);
  }
}

}  // namespace
}  // namespace curvesfm
