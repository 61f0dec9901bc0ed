#include "frontend/image/epipolar_depth.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/errors.h"
#include "core/pose3.h"
#include "frontend/image/edge_chains.h"
#include "frontend/image/edge_detector.h"
#include "sim/planar_scene.h"

namespace curvesfm {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
const char* const kPhotograph = "/usr/share/doc/opencv-doc/examples/data/building.jpg";

// A textured plane z = 0 (world, sim/planar_scene.h) seen by cameras above it looking down.
struct PlaneScene {
  Camera camera{CameraIntrinsics{}};
  cv::Mat texture;             // CV_8UC1.
  double plane_width_m = 0.0;  // Extent of the texture's longer side.

  cv::Mat render(const Pose3& cam_from_world) const {
    return renderPlanarView(texture, plane_width_m, camera, cam_from_world);
  }

  // Depth (z in the camera) of the plane at `pixel`.
  double trueDepth(const Pose3& cam_from_world, const Eigen::Vector2i& pixel) const {
    const Pose3 world_from_cam = cam_from_world.inverse();
    const Eigen::Vector3d ray = camera.unproject(pixel.cast<double>(), 1.0);
    const Eigen::Vector3d direction = world_from_cam.rotationMatrix() * ray;
    return -world_from_cam.translation().z() / direction.z();
  }
};

// A camera at `centre` (world, z > 0) looking down (-z) with its image x along world x, tilted by
// small angles about the world's x and y axes.
Pose3 lookingAtPlane(const Eigen::Vector3d& centre, double tilt_x_deg, double tilt_y_deg) {
  const Eigen::Matrix3d looking_down = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  const Eigen::Matrix3d world_from_cam_rotation =
      (Eigen::AngleAxisd(tilt_x_deg * kRadPerDeg, Eigen::Vector3d::UnitX()) *
       Eigen::AngleAxisd(tilt_y_deg * kRadPerDeg, Eigen::Vector3d::UnitY()))
          .toRotationMatrix() *
      looking_down;
  return Pose3(world_from_cam_rotation, centre).inverse();
}

// Random discs, rectangles and strokes of random grey, blurred: many edges in all directions.
cv::Mat randomTexture(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat texture(height, width, CV_8UC1, cv::Scalar(128));
  std::uniform_int_distribution<int> x(0, width - 1);
  std::uniform_int_distribution<int> y(0, height - 1);
  std::uniform_int_distribution<int> grey(20, 235);
  std::uniform_int_distribution<int> size(4, 40);
  for (int k = 0; k < width * height / 2500; ++k) {
    const cv::Scalar colour(grey(rng));
    const cv::Point corner(x(rng), y(rng));
    if (k % 3 == 0) {
      cv::circle(texture, corner, size(rng), colour, cv::FILLED, cv::LINE_AA);
    } else if (k % 3 == 1) {
      cv::rectangle(texture, cv::Rect(corner.x, corner.y, 2 * size(rng), size(rng)), colour,
                    cv::FILLED);
    } else {
      cv::line(texture, corner, {x(rng), y(rng)}, colour, 3, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  return texture;
}

// Horizontal bands of random grey: every edge is a horizontal line.
cv::Mat stripeTexture(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> grey(20, 235);
  std::uniform_int_distribution<int> band(8, 30);
  cv::Mat texture(height, width, CV_8UC1);
  for (int y = 0; y < height;) {
    const int rows = std::min(band(rng), height - y);
    texture.rowRange(y, y + rows).setTo(cv::Scalar(grey(rng)));
    y += rows;
  }
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  return texture;
}

// About one texel per pixel at 1.5 m for the default camera (f = 525 px).
PlaneScene makeScene(const cv::Mat& texture) {
  PlaneScene scene;
  scene.texture = texture;
  scene.plane_width_m = std::max(texture.cols, texture.rows) * 1.5 / 525.0;
  return scene;
}

std::vector<EdgeChain> chainsOf(const cv::Mat& image) {
  return extractEdgeChains(detectEdges(image));
}

struct Accuracy {
  int pixels = 0;
  int valid = 0;
  double median_relative_error = 0.0;
  double p90_relative_error = 0.0;
  double gross_error_fraction = 0.0;  // Of the valid depths, those off by more than 5 %.
  double median_z_score = 0.0;        // |error in inverse depth| / sigma.
  double validFraction() const { return pixels == 0 ? 0.0 : static_cast<double>(valid) / pixels; }
};

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = static_cast<std::size_t>(q * (values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

Accuracy measure(const PlaneScene& scene, const Pose3& key, const std::vector<EdgeChain>& chains,
                 const ChainDepths& depths) {
  Accuracy accuracy;
  std::vector<double> errors;
  std::vector<double> z_scores;
  for (std::size_t c = 0; c < chains.size(); ++c) {
    for (std::size_t i = 0; i < chains[c].pixels.size(); ++i) {
      ++accuracy.pixels;
      const PixelDepth& d = depths.chains[c][i];
      if (!d.valid()) continue;
      ++accuracy.valid;
      const double truth = scene.trueDepth(key, chains[c].pixels[i]);
      errors.push_back(std::abs(d.depth - truth) / truth);
      z_scores.push_back(std::abs(1.0 / d.depth - 1.0 / truth) /
                         std::sqrt(d.inverse_depth_variance));
    }
  }
  accuracy.median_relative_error = quantile(errors, 0.5);
  accuracy.p90_relative_error = quantile(errors, 0.9);
  accuracy.median_z_score = quantile(z_scores, 0.5);
  const auto gross = std::count_if(errors.begin(), errors.end(), [](double e) { return e > 0.05; });
  accuracy.gross_error_fraction = errors.empty() ? 0.0 : static_cast<double>(gross) / errors.size();
  return accuracy;
}

// The keyframe and two references 12 cm to the side and 10 cm up, all slightly tilted so that
// the plane's depth varies over the image (about 1.4 to 1.6 m).
struct ThreeViews {
  Pose3 key = lookingAtPlane({0.0, 0.0, 1.5}, 4.0, -3.0);
  Pose3 side = lookingAtPlane({0.12, 0.0, 1.5}, 4.0, -1.0);
  Pose3 up = lookingAtPlane({0.0, 0.10, 1.45}, 5.0, -3.0);
};

EpipolarDepthOptions planeOptions() {
  EpipolarDepthOptions options;
  options.min_depth = 0.5;
  options.max_depth = 5.0;
  return options;
}

// `image` plus Gaussian noise of standard deviation `sigma` (grey levels), rounded and clipped.
cv::Mat withNoise(const cv::Mat& image, double sigma, cv::RNG& rng) {
  if (sigma <= 0.0) return image;
  cv::Mat noise(image.size(), CV_16SC1);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat sum;
  image.convertTo(sum, CV_16SC1);
  sum += noise;
  sum.convertTo(sum, CV_8UC1);
  return sum;
}

// The three views of a texture, their chains, and the depths estimated with `options`.
struct ThreeViewRun {
  PlaneScene scene;
  ThreeViews views;
  std::vector<EdgeChain> chains;
  ChainDepths depths;
  Accuracy accuracy;
};

ThreeViewRun runThreeViews(const cv::Mat& texture, const EpipolarDepthOptions& options,
                           double noise_sigma = 0.0) {
  ThreeViewRun run;
  run.scene = makeScene(texture);
  cv::RNG rng(11);
  const cv::Mat key_image = withNoise(run.scene.render(run.views.key), noise_sigma, rng);
  run.chains = chainsOf(key_image);
  const std::vector<DepthReferenceView> references = {
      {withNoise(run.scene.render(run.views.side), noise_sigma, rng), run.views.side},
      {withNoise(run.scene.render(run.views.up), noise_sigma, rng), run.views.up}};
  run.depths = estimateChainDepths(key_image, run.views.key, run.chains, references,
                                   run.scene.camera, options);
  run.accuracy = measure(run.scene, run.views.key, run.chains, run.depths);
  return run;
}

TEST(EpipolarDepth, RandomTexturePlaneDepthsMatchTruth) {
  const ThreeViewRun run = runThreeViews(randomTexture(1000, 800, 3), planeOptions());
  const Accuracy& accuracy = run.accuracy;
  ASSERT_GT(accuracy.pixels, 3000);
  EXPECT_EQ(run.depths.counts.total(), accuracy.pixels);
  EXPECT_EQ(run.depths.counts.valid(), accuracy.valid);
  // Measured: 90 % valid, median 0.09 %, 90th percentile 0.35 %, 0.8 % off by more than 5 %.
  EXPECT_GT(accuracy.validFraction(), 0.8);
  EXPECT_LT(accuracy.median_relative_error, 0.005);
  EXPECT_LT(accuracy.p90_relative_error, 0.01);
  EXPECT_LT(accuracy.gross_error_fraction, 0.03);
  // The default epipolar_sigma_px (0.5 px of pose error) dominates with exact poses: the variance
  // is conservative (measured median |error| / sigma 0.06).
  EXPECT_LT(accuracy.median_z_score, 0.67);
}

TEST(EpipolarDepth, PhotographPlaneDepthsMatchTruth) {
  const cv::Mat photograph = cv::imread(kPhotograph, cv::IMREAD_GRAYSCALE);
  if (photograph.empty()) GTEST_SKIP() << kPhotograph << " not installed (opencv-doc)";
  const Accuracy accuracy = runThreeViews(photograph, planeOptions()).accuracy;
  ASSERT_GT(accuracy.pixels, 3000);
  // Measured: 83 % valid, median 0.09 %, 90th percentile 0.31 %, 1.7 % off by more than 5 %.
  EXPECT_GT(accuracy.validFraction(), 0.7);
  EXPECT_LT(accuracy.median_relative_error, 0.005);
  EXPECT_LT(accuracy.p90_relative_error, 0.01);
  EXPECT_LT(accuracy.gross_error_fraction, 0.04);
}

// An unbounded range searches up to the vanishing point of each ray: longer segments, more
// rivals, but the same depths.
TEST(EpipolarDepth, SearchesToInfinity) {
  EpipolarDepthOptions options = planeOptions();
  options.max_depth = std::numeric_limits<double>::infinity();
  const Accuracy accuracy = runThreeViews(randomTexture(1000, 800, 3), options).accuracy;
  // Measured: 90 % valid, median 0.09 %, 1.1 % off by more than 5 %.
  EXPECT_GT(accuracy.validFraction(), 0.8);
  EXPECT_LT(accuracy.median_relative_error, 0.005);
  EXPECT_LT(accuracy.gross_error_fraction, 0.03);
}

// Views with Gaussian noise of 3 grey levels, and options that know it.
constexpr double kNoiseSigma = 3.0;

Accuracy noisyAccuracy(EpipolarDepthOptions options) {
  options.image_noise_sigma_grey = kNoiseSigma;
  return runThreeViews(randomTexture(1000, 800, 5), options, kNoiseSigma).accuracy;
}

TEST(EpipolarDepth, NoisyImagesStayAccurate) {
  const Accuracy accuracy = noisyAccuracy(planeOptions());
  // Measured: 85 % valid, median 0.13 %, 90th percentile 0.43 %, 1.6 % off by more than 5 %.
  EXPECT_GT(accuracy.validFraction(), 0.7);
  EXPECT_LT(accuracy.median_relative_error, 0.005);
  EXPECT_LT(accuracy.gross_error_fraction, 0.04);
}

// With exact poses (a negligible epipolar_sigma_px) and no smoothing the variance is the
// photometric one alone, from the curvature of the 1D cost and the noise level: it should
// describe the errors.
TEST(EpipolarDepth, PhotometricVarianceMatchesTheErrors) {
  EpipolarDepthOptions options = planeOptions();
  options.epipolar_sigma_px = 0.001;
  options.smoothing_half_window = 0;
  options.min_window_support = 1;
  const Accuracy accuracy = noisyAccuracy(options);
  // A Gaussian error has median |z| = 0.67; measured 0.42 (bilinear interpolation averages some
  // of the reference's noise away, which the model ignores).
  EXPECT_GT(accuracy.validFraction(), 0.7);
  EXPECT_GT(accuracy.median_z_score, 0.25);
  EXPECT_LT(accuracy.median_z_score, 1.0);
}

TEST(EpipolarDepth, PixelStepInterpolatesSkippedPixels) {
  EpipolarDepthOptions options = planeOptions();
  options.pixel_step = 2;
  options.min_window_support = 2;
  const ThreeViewRun run = runThreeViews(randomTexture(1000, 800, 3), options);
  int interpolated = 0;
  for (std::size_t c = 0; c < run.chains.size(); ++c) {
    for (std::size_t i = 0; i < run.chains[c].pixels.size(); ++i) {
      const PixelDepth& d = run.depths.chains[c][i];
      EXPECT_TRUE(!d.interpolated || i % 2 == 1) << "searched pixel marked interpolated";
      interpolated += d.valid() && d.interpolated;
    }
  }
  // Measured: 91 % valid, median 0.10 %.
  EXPECT_GT(interpolated, run.accuracy.pixels / 4);
  EXPECT_GT(run.accuracy.validFraction(), 0.8);
  EXPECT_LT(run.accuracy.median_relative_error, 0.005);
}

// Each chain is searched on one thread, so the chains split over threads give the same depths.
TEST(EpipolarDepth, ThreadsGiveTheSameDepths) {
  const ThreeViewRun one = runThreeViews(randomTexture(1000, 800, 3), planeOptions());
  ASSERT_GT(one.accuracy.pixels, 3000);
  for (const int threads : {2, 3, 64}) {
    EpipolarDepthOptions options = planeOptions();
    options.num_threads = threads;
    const ThreeViewRun many = runThreeViews(randomTexture(1000, 800, 3), options);
    ASSERT_EQ(many.depths.chains.size(), one.depths.chains.size());
    EXPECT_EQ(many.depths.counts.by_status, one.depths.counts.by_status) << threads << " threads";
    for (std::size_t c = 0; c < one.depths.chains.size(); ++c) {
      for (std::size_t i = 0; i < one.depths.chains[c].size(); ++i) {
        const PixelDepth& a = one.depths.chains[c][i];
        const PixelDepth& b = many.depths.chains[c][i];
        ASSERT_TRUE(a.status == b.status && a.depth == b.depth &&
                    a.inverse_depth_variance == b.inverse_depth_variance &&
                    a.reference == b.reference)
            << "chain " << c << " pixel " << i << ", " << threads << " threads";
      }
    }
  }
}

// Horizontal stripes seen without rotation from the keyframe, from 12 cm to the side (horizontal
// epipolar lines, along the edges) and from 10 cm up (vertical ones, across the edges).
struct StripeViews {
  PlaneScene scene = makeScene(stripeTexture(1000, 800, 9));
  Pose3 key = lookingAtPlane({0.0, 0.0, 1.5}, 0.0, 0.0);
  Pose3 side = lookingAtPlane({0.12, 0.0, 1.5}, 0.0, 0.0);
  Pose3 up = lookingAtPlane({0.0, -0.1, 1.5}, 0.0, 0.0);
  cv::Mat key_image = scene.render(key);
  std::vector<EdgeChain> chains = chainsOf(key_image);
};

TEST(EpipolarDepth, RejectsEdgesAlongTheEpipolarLine) {
  const StripeViews views;
  const cv::Mat side_image = views.scene.render(views.side);
  const ChainDepths along =
      estimateChainDepths(views.key_image, views.key, views.chains, {{side_image, views.side}},
                          views.scene.camera, planeOptions());
  ASSERT_GT(along.counts.total(), 1000);
  EXPECT_EQ(along.counts.valid(), 0);
  EXPECT_GT(along.counts.count(DepthStatus::kEdgeAlongEpipolar), 0.95 * along.counts.total());

  // Given a reference whose epipolar lines cross the edges, every depth comes from that one.
  const std::vector<DepthReferenceView> both = {{side_image, views.side},
                                                {views.scene.render(views.up), views.up}};
  const ChainDepths across = estimateChainDepths(views.key_image, views.key, views.chains, both,
                                                 views.scene.camera, planeOptions());
  EXPECT_GT(across.counts.valid(), 0.8 * across.counts.total());
  for (const std::vector<PixelDepth>& chain : across.chains) {
    for (const PixelDepth& d : chain) {
      if (d.valid()) {
        EXPECT_EQ(d.reference, 1);
      }
    }
  }
}

cv::Mat asFloat(const cv::Mat& grey) {
  cv::Mat image;
  grey.convertTo(image, CV_32F);
  return image;
}

// The pipeline converts each keyframe once and passes CV_32FC1 images: the same depths.
TEST(EpipolarDepth, FloatImagesGiveTheSameDepths) {
  const PlaneScene scene = makeScene(randomTexture(1000, 800, 3));
  const ThreeViews views;
  const cv::Mat key = scene.render(views.key);
  const cv::Mat side = scene.render(views.side);
  const cv::Mat up = scene.render(views.up);
  const std::vector<EdgeChain> chains = chainsOf(key);
  const ChainDepths grey = estimateChainDepths(
      key, views.key, chains, {{side, views.side}, {up, views.up}}, scene.camera, planeOptions());
  const ChainDepths floats = estimateChainDepths(
      asFloat(key), views.key, chains, {{asFloat(side), views.side}, {asFloat(up), views.up}},
      scene.camera, planeOptions());
  ASSERT_GT(grey.counts.valid(), 1000);
  ASSERT_EQ(floats.chains.size(), grey.chains.size());
  for (std::size_t c = 0; c < grey.chains.size(); ++c) {
    for (std::size_t i = 0; i < grey.chains[c].size(); ++i) {
      EXPECT_EQ(floats.chains[c][i].status, grey.chains[c][i].status);
      EXPECT_EQ(floats.chains[c][i].depth, grey.chains[c][i].depth);
      EXPECT_EQ(floats.chains[c][i].inverse_depth_variance,
                grey.chains[c][i].inverse_depth_variance);
    }
  }
}

TEST(EpipolarDepth, ZeroBaselineHasNoReference) {
  const PlaneScene scene = makeScene(randomTexture(1000, 800, 3));
  const Pose3 key = lookingAtPlane({0.0, 0.0, 1.5}, 2.0, 0.0);
  const cv::Mat key_image = scene.render(key);
  const std::vector<EdgeChain> chains = chainsOf(key_image);
  const ChainDepths depths =
      estimateChainDepths(key_image, key, chains, {{key_image, key}}, scene.camera, planeOptions());
  EXPECT_EQ(depths.counts.count(DepthStatus::kNoReference), depths.counts.total());
}

TEST(ReferenceChooser, PrefersARealBaseline) {
  const PlaneScene scene = makeScene(randomTexture(1000, 800, 3));
  const ThreeViews views;
  const std::vector<EdgeChain> chains = chainsOf(scene.render(views.key));
  const std::vector<ReferenceCandidate> ranked =
      rankReferenceFrames(views.key, {views.key, views.side}, scene.camera, chains, planeOptions());
  ASSERT_EQ(ranked.size(), 2u);
  EXPECT_EQ(ranked[0].index, 1);
  EXPECT_TRUE(ranked[0].eligible);
  EXPECT_NEAR(ranked[0].baseline, 0.12, 1e-9);
  EXPECT_GT(ranked[0].score, 5.0);
  EXPECT_EQ(ranked[1].index, 0);
  EXPECT_FALSE(ranked[1].eligible);
  EXPECT_EQ(ranked[1].score, 0.0);
}

TEST(ReferenceChooser, PrefersEpipolarLinesAcrossTheEdges) {
  const StripeViews views;
  const std::vector<ReferenceCandidate> ranked = rankReferenceFrames(
      views.key, {views.side, views.up}, views.scene.camera, views.chains, planeOptions());
  ASSERT_EQ(ranked.size(), 2u);
  EXPECT_EQ(ranked[0].index, 1);  // The shorter baseline, but across the horizontal edges.
  EXPECT_TRUE(ranked[1].eligible);
  EXPECT_LT(ranked[1].score, 0.1 * ranked[0].score);
}

TEST(ReferenceChooser, RejectsLargeViewpointChanges) {
  const Camera camera{CameraIntrinsics{}};
  const Pose3 key = lookingAtPlane({0.0, 0.0, 1.5}, 0.0, 0.0);
  const Pose3 turned = lookingAtPlane({0.2, 0.0, 1.5}, 0.0, 45.0);
  const std::vector<ReferenceCandidate> ranked =
      rankReferenceFrames(key, {turned}, camera, {}, planeOptions());
  ASSERT_EQ(ranked.size(), 1u);
  EXPECT_NEAR(ranked[0].optical_axis_angle_deg, 45.0, 1e-9);
  EXPECT_FALSE(ranked[0].eligible);
}

void expectInvalid(void (*mutate)(EpipolarDepthOptions*), const std::string& field) {
  EpipolarDepthOptions options;
  mutate(&options);
  try {
    options.validate();
    ADD_FAILURE() << field << " accepted";
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("EpipolarDepthOptions." + field + " = "),
              std::string::npos)
        << e.what();
  }
}

TEST(EpipolarDepthOptions, DefaultsAreValid) { EXPECT_NO_THROW(EpipolarDepthOptions().validate()); }

TEST(EpipolarDepthOptions, BadValuesThrowNamingTheField) {
  expectInvalid([](EpipolarDepthOptions* o) { o->min_depth = 0.0; }, "min_depth");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_depth = 0.1; }, "max_depth");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_depth = std::nan(""); }, "max_depth");
  expectInvalid([](EpipolarDepthOptions* o) { o->min_parallax_deg = -1.0; }, "min_parallax_deg");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_gradient_epipolar_angle_deg = 90.0; },
                "max_gradient_epipolar_angle_deg");
  expectInvalid([](EpipolarDepthOptions* o) { o->patch_half_size_1d = 0; }, "patch_half_size_1d");
  expectInvalid([](EpipolarDepthOptions* o) { o->patch_half_size_2d = 11; }, "patch_half_size_2d");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_candidates = 9; }, "max_candidates");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_patch_rms_grey = 0.0; }, "max_patch_rms_grey");
  expectInvalid([](EpipolarDepthOptions* o) { o->max_ambiguity_ratio = 1.5; },
                "max_ambiguity_ratio");
  expectInvalid([](EpipolarDepthOptions* o) { o->epipolar_sigma_px = 0.0; }, "epipolar_sigma_px");
  expectInvalid([](EpipolarDepthOptions* o) { o->pixel_step = 0; }, "pixel_step");
  expectInvalid([](EpipolarDepthOptions* o) { o->min_window_support = 8; }, "min_window_support");
  expectInvalid([](EpipolarDepthOptions* o) { o->outlier_sigmas = -1.0; }, "outlier_sigmas");
  expectInvalid([](EpipolarDepthOptions* o) { o->num_threads = 0; }, "num_threads");
  // Infinity is a valid far limit.
  EpipolarDepthOptions options;
  options.max_depth = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(options.validate());
}

