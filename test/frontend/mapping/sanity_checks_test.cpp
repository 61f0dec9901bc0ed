#include "frontend/mapping/sanity_checks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace curvesfm {
namespace {

// A straight curve of `segments` segments from `from` to `to`.
PolyBezier lineCurve(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int segments) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= segments; ++i) points.push_back(from + (to - from) * i / segments);
  const Direction direction((to - from).normalized());
  const double arm = (to - from).norm() / segments / 3.0;
  return PolyBezier(points, std::vector<Direction>(points.size(), direction),
                    std::vector<SegmentLengths>(segments, {arm, arm}));
}

// A zigzag of `segments` strokes between y = 0 and y = 1 at x in [0, 1], z = 0.5; short arms
// keep every stroke inside its column.
PolyBezier zigzag(int segments) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= segments; ++i) {
    points.emplace_back(static_cast<double>(i) / segments, i % 2, 0.5);
  }
  std::vector<Direction> directions(points.size(), Direction(Eigen::Vector3d::UnitX()));
  return PolyBezier(points, directions, std::vector<SegmentLengths>(segments, {0.005, 0.005}));
}

// Cameras on the x axis from 0 to 10, looking at points in the box [0, 10] x [0, 5] x [5, 15].
std::vector<Eigen::Vector3d> cameraCentres() {
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i <= 10; ++i) centres.emplace_back(i, 0.0, 0.0);
  return centres;
}

std::vector<Eigen::Vector3d> scenePoints() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= 10; ++i) {
    for (int j = 0; j <= 5; ++j) {
      for (int k = 5; k <= 15; ++k) points.emplace_back(i, j, k);
    }
  }
  return points;
}

SanityOptions noMargin() {
  SanityOptions options;
  options.extent_margin = 0.0;
  options.extent_percentile = 0.0;
  return options;
}

TEST(SceneExtent, SpansCamerasAndPointsEnlargedByTheMargin) {
  const SceneExtent box = sceneExtent(cameraCentres(), scenePoints(), "points", noMargin());
  ASSERT_TRUE(box.valid());
  EXPECT_EQ(box.source, "points");
  EXPECT_TRUE(box.min.isApprox(Eigen::Vector3d(0, 0, 0)));
  EXPECT_TRUE(box.max.isApprox(Eigen::Vector3d(10, 5, 15)));
  SanityOptions options = noMargin();
  options.extent_margin = 0.5;
  const SceneExtent enlarged = sceneExtent(cameraCentres(), scenePoints(), "points", options);
  const double margin = 0.5 * box.diagonal();
  EXPECT_TRUE(enlarged.min.isApprox(box.min - Eigen::Vector3d::Constant(margin)));
  EXPECT_TRUE(enlarged.max.isApprox(box.max + Eigen::Vector3d::Constant(margin)));
  EXPECT_NEAR(enlarged.scaled(1000.0).diagonal(), 1000.0 * enlarged.diagonal(), 1e-6);
}

// A few stray points far away do not widen the extent: the percentiles leave them out.
TEST(SceneExtent, PercentilesIgnoreAFewStrayPoints) {
  std::vector<Eigen::Vector3d> points = scenePoints();
  points.emplace_back(1e5, 0.0, 10.0);
  points.emplace_back(0.0, -1e5, 1e5);
  SanityOptions options = noMargin();
  options.extent_percentile = 2.0;
  const SceneExtent box = sceneExtent(cameraCentres(), points, "points", options);
  EXPECT_LT(box.diagonal(), 20.0);
  EXPECT_GE(box.max.z(), 14.0);
}

TEST(SceneExtent, OneCameraAndNoPointsSpanNothing) {
  EXPECT_FALSE(sceneExtent({Eigen::Vector3d::Zero()}, {}, "points", SanityOptions()).valid());
  EXPECT_FALSE(sceneExtent({}, {}, "points", SanityOptions()).valid());
  EXPECT_EQ(sceneExtent(cameraCentres(), {}, "points", SanityOptions()).source, "");
}

