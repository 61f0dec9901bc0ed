#include "core/nearest_edge_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

NearestEdgeFieldOptions withReach(int reach) {
  NearestEdgeFieldOptions options;
  options.max_distance_px = reach;
  return options;
}

// Gradients that give every pixel a distinct, non-zero normal; the field's index does not
// depend on them.
void randomGradients(const cv::Size& size, std::mt19937& rng, cv::Mat* grad_x, cv::Mat* grad_y) {
  std::uniform_real_distribution<float> uniform(-100.0f, 100.0f);
  *grad_x = cv::Mat(size, CV_32FC1);
  *grad_y = cv::Mat(size, CV_32FC1);
  for (int r = 0; r < size.height; ++r) {
    for (int c = 0; c < size.width; ++c) {
      grad_x->at<float>(r, c) = uniform(rng);
      grad_y->at<float>(r, c) = uniform(rng);
    }
  }
}

cv::Mat randomEdges(const cv::Size& size, double density, std::mt19937& rng) {
  std::bernoulli_distribution is_edge(density);
  cv::Mat edges(size, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < size.height; ++r) {
    for (int c = 0; c < size.width; ++c) edges.at<std::uint8_t>(r, c) = is_edge(rng) ? 255 : 0;
  }
  return edges;
}

NearestEdgeField buildWithRandomGradients(const cv::Mat& edges, int reach, unsigned seed = 1) {
  std::mt19937 rng(seed);
  cv::Mat grad_x;
  cv::Mat grad_y;
  randomGradients(edges.size(), rng, &grad_x, &grad_y);
  return NearestEdgeField::build(edges, grad_x, grad_y, withReach(reach));
}

// Brute force: the smallest squared distance from (column, row) to an edge pixel, searched in the
// (2R+1)^2 window (enough to decide whether it is <= R^2); -1 if there is none within R.
int bruteForceSquaredDistance(const cv::Mat& edges, int column, int row, int reach) {
  int best = -1;
  for (int r = std::max(0, row - reach); r <= std::min(edges.rows - 1, row + reach); ++r) {
    for (int c = std::max(0, column - reach); c <= std::min(edges.cols - 1, column + reach); ++c) {
      if (edges.at<std::uint8_t>(r, c) == 0) continue;
      const int squared = (c - column) * (c - column) + (r - row) * (r - row);
      if (squared <= reach * reach && (best < 0 || squared < best)) best = squared;
    }
  }
  return best;
}

// Checks every pixel of `field` against brute force; returns the number of mismatches (and
// reports the first few).
int countMismatches(const NearestEdgeField& field, const cv::Mat& edges, int reach) {
  int mismatches = 0;
  for (int row = 0; row < edges.rows; ++row) {
    for (int column = 0; column < edges.cols; ++column) {
      const int expected = bruteForceSquaredDistance(edges, column, row, reach);
      const EdgePixel* edge = field.nearestToPixel(column, row);
      int actual = -1;
      bool on_edge = true;
      if (edge != nullptr) {
        const int c = static_cast<int>(edge->pixel.x());
        const int r = static_cast<int>(edge->pixel.y());
        on_edge = edges.at<std::uint8_t>(r, c) != 0;
        actual = (c - column) * (c - column) + (r - row) * (r - row);
      }
      if (actual != expected || !on_edge) {
        if (++mismatches <= 5) {
          ADD_FAILURE() << "pixel (" << column << ", " << row << "): squared distance " << actual
                        << " (on an edge: " << on_edge << "), brute force " << expected;
        }
      }
    }
  }
  return mismatches;
}

TEST(NearestEdgeField, ExactOnRandomEdgeMaps) {
  for (const cv::Size size : {cv::Size(37, 23), cv::Size(160, 120)}) {
    for (const double density : {0.005, 0.2}) {
      // 1 to 15: every block by the window search; 25: window search and envelope mixed.
      for (const int reach : {1, 3, 15, 25}) {
        for (const unsigned seed : {1u, 2u, 3u}) {
          if (reach > 15 && seed > 1) continue;  // The brute force grows with R^2.
          std::mt19937 rng(seed);
          const cv::Mat edges = randomEdges(size, density, rng);
          const NearestEdgeField field = buildWithRandomGradients(edges, reach, seed);
          ASSERT_EQ(field.width(), size.width);
          ASSERT_EQ(field.height(), size.height);
          ASSERT_EQ(field.maxDistance(), reach);
          EXPECT_EQ(countMismatches(field, edges, reach), 0)
              << size << " density " << density << " R " << reach << " seed " << seed;
        }
      }
    }
  }
}

