#include "frontend/image/curve_extension.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr double kFocal = 500.0;
constexpr double kDepth = 2.0;
// Pixels per metre across the optical axis at kDepth.
constexpr double kPixelsPerMetre = kFocal / kDepth;

Camera testCamera() {
  CameraIntrinsics intrinsics;
  intrinsics.fx = kFocal;
  intrinsics.fy = kFocal;
  intrinsics.cx = 320.0;
  intrinsics.cy = 240.0;
  intrinsics.width = 640;
  intrinsics.height = 480;
  return Camera(intrinsics);
}

// A straight curve of `segments` equal segments from `from` to `to`.
PolyBezier line(const Eigen::Vector3d& from, const Eigen::Vector3d& to, int segments) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i <= segments; ++i) {
    points.push_back(from + (to - from) * static_cast<double>(i) / segments);
  }
  const std::vector<Direction> directions(segments + 1, Direction(to - from));
  const double arm = (to - from).norm() / segments / 3.0;
  return PolyBezier(points, directions, std::vector<SegmentLengths>(segments, {arm, arm}));
}

Eigen::Vector3d onAxisLine(double x) { return {x, 0.0, kDepth}; }

// The existing curve: 0.4 m along x at depth 2 m, ending on the optical axis (pixel (320, 240)).
PolyBezier existingCurve() { return line(onAxisLine(-0.4), onAxisLine(0.0), 2); }

std::vector<OpenEnd> bothEnds(const PolyBezier& curve) {
  std::vector<OpenEnd> ends;
  for (const CurveEnd end : {CurveEnd::kFront, CurveEnd::kBack}) {
    ends.push_back(*openEnd(0, curve, end, Pose3(), testCamera()));
  }
  return ends;
}

std::optional<CurveJoin> join(const PolyBezier& candidate,
                              const CurveExtensionOptions& options = {}) {
  return findJoin(candidate, bothEnds(existingCurve()), Pose3(), testCamera(), options);
}

TEST(OpenEnd, GivesTheEndPointItsPixelAndTheDirectionsLeavingTheCurve) {
  const PolyBezier curve = existingCurve();
  const OpenEnd back = *openEnd(3, curve, CurveEnd::kBack, Pose3(), testCamera());
  EXPECT_EQ(back.curve, 3);
  EXPECT_EQ(back.point, onAxisLine(0.0));
  EXPECT_DOUBLE_EQ(back.depth, kDepth);
  EXPECT_TRUE(back.pixel.isApprox(Eigen::Vector2d(320.0, 240.0)));
  EXPECT_TRUE(back.pixel_outward.isApprox(Eigen::Vector2d::UnitX()));
  const OpenEnd front = *openEnd(3, curve, CurveEnd::kFront, Pose3(), testCamera());
  EXPECT_TRUE(front.pixel_outward.isApprox(-Eigen::Vector2d::UnitX()));
  const PolyBezier behind = line({-0.4, 0.0, -kDepth}, {0.0, 0.0, -kDepth}, 2);
  EXPECT_FALSE(openEnd(0, behind, CurveEnd::kBack, Pose3(), testCamera()));
}

TEST(FindJoin, ContinuesTheBackInEitherOrientation) {
  const double gap_m = 3.0 / kPixelsPerMetre;
  const PolyBezier addition = line(onAxisLine(gap_m), onAxisLine(0.2), 2);
  const std::optional<CurveJoin> forward = join(addition);
  ASSERT_TRUE(forward);
  EXPECT_EQ(forward->open_end, 1);
  EXPECT_EQ(forward->new_end, CurveEnd::kFront);
  EXPECT_NEAR(forward->gap_px, 3.0, 1e-9);
  const std::optional<CurveJoin> backward = join(reversed(addition));
  ASSERT_TRUE(backward);
  EXPECT_EQ(backward->open_end, 1);
  EXPECT_EQ(backward->new_end, CurveEnd::kBack);
}

TEST(FindJoin, ContinuesTheFront) {
  const double gap_m = 4.0 / kPixelsPerMetre;
  const std::optional<CurveJoin> found = join(line(onAxisLine(-0.6), onAxisLine(-0.4 - gap_m), 2));
  ASSERT_TRUE(found);
  EXPECT_EQ(found->open_end, 0);
  EXPECT_EQ(found->new_end, CurveEnd::kBack);
}

TEST(FindJoin, RejectsAGapTooWideInTheImage) {
  EXPECT_FALSE(join(line(onAxisLine(10.0 / kPixelsPerMetre), onAxisLine(0.2), 2)));
  CurveExtensionOptions wide;
  wide.max_gap_px = 12.0;
  EXPECT_TRUE(join(line(onAxisLine(10.0 / kPixelsPerMetre), onAxisLine(0.2), 2), wide));
}

// The other side of a thin line: parallel, 3 px across.
TEST(FindJoin, RejectsAParallelEdgeBesideTheEnd) {
  const double across = 3.0 / kPixelsPerMetre;
  EXPECT_FALSE(join(line({1.0 / kPixelsPerMetre, across, kDepth}, {0.2, across, kDepth}, 2)));
}

TEST(FindJoin, RejectsACurveThatOverlapsTheEnd) {
  EXPECT_FALSE(join(line(onAxisLine(-4.0 / kPixelsPerMetre), onAxisLine(0.2), 2)));
}

