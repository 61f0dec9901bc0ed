#include "factors/point_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "core/so3.h"
#include "sim/point_scene.h"

namespace curvesfm {
namespace {

PointSceneOptions smallScene(double pixel_noise) {
  PointSceneOptions options;
  options.num_cameras = 12;
  options.num_points = 300;
  options.track_length = 6;
  options.pixel_noise = pixel_noise;
  options.seed = 7;
  return options;
}

struct Solved {
  PointSceneErrors before;
  PointSceneErrors after;
  OptimizationSummary summary;
};

Solved solve(const PointScene& scene, OptimizerOptions optimizer = OptimizerOptions()) {
  PointBundleAdjustmentProblem problem =
      buildPointBundleAdjustment({scene.camera, scene.initial_cam_from_world, scene.initial_points,
                                  scene.observations, scene.trueScaleDistance()},
                                 PointBundleAdjustmentOptions());
  Solved solved;
  solved.before = evaluatePointScene(scene, scene.initial_cam_from_world, scene.initial_points);
  solved.summary = optimize(problem.graph, &problem.values, problem.config, optimizer);
  solved.after =
      evaluatePointScene(scene, extractPoses(problem.values, scene.true_cam_from_world.size()),
                         extractPoints(problem.values, scene.true_points.size()));
  return solved;
}

TEST(PointBundleAdjustment, RecoversGroundTruthFromNoiseFreePixels) {
  const PointScene scene = makePointScene(smallScene(0.0));
  OptimizerOptions optimizer;
  optimizer.function_tolerance = 1e-14;
  optimizer.parameter_tolerance = 1e-14;
  optimizer.gradient_tolerance = 1e-14;
  optimizer.max_iterations = 100;
  const Solved solved = solve(scene, optimizer);
  EXPECT_TRUE(solved.summary.usable) << solved.summary.message;
  EXPECT_GT(solved.before.position_rmse, 0.01);
  EXPECT_LT(solved.after.position_rmse, 1e-7);
  EXPECT_LT(solved.after.position_ate_sim3, 1e-7);
  EXPECT_LT(solved.after.rotation_mean_deg, 1e-6);
  EXPECT_LT(solved.after.point_rmse, 1e-7);
  EXPECT_LT(solved.after.reprojection_rmse_px, 1e-6);
}

TEST(PointBundleAdjustment, ConvergesToTheNoiseLevel) {
  const double sigma = 0.5;
  const PointScene scene = makePointScene(smallScene(sigma));
  const Solved solved = solve(scene);
  EXPECT_TRUE(solved.summary.usable) << solved.summary.message;
  // 2-D pixel noise: rms |residual| ~ sigma * sqrt(2) less the DoF the fit absorbs.
  EXPECT_LT(solved.after.reprojection_rmse_px, sigma * std::sqrt(2.0));
  EXPECT_GT(solved.after.reprojection_rmse_px, 0.6 * sigma * std::sqrt(2.0));
  // In the fixed gauge, errors drift along the chain of cameras; the trajectory's shape (ATE
  // after Sim(3) alignment) and the rotations are what the observations pin down.
  EXPECT_LT(solved.after.position_ate_sim3, 0.25 * solved.before.position_ate_sim3);
  EXPECT_LT(solved.after.rotation_mean_deg, 0.2 * solved.before.rotation_mean_deg);
}

TEST(PointBundleAdjustment, HoldsTheGauge) {
  const PointScene scene = makePointScene(smallScene(0.5));
  PointBundleAdjustmentProblem problem =
      buildPointBundleAdjustment({scene.camera, scene.initial_cam_from_world, scene.initial_points,
                                  scene.observations, scene.trueScaleDistance()},
                                 PointBundleAdjustmentOptions());
  EXPECT_TRUE(problem.config.isConstant(poseKey(0)));
  optimize(problem.graph, &problem.values, problem.config, OptimizerOptions());
  const auto poses = extractPoses(problem.values, 2);
  EXPECT_EQ(poses[0].translation(), scene.initial_cam_from_world[0].translation());
  EXPECT_NEAR((poses[1].inverseTranslation() - poses[0].inverseTranslation()).norm(),
              scene.trueScaleDistance(), 1e-3);
}

TEST(PointBundleAdjustment, RejectsOutOfRangeObservationsAndBadOptions) {
  const PointScene scene = makePointScene(smallScene(0.5));
  PointBundleAdjustmentInput input{scene.camera, scene.initial_cam_from_world, scene.initial_points,
                                   scene.observations, 0.0};
  input.observations.push_back({99, 0, Eigen::Vector2d(1, 1)});
  EXPECT_THROW(buildPointBundleAdjustment(input, PointBundleAdjustmentOptions()), CheckError);
  PointBundleAdjustmentOptions bad;
  bad.pixel_sigma = 0.0;
  EXPECT_THROW(bad.validate(), InvalidOptions);
}

// A camera whose focal lengths are 6 % too long: with the focal length free, BA finds the
// true one (the scale factor 1 / 1.06) and the trajectory the true camera gives; held, the
// wrong focal length bends the trajectory.
TEST(PointBundleAdjustment, RefinesAFocalLengthGivenRoughly) {
  PointSceneOptions options = smallScene(0.3);
  options.arc_degrees = 120.0;
  const PointScene scene = makePointScene(options);
  CameraIntrinsics rough = scene.camera->intrinsics();
  rough.fx *= 1.06;
  rough.fy *= 1.06;
  const auto solveWith = [&](bool refine_focal, double* focal_scale) {
    PointBundleAdjustmentOptions ba;
    ba.refine_focal = refine_focal;
    PointBundleAdjustmentProblem problem = buildPointBundleAdjustment(
        {std::make_shared<const Camera>(rough), scene.initial_cam_from_world, scene.initial_points,
         scene.observations, scene.trueScaleDistance()},
        ba);
    const OptimizationSummary summary =
        optimize(problem.graph, &problem.values, problem.config, OptimizerOptions());
    EXPECT_TRUE(summary.usable) << summary.message;
    *focal_scale = extractFocalScale(problem.values);
    return evaluatePointScene(scene, extractPoses(problem.values, scene.true_cam_from_world.size()),
                              extractPoints(problem.values, scene.true_points.size()));
  };
  double refined_scale = 0.0;
  double held_scale = 0.0;
  const PointSceneErrors refined = solveWith(true, &refined_scale);
  const PointSceneErrors held = solveWith(false, &held_scale);
  EXPECT_NEAR(refined_scale, 1.0 / 1.06, 0.003);
  EXPECT_DOUBLE_EQ(held_scale, 1.0);
  EXPECT_LT(refined.position_ate_sim3, 0.5 * held.position_ate_sim3);
  EXPECT_LT(refined.reprojection_rmse_px, held.reprojection_rmse_px);
}

// The prediction against the errors BA leaves: over 20 scenes with fresh pixel noise, the rms of
// the centres' ATE that a BA without robust kernel reaches from a perturbed start, and the rms of
// the predictions at each scene's true poses and points, agree within sampling error (the rms of
// 20 draws of about 50 squared terms each: a few per cent). The noise its residuals tell at the
// optimum, net of what BA fitted, is the noise applied (the plain rms would say 0.87 x).
TEST(PredictedCentreAte, MatchesTheErrorsBundleAdjustmentLeaves) {
  double measured_squares = 0.0;
  double predicted_squares = 0.0;
  double sigma_squares = 0.0;
  const int scenes = 20;
  for (int seed = 1; seed <= scenes; ++seed) {
    PointSceneOptions options = smallScene(0.5);
    options.intrinsics.k1 = options.intrinsics.k2 = 0.0;
    options.seed = static_cast<unsigned>(seed);
    const PointScene scene = makePointScene(options);
    PointBundleAdjustmentOptions ba;
    ba.kernel = RobustKernelType::kNone;
    ba.pixel_sigma = options.pixel_noise;
    PointBundleAdjustmentProblem problem = buildPointBundleAdjustment(
        {scene.camera, scene.initial_cam_from_world, scene.initial_points, scene.observations,
         scene.trueScaleDistance()},
        ba);
    ASSERT_TRUE(
        optimize(problem.graph, &problem.values, problem.config, OptimizerOptions()).usable);
    const PointSceneErrors errors =
        evaluatePointScene(scene, extractPoses(problem.values, scene.true_cam_from_world.size()),
                           extractPoints(problem.values, scene.true_points.size()));
    measured_squares += errors.position_ate_sim3 * errors.position_ate_sim3;
    const double sigma = estimatedPixelSigma(
        {scene.camera, extractPoses(problem.values, scene.true_cam_from_world.size()),
         extractPoints(problem.values, scene.true_points.size()), scene.observations},
        true);
    sigma_squares += sigma * sigma;
    const double predicted = predictedCentreAte(
        {scene.camera, scene.true_cam_from_world, scene.true_points, scene.observations},
        options.pixel_noise);
    predicted_squares += predicted * predicted;
  }
  const double measured = std::sqrt(measured_squares / scenes);
  const double predicted = std::sqrt(predicted_squares / scenes);
  EXPECT_GT(measured, 0.0);
  EXPECT_NEAR(measured / predicted, 1.0, 0.15)
      << measured << " m measured, " << predicted << " m predicted";
  EXPECT_NEAR(std::sqrt(sigma_squares / scenes), 0.5, 0.01);
}

// A similarity of the world moves nothing but the unit; the pixel noise scales the figure.
TEST(PredictedCentreAte, FollowsTheSceneScaleAndThePixelNoise) {
  PointSceneOptions options = smallScene(0.5);
  options.intrinsics.k1 = options.intrinsics.k2 = 0.0;
  const PointScene scene = makePointScene(options);
  const PointBundleAdjustmentInput input{scene.camera, scene.true_cam_from_world, scene.true_points,
                                         scene.observations};
  const double base = predictedCentreAte(input, 0.5);
  EXPECT_GT(base, 0.0);
  EXPECT_NEAR(predictedCentreAte(input, 1.0), 2.0 * base, 1e-9 * base);
  // x -> s R x + t: cam_from_world (Rc, tc) becomes (Rc R^T, s tc - Rc R^T t).
  const double s = 1000.0;
  const Eigen::Matrix3d rotation = so3::exp(Eigen::Vector3d(0.3, -0.2, 0.5)).toRotationMatrix();
  const Eigen::Vector3d shift(4.0, -7.0, 2.0);
  PointBundleAdjustmentInput moved = input;
  for (Pose3& pose : moved.cam_from_world) {
    const Eigen::Matrix3d r = pose.rotationMatrix() * rotation.transpose();
    pose = Pose3(r, s * pose.translation() - r * shift);
  }
  for (Eigen::Vector3d& p : moved.points) p = s * rotation * p + shift;
  EXPECT_NEAR(predictedCentreAte(moved, 0.5), s * base, 1e-6 * s * base);
}

// Two halves of a sequence that share no point: nothing fixes one against the other.
TEST(PredictedCentreAte, IsInfiniteWhenNothingTiesTheCamerasTogether) {
  PointSceneOptions options = smallScene(0.5);
  options.intrinsics.k1 = options.intrinsics.k2 = 0.0;
  const PointScene scene = makePointScene(options);
  PointBundleAdjustmentInput input{scene.camera, scene.true_cam_from_world, scene.true_points, {}};
  const int half = static_cast<int>(scene.true_cam_from_world.size()) / 2;
  std::vector<int> first_half_only(scene.true_points.size(), -1);
  for (const PointObservation& o : scene.observations) {
    const int side = o.camera_index < half ? 0 : 1;
    int& owner = first_half_only[o.point_index];
    if (owner < 0) owner = side;
    if (owner == side) input.observations.push_back(o);
  }
  EXPECT_TRUE(std::isinf(predictedCentreAte(input, 0.5)));
}

}  // namespace
}  // namespace curvesfm
