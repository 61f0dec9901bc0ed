#include "frontend/image/edge_chains.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/nearest_edge_field.h"
#include "frontend/image/edge_detector.h"

namespace curvesfm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// An edge image whose edges are drawn directly (one pixel wide) and whose gradients are zero:
// the chain structure does not depend on them.
EdgeImage drawnEdges(const cv::Mat& edges) {
  EdgeImage image;
  image.edges = edges;
  image.grad_x = cv::Mat(edges.size(), CV_16SC1, cv::Scalar(0));
  image.grad_y = cv::Mat(edges.size(), CV_16SC1, cv::Scalar(0));
  return image;
}

cv::Mat blank(int width = 200, int height = 200) {
  return cv::Mat(height, width, CV_8UC1, cv::Scalar(0));
}

std::set<std::pair<int, int>> edgePixels(const cv::Mat& edges) {
  std::set<std::pair<int, int>> pixels;
  for (int r = 0; r < edges.rows; ++r) {
    for (int c = 0; c < edges.cols; ++c) {
      if (edges.at<std::uint8_t>(r, c) != 0) pixels.insert({c, r});
    }
  }
  return pixels;
}

bool areNeighbours(const Eigen::Vector2i& a, const Eigen::Vector2i& b) {
  const Eigen::Vector2i d = (a - b).cwiseAbs();
  return d.maxCoeff() == 1;
}

// Consecutive pixels (and last-first for loops) are distinct 8-neighbours, normals are unit.
void expectWellFormed(const EdgeChain& chain) {
  ASSERT_EQ(chain.pixels.size(), chain.normals.size());
  for (std::size_t i = 1; i < chain.pixels.size(); ++i) {
    EXPECT_TRUE(areNeighbours(chain.pixels[i - 1], chain.pixels[i]))
        << "pixels " << i - 1 << " and " << i << " of " << chain.pixels.size();
  }
  if (chain.closed) {
    EXPECT_TRUE(areNeighbours(chain.pixels.back(), chain.pixels.front()));
  }
  for (const Eigen::Vector2f& n : chain.normals) EXPECT_NEAR(n.norm(), 1.0f, 1e-5f);
}

// Fraction of `drawn` pixels that are in the chains; fails for chain pixels not in `drawn`.
double coverage(const std::vector<EdgeChain>& chains, const std::set<std::pair<int, int>>& drawn) {
  std::set<std::pair<int, int>> covered;
  for (const EdgeChain& chain : chains) {
    for (const Eigen::Vector2i& p : chain.pixels) {
      EXPECT_TRUE(drawn.count({p.x(), p.y()})) << "(" << p.x() << ", " << p.y() << ")";
      EXPECT_TRUE(covered.insert({p.x(), p.y()}).second) << "pixel in two chains";
    }
  }
  return static_cast<double>(covered.size()) / static_cast<double>(drawn.size());
}

double distanceTo(const Eigen::Vector2i& pixel, const Eigen::Vector2d& point) {
  return (pixel.cast<double>() - point).norm();
}

// The one chain traced from the drawn `edges`: well formed, closed or not as `closed`, covering
// at least `min_coverage` of the drawn pixels (and nothing else), with an arc length within 10 %
// of `length` (a digital 8-connected curve is up to 8 % longer than the curve). Empty on failure.
EdgeChain expectOneChain(const cv::Mat& edges, bool closed, double min_coverage, double length) {
  const std::vector<EdgeChain> chains = extractEdgeChains(drawnEdges(edges));
  EXPECT_EQ(chains.size(), 1u);
  if (chains.size() != 1u) return EdgeChain();
  expectWellFormed(chains[0]);
  EXPECT_EQ(chains[0].closed, closed);
  EXPECT_GE(coverage(chains, edgePixels(edges)), min_coverage);
  EXPECT_NEAR(chains[0].arcLength(), length, 0.1 * length);
  return chains[0];
}

TEST(EdgeChains, StraightLineGivesOneOrderedChain) {
  cv::Mat edges = blank();
  cv::line(edges, {10, 20}, {150, 75}, 255, 1, cv::LINE_8);
  const EdgeChain chain = expectOneChain(edges, false, 1.0, std::hypot(140.0, 55.0));
  ASSERT_FALSE(chain.pixels.empty());
  // The ends are the line's end points, in either order.
  const Eigen::Vector2i a = chain.pixels.front();
  const Eigen::Vector2i b = chain.pixels.back();
  EXPECT_EQ(std::min(a.x(), b.x()), 10);
  EXPECT_EQ(std::max(a.x(), b.x()), 150);
}

TEST(EdgeChains, CircleArcGivesOneChainAlongTheArc) {
  cv::Mat edges = blank();
  const double radius = 40.0;
  cv::ellipse(edges, {100, 100}, {40, 40}, 0.0, 0.0, 120.0, 255, 1, cv::LINE_8);
  const EdgeChain chain = expectOneChain(edges, false, 0.95, radius * 2.0 * kPi / 3.0);
  for (const Eigen::Vector2i& p : chain.pixels) {
    EXPECT_NEAR(distanceTo(p, {100.0, 100.0}), radius, 1.0);
  }
}

