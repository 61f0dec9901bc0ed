#include "frontend/image/curve_initialiser.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace curvesfm {
namespace {

using CurveInCam = std::function<Eigen::Vector3d(double)>;  // s in [0, 1] -> camera frame.

// A chain with a depth per pixel, as extractEdgeChains and estimateChainDepths would give.
struct Scene {
  Camera camera{CameraIntrinsics{}};
  // A generic pose, so that lifting to the world frame is exercised.
  Pose3 world_from_cam{
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, -2.0, 0.5).normalized())),
      Eigen::Vector3d(0.5, -0.3, 1.2)};
  EdgeChain chain;
  ChainDepths depths;

  Pose3 camFromWorld() const { return world_from_cam.inverse(); }

  void addPixel(const Eigen::Vector2i& pixel, double depth) {
    chain.pixels.push_back(pixel);
    chain.normals.emplace_back(1.0f, 0.0f);
    PixelDepth d;
    d.depth = depth;
    d.status = DepthStatus::kValid;
    if (depths.chains.empty()) depths.chains.emplace_back();
    depths.chains[0].push_back(d);
  }

  void invalidate(int first, int last) {
    for (int i = first; i <= last; ++i) depths.chains[0][i] = PixelDepth();
  }

  CurveInitialisation run(const CurveInitialiserOptions& options = {}) const {
    return CurveInitialiser(options).initialise(camera, camFromWorld(), {chain}, depths);
  }
};

// Rasterises a camera-frame curve into integer pixels as Canny would: the rounded projections of
// dense samples, each pixel with the exact depth of the curve point projecting nearest its centre.
void rasterise(const CurveInCam& curve, Scene* scene) {
  constexpr int kSamples = 40000;
  Eigen::Vector2i current(-1, -1);
  double best_offset = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= kSamples; ++k) {
    const Eigen::Vector3d point = curve(double(k) / kSamples);
    Eigen::Vector2d uv;
    ASSERT_TRUE(scene->camera.project(point, &uv));
    const Eigen::Vector2i pixel(std::lround(uv.x()), std::lround(uv.y()));
    const double offset = (uv - pixel.cast<double>()).norm();
    if (pixel != current) {
      if (current.x() >= 0) {
        ASSERT_LE((pixel - current).cwiseAbs().maxCoeff(), 1) << "not 8-connected";
      }
      scene->addPixel(pixel, point.z());
      current = pixel;
      best_offset = offset;
    } else if (offset < best_offset) {
      scene->depths.chains[0].back().depth = point.z();
      best_offset = offset;
    }
  }
}

// The point of the 3D line through a and b (camera frame) seen at `pixel`, which must lie on the
// line's image: the exact lift of that pixel.
Eigen::Vector3d pointOnLine(const Camera& camera, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector2i& pixel) {
  const Eigen::Vector3d ray = camera.unproject(pixel.cast<double>(), 1.0);
  Eigen::Matrix<double, 3, 2> system;
  system << ray, a - b;
  const Eigen::Vector2d solution = system.colPivHouseholderQr().solve(a);
  return solution[0] * ray;
}

double distanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Distances (m) from dense samples of a fitted curve to the true curve.
struct Accuracy {
  double max = 0.0;
  double rms = 0.0;
};

// `truth`: the true curve as a dense polyline.
Accuracy measureAccuracy(const PolyBezier& curve, const std::vector<Eigen::Vector3d>& truth) {
  Accuracy accuracy;
  const std::vector<Eigen::Vector3d> samples = curve.sample(20);
  for (const Eigen::Vector3d& p : samples) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i + 1 < truth.size(); ++i) {
      nearest = std::min(nearest, distanceToSegment(p, truth[i], truth[i + 1]));
    }
    accuracy.max = std::max(accuracy.max, nearest);
    accuracy.rms += nearest * nearest;
  }
  accuracy.rms = std::sqrt(accuracy.rms / samples.size());
  ::testing::Test::RecordProperty("max_distance_mm", std::to_string(accuracy.max * 1e3));
  ::testing::Test::RecordProperty("rms_distance_mm", std::to_string(accuracy.rms * 1e3));
  return accuracy;
}