// Random lines leave long runs of equal vertical distances and many ties, unlike random pixels.
TEST(NearestEdgeField, ExactOnLineDrawings) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(-20, 180);
  std::uniform_int_distribution<int> y(-20, 140);
  for (const int reach : {2, 15, 40}) {
    cv::Mat edges(120, 160, CV_8UC1, cv::Scalar(0));
    for (int k = 0; k < 12; ++k) cv::line(edges, {x(rng), y(rng)}, {x(rng), y(rng)}, 255, 1);
    const NearestEdgeField field = buildWithRandomGradients(edges, reach);
    EXPECT_EQ(countMismatches(field, edges, reach), 0) << "R " << reach;
  }
}

TEST(NearestEdgeField, EmptyEdgeMapHasNoNearestEdge) {
  const cv::Mat edges(23, 37, CV_8UC1, cv::Scalar(0));
  const NearestEdgeField field = buildWithRandomGradients(edges, 15);
  EXPECT_TRUE(field.edges().empty());
  for (int row = 0; row < edges.rows; ++row) {
    for (int column = 0; column < edges.cols; ++column) {
      EXPECT_EQ(field.nearestToPixel(column, row), nullptr);
    }
  }
}

TEST(NearestEdgeField, AllEdgeMapMapsEveryPixelToItself) {
  const cv::Mat edges(23, 37, CV_8UC1, cv::Scalar(1));
  const NearestEdgeField field = buildWithRandomGradients(edges, 1);
  ASSERT_EQ(field.edges().size(), 23u * 37u);
  for (int row = 0; row < edges.rows; ++row) {
    for (int column = 0; column < edges.cols; ++column) {
      const EdgePixel* edge = field.nearestToPixel(column, row);
      ASSERT_NE(edge, nullptr);
      EXPECT_EQ(edge->pixel, Eigen::Vector2f(column, row));
      EXPECT_EQ(edge - field.edges().data(), row * 37 + column) << "edge list is row-major";
    }
  }
}

TEST(NearestEdgeField, ExactWithEdgesOnTheBorder) {
  for (const int reach : {1, 3, 15}) {
    cv::Mat edges(23, 37, CV_8UC1, cv::Scalar(0));
    edges.row(0).setTo(255);
    edges.col(36).setTo(255);
    edges.at<std::uint8_t>(22, 0) = 255;
    edges.at<std::uint8_t>(11, 0) = 255;
    const NearestEdgeField field = buildWithRandomGradients(edges, reach);
    EXPECT_EQ(countMismatches(field, edges, reach), 0) << "R " << reach;
  }
}

TEST(NearestEdgeField, SingleEdgeReachesExactlyTheDiscOfRadiusR) {
  cv::Mat edges(41, 41, CV_8UC1, cv::Scalar(0));
  edges.at<std::uint8_t>(20, 20) = 255;
  const int reach = 7;
  const NearestEdgeField field = buildWithRandomGradients(edges, reach);
  int inside = 0;
  for (int row = 0; row < 41; ++row) {
    for (int column = 0; column < 41; ++column) {
      const int squared = (column - 20) * (column - 20) + (row - 20) * (row - 20);
      EXPECT_EQ(field.nearestToPixel(column, row) != nullptr, squared <= reach * reach)
          << column << ", " << row;
      inside += squared <= reach * reach ? 1 : 0;
    }
  }
  EXPECT_EQ(inside, 149);  // Lattice points in a disc of radius 7.
}

TEST(NearestEdgeField, ExactOnThinImagesAndHugeReach) {
  std::mt19937 rng(11);
  for (const cv::Size size : {cv::Size(1, 50), cv::Size(50, 1), cv::Size(1, 1), cv::Size(3, 70)}) {
    const cv::Mat edges = randomEdges(size, 0.05, rng);
    for (const int reach : {1, 4, 1000}) {
      const NearestEdgeField field = buildWithRandomGradients(edges, reach);
      EXPECT_EQ(countMismatches(field, edges, reach), 0) << size << " R " << reach;
    }
  }
}