TEST(EdgeChains, ClosedCircleGivesOneClosedChain) {
  cv::Mat edges = blank();
  cv::circle(edges, {90, 110}, 30, 255, 1, cv::LINE_8);
  expectOneChain(edges, true, 0.95, 2.0 * kPi * 30.0);
}

TEST(EdgeChains, FourConnectedStaircaseIsThinnedIntoOneChain) {
  cv::Mat edges = blank();
  // LINE_4 steps put a redundant corner pixel at every step: each would see three neighbours.
  cv::line(edges, {10, 10}, {120, 70}, 255, 1, cv::LINE_4);
  // Thinning removes the corner pixels (about a third of them all).
  expectOneChain(edges, false, 0.6, std::hypot(110.0, 60.0));
}

TEST(EdgeChains, TJunctionGivesThreeChains) {
  cv::Mat edges = blank();
  cv::line(edges, {10, 50}, {90, 50}, 255, 1, cv::LINE_8);
  cv::line(edges, {50, 51}, {50, 90}, 255, 1, cv::LINE_8);
  const std::vector<EdgeChain> chains = extractEdgeChains(drawnEdges(edges));
  ASSERT_EQ(chains.size(), 3u);
  for (const EdgeChain& chain : chains) {
    expectWellFormed(chain);
    EXPECT_NEAR(static_cast<double>(chain.pixels.size()), 40.0, 2.0);
  }
  EXPECT_GT(coverage(chains, edgePixels(edges)), 0.95);
}

TEST(EdgeChains, RightAngleCornerSplitsIntoTwoChains) {
  cv::Mat edges = blank();
  const std::vector<cv::Point> corner = {{20, 20}, {80, 20}, {80, 80}};
  cv::polylines(edges, corner, false, 255, 1, cv::LINE_8);
  const std::vector<EdgeChain> chains = extractEdgeChains(drawnEdges(edges));
  ASSERT_EQ(chains.size(), 2u);
  for (const EdgeChain& chain : chains) {
    expectWellFormed(chain);
    EXPECT_NEAR(static_cast<double>(chain.pixels.size()), 60.0, 2.0);
    const double to_corner = std::min(distanceTo(chain.pixels.front(), {80.0, 20.0}),
                                      distanceTo(chain.pixels.back(), {80.0, 20.0}));
    EXPECT_LE(to_corner, 2.0);
  }
  // Thinning removes the apex: its two neighbours touch diagonally.
  EXPECT_NEAR(coverage(chains, edgePixels(edges)), 1.0, 1.5 / 120.0);
}

TEST(EdgeChains, GentleArcIsNotSplitButASquareLoopIsCutAtItsCorners) {
  cv::Mat arc = blank();
  // Radius 20 px turns 6 / 20 rad = 17 deg over the default window: below the 45 deg limit.
  cv::ellipse(arc, {100, 100}, {20, 20}, 0.0, 0.0, 270.0, 255, 1, cv::LINE_8);
  EXPECT_EQ(extractEdgeChains(drawnEdges(arc)).size(), 1u);

  cv::Mat square = blank();
  cv::rectangle(square, cv::Rect(30, 40, 100, 80), 255, 1, cv::LINE_8);
  const std::vector<EdgeChain> sides = extractEdgeChains(drawnEdges(square));
  ASSERT_EQ(sides.size(), 4u);
  for (const EdgeChain& side : sides) {
    EXPECT_FALSE(side.closed);
    expectWellFormed(side);
  }
  EXPECT_NEAR(coverage(sides, edgePixels(square)), 1.0, 4.5 / 360.0);  // Less the 4 apexes.
}

TEST(EdgeChains, ChainsShorterThanTheMinimumAreDropped) {
  cv::Mat edges = blank();
  cv::line(edges, {10, 10}, {17, 10}, 255, 1, cv::LINE_8);  // 8 pixels.
  cv::line(edges, {10, 30}, {60, 30}, 255, 1, cv::LINE_8);  // 51 pixels.
  EdgeChainOptions options;
  options.min_length_px = 10;
  const std::vector<EdgeChain> long_only = extractEdgeChains(drawnEdges(edges), options);
  ASSERT_EQ(long_only.size(), 1u);
  EXPECT_EQ(long_only[0].pixels.size(), 51u);
  options.min_length_px = 8;
  EXPECT_EQ(extractEdgeChains(drawnEdges(edges), options).size(), 2u);
}

// An image of `size` whose grey level is 50 + 150 * coverage(signed_distance(c, r)), with the
// coverage of a pixel by the bright side approximated by clamp(d + 0.5, 0, 1): an anti-aliased
// rendering whose edge lies exactly where the signed distance is 0.
template <class SignedDistance>
cv::Mat renderTwoTone(const cv::Size& size, SignedDistance signed_distance) {
  cv::Mat image(size, CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const double coverage = std::min(1.0, std::max(0.0, signed_distance(c, r) + 0.5));
      image.at<std::uint8_t>(r, c) = cv::saturate_cast<std::uint8_t>(50.0 + 150.0 * coverage);
    }
  }
  return image;
}

