#include "frontend/mapping/pipeline.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
  EXPECT_FALSE(PipelineOptions{}.local_ba_refines_poses);
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

}  // namespace
}  // namespace curvesfm