std::vector<Eigen::Vector3d> denseWorldCurve(const Scene& scene, const CurveInCam& curve) {
  constexpr int kVertices = 4000;
  std::vector<Eigen::Vector3d> truth;
  for (int k = 0; k <= kVertices; ++k) {
    truth.push_back(scene.world_from_cam * curve(double(k) / kVertices));
  }
  return truth;
}

// Rasterises `curve`, initialises it and checks the count and shape of the one curve expected;
// returns how far the fit lies from the truth.
Accuracy initialiseKnownCurve(const CurveInCam& curve) {
  Scene scene;
  rasterise(curve, &scene);
  const CurveInitialisation result = scene.run();
  const int n = static_cast<int>(scene.chain.pixels.size());
  EXPECT_EQ(result.counts.segmentsRejected(), 0);
  EXPECT_EQ(result.counts.pixels_lifted, n);
  if (result.curves.size() != 1u) {
    ADD_FAILURE() << "expected one curve, got " << result.curves.size();
    return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  const InitialCurve& initial = result.curves[0];
  EXPECT_EQ(initial.curve.numSegments(), std::lround(n / 12.0)) << n << " pixels";
  EXPECT_EQ(initial.segment_pixels.front().first, 0);
  EXPECT_EQ(initial.segment_pixels.back().last, n - 1);
  for (size_t i = 0; i + 1 < initial.segment_pixels.size(); ++i) {
    EXPECT_EQ(initial.segment_pixels[i].last, initial.segment_pixels[i + 1].first);
  }
  return measureAccuracy(initial.curve, denseWorldCurve(scene, curve));
}

TEST(CurveInitialiser, CircleArcFromIntegerPixelsLiesOnTheTrueCurve) {
  // Radius 0.3 m at 2 m, in a plane tilted 40 deg to the image: depths 1.81-2.19 m.
  const Eigen::Vector3d centre(0.05, -0.02, 2.0);
  const Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  const Eigen::Vector3d e2(0.0, std::cos(0.7), std::sin(0.7));
  const Accuracy accuracy = initialiseKnownCurve([&](double s) {
    const double angle = 0.2 + 4.3 * s;
    return Eigen::Vector3d(centre + 0.3 * (std::cos(angle) * e1 + std::sin(angle) * e2));
  });
  // Integer pixels alone put the lifted points up to 0.71 px (2.8 mm here) off the curve, with
  // errors correlated along the staircase, so the fit cannot average them all away; the bound is
  // one pixel's footprint at the far depth, 2.19 m / 525 px = 4.2 mm. Measured: max 2.4 mm,
  // rms 1.1 mm.
  EXPECT_LT(accuracy.max, 4e-3);
  EXPECT_LT(accuracy.rms, 1.5e-3);
}

TEST(CurveInitialiser, HelixArcFromIntegerPixelsLiesOnTheTrueCurve) {
  // Radius 0.25 m, depth rising from 1.7 to 2.2 m over 286 deg.
  const Accuracy accuracy = initialiseKnownCurve([](double s) {
    const double angle = 5.0 * s;
    return Eigen::Vector3d(0.25 * std::cos(angle), 0.25 * std::sin(angle), 1.7 + 0.1 * angle);
  });
  // As for the circle. Measured: max 3.5 mm (at the far end of the chain), rms 1.2 mm.
  EXPECT_LT(accuracy.max, 4e-3);
  EXPECT_LT(accuracy.rms, 1.5e-3);
}

// A 3D line whose image runs through the pixel centres `from` + k `step`, k = 0..n-1, with exact
// depths: the lifted points lie exactly on it.
struct ExactLine {
  Eigen::Vector3d a;  // Camera frame, seen at `from`.
  Eigen::Vector3d b;  // Camera frame, seen at the last pixel.
};

ExactLine addExactLine(const Eigen::Vector2i& from, const Eigen::Vector2i& step, int n,
                       double depth_from, double depth_to, Scene* scene) {
  const Eigen::Vector2i to = from + (n - 1) * step;
  const ExactLine line{scene->camera.unproject(from.cast<double>(), depth_from),
                       scene->camera.unproject(to.cast<double>(), depth_to)};
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2i pixel = from + k * step;
    scene->addPixel(pixel, pointOnLine(scene->camera, line.a, line.b, pixel).z());
  }
  return line;
}

