#include "factors/curve_reprojection_factor.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/bezier.h"
#include "core/so3.h"
#include "graph/ceres_cost_function.h"
#include "graph/ceres_manifolds.h"
#include "test/support/ceres_checks.h"  // AmbientBlocks
#include "test/support/numerical_jacobian.h"

namespace curvesfm {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;

std::shared_ptr<const Camera> pinholeCamera() {
  return std::make_shared<const Camera>(
      CameraIntrinsics{500.0, 500.0, 320.0, 240.0, 0, 0, 0, 0, 0, kWidth, kHeight});
}

std::shared_ptr<const Camera> distortedCamera() {
  return std::make_shared<const Camera>(
      CameraIntrinsics{520.0, 515.0, 320.5, 240.5, -0.12, 0.05, 1e-3, -2e-3, 0.01, kWidth, kHeight});
}

// A vertical edge along image column `column` whose gradient magnitude across it is
// `left, centre, right` at columns column-1, column, column+1 (pointing +x).
std::shared_ptr<const NearestEdgeField> verticalEdgeField(int column, float left = 1.0f,
                                                          float centre = 1.0f,
                                                          float right = 1.0f) {
  cv::Mat edges = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  cv::Mat grad_x = cv::Mat::zeros(kHeight, kWidth, CV_32FC1);
  const cv::Mat grad_y = cv::Mat::zeros(kHeight, kWidth, CV_32FC1);
  edges.col(column).setTo(255);
  grad_x.col(column - 1).setTo(left);
  grad_x.col(column).setTo(centre);
  grad_x.col(column + 1).setTo(right);
  return std::make_shared<const NearestEdgeField>(
      NearestEdgeField::build(edges, grad_x, grad_y, NearestEdgeFieldOptions{}));
}

// Every pixel an edge with a random gradient: every sample is live, and the nearest edge changes
// only when a projection crosses a pixel boundary, which central differences rarely straddle.
std::shared_ptr<const NearestEdgeField> randomDenseField(unsigned seed) {
  const cv::Mat edges(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  cv::Mat grad_x(kHeight, kWidth, CV_32FC1);
  cv::Mat grad_y(kHeight, kWidth, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(grad_x, cv::RNG::NORMAL, 0.0, 1.0);
  rng.fill(grad_y, cv::RNG::NORMAL, 0.0, 1.0);
  return std::make_shared<const NearestEdgeField>(
      NearestEdgeField::build(edges, grad_x, grad_y, NearestEdgeFieldOptions{}));
}

const SegmentKeys kSegment = segmentKeys(3, 1);

// A segment in front of the camera: a vertical line through x = point_x at depth 2 m
// (straight: both tangents along the chord).
Values straightSegment(double point_x) {
  Values values;
  values.insert(poseKey(0), Pose3());
  values.insert(kSegment.q0, Eigen::Vector3d(point_x, -0.2, 2.0));
  values.insert(kSegment.q1, Eigen::Vector3d(point_x, 0.2, 2.0));
  values.insert(kSegment.v0, Direction(Eigen::Vector3d::UnitY()));
  values.insert(kSegment.v1, Direction(Eigen::Vector3d::UnitY()));
  values.insert(kSegment.d1, 0.12);
  values.insert(kSegment.d2, 0.15);
  return values;
}

// A random pose and a random curved segment about 2-4 m in front of it.
Values randomConfiguration(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Pose3 cam_from_world(so3::exp(0.3 * Eigen::Vector3d(n(rng), n(rng), n(rng))),
                             Eigen::Vector3d(n(rng), n(rng), n(rng)));
  const Pose3 world_from_cam = cam_from_world.inverse();
  const Eigen::Vector3d start(0.3 * n(rng), 0.2 * n(rng), 2.5 + 0.3 * std::abs(n(rng)));
  const Eigen::Vector3d end = start + Eigen::Vector3d(0.4, 0.1 * n(rng), 0.2 * n(rng));
  Values values;
  values.insert(poseKey(0), cam_from_world);
  values.insert(kSegment.q0, world_from_cam * start);
  values.insert(kSegment.q1, world_from_cam * end);
  values.insert(kSegment.v0, Direction(testing::randomUnitVector(rng) + 2.0 * Eigen::Vector3d::UnitX()));
  values.insert(kSegment.v1, Direction(testing::randomUnitVector(rng) + 2.0 * Eigen::Vector3d::UnitX()));
  values.insert(kSegment.d1, 0.1 + 0.05 * std::abs(n(rng)));
  values.insert(kSegment.d2, 0.1 + 0.05 * std::abs(n(rng)));
  return values;
}

CurveReprojectionFactor makeFactor(std::shared_ptr<const NearestEdgeField> field,
                                   std::shared_ptr<const Camera> camera, int num_samples = 11,
                                   bool subpixel = true, double max_normal_angle_deg = 90.0,
                                   bool interpolate_edges = false) {
  return CurveReprojectionFactor(
      poseKey(0), kSegment, std::move(field), std::move(camera),
      std::make_shared<const CurveSampling>(num_samples, subpixel, max_normal_angle_deg,
                                            EdgeBlending{interpolate_edges}),
      NoiseModel{});
}

TEST(CurveReprojectionFactor, ZeroOnTheEdgeAndSignedPixelDistanceOffIt) {
  // x = 0.4 at depth 2 projects to column 500 * 0.2 + 320 = 420.
  const auto factor = makeFactor(verticalEdgeField(420), pinholeCamera());
  EXPECT_EQ(factor.residualDimension(), 11);
  EXPECT_LT(factor.unwhitenedError(straightSegment(0.4)).cwiseAbs().maxCoeff(), 1e-9);
  // 1 cm to the right is 500 * 0.01 / 2 = 2.5 px along the +x gradient.
  const Eigen::VectorXd error = factor.unwhitenedError(straightSegment(0.41));
  EXPECT_TRUE(error.isConstant(2.5, 1e-6)) << error.transpose();
}

TEST(CurveReprojectionFactor, SubpixelSwitchUsesTheRefinedEdgePosition) {
  // Magnitudes 1, 3, 2 across the edge: the refined edge lies right of column 420 (how far is
  // the field's business, tested there); the factor must measure from it only when asked.
  const auto field = verticalEdgeField(420, 1.0f, 3.0f, 2.0f);
  const double refined_x = field->nearestToPixel(420, 240)->subpixel.x();
  ASSERT_GT(refined_x, 420.1);
  const Values on_column = straightSegment(0.4);
  EXPECT_LT(makeFactor(field, pinholeCamera(), 11, false).unwhitenedError(on_column).cwiseAbs()
                .maxCoeff(),
            1e-9);
  const Eigen::VectorXd refined =
      makeFactor(field, pinholeCamera(), 11, true).unwhitenedError(on_column);
  EXPECT_TRUE(refined.isConstant(420.0 - refined_x, 1e-6)) << refined.transpose();
}

// Every pixel an edge, its normal turning slowly over the image (as along real edges, where
// neighbouring edge pixels agree to well under 90 deg) with a little noise, and random gradient
// magnitudes, so that the sub-pixel positions scatter about the pixel centres.
std::shared_ptr<const NearestEdgeField> smoothDenseField(unsigned seed) {
  const cv::Mat edges(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  cv::Mat grad_x(kHeight, kWidth, CV_32FC1);
  cv::Mat grad_y(kHeight, kWidth, CV_32FC1);
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const float angle = 0.02f * x + 0.015f * y + 0.1f * noise(rng);
      const float magnitude = 1.0f + 0.3f * std::abs(noise(rng));
      grad_x.at<float>(y, x) = magnitude * std::cos(angle);
      grad_y.at<float>(y, x) = magnitude * std::sin(angle);
    }
  }
  return std::make_shared<const NearestEdgeField>(
      NearestEdgeField::build(edges, grad_x, grad_y, NearestEdgeFieldOptions{}));
}

TEST(CurveReprojectionFactor, JacobiansMatchNumericalAtRandomConfigurations) {
  std::mt19937 rng(5);
  const auto field = randomDenseField(7);
  for (int trial = 0; trial < 30; ++trial) {
    const Values values = randomConfiguration(rng);
    const auto factor = makeFactor(field, distortedCamera(), 11, trial % 2 == 0);
    ASSERT_EQ(factor.sampleCounts(values).on_field, 11) << "trial " << trial;
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
  }
}

TEST(CurveReprojectionFactor, InterpolatedJacobiansMatchNumericalAtRandomConfigurations) {
  std::mt19937 rng(6);
  const auto field = smoothDenseField(8);
  for (int trial = 0; trial < 30; ++trial) {
    const Values values = randomConfiguration(rng);
    const auto factor = makeFactor(field, distortedCamera(), 11, trial % 2 == 0, 90.0, true);
    ASSERT_EQ(factor.sampleCounts(values).on_field, 11) << "trial " << trial;
    // The blend is continuous, but its derivative changes at pixel boundaries: a tiny step keeps
    // central differences from straddling one.
    testing::expectJacobiansMatchNumerical(factor, values, 1e-5, 1e-8);
  }
}

// The edges of a bright disc of radius 100 px about (520, 240), rendered anti-aliased and
// blurred a little, through Sobel and Canny as the frontend does: a curved edge, whose pixels'
// normals and sub-pixel positions change from one edge pixel to the next.
// The field of an 8-bit grey image's Canny edges after a light blur.
std::shared_ptr<const NearestEdgeField> cannyEdgeField(cv::Mat image) {
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  cv::Mat grad_x, grad_y, edges;
  cv::Sobel(image, grad_x, CV_32F, 1, 0);
  cv::Sobel(image, grad_y, CV_32F, 0, 1);
  cv::Canny(image, edges, 50, 100);
  return std::make_shared<const NearestEdgeField>(
      NearestEdgeField::build(edges, grad_x, grad_y, NearestEdgeFieldOptions{}));
}

std::shared_ptr<const NearestEdgeField> discEdgeField() {
  cv::Mat image(kHeight, kWidth, CV_8UC1, cv::Scalar(40));
  cv::circle(image, cv::Point(520 * 16, 240 * 16), 100 * 16, cv::Scalar(200), cv::FILLED,
             cv::LINE_AA, 4);
  return cannyEdgeField(image);
}

// The largest change of any sample's residual between consecutive positions of a segment slid
// sideways in steps of 0.01 px across three pixel columns, over the disc's left edge: the
// vertical segment at x = 0.4 m, 2 m deep, projects to column 420, the disc's leftmost column.
double largestResidualStep(bool interpolate_edges) {
  const auto factor =
      makeFactor(discEdgeField(), pinholeCamera(), 11, true, 90.0, interpolate_edges);
  // 0.00004 m at depth 2 m is 500 * 0.00004 / 2 = 0.01 px.
  Eigen::VectorXd previous = factor.unwhitenedError(straightSegment(0.4 - 0.00004 * 150));
  double largest = 0.0;
  for (int step = -149; step <= 150; ++step) {
    const Eigen::VectorXd error = factor.unwhitenedError(straightSegment(0.4 + 0.00004 * step));
    largest = std::max(largest, (error - previous).cwiseAbs().maxCoeff());
    previous = error;
  }
  return largest;
}

TEST(CurveReprojectionFactor, InterpolatedResidualDoesNotJumpAtPixelBoundaries) {
  // The nearest edge pixel's residual jumps where a sample crosses into the next pixel (here by
  // up to 0.03 px, from the curvature and the sub-pixel scatter); the blend moves with the
  // sample, by about the 0.01 px step.
  const double nearest = largestResidualStep(false), blended = largestResidualStep(true);
  EXPECT_GT(nearest, 0.02);
  EXPECT_LT(blended, 0.0125);
}

// Canny edges of a photograph at 640x480: curved, broken and close edges, where the four pixel
// centres around a sample often belong to different edges.
std::shared_ptr<const NearestEdgeField> photographEdgeField(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) return nullptr;
  cv::resize(image, image, cv::Size(kWidth, kHeight), 0.0, 0.0, cv::INTER_AREA);
  return cannyEdgeField(image);
}

// How many samples' residuals change by more than 0.01 px when vertical segments across the
// image move sideways by 0.002 px over a pixel's midline or a pixel boundary (where the nearest
// edge pixel, or the four blended ones, change), counting samples within 3 px of an edge.
int residualJumpsAcrossPixelBoundaries(std::shared_ptr<const NearestEdgeField> field,
                                       bool interpolate_edges) {
  const auto factor =
      makeFactor(std::move(field), pinholeCamera(), 11, true, 90.0, interpolate_edges);
  const double metres_per_px = 2.0 / 500.0;  // At 2 m depth.
  int jumps = 0;
  for (double top = -0.45; top < 0.0; top += 0.09) {
    for (int column = 40; column < kWidth - 40; ++column) {
      for (double boundary : {0.5, 1.0}) {
        const double x = (column + boundary - 0.001 - 320.0) * metres_per_px;
        Values before = straightSegment(x), after = straightSegment(x + 0.002 * metres_per_px);
        for (Values* values : {&before, &after}) {
          const double shifted_x = values->at<Eigen::Vector3d>(kSegment.q0).x();
          values->update(kSegment.q0, Eigen::Vector3d(shifted_x, top, 2.0));
          values->update(kSegment.q1, Eigen::Vector3d(shifted_x, top + 0.4, 2.0));
        }
        const Eigen::VectorXd r0 = factor.unwhitenedError(before);
        const Eigen::VectorXd r1 = factor.unwhitenedError(after);
        for (int k = 0; k < r0.size(); ++k) {
          if (std::abs(r0[k]) < 3.0 && std::abs(r1[k]) < 3.0 && std::abs(r1[k] - r0[k]) > 0.01)
            ++jumps;
        }
      }
    }
  }
  return jumps;
}

TEST(CurveReprojectionFactor, InterpolatedResidualJumpsRarelyOnAPhotographsEdges) {
  // The blend jumps only where the heaviest group of corners on one edge changes to another
  // edge; the nearest edge pixel's residual at most pixel crossings near curved edges.
  const std::string photograph = "/usr/share/doc/opencv-doc/examples/data/graf1.png";
  const auto field = photographEdgeField(photograph);
  if (!field) GTEST_SKIP() << photograph << " not installed (opencv-doc)";
  const int nearest = residualJumpsAcrossPixelBoundaries(field, false);
  const int blended = residualJumpsAcrossPixelBoundaries(field, true);
  EXPECT_GT(nearest, 5000);         // 9,433 of about 61,600 moves.
  EXPECT_LT(blended, nearest / 4);  // 1,384.
}

// A vertical segment on the edge at column 420 that runs past the image's bottom row (rows
// 340-540 at 2 m depth), `offset_px` to the right of the edge.
Values segmentPastTheBottom(double offset_px) {
  Values values = straightSegment(0.4 + offset_px * 2.0 / 500.0);
  const double x = values.at<Eigen::Vector3d>(kSegment.q0).x();
  values.update(kSegment.q0, Eigen::Vector3d(x, 0.4, 2.0));
  values.update(kSegment.q1, Eigen::Vector3d(x, 1.2, 2.0));
  return values;
}

CurveReprojectionFactor borderFactor(double border_margin_px) {
  return CurveReprojectionFactor(
      poseKey(0), kSegment, verticalEdgeField(420), pinholeCamera(),
      std::make_shared<const CurveSampling>(11, true, 90.0, EdgeBlending{}, border_margin_px),
      NoiseModel{});
}

TEST(CurveReprojectionFactor, SamplesPastTheBorderFollowTheEdgeLineWithinTheMargin) {
  const Values values = segmentPastTheBottom(0.3);
  // Rows 340 + 20 k: samples 7-10 (rows 480-540) lie outside the 480-row image.
  const CurveReprojectionFactor capped = borderFactor(0.0);
  EXPECT_EQ(capped.sampleCounts(values).outside_image, 4);
  EXPECT_DOUBLE_EQ(capped.unwhitenedError(values)[8], capped.cappedResidual());

  // A 40 px margin measures rows up to 519 against the edge line: the same 0.3 px as inside.
  const CurveReprojectionFactor extended = borderFactor(40.0);
  EXPECT_EQ(extended.sampleCounts(values).outside_image, 2);
  const Eigen::VectorXd error = extended.unwhitenedError(values);
  for (int k = 0; k <= 8; ++k) EXPECT_NEAR(error[k], 0.3, 1e-6) << "sample " << k;
  EXPECT_DOUBLE_EQ(error[9], extended.cappedResidual());
  testing::expectJacobiansMatchNumerical(extended, values, 1e-5);
}

TEST(CurveReprojectionFactor, JacobiansMatchNumericalOnAStraightEdge) {
  // The realistic case: one edge, so every sample refers to pixels of the same line.
  const auto factor = makeFactor(verticalEdgeField(420), distortedCamera(), 7);
  Values values = straightSegment(0.43);
  values.update(poseKey(0), Pose3(so3::exp(Eigen::Vector3d(0.01, -0.02, 0.03)),
                                  Eigen::Vector3d(0.01, 0.02, -0.03)));
  ASSERT_EQ(factor.sampleCounts(values).on_field, 7);
  testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
}

// Near the vertical edge of verticalEdgeField(420): a curved segment about column 424 seen
// from a slightly moved camera. Every edge pixel there has the same x and normal, so the
// residual is smooth even where the nearest edge pixel changes, as a step-size search needs.
Values nearVerticalEdge(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Values values = straightSegment(0.41);
  values.update(poseKey(0), Pose3(so3::exp(0.002 * Eigen::Vector3d(n(rng), n(rng), n(rng))),
                                  0.005 * Eigen::Vector3d(n(rng), n(rng), n(rng))));
  values.update(kSegment.v0, Direction(Eigen::Vector3d(0.05 * n(rng), 1.0, 0.05 * n(rng))));
  values.update(kSegment.v1, Direction(Eigen::Vector3d(0.05 * n(rng), 1.0, 0.05 * n(rng))));
  return values;
}

TEST(CurveReprojectionFactor, CeresAdapterGivesTheTangentJacobiansThroughEachManifold) {
  // Ceres sees s + 1 dynamic rows and ambient blocks: its Jacobian times each manifold's
  // PlusJacobian must be the factor's tangent Jacobian; the maths of that Jacobian is checked
  // against central differences above. (ceres::GradientChecker's Ridders estimate disagreed by
  // ~1% on a few rows of this factor although central differences of the same residual, at
  // steps 1e-4 to 1e-8, are stable and agree with ours; we did not find out why.)
  std::mt19937 rng(8);
  const auto factor = std::make_shared<const CurveReprojectionFactor>(
      makeFactor(verticalEdgeField(420), distortedCamera()));
  const FactorCostFunction cost(factor);
  for (int trial = 0; trial < 10; ++trial) {
    const Values values = nearVerticalEdge(rng);
    const testing::AmbientBlocks blocks(*factor, values);
    const int rows = factor->residualDimension();
    Eigen::VectorXd residuals(rows);
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> ambient;
    std::vector<double*> jacobian_pointers;
    for (const auto& block : blocks.storage) {
      ambient.emplace_back(rows, static_cast<int>(block.size()));
    }
    for (auto& jacobian : ambient) jacobian_pointers.push_back(jacobian.data());
    ASSERT_TRUE(cost.Evaluate(blocks.pointers.data(), residuals.data(), jacobian_pointers.data()));
    const Linearization linear = factor->linearize(values);
    EXPECT_LT((residuals - linear.error).cwiseAbs().maxCoeff(), 1e-12);
    for (std::size_t i = 0; i < ambient.size(); ++i) {
      Eigen::MatrixXd tangent = ambient[i];
      if (const ceres::Manifold* manifold = manifoldFor(values.type(factor->keys()[i]))) {
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> plus(
            manifold->AmbientSize(), manifold->TangentSize());
        ASSERT_TRUE(manifold->PlusJacobian(blocks.pointers[i], plus.data()));
        tangent = ambient[i] * plus;
      }
      EXPECT_LT((tangent - linear.jacobians[i]).cwiseAbs().maxCoeff(),
                1e-9 * std::max(1.0, linear.jacobians[i].cwiseAbs().maxCoeff()))
          << "block " << i;
    }
  }
}

void expectCappedWithZeroJacobians(const CurveReprojectionFactor& factor, const Values& values) {
  const Linearization linear = factor.linearize(values);
  EXPECT_TRUE(linear.error.isConstant(factor.cappedResidual())) << linear.error.transpose();
  for (const Eigen::MatrixXd& jacobian : linear.jacobians) {
    EXPECT_TRUE(jacobian.allFinite());
    EXPECT_TRUE(jacobian.isZero());
  }
}

TEST(CurveReprojectionFactor, SamplesBehindTheCameraAreCappedAndCounted) {
  const auto factor = makeFactor(verticalEdgeField(420), pinholeCamera(), 5);
  Values values = straightSegment(0.4);
  values.update(poseKey(0), Pose3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -3.0)));
  expectCappedWithZeroJacobians(factor, values);
  const CurveSampleCounts counts = factor.sampleCounts(values);
  EXPECT_EQ(counts.behind_camera, 5);
  EXPECT_EQ(counts.capped(), 5);
}