TEST(EpipolarDepth, BadInputsThrow) {
  const Camera camera{CameraIntrinsics{}};
  const cv::Mat image(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
  const Pose3 key;
  EpipolarDepthOptions bad;
  bad.pixel_step = 0;
  EXPECT_THROW(estimateChainDepths(image, key, {}, {}, camera, bad), InvalidOptions);
  const cv::Mat colour(camera.height(), camera.width(), CV_8UC3);
  EXPECT_THROW(estimateChainDepths(colour, key, {}, {}, camera), CheckError);
  const cv::Mat doubles(camera.height(), camera.width(), CV_64FC1);
  EXPECT_THROW(estimateChainDepths(doubles, key, {}, {}, camera), CheckError);
  EXPECT_THROW(estimateChainDepths(image, key, {}, {{cv::Mat(), key}}, camera), CheckError);
  CameraIntrinsics distorted;
  distorted.k1 = 0.1;
  EXPECT_THROW(estimateChainDepths(image, key, {}, {}, Camera(distorted)), CheckError);
  EdgeChain broken;
  broken.pixels.push_back({10, 10});
  EXPECT_THROW(estimateChainDepths(image, key, {broken}, {}, camera), CheckError);
}

TEST(EpipolarDepth, PixelsAtTheBorderAreRejected) {
  const Camera camera{CameraIntrinsics{}};
  const cv::Mat image(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
  EdgeChain chain;
  chain.pixels = {{0, 5}, {1, 5}, {-3, 5}, {639, 479}};
  chain.normals.assign(4, Eigen::Vector2f(1.0f, 0.0f));
  const Pose3 side(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.1, 0.0, 0.0));
  const ChainDepths depths = estimateChainDepths(image, Pose3(), {chain}, {{image, side}}, camera);
  EXPECT_EQ(depths.counts.count(DepthStatus::kAtImageBorder), 4);
}

TEST(DepthStatus, NamesAreDistinct) {
  std::vector<std::string> names;
  for (int s = 0; s < kNumDepthStatuses; ++s) {
    names.push_back(toString(static_cast<DepthStatus>(s)));
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(std::unique(names.begin(), names.end()), names.end());
  EXPECT_EQ(toString(DepthStatus::kEdgeAlongEpipolar), "edge_along_epipolar");
}

}  // namespace
}  // namespace curvesfm