TEST(FindJoin, RejectsATurnSharperThanTheAngle) {
  const Eigen::Vector3d start = onAxisLine(2.0 / kPixelsPerMetre);
  const auto turned = [&](double deg) {
    const double a = deg * M_PI / 180.0;
    return line(start, start + 0.2 * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0), 2);
  };
  EXPECT_TRUE(join(turned(20.0)));
  EXPECT_FALSE(join(turned(45.0)));
}

// The angle is the image's: a turn in depth, invisible in the image, is the depth check's.
TEST(FindJoin, JudgesTheAngleInTheImage) {
  const Eigen::Vector3d start = onAxisLine(2.0 / kPixelsPerMetre);
  const double a = 45.0 * M_PI / 180.0;
  const PolyBezier into_depth =
      line(start, start + 0.1 * Eigen::Vector3d(std::cos(a), 0.0, std::sin(a)), 2);
  EXPECT_TRUE(join(into_depth));
}

// Same pixels, 20 % deeper: another surface, not the same edge.
TEST(FindJoin, RejectsAnEndAtAnotherDepth) {
  const PolyBezier near = line(onAxisLine(2.0 / kPixelsPerMetre), onAxisLine(0.2), 2);
  const auto scaled = [&](double factor) {
    std::vector<Eigen::Vector3d> points;
    for (const Eigen::Vector3d& p : near.points()) points.push_back(factor * p);
    return PolyBezier(points, near.directions(), near.lengths());
  };
  EXPECT_TRUE(join(scaled(1.05)));
  EXPECT_FALSE(join(scaled(1.2)));
}

TEST(FindJoin, TakesTheNearestOfSeveralEnds) {
  const PolyBezier other = line(onAxisLine(-0.4), onAxisLine(-1.0 / kPixelsPerMetre), 1);
  std::vector<OpenEnd> ends = bothEnds(existingCurve());
  ends.push_back(*openEnd(1, other, CurveEnd::kBack, Pose3(), testCamera()));
  const PolyBezier addition = line(onAxisLine(2.0 / kPixelsPerMetre), onAxisLine(0.2), 2);
  const std::optional<CurveJoin> found =
      findJoin(addition, ends, Pose3(), testCamera(), CurveExtensionOptions{});
  ASSERT_TRUE(found);
  EXPECT_EQ(found->open_end, 1);
  EXPECT_NEAR(found->gap_px, 2.0, 1e-9);
}

// The existing curve's variables must come through unchanged, at their new indices.
void expectKeepsExisting(const PolyBezier& existing, const PolyBezier& extended, int offset) {
  for (int i = 0; i < existing.numSegments(); ++i) {
    EXPECT_EQ(extended.points()[i + offset], existing.points()[i]) << i;
    EXPECT_EQ(extended.directions()[i + offset].vector(), existing.directions()[i].vector()) << i;
    EXPECT_EQ(extended.lengths()[i + offset].d1, existing.lengths()[i].d1) << i;
    EXPECT_EQ(extended.lengths()[i + offset].d2, existing.lengths()[i].d2) << i;
  }
  EXPECT_EQ(extended.points()[existing.numSegments() + offset], existing.points().back());
}

TEST(ExtendCurve, AppendsAtTheBackInTheAdditionsOrder) {
  const PolyBezier existing = existingCurve();
  const PolyBezier addition = line(onAxisLine(0.01), onAxisLine(0.31), 3);
  for (const bool flip : {false, true}) {
    const ExtendedCurve extended =
        extendCurve(existing, CurveEnd::kBack, flip ? reversed(addition) : addition,
                    flip ? CurveEnd::kBack : CurveEnd::kFront);
    ASSERT_EQ(extended.curve.numSegments(), 5);
    expectKeepsExisting(existing, extended.curve, 0);
    EXPECT_EQ(extended.curve.points().back(), onAxisLine(0.31));
    const std::vector<int> expected = flip ? std::vector<int>{4, 3, 2} : std::vector<int>{2, 3, 4};
    EXPECT_EQ(extended.added_segments, expected);
  }
}

TEST(ExtendCurve, PrependsAtTheFrontAndPullsTheJoinOntoTheExistingEnd) {
  const PolyBezier existing = existingCurve();
  const PolyBezier addition = line(onAxisLine(-0.7), onAxisLine(-0.41), 3);
  for (const bool flip : {false, true}) {
    const ExtendedCurve extended =
        extendCurve(existing, CurveEnd::kFront, flip ? reversed(addition) : addition,
                    flip ? CurveEnd::kFront : CurveEnd::kBack);
    ASSERT_EQ(extended.curve.numSegments(), 5);
    expectKeepsExisting(existing, extended.curve, 3);
    EXPECT_EQ(extended.curve.points()[0], onAxisLine(-0.7));
    // The segment away from the join keeps its shape.
    EXPECT_TRUE(extended.curve.evaluate(0, 0.5).isApprox(addition.evaluate(0, 0.5), 1e-12));
    const std::vector<int> expected = flip ? std::vector<int>{2, 1, 0} : std::vector<int>{0, 1, 2};
    EXPECT_EQ(extended.added_segments, expected);
  }
}

TEST(CurveExtensionOptions, ValidateNamesTheField) {
  CurveExtensionOptions options;
  EXPECT_NO_THROW(options.validate());
  options.max_angle_deg = 0.0;
  EXPECT_THAT([&] { options.validate(); },
              testing::ThrowsMessage<InvalidOptions>(
                  testing::HasSubstr("CurveExtensionOptions.max_angle_deg")));
  options = {};
  options.max_gap_px = std::nan("");
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = {};
  options.max_lateral_px = -1.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = {};
  options.max_relative_depth_gap = 0.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