TEST(CurveReprojectionFactor, SamplesOutsideTheImageOrBeyondReachAreCappedAndCounted) {
  const auto factor = makeFactor(verticalEdgeField(420), pinholeCamera(), 5);
  // x = 2 m at depth 2 projects to column 820: outside the 640 px image.
  expectCappedWithZeroJacobians(factor, straightSegment(2.0));
  EXPECT_EQ(factor.sampleCounts(straightSegment(2.0)).outside_image, 5);
  // Column 320 is 100 px from the edge, beyond the 15 px reach.
  expectCappedWithZeroJacobians(factor, straightSegment(0.0));
  EXPECT_EQ(factor.sampleCounts(straightSegment(0.0)).beyond_reach, 5);
  EXPECT_EQ(factor.cappedResidual(), 15.0);
}

TEST(CurveReprojectionFactor, PartlyVisibleSegmentMixesLiveAndCappedRows) {
  // The segment from y = -0.2 to 0.2 at depth 2 spans rows 190..290; cut the edge so that
  // rows above 240 are more than the reach away from it.
  cv::Mat edges = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  edges(cv::Rect(420, 0, 1, 200)).setTo(255);
  const cv::Mat grad_x(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0f));
  const cv::Mat grad_y = cv::Mat::zeros(kHeight, kWidth, CV_32FC1);
  const auto field =
      std::make_shared<const NearestEdgeField>(NearestEdgeField::build(edges, grad_x, grad_y));
  const auto factor = makeFactor(field, pinholeCamera(), 11);
  const Values values = straightSegment(0.4);
  const CurveSampleCounts counts = factor.sampleCounts(values);
  EXPECT_GT(counts.on_field, 0);
  EXPECT_GT(counts.beyond_reach, 0);
  EXPECT_EQ(counts.total(), 11);
  testing::expectJacobiansMatchNumerical(factor, values, 1e-5);
}

