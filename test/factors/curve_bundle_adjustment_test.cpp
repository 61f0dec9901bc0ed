#include "factors/curve_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/errors.h"
#include "graph/scheduler.h"
#include "sim/curve_scene.h"
#include "sim/curve_scene_input.h"

namespace curvesfm {
namespace {

int countFactors(const FactorGraph& graph, const std::string& type) {
  int count = 0;
  for (const auto& factor : graph) count += factor->typeName() == type;
  return count;
}

TEST(CurveBundleAdjustment, MotionPriorTiesEachConsecutivePairOnlyWhenOnAndGiven) {
  CurveSceneOptions scene_options;
  scene_options.num_keyframes = 4;
  const CurveScene scene = makeCurveScene(scene_options);
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, {}).graph, "relative_pose"), 0);
  input.motion_prior_cam_from_world = scene.true_cam_from_world;
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, {}).graph, "relative_pose"), 3);
  CurveBundleAdjustmentOptions off;
  off.motion_prior = false;
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, off).graph, "relative_pose"), 0);
  input.motion_prior_cam_from_world.pop_back();
  EXPECT_THROW(buildCurveBundleAdjustment(input, {}), CheckError);
}

TEST(CurveBundleAdjustment, StartPriorTiesEveryKeyframeOnlyWhenOnAndGiven) {
  CurveSceneOptions scene_options;
  scene_options.num_keyframes = 4;
  const CurveScene scene = makeCurveScene(scene_options);
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  CurveBundleAdjustmentOptions on;
  on.start_prior = true;
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, on).graph, "camera_prior"), 0);
  input.motion_prior_cam_from_world = scene.true_cam_from_world;
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, {}).graph, "camera_prior"), 0);
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, on).graph, "camera_prior"), 4);
  input.motion_prior_cam_from_world.pop_back();
  EXPECT_THROW(buildCurveBundleAdjustment(input, on), CheckError);
}

TEST(CurveBundleAdjustment, HybridGraphKeepsPointsBesideCurvesWithTheirOwnNoise) {
  CurveSceneOptions scene_options;
  scene_options.num_keyframes = 3;
  const CurveScene scene = makeCurveScene(scene_options);
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  // One point seen by all three keyframes at its true projections, shifted by 1 px in keyframe 1.
  const Eigen::Vector3d point = input.curves[0].points()[0];
  input.points = {point};
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(input.camera->project(input.cam_from_world[j] * point, &pixel));
    if (j == 1) pixel.x() += 1.0;
    input.point_observations.push_back({j, 0, pixel});
  }
  EXPECT_EQ(countFactors(buildCurveBundleAdjustment(input, {}).graph, "point_reprojection"), 0);
  CurveBundleAdjustmentOptions hybrid;
  hybrid.points = true;
  hybrid.point_kernel = RobustKernelType::kNone;
  hybrid.point_pixel_sigma = 0.5;
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, hybrid);
  EXPECT_EQ(countFactors(problem.graph, "point_reprojection"), 3);
  EXPECT_EQ(problem.values.at<Eigen::Vector3d>(pointKey(0)), point);
  // Cost 0.5 (r / sigma)^2 of the one shifted observation: 0.5 * (1 / 0.5)^2 = 2.
  EXPECT_NEAR(problem.graph.costByType(problem.values).at("point_reprojection").cost, 2.0, 1e-6);
  const auto pointCost = [&] {
    const CurveBundleAdjustmentProblem built = buildCurveBundleAdjustment(input, hybrid);
    return built.graph.costByType(built.values).at("point_reprojection").cost;
  };
  // Seen as a descriptor keypoint, the shifted observation takes the keypoints' sigma:
  // 0.5 * (1 / 0.25)^2 = 8; with that sigma 0, the points'.
  input.point_observations[1].keypoint = true;
  hybrid.keypoint_pixel_sigma = 0.25;
  EXPECT_NEAR(pointCost(), 8.0, 1e-6);
  // A keypoint twice the reference size doubles its sigma: 0.5 * (1 / 0.5)^2 = 2; one smaller
  // than the reference keeps the keypoints' sigma.
  hybrid.keypoint_reference_size = 3.0;
  input.point_observations[1].keypoint_size = 6.0;
  EXPECT_NEAR(pointCost(), 2.0, 1e-6);
  input.point_observations[1].keypoint_size = 2.0;
  EXPECT_NEAR(pointCost(), 8.0, 1e-6);
  // Without a keypoint sigma the size grows the points' sigma, 0.5 px x 6 / 3: 0.5 * (1 / 1)^2. A
  // KLT observation keeps the points' sigma whatever size it carries.
  hybrid.keypoint_pixel_sigma = 0.0;
  input.point_observations[1].keypoint_size = 6.0;
  EXPECT_NEAR(pointCost(), 0.5, 1e-6);
  input.point_observations[1].keypoint = false;
  EXPECT_NEAR(pointCost(), 2.0, 1e-6);
  input.point_observations[1].keypoint = true;
  hybrid.keypoint_reference_size = 0.0;
  hybrid.keypoint_pixel_sigma = 0.0;
  EXPECT_NEAR(pointCost(), 2.0, 1e-6);
  input.point_observations.push_back({3, 0, Eigen::Vector2d::Zero()});
  EXPECT_THROW(buildCurveBundleAdjustment(input, hybrid), CheckError);
}