TEST(CurveInitialiser, ExactLinesAreReproducedExactly) {
  for (const Eigen::Vector2i& step : {Eigen::Vector2i(1, 0), Eigen::Vector2i(1, 1)}) {
    Scene scene;
    const ExactLine line = addExactLine({100, 120}, step, 150, 1.8, 2.4, &scene);
    const CurveInitialisation result = scene.run();
    ASSERT_EQ(result.curves.size(), 1u);
    const PolyBezier& curve = result.curves[0].curve;
    EXPECT_EQ(curve.numSegments(), 13);  // round(150 / 12).
    const Eigen::Vector3d a = scene.world_from_cam * line.a;
    const Eigen::Vector3d b = scene.world_from_cam * line.b;
    const Eigen::Vector3d axis = (b - a).normalized();
    for (const Eigen::Vector3d& p : curve.sample(20)) {
      EXPECT_LT((p - a - (p - a).dot(axis) * axis).norm(), 1e-9);
    }
    // Along the line the perspective spacing is not the cubic's, so the ends move a little.
    EXPECT_LT((curve.points().front() - a).norm(), 1e-3);
    EXPECT_LT((curve.points().back() - b).norm(), 1e-3);
    for (const Direction& v : curve.directions()) EXPECT_NEAR(v.vector().dot(axis), 1.0, 1e-9);
  }
}

// 60 pixels along image row 300 at 2 m, split by the default 12 px into 5 segments with
// boundaries at pixels 0, 12, 24, 35, 47, 59.
Scene straightScene() {
  Scene scene;
  addExactLine({100, 300}, {1, 0}, 60, 2.0, 2.0, &scene);
  return scene;
}

TEST(CurveInitialiser, LongDepthGapSplitsTheChain) {
  Scene scene = straightScene();
  scene.invalidate(28, 31);
  const CurveInitialisation result = scene.run();
  ASSERT_EQ(result.curves.size(), 2u);
  EXPECT_EQ(result.curves[0].segment_pixels.front().first, 0);
  EXPECT_EQ(result.curves[0].segment_pixels.back().last, 27);
  EXPECT_EQ(result.curves[1].segment_pixels.front().first, 32);
  EXPECT_EQ(result.curves[1].segment_pixels.back().last, 59);
  EXPECT_EQ(result.curves[1].chain, 0);
  EXPECT_EQ(result.counts.pixels, 60);
  EXPECT_EQ(result.counts.pixels_lifted, 56);
  EXPECT_EQ(result.counts.runs, 2);
  EXPECT_EQ(result.counts.curves, 2);
}

TEST(CurveInitialiser, ShortDepthGapIsBridgedUpToMaxGap) {
  Scene scene = straightScene();
  scene.invalidate(30, 30);
  EXPECT_EQ(scene.run().curves.size(), 1u);
  CurveInitialiserOptions no_gaps;
  no_gaps.max_gap_px = 0;
  EXPECT_EQ(scene.run(no_gaps).curves.size(), 2u);
}

TEST(CurveInitialiser, DepthJumpSplitsTheChain) {
  Scene scene = straightScene();
  for (int i = 30; i < 60; ++i) scene.depths.chains[0][i].depth = 2.5;
  const CurveInitialisation result = scene.run();
  ASSERT_EQ(result.curves.size(), 2u);
  EXPECT_EQ(result.curves[0].segment_pixels.back().last, 29);
  EXPECT_EQ(result.curves[1].segment_pixels.front().first, 30);
  EXPECT_EQ(result.counts.depth_jumps, 1);
  // Both halves stay in the plane they were lifted from.
  for (const Eigen::Vector3d& p : result.curves[1].curve.points()) {
    EXPECT_NEAR((scene.camFromWorld() * p).z(), 2.5, 1e-3);
  }
}

TEST(CurveInitialiser, RunsShorterThanFourPixelsAreDroppedAndCounted) {
  Scene scene;
  addExactLine({100, 300}, {1, 0}, 3, 2.0, 2.0, &scene);
  CurveInitialisation result = scene.run();
  EXPECT_TRUE(result.curves.empty());
  EXPECT_EQ(result.counts.runs_too_short, 1);
  EXPECT_EQ(result.counts.runs, 0);

  // Runs of 3 between gaps of 2 pixels: nothing to fit either.
  scene = Scene();
  addExactLine({100, 300}, {1, 0}, 18, 2.0, 2.0, &scene);
  for (int i = 3; i < 18; i += 5) scene.invalidate(i, i + 1);
  result = scene.run();
  EXPECT_TRUE(result.curves.empty());
  EXPECT_EQ(result.counts.runs_too_short, 4);
}