TEST(CurveReprojectionFactor, RejectsMissingInputsAndBadSampling) {
  const auto field = verticalEdgeField(420);
  EXPECT_THROW(CurveReprojectionFactor(poseKey(0), kSegment, nullptr, pinholeCamera(),
                                       std::make_shared<const CurveSampling>(5, true),
                                       NoiseModel{}),
               CheckError);
  EXPECT_THROW(CurveReprojectionFactor(poseKey(0), kSegment, field, pinholeCamera(), nullptr,
                                       NoiseModel{}),
               CheckError);
  EXPECT_THROW(CurveSampling(CurveReprojectionFactor::kMaxSamples + 1, true), CheckError);
  EXPECT_THROW(CurveSampling(1, true), CheckError);
  EXPECT_THROW(CurveSampling(11, true, 0.0), CheckError);
  EXPECT_THROW(CurveSampling(11, true, 91.0), CheckError);
  EXPECT_THROW(CurveSampling(11, true, 90.0, EdgeBlending{true, -0.1, 45.0}), CheckError);
  EXPECT_THROW(CurveSampling(11, true, 90.0, EdgeBlending{true, 0.5, 91.0}), CheckError);
  EXPECT_THROW(CurveSampling(11, true, 90.0, EdgeBlending{}, -1.0), CheckError);
}

