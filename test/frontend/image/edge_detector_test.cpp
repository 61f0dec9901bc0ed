#include "frontend/image/edge_detector.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>

#include "core/errors.h"
#include "core/nearest_edge_field.h"
#include "sim/curve_scene.h"

namespace curvesfm {
namespace {

// A rectangle and a disc on a mid-grey background, and the boundaries of both drawn one pixel
// wide (the true edges).
struct Scene {
  cv::Mat image;
  cv::Mat boundaries;
};

Scene renderScene(double noise_sigma, unsigned seed = 7) {
  Scene scene;
  scene.image = cv::Mat(240, 320, CV_8UC1, cv::Scalar(110));
  cv::rectangle(scene.image, cv::Rect(40, 50, 110, 90), cv::Scalar(170), cv::FILLED);
  cv::circle(scene.image, {220, 150}, 50, cv::Scalar(60), cv::FILLED, cv::LINE_AA);
  scene.boundaries = cv::Mat(scene.image.size(), CV_8UC1, cv::Scalar(0));
  cv::rectangle(scene.boundaries, cv::Rect(40, 50, 110, 90), cv::Scalar(255), 2);
  cv::circle(scene.boundaries, {220, 150}, 50, cv::Scalar(255), 2);
  if (noise_sigma > 0.0) {
    cv::Mat noise(scene.image.size(), CV_16SC1);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    cv::Mat noisy;
    scene.image.convertTo(noisy, CV_16SC1);
    noisy += noise;
    noisy.convertTo(scene.image, CV_8UC1);
  }
  return scene;
}

// Fraction of the non-zero pixels of `from` within `radius` px of a non-zero pixel of `to`.
double fractionNear(const cv::Mat& from, const cv::Mat& to, double radius) {
  cv::Mat distance;
  cv::distanceTransform(to == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  int near = 0;
  const int total = cv::countNonZero(from);
  for (int r = 0; r < from.rows; ++r) {
    for (int c = 0; c < from.cols; ++c) {
      if (from.at<std::uint8_t>(r, c) != 0 && distance.at<float>(r, c) <= radius) ++near;
    }
  }
  return total == 0 ? 0.0 : static_cast<double>(near) / total;
}

TEST(EdgeDetector, OutputFeedsTheNearestEdgeField) {
  const Scene scene = renderScene(0.0);
  const EdgeImage edges = detectEdges(scene.image);
  EXPECT_EQ(edges.edges.type(), CV_8UC1);
  EXPECT_EQ(edges.grad_x.type(), CV_16SC1);
  EXPECT_EQ(edges.grad_y.type(), CV_16SC1);
  EXPECT_EQ(edges.edges.size(), scene.image.size());
  EXPECT_EQ(cv::countNonZero((edges.edges != 0) & (edges.edges != 255)), 0);
  EXPECT_DOUBLE_EQ(edges.gain, 8.0);
  const NearestEdgeField field = NearestEdgeField::build(edges.edges, edges.grad_x, edges.grad_y);
  EXPECT_EQ(field.edges().size(), static_cast<std::size_t>(cv::countNonZero(edges.edges)));
}

TEST(EdgeDetector, FindsTheEdgesOfANoiseFreeRendering) {
  const Scene scene = renderScene(0.0);
  const EdgeImage edges = detectEdges(scene.image);
  EXPECT_GT(fractionNear(edges.edges, scene.boundaries, 2.0), 0.99);
  EXPECT_GT(fractionNear(scene.boundaries, edges.edges, 2.0), 0.99);
}

TEST(EdgeDetector, AutomaticThresholdsFindEdgesOfANoisyImageWithoutNoiseEdges) {
  const Scene scene = renderScene(12.0);
  const EdgeImage edges = detectEdges(scene.image);
  // Precision: almost every edge pixel is on a true boundary; recall: almost every boundary
  // pixel has an edge next to it.
  EXPECT_GT(fractionNear(edges.edges, scene.boundaries, 2.0), 0.95);
  EXPECT_GT(fractionNear(scene.boundaries, edges.edges, 2.0), 0.95);
  EXPECT_GT(edges.high_threshold, edges.low_threshold);
  EXPECT_DOUBLE_EQ(edges.low_threshold, 0.4 * edges.high_threshold);
}

TEST(EdgeDetector, PureNoiseGivesAlmostNoEdges) {
  cv::Mat noise(240, 320, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 128.0, 12.0);
  const EdgeImage edges = detectEdges(noise);
  EXPECT_LT(cv::countNonZero(edges.edges), static_cast<int>(0.002 * noise.total()));
}

TEST(EdgeDetector, GivenThresholdsAreUsedAsGiven) {
  const Scene scene = renderScene(12.0);
  EdgeDetectorOptions options;
  options.canny_low_threshold = 1.0;
  options.canny_high_threshold = 3.0;
  const EdgeImage edges = detectEdges(scene.image, options);
  EXPECT_DOUBLE_EQ(edges.low_threshold, 1.0);
  EXPECT_DOUBLE_EQ(edges.high_threshold, 3.0);
  // Low thresholds on a noisy image: far more (noise) edges than with the automatic ones.
  EXPECT_GT(cv::countNonZero(edges.edges), 2 * cv::countNonZero(detectEdges(scene.image).edges));
}

TEST(EdgeDetector, ColourAndGreyInputsAgreeAndApertureFiveWorks) {
  const Scene scene = renderScene(5.0);
  cv::Mat bgr;
  cv::cvtColor(scene.image, bgr, cv::COLOR_GRAY2BGR);
  const EdgeImage grey_edges = detectEdges(scene.image);
  EXPECT_EQ(cv::countNonZero(detectEdges(bgr).edges != grey_edges.edges), 0);

  EdgeDetectorOptions options;
  options.sobel_aperture = 5;
  const EdgeImage edges = detectEdges(bgr, options);
  EXPECT_DOUBLE_EQ(edges.gain, 128.0);
  EXPECT_GT(fractionNear(edges.edges, scene.boundaries, 2.0), 0.95);
  EXPECT_GT(fractionNear(scene.boundaries, edges.edges, 2.0), 0.95);
}

// Until session 39 the blur wrote into a grey input, and the pipeline's depth search sampled
// that blurred image without saying so: EdgeImage::blurred now carries it.
TEST(EdgeDetector, LeavesItsInputAsItWasAndReturnsTheBlurredImage) {
  const Scene scene = renderScene(5.0);
  const cv::Mat input = scene.image.clone();
  const EdgeImage edges = detectEdges(input);
  EXPECT_EQ(cv::countNonZero(input != scene.image), 0);
  cv::Mat blurred;
  cv::GaussianBlur(scene.image, blurred, cv::Size(0, 0), 1.0, 1.0);
  ASSERT_EQ(edges.blurred.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(edges.blurred != blurred), 0);

  EdgeDetectorOptions unblurred;
  unblurred.blur_sigma_px = 0.0;
  EXPECT_EQ(detectEdges(input, unblurred).blurred.data, input.data);
}

TEST(EdgeDetector, MaskedPixelsCarryNoEdge) {
  const Scene scene = renderScene(0.0);
  cv::Mat mask(scene.image.size(), CV_8UC1, cv::Scalar(255));
  mask.colRange(0, 160).setTo(0);
  const EdgeImage edges = detectEdges(scene.image, EdgeDetectorOptions(), mask);
  EXPECT_EQ(cv::countNonZero(edges.edges.colRange(0, 160)), 0);
  EXPECT_GT(cv::countNonZero(edges.edges.colRange(160, 320)), 200);
}

TEST(EdgeDetector, BadOptionsAndImagesThrow) {
  const cv::Mat image(20, 20, CV_8UC1, cv::Scalar(0));
  EdgeDetectorOptions options;
  options.sobel_aperture = 7;
  EXPECT_THROW(detectEdges(image, options), InvalidOptions);
  options = EdgeDetectorOptions();
  options.blur_sigma_px = -1.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = EdgeDetectorOptions();
  options.canny_low_threshold = 10.0;
  options.canny_high_threshold = 5.0;
  try {
    options.validate();
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("EdgeDetectorOptions.canny_low_threshold = 10"), std::string::npos)
        << message;
  }
  options = EdgeDetectorOptions();
  options.auto_max_seed_fraction = 0.0;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = EdgeDetectorOptions();
  options.auto_low_ratio = 1.5;
  EXPECT_THROW(options.validate(), InvalidOptions);
  options = EdgeDetectorOptions();
  options.canny_high_threshold = -1.0;
  EXPECT_THROW(options.validate(), InvalidOptions);

  EXPECT_THROW(detectEdges(cv::Mat()), CheckError);
  EXPECT_THROW(detectEdges(cv::Mat(20, 20, CV_32FC1, cv::Scalar(0))), CheckError);
  EXPECT_THROW(detectEdges(image, EdgeDetectorOptions(), cv::Mat(10, 10, CV_8UC1)), CheckError);
}

// `run`'s automatic thresholds fall to their floor on a noise-free rendering, low enough to see a
// step's linear return to the background as a second edge beside the curve; a long, gentle
// return (what `synth curves` draws) leaves one edge per curve, bar short steps where a curve
// bends more tightly than its band is wide. Measured: 61 % and 16 % of the edge pixels more than
// 2 px from every curve.
TEST(DetectEdges, AutomaticThresholdsSeeOneEdgePerRenderedCurveWhenItsReturnIsGentle) {
  CurveSceneOptions options;
  options.num_keyframes = 2;
  options.num_curves = 20;
  auto shareAwayFromCurves = [](const CurveSceneOptions& scene_options) {
    CurveScene scene = makeCurveScene(scene_options);
    scene.keyframes[0].edges = detectEdges(scene.keyframes[0].image).edges;
    const EdgeAgreement agreement = measureEdgeAgreement(scene, 0);
    EXPECT_GT(agreement.curve_samples_on_edges, 0.85);
    return 1.0 - agreement.edge_pixels_near_curves;
  };
  EXPECT_GT(shareAwayFromCurves(options), 0.5);
  options.step_contrast = 40.0;
  options.edge_return_length_px = 48.0;
  EXPECT_LT(shareAwayFromCurves(options), 0.25);
}

}  // namespace
}  // namespace curvesfm