// A step edge through (cx, cy) with unit normal (cos a, sin a) pointing to the bright side.
cv::Mat renderStep(double angle_rad, double cx, double cy) {
  return renderTwoTone(cv::Size(160, 120), [&](int c, int r) {
    return (c - cx) * std::cos(angle_rad) + (r - cy) * std::sin(angle_rad);
  });
}

TEST(EdgeChains, NormalsOfARenderedStepFollowTheTrueNormal) {
  for (const double angle_deg : {0.0, 17.0, 30.0, 45.0, 71.0, 135.0, 200.0}) {
    const double angle = angle_deg * kPi / 180.0;
    const EdgeImage edges = detectEdges(renderStep(angle, 80.3, 60.6));
    const std::vector<EdgeChain> chains = extractEdgeChains(edges);
    ASSERT_EQ(chains.size(), 1u) << angle_deg << " deg";
    const Eigen::Vector2f truth(static_cast<float>(std::cos(angle)),
                                static_cast<float>(std::sin(angle)));
    int checked = 0;
    for (std::size_t i = 0; i < chains[0].pixels.size(); ++i) {
      const Eigen::Vector2i& p = chains[0].pixels[i];
      if (p.x() < 4 || p.y() < 4 || p.x() > 155 || p.y() > 115) continue;  // Border effects.
      const double cosine = std::min(1.0f, chains[0].normals[i].dot(truth));
      EXPECT_LT(std::acos(cosine) * 180.0 / kPi, 3.0) << angle_deg << " deg, pixel " << i;
      ++checked;
    }
    EXPECT_GT(checked, 50);
    // Bright side on the right of the chain (y down): cross(direction, normal) > 0.
    const Eigen::Vector2f direction =
        (chains[0].pixels.back() - chains[0].pixels.front()).cast<float>();
    EXPECT_GT(direction.x() * truth.y() - direction.y() * truth.x(), 0.0f) << angle_deg << " deg";
  }
}

TEST(EdgeChains, RenderedDiscGivesOneClosedChainOnItsRim) {
  const cv::Mat image = renderTwoTone(cv::Size(160, 160), [](int c, int r) {
    return 35.0 - std::hypot(c - 80.0, r - 75.0);  // Bright inside.
  });
  const EdgeImage edges = detectEdges(image);
  const std::vector<EdgeChain> chains = extractEdgeChains(edges);
  ASSERT_EQ(chains.size(), 1u);
  expectWellFormed(chains[0]);
  EXPECT_TRUE(chains[0].closed);
  for (const Eigen::Vector2i& p : chains[0].pixels) {
    EXPECT_NEAR(distanceTo(p, {80.0, 75.0}), 35.0, 1.0);
  }
  EXPECT_NEAR(chains[0].arcLength(), 2.0 * kPi * 35.0, 0.1 * 2.0 * kPi * 35.0);
}

TEST(EdgeChains, ChainEdgeMapFeedsTheNearestEdgeField) {
  cv::Mat edges = blank();
  cv::line(edges, {10, 20}, {150, 75}, 255, 1, cv::LINE_8);
  cv::line(edges, {10, 150}, {14, 150}, 255, 1, cv::LINE_8);  // Too short to be a chain.
  const EdgeImage image = drawnEdges(edges);
  const std::vector<EdgeChain> chains = extractEdgeChains(image);
  const cv::Mat map = chainEdgeMap(chains, edges.size());
  EXPECT_EQ(cv::countNonZero(map), static_cast<int>(chains[0].pixels.size()));
  const NearestEdgeField field = NearestEdgeField::build(map, image.grad_x, image.grad_y);
  EXPECT_EQ(field.edges().size(), chains[0].pixels.size());
  EXPECT_THROW(chainEdgeMap(chains, cv::Size(20, 20)), CheckError);
}

TEST(EdgeChains, BadOptionsAndImagesThrow) {
  const EdgeImage image = drawnEdges(blank(20, 20));
  EdgeChainOptions options;
  options.min_length_px = 1;
  EXPECT_THROW(extractEdgeChains(image, options), InvalidOptions);
  options = EdgeChainOptions();
  options.max_turn_deg = 0.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options.max_turn_deg = 181.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = EdgeChainOptions();
  options.turn_window_px = 0;
  try {
    options.validate();
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_EQ(std::string(e.what()),
              "InvalidOptions: EdgeChainOptions.turn_window_px = 0: in [1, 1000]");
  }
  EdgeImage bad = image;
  bad.grad_x = cv::Mat(20, 20, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(extractEdgeChains(bad), CheckError);
  bad = image;
  bad.edges = blank(21, 20);
  EXPECT_THROW(extractEdgeChains(bad), CheckError);
}

}  // namespace
}  // namespace curvesfm