TEST(CurveReprojectionFactor, OrientationCheckCapsSamplesOnEdgesAlongTheCurve) {
  // A horizontal segment just beside a vertical edge: its samples find the edge within reach,
  // but the edge normal (+x) runs along the projected curve, so with the check they are capped.
  Values values = straightSegment(0.4);  // camera at the origin
  values.update(kSegment.q0, Eigen::Vector3d(0.38, 0.0, 2.0));
  values.update(kSegment.q1, Eigen::Vector3d(0.42, 0.0, 2.0));
  values.update(kSegment.v0, Direction(Eigen::Vector3d::UnitX()));
  values.update(kSegment.v1, Direction(Eigen::Vector3d::UnitX()));
  values.update(kSegment.d1, 0.01);
  values.update(kSegment.d2, 0.01);

  const auto field = verticalEdgeField(420);
  const CurveSampleCounts unchecked = makeFactor(field, pinholeCamera()).sampleCounts(values);
  EXPECT_EQ(unchecked.on_field, 11);
  const auto checked = makeFactor(field, pinholeCamera(), 11, true, 45.0);
  const CurveSampleCounts counts = checked.sampleCounts(values);
  EXPECT_EQ(counts.wrong_orientation, 11);
  EXPECT_TRUE(checked.unwhitenedError(values).isConstant(checked.cappedResidual()));
  // The same check passes a segment that runs along the edge.
  EXPECT_EQ(checked.sampleCounts(straightSegment(0.4)).on_field, 11);
}

}  // namespace
}  // namespace curvesfm
