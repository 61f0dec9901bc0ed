#include "frontend/mapping/pipeline.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <limits>
#include <vector>

#include "core/angles.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

TEST(PipelineOptions, ValidateNamesTheStageAndField) {
  PipelineOptions options;
  options.depth_reference_candidates = 0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("PipelineOptions.depth_reference_candidates")));
  options = {};
  options.map.promotion_observations = 0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  EXPECT_EQ(PipelineOptions{}.local_ba.strategy, Strategy::kAlternating);
  EXPECT_EQ(PipelineOptions{}.local_ba.scope, Scope::kLocal);
  EXPECT_EQ(PipelineOptions{}.local_ba.optimizer.initial_trust_region_radius, 10.0);
  EXPECT_EQ(PipelineOptions{}.local_ba.optimizer.function_tolerance, 1e-4);
  EXPECT_EQ(PipelineOptions{}.global_ba.optimizer.function_tolerance, 1e-6);
  EXPECT_EQ(PipelineOptions{}.global_ba.optimizer.stall_iterations, 5);
  EXPECT_EQ(PipelineOptions{}.local_ba.optimizer.stall_iterations, 0);
  EXPECT_EQ(PipelineOptions{}.reassociation_interim_iterations, 8);
  options = {};
  options.reassociation_interim_iterations = -1;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("PipelineOptions.reassociation_interim_iterations")));
  options = {};
  options.global_ba.optimizer.stall_iterations = -1;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(testing::HasSubstr("stall_iterations")));
  options = {};
  options.global_ba.optimizer.stall_tolerance = 0.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(testing::HasSubstr("stall_tolerance")));
  EXPECT_FALSE(PipelineOptions{}.local_ba_refines_poses);
}

// Means over the keyframes only; the image stage is the frontend's first three stages.
TEST(KeyframeTimes, AverageTheKeyframesStages) {
  KeyframeStats key;
  key.keyframe_index = 0;
  key.undistort_seconds = 0.001;
  key.edges_seconds = 0.002;
  key.field_seconds = 0.003;
  key.depth_seconds = 0.004;
  key.correspondence_seconds = 0.005;
  key.initialise_seconds = 0.006;
  KeyframeStats slower = key;
  slower.keyframe_index = 1;
  slower.depth_seconds = 0.014;
  KeyframeStats skipped;  // No keyframe: keyframe_index -1.
  skipped.edges_seconds = 1.0;
  const KeyframeTimes t = keyframeTimes({key, skipped, slower});
  EXPECT_EQ(t.keyframes, 2);
  EXPECT_NEAR(t.image_stage_ms, 6.0, 1e-9);
  EXPECT_NEAR(t.depth_ms, 9.0, 1e-9);
  EXPECT_NEAR(t.frontend_ms, 26.0, 1e-9);
  EXPECT_NEAR(t.slowest_frontend_ms, 31.0, 1e-9);
}

TEST(PipelineOptions, LocalBaKeyframesPerCurveMustExceedTheWindow) {
  PipelineOptions options;
  options.local_ba_max_curve_keyframes = options.local_ba.local_window;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(testing::HasSubstr(
                  "PipelineOptions.local_ba_max_curve_keyframes = 5: must be 0 (all) or more than "
                  "local_ba.local_window (5)")));
  options.local_ba_max_curve_keyframes = 6;
  EXPECT_NO_THROW(options.validate());
  EXPECT_EQ(PipelineOptions{}.local_ba_max_curve_keyframes, 20);
}

TEST(PipelineOptions, ValidateChecksTheReassociationGates) {
  PipelineOptions options;
  options.reassociation_max_edge_distance_px = -1.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("PipelineOptions.reassociation_max_edge_distance_px")));
  options = {};
  options.reassociation_max_viewing_angle_deg = 181.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("PipelineOptions.reassociation_max_viewing_angle_deg")));
  for (const double ratio : {0.0, 1.5}) {
    options = {};
    options.reassociation_occluder_depth_ratio = ratio;
    EXPECT_THAT([&] { options.validate(); },
                testing::ThrowsMessage<InvalidOptions>(
                    testing::HasSubstr("PipelineOptions.reassociation_occluder_depth_ratio")));
  }
  EXPECT_FALSE(PipelineOptions{}.reassociation_skip_explained);
}