TEST(CurveInitialiser, BadSegmentCutsTheCurve) {
  Scene scene = straightScene();
  // Depth noise of +-3% (6 cm) inside segment 2 (pixels 24-35): neighbours differ by 6%, below
  // the 10% jump threshold, but the fit's residual is far above 10% of the 4.6 cm chord.
  for (int i = 25; i < 35; ++i) scene.depths.chains[0][i].depth = i % 2 ? 2.06 : 1.94;
  CurveInitialisation result = scene.run();
  EXPECT_EQ(result.counts.segments_accepted, 4);
  EXPECT_EQ(result.counts.segmentsRejected(), 1);
  EXPECT_EQ(result.counts.segments_bad_fit, 1);
  ASSERT_EQ(result.curves.size(), 2u);
  EXPECT_EQ(result.curves[0].segment_pixels.back().last, 24);
  EXPECT_EQ(result.curves[1].segment_pixels.front().first, 35);
  EXPECT_EQ(result.curves[1].curve.numSegments(), 2);

  CurveInitialiserOptions longer;
  longer.min_segments = 3;
  result = scene.run(longer);
  EXPECT_TRUE(result.curves.empty());
  EXPECT_EQ(result.counts.curves_too_few_segments, 2);
}

TEST(CurveInitialiser, ShortChordsAndLoopsAreRejected) {
  CurveInitialiserOptions huge_chords;
  huge_chords.min_chord = 1.0;
  CurveInitialisation result = straightScene().run(huge_chords);
  EXPECT_TRUE(result.curves.empty());
  EXPECT_EQ(result.counts.segments_short_chord, 5);

  // One segment going once around a circle of 2.6 px radius: its ends nearly meet.
  CurveInitialiserOptions one_segment;
  one_segment.pixels_per_segment = 100;
  Scene scene;
  rasterise(
      [](double s) {
        const double angle = 6.0 * s;
        return Eigen::Vector3d(0.01 * std::cos(angle), 0.01 * std::sin(angle), 2.0);
      },
      &scene);
  result = scene.run(one_segment);
  EXPECT_TRUE(result.curves.empty());
  EXPECT_EQ(result.counts.segments_loop, 1) << scene.chain.pixels.size() << " pixels";
}

TEST(CurveInitialiser, MismatchedDepthsThrow) {
  Scene scene = straightScene();
  scene.depths.chains[0].pop_back();
  EXPECT_THROW(scene.run(), CheckError);
  scene.depths.chains.clear();
  EXPECT_THROW(scene.run(), CheckError);
}

TEST(CurveInitialiserOptions, BadValuesThrowNamingTheField) {
  EXPECT_NO_THROW(CurveInitialiserOptions().validate());
  const std::vector<std::pair<std::string, std::function<void(CurveInitialiserOptions&)>>> cases = {
      {"pixels_per_segment", [](auto& o) { o.pixels_per_segment = 3; }},
      {"min_segments", [](auto& o) { o.min_segments = 0; }},
      {"max_gap_px", [](auto& o) { o.max_gap_px = -1; }},
      {"max_relative_depth_jump", [](auto& o) { o.max_relative_depth_jump = 0.0; }},
      {"max_rms_residual_rel_chord", [](auto& o) { o.max_rms_residual_rel_chord = std::nan(""); }},
      {"min_chord", [](auto& o) { o.min_chord = -1.0; }},
      {"max_arm_to_chord", [](auto& o) { o.max_arm_to_chord = 0.0; }}};
  for (const auto& [field, mutate] : cases) {
    CurveInitialiserOptions options;
    mutate(options);
    try {
      CurveInitialiser initialiser(options);
      ADD_FAILURE() << field << " accepted";
    } catch (const InvalidOptions& e) {
      EXPECT_NE(std::string(e.what()).find("CurveInitialiserOptions." + field + " = "),
                std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace curvesfm