// Beyond 32767 columns the row pass switches to 64-bit arithmetic; R > 127 disables the window
// search, R = 40 mixes it with the envelope.
TEST(NearestEdgeField, ExactOnVeryWideImages) {
  std::mt19937 rng(13);
  const cv::Mat edges = randomEdges(cv::Size(33000, 2), 0.002, rng);
  for (const int reach : {15, 40, 200}) {
    const NearestEdgeField field = buildWithRandomGradients(edges, reach);
    EXPECT_EQ(countMismatches(field, edges, reach), 0) << "R " << reach;
  }
}

TEST(NearestEdgeField, BuildIsDeterministic) {
  std::mt19937 rng(5);
  const cv::Mat edges = randomEdges(cv::Size(64, 48), 0.1, rng);
  const NearestEdgeField a = buildWithRandomGradients(edges, 6);
  const NearestEdgeField b = buildWithRandomGradients(edges, 6);
  for (int row = 0; row < 48; ++row) {
    for (int column = 0; column < 64; ++column) {
      const EdgePixel* ea = a.nearestToPixel(column, row);
      const EdgePixel* eb = b.nearestToPixel(column, row);
      ASSERT_EQ(ea == nullptr, eb == nullptr);
      if (ea != nullptr) {
        EXPECT_EQ(ea - a.edges().data(), eb - b.edges().data());
      }
    }
  }
}

TEST(NearestEdgeField, CopiesAndMovesKeepTheirLookups) {
  std::mt19937 rng(17);
  const cv::Mat edges = randomEdges(cv::Size(30, 20), 0.05, rng);
  NearestEdgeField original = buildWithRandomGradients(edges, 4);
  const NearestEdgeField copy = original;  // The copy is what is tested.
  const NearestEdgeField moved = std::move(original);
  for (const NearestEdgeField* field : {&copy, &moved}) {
    EXPECT_EQ(countMismatches(*field, edges, 4), 0);
    EXPECT_EQ(field->memoryBytes(), 2u * 30u * 20u + sizeof(EdgePixel) * field->edges().size());
  }
}

TEST(NearestEdgeField, NearestRoundsToThePixelCentre) {
  cv::Mat edges(10, 12, CV_8UC1, cv::Scalar(0));
  edges.at<std::uint8_t>(5, 5) = 255;
  const NearestEdgeField field = buildWithRandomGradients(edges, 1);
  ASSERT_EQ(field.edges().size(), 1u);
  const EdgePixel* edge = &field.edges()[0];
  EXPECT_EQ(field.nearest(5.0, 5.0), edge);
  EXPECT_EQ(field.nearest(5.49, 4.51), edge);
  EXPECT_EQ(field.nearest(6.49, 5.0), edge);     // Pixel (6, 5): distance 1.
  EXPECT_EQ(field.nearest(6.51, 5.0), nullptr);  // Pixel (7, 5): distance 2 > R.
  EXPECT_EQ(field.nearest(5.6, 5.6), nullptr);   // Pixel (6, 6): distance sqrt(2) > R.
  EXPECT_EQ(field.nearest(5.0, 3.6), edge);      // Pixel (5, 4).
  EXPECT_EQ(field.nearest(5.0, 3.4), nullptr);   // Pixel (5, 3).
}