// With length_from_creation, E_s1 measures each segment against the reference it is given (its
// chord at creation), not its current chord, absolutely (lambda1) or relative to that reference
// (length_sigma_rel); without it, against the chord it starts from.
TEST(CurveBundleAdjustment, SegmentLengthTermUsesTheGivenReferences) {
  CurveSceneOptions scene_options;
  scene_options.num_keyframes = 2;
  const CurveScene scene = makeCurveScene(scene_options);
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  input.curves.erase(input.curves.begin() + 1, input.curves.end());
  input.observations.clear();  // The regulariser needs none.
  const PolyBezier& curve = input.curves[0];
  std::vector<double> chords;
  for (int i = 0; i < curve.numSegments(); ++i) {
    chords.push_back((curve.points()[i + 1] - curve.points()[i]).norm());
  }
  auto lengthCost = [&input](const CurveBundleAdjustmentOptions& options) {
    const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, options);
    return problem.graph.costByType(problem.values).at("segment_length").cost;
  };
  CurveBundleAdjustmentOptions absolute;
  absolute.lambda1 = 4.0;  // sigma 0.5
  EXPECT_NEAR(lengthCost(absolute), 0.0, 1e-12);
  // References 20 % longer than the chords: each segment is 0.2 chord short.
  input.segment_reference_lengths = {chords};
  double expected_absolute = 0.0;
  double expected_relative = 0.0;
  for (double& reference : input.segment_reference_lengths[0]) {
    const double chord = reference;
    reference *= 1.2;
    expected_absolute += 0.5 * std::pow((0.2 * chord) / 0.5, 2);
    expected_relative += 0.5 * std::pow((0.2 * chord) / (0.1 * reference), 2);
  }
  EXPECT_NEAR(lengthCost(absolute), 0.0, 1e-12);
  absolute.length_from_creation = true;
  EXPECT_NEAR(lengthCost(absolute), expected_absolute, 1e-9);
  CurveBundleAdjustmentOptions relative;
  relative.length_sigma_rel = 0.1;
  relative.length_from_creation = true;
  EXPECT_NEAR(lengthCost(relative), expected_relative, 1e-9);
  input.segment_reference_lengths[0].pop_back();
  EXPECT_THROW(buildCurveBundleAdjustment(input, absolute), CheckError);
  input.segment_reference_lengths.clear();
  input.segment_reference_lengths.resize(2);
  EXPECT_THROW(buildCurveBundleAdjustment(input, absolute), CheckError);
}

// The motion prior's cost when keyframe 2 of a trajectory scaled by `scale` is moved by
// scale * 1 mm off it.
double motionPriorCost(const CurveScene& scene, double scale) {
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  for (std::size_t j = 0; j < input.cam_from_world.size(); ++j) {
    const Pose3& truth = scene.true_cam_from_world[j];
    input.motion_prior_cam_from_world.push_back(
        Pose3(truth.rotation(), scale * truth.translation()));
    input.cam_from_world[j] = input.motion_prior_cam_from_world[j];
  }
  input.cam_from_world[2] =
      input.cam_from_world[2].retract((Vector6d() << 0, 0, 0, scale * 1e-3, 0, 0).finished());
  const CurveBundleAdjustmentProblem problem = buildCurveBundleAdjustment(input, {});
  return problem.graph.costByType(problem.values).at("relative_pose").cost;
}

