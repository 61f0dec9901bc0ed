#include "frontend/mapping/nearest_curve_depths.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace curvesfm {
namespace {

// A horizontal polyline at row y from x0 to x1 in steps of 5 px, every vertex at `depth`.
struct Polyline {
  std::vector<cv::Point> pixels;
  std::vector<double> depths;
};

Polyline horizontal(int y, int x0, int x1, double depth) {
  Polyline line;
  for (int x = x0; x <= x1; x += 5) {
    line.pixels.emplace_back(x, y);
    line.depths.push_back(depth);
  }
  return line;
}

TEST(NearestCurveDepths, ACurveHidesWhatLiesBehindItNotADuplicateAtItsDepth) {
  NearestCurveDepths nearest(100, 80, 2, 0.9);
  const Polyline occluder = horizontal(40, 10, 60, 2.0);
  nearest.add(occluder.pixels, occluder.depths);

  const Polyline behind = horizontal(41, 10, 60, 3.0);
  EXPECT_DOUBLE_EQ(nearest.fractionOccluded(behind.pixels, behind.depths), 1.0);
  // Within the ratio's margin: two curves on one surface do not hide each other.
  const Polyline duplicate = horizontal(40, 10, 60, 2.1);
  EXPECT_DOUBLE_EQ(nearest.fractionOccluded(duplicate.pixels, duplicate.depths), 0.0);
  const Polyline in_front = horizontal(40, 10, 60, 1.0);
  EXPECT_DOUBLE_EQ(nearest.fractionOccluded(in_front.pixels, in_front.depths), 0.0);
  // Beyond the band of 2 px.
  const Polyline beside = horizontal(43, 10, 60, 3.0);
  EXPECT_DOUBLE_EQ(nearest.fractionOccluded(beside.pixels, beside.depths), 0.0);
  // Half of it behind the occluder's end.
  const Polyline half = horizontal(40, 35, 84, 3.0);
  EXPECT_NEAR(nearest.fractionOccluded(half.pixels, half.depths), 0.6, 1e-12);
}

TEST(NearestCurveDepths, KeepsTheNearestCurveAndInterpolatesDepthAlongAPiece) {
  NearestCurveDepths nearest(100, 80, 0, 1.0);
  nearest.add({{0, 10}, {40, 10}}, {1.0, 5.0});
  EXPECT_FLOAT_EQ(nearest.depthAt({0, 10}), 1.0f);
  EXPECT_FLOAT_EQ(nearest.depthAt({20, 10}), 3.0f);
  EXPECT_FLOAT_EQ(nearest.depthAt({40, 10}), 5.0f);
  EXPECT_TRUE(std::isinf(nearest.depthAt({20, 11})));
  nearest.add({{20, 0}, {20, 20}}, {2.0, 2.0});
  nearest.add({{30, 0}, {30, 20}}, {9.0, 9.0});
  EXPECT_FLOAT_EQ(nearest.depthAt({20, 10}), 2.0f);
  EXPECT_FLOAT_EQ(nearest.depthAt({30, 10}), 4.0f);
}

TEST(NearestCurveDepths, APieceRunningOutOfTheImageKeepsItsDepthsInside) {
  NearestCurveDepths nearest(100, 80, 0, 1.0);
  // From x = -100 (depth 1) to x = 100 (depth 3): depth 2 at x = 0, 2.5 at x = 50.
  nearest.add({{-100, 5}, {100, 5}}, {1.0, 3.0});
  EXPECT_NEAR(nearest.depthAt({0, 5}), 2.0f, 1e-6);
  EXPECT_NEAR(nearest.depthAt({50, 5}), 2.5f, 1e-6);
  // Far outside: nothing to draw, and no time spent there.
  nearest.add({{-100000, -5}, {100000, -5}}, {1.0, 1.0});
  EXPECT_TRUE(std::isinf(nearest.depthAt({50, 0})));
  const std::vector<cv::Point> outside = {{-5, -5}, {200, 5}};
  EXPECT_DOUBLE_EQ(nearest.fractionOccluded(outside, {100.0, 100.0}), 0.0);
}

TEST(NearestCurveDepths, RefusesBadSizesRatiosAndMismatchedDepths) {
  EXPECT_THROW(NearestCurveDepths(0, 10, 1, 0.9), CheckError);
  EXPECT_THROW(NearestCurveDepths(10, 10, -1, 0.9), CheckError);
  EXPECT_THROW(NearestCurveDepths(10, 10, 1, 0.0), CheckError);
  EXPECT_THROW(NearestCurveDepths(10, 10, 1, 1.5), CheckError);
  NearestCurveDepths nearest(10, 10, 1, 0.9);
  EXPECT_THROW(nearest.add({{1, 1}, {2, 2}}, {1.0}), CheckError);
  EXPECT_THROW(nearest.fractionOccluded({{1, 1}}, {}), CheckError);
}

}  // namespace
}  // namespace curvesfm