TEST(PipelineOptions, TheLastGlobalBaKernelWidthIsZeroOrPositive) {
  EXPECT_EQ(PipelineOptions{}.last_global_ba_kernel_width, 1.0);
  for (const double width : {-1.0, std::numeric_limits<double>::infinity()}) {
    PipelineOptions options;
    options.last_global_ba_kernel_width = width;
    EXPECT_THAT([&] { options.validate(); },
                testing::ThrowsMessage<InvalidOptions>(
                    testing::HasSubstr("PipelineOptions.last_global_ba_kernel_width")));
  }
}

TEST(PipelineOptions, RegistrationThreadsAreBetweenOneAndSixtyFour) {
  for (const int threads : {0, 65}) {
    PipelineOptions options;
    options.registration_threads = threads;
    EXPECT_THAT([&] { options.validate(); },
                testing::ThrowsMessage<InvalidOptions>(
                    testing::HasSubstr("PipelineOptions.registration_threads")));
  }
}

// Camera centres along x (pose units) and turns about y (deg): frame 1 has not moved yet, so the
// scene scale is frame 2's distance, 0.1; the default keyframe thresholds are 0.74 scene scales
// and 2 deg.
std::vector<Pose3> keyframeTestPoses() {
  const double x[] = {0.0, 0.0, 0.1, 0.15, 0.18, 0.18, 0.18};
  const double turn_deg[] = {0.0, 0.0, 0.0, 0.0, 0.0, 3.0, 3.0};
  std::vector<Pose3> poses;
  for (int i = 0; i < 7; ++i) {
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(turn_deg[i] * kDegToRad, Eigen::Vector3d::UnitY()).toRotationMatrix();
    poses.emplace_back(rotation, -rotation * Eigen::Vector3d(x[i], 0.0, 0.0));
  }
  return poses;
}

TEST(SelectKeyframes, LearnsTheSceneScaleAndChoosesAsTheRunDoes) {
  const std::vector<Pose3> poses = keyframeTestPoses();
  const PipelineOptions options;
  const std::vector<bool> keyframes = selectKeyframes(poses, options);
  EXPECT_THAT(keyframes, testing::ElementsAre(true, false, true, false, true, true, false));
  // The run itself, given images only where selectKeyframes said: blank ones, no edges, no map.
  Pipeline pipeline(Camera(CameraIntrinsics{}), options);
  const cv::Mat blank(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const KeyframeStats stats =
        pipeline.addFrame({static_cast<double>(i), keyframes[i] ? blank : cv::Mat(), poses[i]});
    EXPECT_EQ(stats.keyframe_index >= 0, keyframes[i]) << "frame " << i;
  }
}

TEST(Pipeline, AKeyframeWithoutItsImageIsAnError) {
  Pipeline pipeline(Camera(CameraIntrinsics{}), PipelineOptions{});
  const auto first_frame_without_image = [&] { pipeline.addFrame({0.0, cv::Mat(), Pose3()}); };
  EXPECT_THAT(first_frame_without_image, testing::ThrowsMessage<CheckError>(testing::HasSubstr(
                                             "frame 0 is a keyframe but came without its image")));
  Pipeline fresh(Camera(CameraIntrinsics{}), PipelineOptions{});  // addFrame threw: start anew.
  const auto grey_first_frame = [&] {
    fresh.addFrame({0.0, cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)), Pose3()});
  };
  EXPECT_THAT(grey_first_frame, testing::ThrowsMessage<CheckError>(testing::HasSubstr(
                                    "frame 0: expected a CV_8UC3 BGR image, found type 0")));
}

}  // namespace
}  // namespace curvesfm