TEST(CurveBundleAdjustment, MotionPriorTranslationSigmaFollowsTheUnitOfThePoses) {
  const CurveScene scene = makeCurveScene(CurveSceneOptions{});
  const double cost = motionPriorCost(scene, 1.0);
  EXPECT_GT(cost, 0.0);
  EXPECT_NEAR(motionPriorCost(scene, 10.0), cost, 1e-9 * cost);
}

TEST(CurveBundleAdjustmentOptions, ValidateNamesTheFieldAndConstraint) {
  const auto expectRejected = [](CurveBundleAdjustmentOptions options, const std::string& field) {
    try {
      options.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const InvalidOptions& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  CurveBundleAdjustmentOptions options;
  EXPECT_NO_THROW(options.validate());
  options.samples_per_segment = 0;
  expectRejected(options, "samples_per_segment");
  options = {};
  options.samples_per_segment = CurveReprojectionFactor::kMaxSamples;
  expectRejected(options, "samples_per_segment");
  options = {};
  options.lambda1 = -1.0;
  expectRejected(options, "lambda1");
  options = {};
  options.length_sigma_rel = -0.1;
  expectRejected(options, "length_sigma_rel");
  options = {};
  options.interpolate_max_line_offset_px = -0.1;
  expectRejected(options, "interpolate_max_line_offset_px");
  options = {};
  options.interpolate_max_normal_angle_deg = 91.0;
  expectRejected(options, "interpolate_max_normal_angle_deg");
  options = {};
  options.border_margin_px = -1.0;
  expectRejected(options, "border_margin_px");
  options = {};
  options.max_normal_angle_deg = 0.0;
  expectRejected(options, "max_normal_angle_deg");
  options.max_normal_angle_deg = 120.0;
  expectRejected(options, "max_normal_angle_deg");
  options = {};
  options.lambda2 = std::nan("");
  expectRejected(options, "lambda2");
  options = {};
  options.kernel_width = 0.0;
  expectRejected(options, "kernel_width");
  options = {};
  options.pixel_sigma = -1.0;
  expectRejected(options, "pixel_sigma");
  options = {};
  options.keypoint_pixel_sigma = -0.5;
  expectRejected(options, "keypoint_pixel_sigma");
  options = {};
  options.keypoint_reference_size = -1.0;
  expectRejected(options, "keypoint_reference_size");
  options = {};
  options.motion_prior_rotation_sigma_deg = 0.0;
  expectRejected(options, "motion_prior_rotation_sigma_deg");
  options = {};
  options.motion_prior_translation_sigma_rel = std::nan("");
  expectRejected(options, "motion_prior_translation_sigma_rel");
  options = {};
  options.start_prior_rotation_sigma_deg = -0.1;
  expectRejected(options, "start_prior_rotation_sigma_deg");
  options = {};
  options.start_prior_centre_sigma_rel = 0.0;
  expectRejected(options, "start_prior_centre_sigma_rel");
}

TEST(CurveBundleAdjustment, RejectsMismatchedFieldsAndObservationsOutOfRange) {
  CurveSceneOptions options;
  options.num_keyframes = 3;
  options.num_curves = 2;
  const CurveScene scene = makeCurveScene(options);
  CurveBundleAdjustmentInput input = makeCurveBundleAdjustmentInput(scene);
  CurveBundleAdjustmentInput missing_field = input;
  missing_field.fields.pop_back();
  EXPECT_THROW(buildCurveBundleAdjustment(missing_field, {}), CheckError);
  CurveBundleAdjustmentInput bad_observation = input;
  bad_observation.observations.push_back({0, scene.true_curves[0].numSegments(), 0});
  EXPECT_THROW(buildCurveBundleAdjustment(bad_observation, {}), CheckError);
  CurveBundleAdjustmentInput wrong_size = input;
  wrong_size.fields[1] = std::make_shared<const NearestEdgeField>();
  EXPECT_THROW(buildCurveBundleAdjustment(wrong_size, {}), CheckError);
  EXPECT_NO_THROW(buildCurveBundleAdjustment(input, {}));
}

}  // namespace
}  // namespace curvesfm