TEST(CheckCurve, JudgesCurvesAgainstTheExtent) {
  const SceneExtent box = sceneExtent(cameraCentres(), scenePoints(), "points", noMargin());
  const CurveCheck inside = checkCurve(lineCurve({1, 1, 8}, {4, 1, 8}, 3), box, 8);
  EXPECT_EQ(inside.reason, CurveImplausibility::kNone);
  EXPECT_NEAR(inside.length, 3.0, 1e-9);
  // The runaway kind: one end far beyond the scene.
  const CurveCheck runaway = checkCurve(lineCurve({1, 1, 8}, {1, 1, 2000}, 3), box, 8);
  EXPECT_EQ(runaway.reason, CurveImplausibility::kOutsideExtent);
  EXPECT_NEAR(runaway.length, 1992.0, 1e-6);
  // In the unit cube (diagonal 1.73): one stroke across fits, 40 strokes folded inside are
  // longer than the extent.
  const SceneExtent cube = sceneExtent({{0, 0, 0}, {1, 1, 1}}, {}, "", noMargin());
  EXPECT_EQ(checkCurve(zigzag(1), cube, 8).reason, CurveImplausibility::kNone);
  const CurveCheck folded = checkCurve(zigzag(40), cube, 8);
  EXPECT_GT(folded.length, 39.0);
  EXPECT_EQ(folded.reason, CurveImplausibility::kLongerThanExtent);
  // Without an extent nothing is judged.
  EXPECT_EQ(checkCurve(lineCurve({0, 0, 0}, {0, 0, 1e9}, 1), SceneExtent(), 8).reason,
            CurveImplausibility::kNone);
}

// Keyframes on a line, 1 apart.
std::vector<Pose3> line(int n) {
  std::vector<Pose3> poses;
  for (int j = 0; j < n; ++j) {
    poses.emplace_back(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-j, -0.1 * j * j, 0.0));
  }
  return poses;
}

TEST(LargestPoseMove, ASimilarityIsNoMoveAndAJumpIsMeasuredInSpacings) {
  const std::vector<Pose3> initial = line(8);
  // The whole trajectory scaled by 3 and shifted: the same shape, no move.
  std::vector<Pose3> similar;
  for (const Pose3& p : initial) {
    similar.emplace_back(p.rotation(), 3.0 * p.translation() + Eigen::Vector3d(1, 2, 3));
  }
  const PoseMove none = largestPoseMove(initial, similar);
  ASSERT_GE(none.keyframe, 0);
  EXPECT_LT(none.spacings(), 1e-9);
  EXPECT_NEAR(none.spacing, std::hypot(1.0, 0.1 * 7), 0.2);
  // One keyframe 5 units off: after alignment it is still far, the others barely moved.
  std::vector<Pose3> jumped = initial;
  jumped[4] = Pose3(initial[4].rotation(), initial[4].translation() + Eigen::Vector3d(0, 0, 5));
  const PoseMove move = largestPoseMove(initial, jumped);
  EXPECT_EQ(move.keyframe, 4);
  EXPECT_GT(move.spacings(), 2.0);
  EXPECT_EQ(largestPoseMove(line(2), line(2)).keyframe, -1);
  EXPECT_THROW(largestPoseMove(line(3), line(4)), CheckError);
}

TEST(JudgeRun, APlausibleRunHasNoVerdict) {
  PoseMove move;
  move.keyframe = 3;
  move.distance = 0.1;
  move.spacing = 1.0;
  EXPECT_TRUE(judgeRun(30, 200, 210, 10, move, SanityOptions()).empty());
}

TEST(JudgeRun, EachImplausibilityGetsItsVerdict) {
  PoseMove move;
  move.keyframe = 3;
  move.distance = 4.0;
  move.spacing = 2.0;
  const std::vector<RunVerdict> verdicts = judgeRun(2, 3, 10, 7, move, SanityOptions());
  ASSERT_EQ(verdicts.size(), 4u);
  EXPECT_EQ(verdicts[0].kind, RunVerdictKind::kFewKeyframes);
  EXPECT_EQ(verdicts[1].kind, RunVerdictKind::kFewCurves);
  EXPECT_EQ(verdicts[2].kind, RunVerdictKind::kMostCurvesImplausible);
  EXPECT_THAT(verdicts[2].message, testing::HasSubstr("7 of 10 curves"));
  EXPECT_EQ(verdicts[3].kind, RunVerdictKind::kPosesMovedFar);
  EXPECT_THAT(verdicts[3].message, testing::HasSubstr("keyframe 3 moved 2 keyframe spacings"));
}

TEST(SanityOptions, ValidateNamesTheField) {
  SanityOptions options;
  options.extent_margin = -1.0;
  EXPECT_THAT([&] { options.validate(); }, testing::ThrowsMessage<InvalidOptions>(
                                               testing::HasSubstr("SanityOptions.extent_margin")));
  options = {};
  options.max_pose_move_spacings = 0.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = {};
  options.extent_percentile = 30.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = {};
  options.max_curve_residual_px = -1.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("SanityOptions.max_curve_residual_px")));
  options = {};
  options.min_chord_ratio = 1.0;
  EXPECT_THAT(
      [&] { options.validate(); },
      testing::ThrowsMessage<InvalidOptions>(testing::HasSubstr("SanityOptions.min_chord_ratio")));
  options = {};
  options.min_epipolar_angle_deg = 90.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("SanityOptions.min_epipolar_angle_deg")));
}

}  // namespace
}  // namespace curvesfm