TEST(NearestEdgeField, NearestOutsideTheImageIsNull) {
  const cv::Mat edges(10, 12, CV_8UC1, cv::Scalar(255));
  const NearestEdgeField field = buildWithRandomGradients(edges, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(field.nearest(-0.49, -0.49), nullptr);
  EXPECT_NE(field.nearest(11.49, 9.49), nullptr);
  EXPECT_EQ(field.nearest(-0.5, 0.0), nullptr);
  EXPECT_EQ(field.nearest(0.0, -0.5), nullptr);
  EXPECT_EQ(field.nearest(-3.0, 2.0), nullptr);
  EXPECT_EQ(field.nearest(11.5, 0.0), nullptr);  // width - 0.5
  EXPECT_EQ(field.nearest(0.0, 9.5), nullptr);   // height - 0.5
  EXPECT_EQ(field.nearest(nan, 1.0), nullptr);
  EXPECT_EQ(field.nearest(1.0, nan), nullptr);
  EXPECT_EQ(field.nearest(inf, 1.0), nullptr);
  EXPECT_EQ(field.nearest(1.0, -inf), nullptr);
  EXPECT_EQ(field.nearestToPixel(-1, 0), nullptr);
  EXPECT_EQ(field.nearestToPixel(0, 10), nullptr);
  EXPECT_EQ(field.nearestToPixel(12, 0), nullptr);
  EXPECT_NE(field.nearestToPixel(11, 9), nullptr);
}

TEST(NearestEdgeField, DefaultFieldMissesEverywhere) {
  const NearestEdgeField field;
  EXPECT_EQ(field.width(), 0);
  EXPECT_EQ(field.nearest(0.0, 0.0), nullptr);
  EXPECT_EQ(field.nearestToPixel(0, 0), nullptr);
  EXPECT_EQ(field.memoryBytes(), 0u);
}

TEST(NearestEdgeField, EmptyImageGivesAnEmptyField) {
  const NearestEdgeField field = NearestEdgeField::build(
      cv::Mat(0, 0, CV_8UC1), cv::Mat(0, 0, CV_16SC1), cv::Mat(0, 0, CV_16SC1));
  EXPECT_EQ(field.width(), 0);
  EXPECT_EQ(field.height(), 0);
  EXPECT_TRUE(field.edges().empty());
  EXPECT_EQ(field.nearest(0.0, 0.0), nullptr);
}

TEST(NearestEdgeField, MemoryIsTwoBytesPerPixelPlusTheEdgeList) {
  std::mt19937 rng(3);
  const cv::Mat edges = randomEdges(cv::Size(64, 48), 0.1, rng);
  const NearestEdgeField field = buildWithRandomGradients(edges, 15);
  EXPECT_EQ(field.memoryBytes(), 2u * 64u * 48u + sizeof(EdgePixel) * field.edges().size());
  EXPECT_EQ(field.edges().size(), static_cast<std::size_t>(cv::countNonZero(edges)));
}

TEST(NearestEdgeField, SixtyFiveThousandEdgePixelsTakeFourBytesPerPixelAndStillFindTheirs) {
  // 65,535 edge pixels: one more than two bytes can index beside the "none" value.
  cv::Mat edges(256, 256, CV_8UC1, cv::Scalar(255));
  edges.at<std::uint8_t>(0, 0) = 0;
  const NearestEdgeField field = buildWithRandomGradients(edges, 2);
  ASSERT_EQ(field.edges().size(), 65535u);
  EXPECT_EQ(field.memoryBytes(), 4u * 256u * 256u + sizeof(EdgePixel) * 65535u);
  EXPECT_EQ(countMismatches(field, edges, 2), 0);
  const EdgePixel* last = field.nearestToPixel(255, 255);
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(last, &field.edges().back());

  edges.at<std::uint8_t>(0, 1) = 0;  // 65,534: two bytes again.
  const NearestEdgeField narrow = buildWithRandomGradients(edges, 2);
  EXPECT_EQ(narrow.memoryBytes(), 2u * 256u * 256u + sizeof(EdgePixel) * 65534u);
  EXPECT_EQ(countMismatches(narrow, edges, 2), 0);
  EXPECT_EQ(narrow.nearestToPixel(255, 255), &narrow.edges().back());
}

TEST(NearestEdgeField, NormalsAreUnitGradientDirections) {
  std::mt19937 rng(9);
  const cv::Mat edges = randomEdges(cv::Size(40, 30), 0.3, rng);
  cv::Mat grad_x;
  cv::Mat grad_y;
  randomGradients(edges.size(), rng, &grad_x, &grad_y);
  grad_x.at<float>(4, 7) = 0.0f;  // One zero gradient, edge or not.
  grad_y.at<float>(4, 7) = 0.0f;
  for (const int type : {CV_32FC1, CV_16SC1}) {
    cv::Mat gx;
    cv::Mat gy;
    grad_x.convertTo(gx, type);
    grad_y.convertTo(gy, type);
    const NearestEdgeField field = NearestEdgeField::build(edges, gx, gy);
    ASSERT_FALSE(field.edges().empty());
    for (const EdgePixel& edge : field.edges()) {
      const int c = static_cast<int>(edge.pixel.x());
      const int r = static_cast<int>(edge.pixel.y());
      const Eigen::Vector2d g(grad_x.at<float>(r, c), grad_y.at<float>(r, c));
      EXPECT_NEAR(edge.normal.norm(), 1.0, 1e-6);
      if (g.norm() == 0.0 || (type == CV_16SC1 && g.norm() < 1.0)) continue;
      // CV_16S rounds the components; allow for that.
      const double tolerance = type == CV_32FC1 ? 1e-6 : 1.0 / g.norm();
      EXPECT_NEAR(edge.normal.x(), g.x() / g.norm(), tolerance);
      EXPECT_NEAR(edge.normal.y(), g.y() / g.norm(), tolerance);
      // The sub-pixel shift runs along the normal and stays within half a pixel.
      const Eigen::Vector2f shift = edge.subpixel - edge.pixel;
      EXPECT_LE(shift.norm(), 0.5f + 1e-5f);  // Rounding of pixel + shift in float.
      EXPECT_NEAR(shift.x() * edge.normal.y() - shift.y() * edge.normal.x(), 0.0, 1e-5);
    }
  }
}

TEST(NearestEdgeField, ZeroGradientGivesDefaultNormalAndNoShift) {
  cv::Mat edges(5, 5, CV_8UC1, cv::Scalar(0));
  edges.at<std::uint8_t>(2, 2) = 255;
  const cv::Mat zero(5, 5, CV_16SC1, cv::Scalar(0));
  const NearestEdgeField field = NearestEdgeField::build(edges, zero, zero);
  ASSERT_EQ(field.edges().size(), 1u);
  EXPECT_EQ(field.edges()[0].normal, Eigen::Vector2f(1.0f, 0.0f));
  EXPECT_EQ(field.edges()[0].subpixel, Eigen::Vector2f(2.0f, 2.0f));
}

// The Gaussian fit: the vertex of the parabola through the logarithms of the three magnitudes,
// in steps from the middle sample.
double gaussianVertex(double before, double center, double after) {
  return 0.5 * (std::log(before) - std::log(after)) /
         (std::log(before) - 2.0 * std::log(center) + std::log(after));
}

// Gradients along +x with magnitudes `profile` in columns 1, 2, 3 of every row; the edge pixel
// is (2, 2), and (0, 2) lies on the border.
NearestEdgeField buildRidge(const std::array<float, 3>& profile) {
  cv::Mat edges(5, 6, CV_8UC1, cv::Scalar(0));
  edges.at<std::uint8_t>(2, 0) = 255;
  edges.at<std::uint8_t>(2, 2) = 255;
  cv::Mat grad_x(5, 6, CV_32FC1, cv::Scalar(0.0f));
  const cv::Mat grad_y(5, 6, CV_32FC1, cv::Scalar(0.0f));
  for (int r = 0; r < 5; ++r) {
    grad_x.at<float>(r, 0) = 5.0f;
    for (int k = 0; k < 3; ++k) grad_x.at<float>(r, 1 + k) = profile[k];
  }
  return NearestEdgeField::build(edges, grad_x, grad_y);
}

TEST(NearestEdgeField, SubpixelIsTheVertexOfTheLogMagnitudeParabola) {
  const NearestEdgeField field = buildRidge({1.0f, 3.0f, 2.0f});
  ASSERT_EQ(field.edges().size(), 2u);
  EXPECT_EQ(field.edges()[0].subpixel, Eigen::Vector2f(0.0f, 2.0f)) << "border: no shift";
  EXPECT_NEAR(field.edges()[1].subpixel.x(), 2.0 + gaussianVertex(1.0, 3.0, 2.0), 1e-5);
  EXPECT_FLOAT_EQ(field.edges()[1].subpixel.y(), 2.0f);
  // The Gaussian fit is exact on a Gaussian profile: exp(-(x - 0.3)^2 / 2) sampled at -1, 0, 1.
  const auto gaussian = [](double x) {
    return static_cast<float>(std::exp(-0.5 * (x - 0.3) * (x - 0.3)));
  };
  const NearestEdgeField exact = buildRidge({gaussian(-1.0), gaussian(0.0), gaussian(1.0)});
  EXPECT_NEAR(exact.edges()[1].subpixel.x(), 2.3, 1e-5);
}

TEST(NearestEdgeField, SubpixelOnlyWhereTheProfileIsConcave) {
  // A tie with one neighbour: the maximum lies half-way between them.
  EXPECT_NEAR(buildRidge({1.0f, 3.0f, 3.0f}).edges()[1].subpixel.x(), 2.5f, 1e-5);
  // Flat and convex profiles have no maximum: no shift.
  EXPECT_EQ(buildRidge({3.0f, 3.0f, 3.0f}).edges()[1].subpixel, Eigen::Vector2f(2.0f, 2.0f));
  EXPECT_EQ(buildRidge({3.0f, 1.0f, 3.0f}).edges()[1].subpixel, Eigen::Vector2f(2.0f, 2.0f));
  // Concave with its vertex beyond the neighbour: clamped to half a pixel.
  EXPECT_NEAR(buildRidge({1.0f, 2.0f, 2.5f}).edges()[1].subpixel.x(), 2.5f, 1e-5);
  EXPECT_NEAR(buildRidge({2.5f, 2.0f, 1.0f}).edges()[1].subpixel.x(), 1.5f, 1e-5);
}

// Diagonal gradient: the neighbours across the edge are sqrt(2) px apart along the normal.
TEST(NearestEdgeField, DiagonalSubpixelAccountsForTheLongerStep) {
  cv::Mat edges(5, 5, CV_8UC1, cv::Scalar(0));
  edges.at<std::uint8_t>(2, 2) = 255;
  cv::Mat grad(5, 5, CV_32FC1, cv::Scalar(0.0f));
  grad.at<float>(1, 1) = 1.0f;  // Magnitudes sqrt(2) * {1, 3, 2} along the diagonal.
  grad.at<float>(2, 2) = 3.0f;
  grad.at<float>(3, 3) = 2.0f;
  const NearestEdgeField field = NearestEdgeField::build(edges, grad, grad);
  ASSERT_EQ(field.edges().size(), 1u);
  // t diagonal steps of (1, 1): t sqrt(2) px along the normal, not t px.
  const double t = gaussianVertex(1.0, 3.0, 2.0);
  EXPECT_NEAR(field.edges()[0].subpixel.x(), 2.0 + t, 1e-5);
  EXPECT_NEAR(field.edges()[0].subpixel.y(), 2.0 + t, 1e-5);
}

struct StepEdge {
  double angle_rad;  ///< Direction of the normal (dark to bright).
  double offset;     ///< The edge is the line x cos(angle) + y sin(angle) = offset.
};

// A smooth step of width sigma = 1 px (float intensities).
cv::Mat renderStep(const StepEdge& step, const cv::Size& size) {
  cv::Mat image(size, CV_32FC1);
  const double c = std::cos(step.angle_rad);
  const double s = std::sin(step.angle_rad);
  for (int r = 0; r < size.height; ++r) {
    for (int x = 0; x < size.width; ++x) {
      const double u = x * c + r * s - step.offset;
      image.at<float>(r, x) = static_cast<float>(100.0 + 80.0 * std::erf(u / std::sqrt(2.0)));
    }
  }
  return image;
}

double magnitude(const cv::Mat& grad_x, const cv::Mat& grad_y, int column, int row) {
  return std::hypot(grad_x.at<float>(row, column), grad_y.at<float>(row, column));
}

double bilinearMagnitude(const cv::Mat& grad_x, const cv::Mat& grad_y, double x, double y) {
  const int c = static_cast<int>(std::floor(x));
  const int r = static_cast<int>(std::floor(y));
  const double fx = x - c;
  const double fy = y - r;
  return (1 - fy) * ((1 - fx) * magnitude(grad_x, grad_y, c, r) +
                     fx * magnitude(grad_x, grad_y, c + 1, r)) +
         fy * ((1 - fx) * magnitude(grad_x, grad_y, c, r + 1) +
               fx * magnitude(grad_x, grad_y, c + 1, r + 1));
}

// Offset (px, along the normal) of the vertex of the parabola through (before, center, after)
// sampled `spacing` px apart; 0 where it is not concave; clamped to half a pixel.
double parabolaOffset(double before, double center, double after, double spacing) {
  const double curvature = before - 2.0 * center + after;
  if (!(curvature < 0.0)) return 0.0;
  return std::clamp(0.5 * (before - after) / curvature * spacing, -0.5, 0.5);
}

struct SubpixelErrors {
  double pixel = 0.0;     ///< Mean |distance of the pixel centre to the true line| (px).
  double subpixel = 0.0;  ///< Same for EdgePixel::subpixel (px).
  double max_subpixel = 0.0;
  /// The alternatives the field does not use, on the same edge pixels: a parabola through the
  /// magnitudes themselves at the quantised neighbours, and through magnitudes bilinearly
  /// interpolated one pixel along the exact normal.
  double plain_parabola = 0.0;
  double bilinear_parabola = 0.0;
  double min_normal_dot = 1.0;  ///< Smallest cosine between normal and true normal.
  int count = 0;
};

void accumulate(const StepEdge& step, const cv::Size& size, int gradient_type,
                SubpixelErrors* errors) {
  const cv::Mat image = renderStep(step, size);
  cv::Mat image8;
  image.convertTo(image8, CV_8U);
  cv::Mat edges;
  cv::Canny(image8, edges, 40.0, 80.0, 3, true);
  // CV_16S from the 8-bit image, as a camera pipeline would; CV_32F from the exact intensities.
  const cv::Mat& source = gradient_type == CV_16S ? image8 : image;
  cv::Mat grad_x;
  cv::Mat grad_y;
  cv::Sobel(source, grad_x, gradient_type, 1, 0, 3);
  cv::Sobel(source, grad_y, gradient_type, 0, 1, 3);
  const NearestEdgeField field = NearestEdgeField::build(edges, grad_x, grad_y);
  cv::Mat fx;
  cv::Mat fy;
  grad_x.convertTo(fx, CV_32F);
  grad_y.convertTo(fy, CV_32F);
  const Eigen::Vector2d normal(std::cos(step.angle_rad), std::sin(step.angle_rad));
  const auto error = [&](const Eigen::Vector2d& point) {
    return std::abs(point.dot(normal) - step.offset);
  };
  for (const EdgePixel& edge : field.edges()) {
    // Away from the border, where Sobel sees the replicated image.
    const int c = static_cast<int>(edge.pixel.x());
    const int r = static_cast<int>(edge.pixel.y());
    if (c < 3 || r < 3 || c > size.width - 4 || r > size.height - 4) continue;
    const Eigen::Vector2d pixel = edge.pixel.cast<double>();
    const Eigen::Vector2d n = edge.normal.cast<double>();
    errors->pixel += error(pixel);
    const double subpixel_error = error(edge.subpixel.cast<double>());
    errors->subpixel += subpixel_error;
    errors->max_subpixel = std::max(errors->max_subpixel, subpixel_error);
    errors->min_normal_dot = std::min(errors->min_normal_dot, n.dot(normal));

    // The field's quantisation to the 8-neighbourhood: an axis within 22.5 deg, else diagonal.
    const double tan_eighth_pi = std::tan(M_PI / 8.0);
    const Eigen::Vector2i step_px(
        tan_eighth_pi * std::abs(n.y()) > std::abs(n.x()) ? 0 : (n.x() > 0 ? 1 : -1),
        tan_eighth_pi * std::abs(n.x()) > std::abs(n.y()) ? 0 : (n.y() > 0 ? 1 : -1));
    const double center = magnitude(fx, fy, c, r);
    const double plain = parabolaOffset(magnitude(fx, fy, c - step_px.x(), r - step_px.y()), center,
                                        magnitude(fx, fy, c + step_px.x(), r + step_px.y()),
                                        step_px.cast<double>().dot(n));
    errors->plain_parabola += error(pixel + plain * n);
    const double bilinear = parabolaOffset(bilinearMagnitude(fx, fy, c - n.x(), r - n.y()), center,
                                           bilinearMagnitude(fx, fy, c + n.x(), r + n.y()), 1.0);
    errors->bilinear_parabola += error(pixel + bilinear * n);
    ++errors->count;
  }
}

SubpixelErrors measureSubpixel(int gradient_type) {
  const cv::Size size(48, 40);
  SubpixelErrors errors;
  for (const double degrees :
       {0.0, 10.0, 22.5, 30.0, 45.0, 60.0, 80.0, 90.0, 135.0, 200.0, 290.0}) {
    for (const double fraction : {0.0, 0.15, 0.3, 0.5, 0.7, 0.85}) {
      const double angle = degrees * M_PI / 180.0;
      const double centre = 24.0 * std::cos(angle) + 20.0 * std::sin(angle);
      accumulate({angle, std::floor(centre) + fraction}, size, gradient_type, &errors);
    }
  }
  for (double* mean :
       {&errors.pixel, &errors.subpixel, &errors.plain_parabola, &errors.bilinear_parabola}) {
    *mean /= errors.count;
  }
  return errors;
}

// Straight smooth step edges at many angles and sub-pixel offsets, found by cv::Canny: the
// sub-pixel positions must lie far closer to the true line than the pixel centres, and closer
// than the two alternative fits.
TEST(NearestEdgeField, SubpixelLocatesSmoothStepEdges) {
  for (const int type : {CV_16S, CV_32F}) {
    const SubpixelErrors errors = measureSubpixel(type);
    const std::string name = type == CV_16S ? "16s" : "32f";
    RecordProperty("edges_" + name, errors.count);
    RecordProperty("mean_error_px_pixel_" + name, std::to_string(errors.pixel));
    RecordProperty("mean_error_px_subpixel_" + name, std::to_string(errors.subpixel));
    RecordProperty("max_error_px_subpixel_" + name, std::to_string(errors.max_subpixel));
    RecordProperty("mean_error_px_plain_parabola_" + name, std::to_string(errors.plain_parabola));
    RecordProperty("mean_error_px_bilinear_parabola_" + name,
                   std::to_string(errors.bilinear_parabola));
    EXPECT_GT(errors.count, 1000);
    EXPECT_GT(errors.pixel, 0.2) << "the pixel centres must be off the line";
    EXPECT_LT(errors.subpixel, 0.03) << name;
    EXPECT_LT(errors.max_subpixel, 0.2) << name;
    EXPECT_LT(errors.subpixel, 0.7 * errors.plain_parabola) << name;
    EXPECT_LT(errors.subpixel, 0.7 * errors.bilinear_parabola) << name;
    EXPECT_GT(errors.min_normal_dot, std::cos(3.0 * M_PI / 180.0)) << name;
  }
}

TEST(NearestEdgeField, InvalidOptionsThrow) {
  const cv::Mat edges(4, 4, CV_8UC1, cv::Scalar(0));
  const cv::Mat grad(4, 4, CV_16SC1, cv::Scalar(0));
  for (const int reach : {0, -3, 1001}) {
    EXPECT_THROW(withReach(reach).validate(), InvalidOptions) << reach;
    EXPECT_THROW(NearestEdgeField::build(edges, grad, grad, withReach(reach)), InvalidOptions);
  }
  EXPECT_NO_THROW(withReach(1).validate());
  EXPECT_NO_THROW(withReach(1000).validate());
  try {
    withReach(0).validate();
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_STREQ(e.what(),
                 "InvalidOptions: NearestEdgeFieldOptions.max_distance_px = 0: in [1, 1000]");
  }
}

TEST(NearestEdgeField, MismatchedInputsThrowCheckError) {
  const cv::Mat edges(4, 5, CV_8UC1, cv::Scalar(0));
  const cv::Mat grad16(4, 5, CV_16SC1, cv::Scalar(0));
  const cv::Mat grad32(4, 5, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(NearestEdgeField::build(edges, grad16, cv::Mat(5, 4, CV_16SC1)), CheckError);
  EXPECT_THROW(NearestEdgeField::build(edges, cv::Mat(4, 6, CV_16SC1), grad16), CheckError);
  EXPECT_THROW(NearestEdgeField::build(cv::Mat(3, 5, CV_8UC1), grad16, grad16), CheckError);
  EXPECT_THROW(NearestEdgeField::build(edges, grad16, grad32), CheckError);
  EXPECT_THROW(NearestEdgeField::build(edges, cv::Mat(4, 5, CV_8UC1), cv::Mat(4, 5, CV_8UC1)),
               CheckError);
  EXPECT_THROW(NearestEdgeField::build(cv::Mat(4, 5, CV_16SC1), grad16, grad16), CheckError);
  EXPECT_NO_THROW(NearestEdgeField::build(edges, grad16, grad16));
  EXPECT_NO_THROW(NearestEdgeField::build(edges, grad32, grad32));
}

}  // namespace
}  // namespace curvesfm
