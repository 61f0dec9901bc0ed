#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <future>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <utility>

#include "core/errors.h"
#include "core/trajectory_evaluation.h"
#include "frontend/mapping/pipeline.h"
#include "sim/occluding_cylinder.h"
#include "sim/planar_scene.h"

namespace curvesfm {
namespace {

// Random filled rectangles, circles and thick lines in random colours on a grey ground: strong,
// partly curved edges of every orientation, so that the test runs without OpenCV's sample photos.
cv::Mat syntheticTexture() {
  cv::Mat texture(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::RNG rng(7);
  const auto colour = [&]() {
    return cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
  };
  for (int i = 0; i < 25; ++i) {
    const cv::Point a(rng.uniform(0, 640), rng.uniform(0, 480));
    const cv::Point b(a.x + rng.uniform(30, 160), a.y + rng.uniform(30, 120));
    cv::rectangle(texture, a, b, colour(), cv::FILLED);
  }
  for (int i = 0; i < 20; ++i) {
    cv::circle(texture, {rng.uniform(0, 640), rng.uniform(0, 480)}, rng.uniform(10, 70), colour(),
               cv::FILLED, cv::LINE_AA);
  }
  for (int i = 0; i < 15; ++i) {
    cv::line(texture, {rng.uniform(0, 640), rng.uniform(0, 480)},
             {rng.uniform(0, 640), rng.uniform(0, 480)}, colour(), rng.uniform(3, 8), cv::LINE_AA);
  }
  return texture;
}

// OpenCV's graffiti photo if installed (real texture), else the synthetic one.
cv::Mat planarTexture() {
  const std::string photo = "/usr/share/doc/opencv-doc/examples/data/graf1.png";
  if (std::filesystem::exists(photo)) {
    cv::Mat image = cv::imread(photo, cv::IMREAD_COLOR);
    if (!image.empty()) return image;
  }
  return syntheticTexture();
}

// A short, small version of `curvesfm synth planar`'s orbit: the same geometry at 320 x 240,
// neighbours 2 frame spacings of the default apart so that 8 frames still span a useful arc.
PlanarSceneOptions smallOrbit() {
  PlanarSceneOptions options;
  options.num_frames = 8;
  options.arc_degrees = 90.0 * 2 * 7 / 29;
  options.width = 320;
  options.height = 240;
  options.fx = options.fy = 262.5;
  options.cx = 159.5;
  options.cy = 119.5;
  options.intensity_noise = 0.01;  // The initial poses drift as synth planar's default.
  options.seed = 3;
  return options;
}

// The first five frames of the small orbit.
PlanarScene fiveFrameOrbit() {
  PlanarSceneOptions orbit = smallOrbit();
  orbit.num_frames = 5;
  return makePlanarScene(planarTexture(), orbit);
}

TEST(Pipeline, RefinesAPerturbedPlanarTrajectory) {
  const PlanarScene scene = makePlanarScene(planarTexture(), smallOrbit());
  PipelineOptions options;
  options.map.min_keyframe_translation = 0.0;
  options.map.min_keyframe_rotation_deg = 0.0;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    const KeyframeStats stats =
        pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
    EXPECT_EQ(stats.keyframe_index, static_cast<int>(i));
  }
  const PipelineResult result = pipeline.finish();
  ASSERT_EQ(result.keyframe_cam_from_world.size(), scene.images.size());
  EXPECT_GT(result.curves.size(), 10u);
  const double initial_ate =
      evaluateTrajectory(scene.true_cam_from_world, scene.initial_cam_from_world).position_ate_sim3;
  const double refined_ate =
      evaluateTrajectory(scene.true_cam_from_world, result.keyframe_cam_from_world)
          .position_ate_sim3;
  // Bundle adjustment and re-association must leave the trajectory clearly closer to the truth
  // than the drifting start.
  EXPECT_LT(refined_ate, 0.5 * initial_ate)
      << "initial ATE " << initial_ate << " m, refined " << refined_ate << " m";
  // The poses after every stage, in order: local BA held them, global BA and each re-association
  // round moved them, the last stage is the result.
  ASSERT_GE(result.pose_stages.size(), 2u);
  EXPECT_EQ(result.pose_stages[0].name, "incremental");
  EXPECT_EQ(result.pose_stages[1].name, "global_ba");
  EXPECT_EQ(result.pose_stages.size(), 2 + result.reassociation.size());
  for (std::size_t j = 0; j < scene.images.size(); ++j) {
    EXPECT_EQ(cameraCentreDistance(result.pose_stages[0].keyframe_cam_from_world[j],
                                   scene.initial_cam_from_world[j]),
              0.0);
    EXPECT_EQ(cameraCentreDistance(result.pose_stages.back().keyframe_cam_from_world[j],
                                   result.keyframe_cam_from_world[j]),
              0.0);
  }
  // A normal run is plausible: no curve leaves the scene, no verdict.
  EXPECT_TRUE(result.sanity.extent.valid());
  EXPECT_EQ(result.sanity.checked_curves, static_cast<int>(result.curves.size()));
  EXPECT_TRUE(result.sanity.implausible_curves.empty())
      << "curve " << result.sanity.implausible_curves[0].id << ", length "
      << result.sanity.implausible_curves[0].length;
  for (const RunVerdict& verdict : result.sanity.verdicts) ADD_FAILURE() << verdict.message;
  EXPECT_GE(result.sanity.pose_move.keyframe, 0);
}

// The first five frames of the small orbit, every one a keyframe, without global BA: curves are
// global from keyframe 2 on, so local BA runs from there.
PipelineResult runFiveFramesWithoutGlobalBa(PipelineOptions options) {
  const PlanarScene scene = fiveFrameOrbit();
  options.map.min_keyframe_translation = 0.0;
  options.map.min_keyframe_rotation_deg = 0.0;
  options.run_global_ba = false;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
  }
  return pipeline.finish();
}

// The same run with each keyframe's image stage prepared one frame ahead on another thread (as
// `curvesfm run --images-ahead` does) gives the same result, bit for bit: the stage depends on
// the image alone.
TEST(Pipeline, ImagesPreparedAheadOnAnotherThreadGiveTheSameRun) {
  const PlanarScene scene = fiveFrameOrbit();
  PipelineOptions options;
  options.map.min_keyframe_translation = 0.0;
  options.map.min_keyframe_rotation_deg = 0.0;
  options.run_global_ba = false;
  const PipelineResult inline_run = runFiveFramesWithoutGlobalBa(options);

  Pipeline pipeline(*scene.camera, options);
  const auto prepare = [&](std::size_t i) {
    return std::async(std::launch::async, [&pipeline, &scene, i] {
      return std::make_shared<const KeyframeImage>(pipeline.prepareImage(scene.images[i]));
    });
  };
  std::future<std::shared_ptr<const KeyframeImage>> next = prepare(0);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    std::shared_ptr<const KeyframeImage> image = next.get();
    if (i + 1 < scene.images.size()) next = prepare(i + 1);
    pipeline.addFrame(
        {scene.timestamps[i], cv::Mat(), scene.initial_cam_from_world[i], {}, {}, image});
  }
  const PipelineResult ahead_run = pipeline.finish();

  ASSERT_EQ(ahead_run.curves.size(), inline_run.curves.size());
  EXPECT_GT(inline_run.curves.size(), 5u);
  for (std::size_t c = 0; c < inline_run.curves.size(); ++c) {
    EXPECT_EQ(ahead_run.curves[c].sample(4), inline_run.curves[c].sample(4)) << "curve " << c;
  }
  for (std::size_t k = 0; k < inline_run.keyframe_cam_from_world.size(); ++k) {
    EXPECT_EQ(ahead_run.keyframe_cam_from_world[k].translation(),
              inline_run.keyframe_cam_from_world[k].translation())
        << "keyframe " << k;
  }
}

// The largest camera-centre distance between the keyframe poses of that run and the starting
// poses.
double largestMoveWithoutGlobalBa(bool local_ba_refines_poses) {
  PipelineOptions options;
  options.local_ba_refines_poses = local_ba_refines_poses;
  const PipelineResult result = runFiveFramesWithoutGlobalBa(options);
  double largest = 0.0;
  for (std::size_t j = 0; j < result.keyframe_cam_from_world.size(); ++j) {
    largest = std::max(largest, cameraCentreDistance(result.keyframe_cam_from_world[j],
                                                     result.keyframe_initial_cam_from_world[j]));
  }
  return largest;
}

TEST(Pipeline, LocalBaMovesPosesOnlyWhenAskedTo) {
  EXPECT_EQ(largestMoveWithoutGlobalBa(false), 0.0);
  EXPECT_GT(largestMoveWithoutGlobalBa(true), 1e-5);
}

// As the orbit turns, edges run on past the ends of the curves registered in each new keyframe;
// those pieces extend the curves instead of starting new ones, unless extension is off.
TEST(Pipeline, ExtendsCurvesThatNewEdgesContinue) {
  const auto count = [](bool enabled) {
    PipelineOptions options;
    options.extension.enabled = enabled;
    int started = 0, extended = 0;
    for (const KeyframeStats& s : runFiveFramesWithoutGlobalBa(options).frames) {
      started += s.new_curves;
      extended += s.extended_curves;
    }
    return std::make_pair(started, extended);
  };
  const auto [started_with, extended_with] = count(true);
  const auto [started_without, extended_without] = count(false);
  EXPECT_GT(extended_with, 0);
  EXPECT_EQ(extended_without, 0);
  EXPECT_LT(started_with, started_without);
}

// Points on a 4 cm patch at the plane's centre, no margin: the extent is the box of the cameras
// and that patch, so the curves on the plane beyond it leave the extent. They are dropped,
// listed, and out of the result; and a pose-move threshold below what global BA moves the poses
// gives that verdict (largestPoseMove's own test makes a pose jump far).
TEST(Pipeline, DropsCurvesOutsideTheExtentAndJudgesTheRun) {
  const PlanarScene scene = fiveFrameOrbit();
  PipelineOptions options;
  options.reassociation_rounds = 1;
  options.sanity.extent_margin = 0.0;
  options.sanity.extent_percentile = 0.0;
  options.sanity.max_pose_move_spacings = 1e-6;
  options.sanity.min_curves = 0;
  Pipeline pipeline(*scene.camera, options);
  std::vector<Eigen::Vector3d> patch;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) patch.emplace_back(-0.02 + 0.01 * i, -0.02 + 0.01 * j, 0.0);
  }
  // A slab 1 cm thick about the plane: a curve on the plane lies inside the extent's depth
  // whichever side of z = 0 its fit rounds to.
  patch.emplace_back(0.0, 0.0, 0.005);
  patch.emplace_back(0.0, 0.0, -0.005);
  pipeline.setPoints(patch);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
  }
  const PipelineResult result = pipeline.finish();
  const RunSanity& sanity = result.sanity;
  ASSERT_TRUE(sanity.extent.valid());
  EXPECT_EQ(sanity.extent.source, "points");
  ASSERT_FALSE(sanity.implausible_curves.empty());
  EXPECT_EQ(sanity.droppedCurves(), static_cast<int>(sanity.implausible_curves.size()));
  EXPECT_EQ(sanity.checked_curves,
            static_cast<int>(result.curves.size() + sanity.implausible_curves.size()));
  for (const ImplausibleCurve& c : sanity.implausible_curves) {
    EXPECT_NE(c.reason, CurveImplausibility::kNone) << "curve " << c.id;
    EXPECT_GT(c.length, 0.0);
  }
  // The curves were checked again after the last global BA: what is exported lies inside.
  ASSERT_FALSE(result.curves.empty());
  for (const PolyBezier& curve : result.curves) {
    EXPECT_EQ(checkCurve(curve, sanity.extent, options.sanity.samples_per_segment).reason,
              CurveImplausibility::kNone);
  }
  // Most of the plane lies beyond the patch: most curves go, and that is a verdict too.
  std::vector<RunVerdictKind> expected;
  if (2 * sanity.implausible_curves.size() > static_cast<std::size_t>(sanity.checked_curves)) {
    expected.push_back(RunVerdictKind::kMostCurvesImplausible);
  }
  expected.push_back(RunVerdictKind::kPosesMovedFar);
  std::vector<RunVerdictKind> kinds;
  for (const RunVerdict& verdict : sanity.verdicts) kinds.push_back(verdict.kind);
  EXPECT_EQ(kinds, expected);
  EXPECT_GT(sanity.pose_move.spacings(), 1e-6);
}

// The five frames of the small orbit, global BA and re-association as `options` say.
PipelineResult runFiveFrames(const PipelineOptions& options) {
  const PlanarScene scene = fiveFrameOrbit();
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
  }
  return pipeline.finish();
}

// A budget on the global BAs that a re-association round follows: each stops at it, and the
// last one runs to the global BA's own limits.
TEST(Pipeline, InterimGlobalBasStopAtTheirBudgetAndTheLastRunsOn) {
  PipelineOptions options;
  options.reassociation_rounds = 2;
  options.reassociation_interim_iterations = 2;
  const PipelineResult result = runFiveFrames(options);
  ASSERT_FALSE(result.reassociation.empty());
  std::vector<const ScheduleReport*> interim = {&result.global_ba};
  for (std::size_t r = 0; r + 1 < result.reassociation.size(); ++r) {
    interim.push_back(&result.reassociation[r].global_ba);
  }
  for (const ScheduleReport* ba : interim) {
    EXPECT_EQ(ba->total_iterations, 2) << ba->stop_reason;
    EXPECT_FALSE(ba->converged) << ba->stop_reason;
  }
  const ScheduleReport& last = result.reassociation.back().global_ba;
  EXPECT_GT(last.total_iterations, 2);
  EXPECT_TRUE(last.converged) << last.stop_reason;
}

// The five frames with one re-association round, the defaults changed by `change`.
PipelineResult runFiveFramesOneRound(const std::function<void(PipelineOptions*)>& change) {
  PipelineOptions options;
  options.reassociation_rounds = 1;
  change(&options);
  PipelineResult result = runFiveFrames(options);
  EXPECT_EQ(result.reassociation.size(), 1u);
  return result;
}

// Registration tries a keyframe's segments on several threads; the map takes them in the serial
// order, so the run does not depend on the thread count, re-association included.
TEST(Pipeline, RegistrationOnSeveralThreadsGivesTheSameRun) {
  const PipelineResult serial = runFiveFramesOneRound([](PipelineOptions*) {});
  const PipelineResult parallel =
      runFiveFramesOneRound([](PipelineOptions* o) { o->registration_threads = 3; });
  ASSERT_FALSE(serial.reassociation.empty());
  ASSERT_FALSE(parallel.reassociation.empty());
  EXPECT_GT(serial.reassociation[0].added_observations, 0);
  EXPECT_EQ(parallel.reassociation[0].added_observations,
            serial.reassociation[0].added_observations);
  ASSERT_EQ(parallel.curves.size(), serial.curves.size());
  for (std::size_t c = 0; c < serial.curves.size(); ++c) {
    EXPECT_EQ(parallel.curves[c].sample(4), serial.curves[c].sample(4)) << "curve " << c;
  }
  ASSERT_EQ(parallel.keyframe_cam_from_world.size(), serial.keyframe_cam_from_world.size());
  for (std::size_t k = 0; k < serial.keyframe_cam_from_world.size(); ++k) {
    EXPECT_EQ(parallel.keyframe_cam_from_world[k].translation(),
              serial.keyframe_cam_from_world[k].translation())
        << "keyframe " << k;
  }
}

// The global BA after the last re-association round weighs the edges with its own kernel width;
// the BAs before it keep --ba-kernel-width, so the runs agree until that solve.
TEST(Pipeline, TheLastGlobalBaTakesItsOwnKernelWidth) {
  const PipelineResult same =
      runFiveFramesOneRound([](PipelineOptions* o) { o->last_global_ba_kernel_width = 0.0; });
  const PipelineResult narrow =
      runFiveFramesOneRound([](PipelineOptions* o) { o->last_global_ba_kernel_width = 0.5; });
  ASSERT_FALSE(same.reassociation.empty());
  ASSERT_FALSE(narrow.reassociation.empty());
  EXPECT_EQ(narrow.global_ba.initial_cost, same.global_ba.initial_cost);
  EXPECT_EQ(narrow.global_ba.final_cost, same.global_ba.final_cost);
  // The same poses and curves, weighed by a narrower kernel: a lower cost.
  EXPECT_LT(narrow.reassociation[0].global_ba.initial_cost,
            same.reassociation[0].global_ba.initial_cost);
}

// The five frames of the small orbit with global BA and one re-association round, every length
// of the scene (true and initial poses) multiplied by `unit`: the same scene in metres
// (unit 1) or in millimetres (unit 1000).
PipelineResult runFiveFramesInUnit(double unit) {
  const PlanarScene scene = fiveFrameOrbit();
  PipelineOptions options;
  options.reassociation_rounds = 1;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    const Pose3& given = scene.initial_cam_from_world[i];
    pipeline.addFrame({scene.timestamps[i], scene.images[i],
                       Pose3(given.rotation(), given.translation() * unit)});
  }
  return pipeline.finish();
}

// Every threshold follows the scene scale (PipelineOptions::scene_scale), none assumes metres:
// the same start in millimetres refines to the same trajectory, 1000 times larger.
TEST(Pipeline, ReconstructsTheSameSceneInAnyUnit) {
  const PipelineResult metres = runFiveFramesInUnit(1.0);
  const PipelineResult millimetres = runFiveFramesInUnit(1000.0);
  ASSERT_EQ(metres.keyframe_cam_from_world.size(), 5u);
  ASSERT_EQ(millimetres.keyframe_cam_from_world.size(), 5u);
  EXPECT_GT(metres.curves.size(), 5u);
  EXPECT_EQ(millimetres.curves.size(), metres.curves.size());
  EXPECT_NEAR(millimetres.scene_scale / metres.scene_scale, 1000.0, 1e-9);
  // The refined poses must have moved, or equal results would prove nothing.
  double largest_move = 0.0;
  for (std::size_t j = 0; j < 5; ++j) {
    const Pose3& m = metres.keyframe_cam_from_world[j];
    const Pose3& mm = millimetres.keyframe_cam_from_world[j];
    largest_move =
        std::max(largest_move, cameraCentreDistance(m, metres.keyframe_initial_cam_from_world[j]));
    const Eigen::Vector3d centre_mm = mm.inverseTranslation() / 1000.0;
    EXPECT_LT((centre_mm - m.inverseTranslation()).norm(), 1e-6 * metres.scene_scale)
        << "keyframe " << j << ": centre " << m.inverseTranslation().transpose() << " m in metres, "
        << centre_mm.transpose() << " m from millimetres";
    EXPECT_LT(m.rotation().angularDistance(mm.rotation()), 1e-7) << "keyframe " << j;
  }
  EXPECT_GT(largest_move, 1e-2 * metres.scene_scale);
}

// The hybrid graph: plane points seen at their true projections (0.3 px noise), given 2 mm off,
// refined with the curves. The point factors must be minimised (the refined points fit their
// sightings at the refined poses to about the pixel noise, where the given ones at the start are
// pixels off), and the poses must end clearly closer to the truth than the drifting start and
// than with the curves alone. A better 3D point map is not expected: over five frames of a short
// arc the points' depth is no better determined than the 2 mm they are given with.
struct HybridRun {
  PipelineResult result;
  double start_ate = 0.0;
  double ate = 0.0;
  double given_reprojection_rms = 0.0;    ///< Given points at the initial poses (px).
  double refined_reprojection_rms = 0.0;  ///< Refined points at the refined poses (px).
};

using Sightings = std::vector<std::vector<PointSighting>>;  // Per frame.

double reprojectionRms(const Camera& camera, const std::vector<Pose3>& cam_from_world,
                       const std::vector<Eigen::Vector3d>& points, const Sightings& sightings) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t f = 0; f < sightings.size(); ++f) {
    for (const PointSighting& sighting : sightings[f]) {
      Eigen::Vector2d pixel;
      if (!camera.project(cam_from_world[f] * points[sighting.point], &pixel)) return 1e9;
      sum += (pixel - sighting.pixel).squaredNorm();
      ++count;
    }
  }
  return std::sqrt(sum / std::max(count, 1));
}

HybridRun runFiveFramesWithPoints(bool hybrid) {
  const PlanarScene scene = fiveFrameOrbit();
  std::mt19937 rng(5);
  std::normal_distribution<double> pixel_noise(0.0, 0.3), point_noise(0.0, 0.002);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 8; ++j) points.emplace_back(-0.2 + 0.045 * i, -0.15 + 0.043 * j, 0.0);
  }
  PipelineOptions options;
  options.reassociation_rounds = 0;
  options.ba.points = hybrid;
  Pipeline pipeline(*scene.camera, options);
  std::vector<Eigen::Vector3d> given;
  for (const Eigen::Vector3d& p : points) {
    given.push_back(p + Eigen::Vector3d(point_noise(rng), point_noise(rng), point_noise(rng)));
  }
  pipeline.setPoints(given);
  Sightings sightings(scene.images.size());
  for (std::size_t f = 0; f < scene.images.size(); ++f) {
    for (std::size_t p = 0; p < points.size(); ++p) {
      Eigen::Vector2d pixel;
      if (!scene.camera->project(scene.true_cam_from_world[f] * points[p], &pixel) ||
          !scene.camera->isInImage(pixel)) {
        continue;
      }
      sightings[f].push_back(
          {static_cast<int>(p), pixel + Eigen::Vector2d(pixel_noise(rng), pixel_noise(rng))});
    }
    pipeline.addFrame(
        {scene.timestamps[f], scene.images[f], scene.initial_cam_from_world[f], sightings[f]});
  }
  HybridRun run{pipeline.finish()};
  run.start_ate =
      evaluateTrajectory(scene.true_cam_from_world, scene.initial_cam_from_world).position_ate_sim3;
  run.ate = evaluateTrajectory(scene.true_cam_from_world, run.result.keyframe_cam_from_world)
                .position_ate_sim3;
  run.given_reprojection_rms =
      reprojectionRms(*scene.camera, scene.initial_cam_from_world, given, sightings);
  if (run.result.points.size() == points.size() &&
      run.result.keyframe_cam_from_world.size() == scene.images.size()) {
    run.refined_reprojection_rms = reprojectionRms(
        *scene.camera, run.result.keyframe_cam_from_world, run.result.points, sightings);
  }
  return run;
}

TEST(Pipeline, HybridGraphRefinesPointsBesideTheCurves) {
  const HybridRun curves = runFiveFramesWithPoints(false);
  const HybridRun hybrid = runFiveFramesWithPoints(true);
  ASSERT_EQ(hybrid.result.keyframe_cam_from_world.size(), 5u);
  EXPECT_TRUE(curves.result.points.empty());
  ASSERT_EQ(hybrid.result.points.size(), 80u);
  EXPECT_LT(hybrid.refined_reprojection_rms, 1.0);
  EXPECT_GT(hybrid.given_reprojection_rms, 3.0 * hybrid.refined_reprojection_rms);
  EXPECT_LT(hybrid.ate, 0.6 * hybrid.start_ate) << "curves alone " << curves.ate;
  // The points must not pull the poses away from where the curves alone take them. Which of
  // the two ends lower is not the claim: they differ by a few per cent here, and rounding in
  // the solver's dense kernels has flipped that order (0.390 against 0.386 mm).
  EXPECT_LT(hybrid.ate, 1.1 * curves.ate);
}

// The diagnosis of issue 14: curves lifted and registered at the true poses, the run's start the
// perturbed ones. The incremental stage reports the poses the frontend used; without global BA
// the result is the start, untouched.
TEST(Pipeline, FrontendPosesShapeTheMapNotTheStart) {
  const PlanarScene scene = fiveFrameOrbit();
  PipelineOptions options;
  options.run_global_ba = false;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    PipelineFrame frame{scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]};
    frame.frontend_cam_from_world = scene.true_cam_from_world[i];
    pipeline.addFrame(frame);
  }
  const PipelineResult result = pipeline.finish();
  ASSERT_EQ(result.keyframe_cam_from_world.size(), 5u);
  EXPECT_GT(result.curves.size(), 5u);
  const double spacing = scene.meanFrameBaseline();
  for (std::size_t j = 0; j < 5; ++j) {
    EXPECT_LT(cameraCentreDistance(result.pose_stages[0].keyframe_cam_from_world[j],
                                   scene.true_cam_from_world[j]),
              1e-9 * spacing)
        << "keyframe " << j;
    EXPECT_EQ(
        cameraCentreDistance(result.keyframe_cam_from_world[j], scene.initial_cam_from_world[j]),
        0.0)
        << "keyframe " << j;
  }
}

// One re-association round on the five frames of the small orbit.
ReassociationRound reassociationRound(bool skip_explained, bool skip_occluded) {
  const PlanarScene scene = fiveFrameOrbit();
  PipelineOptions options;
  options.reassociation_rounds = 1;
  options.reassociation_skip_explained = skip_explained;
  options.reassociation_skip_occluded = skip_occluded;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.initial_cam_from_world[i]});
  }
  const PipelineResult result = pipeline.finish();
  if (result.reassociation.empty()) return {-1, -1, {}};
  return result.reassociation[0];
}

// Without the check, re-association lets a curve take edges that another curve observed in that
// keyframe already explains (duplicates on a plane; a hidden curve on an occluder's edge in 3D).
// On a plane only a curve lifted well off it hides another, so the occlusion check leaves almost
// every segment to the checks (with the Cauchy kernel of session 17, 3 of 64 on this scene).
TEST(Pipeline, ReassociationLeavesExplainedEdgesToTheirCurvesAndOnAPlaneAlmostNothingIsHidden) {
  const ReassociationRound with_check = reassociationRound(true, false);
  const ReassociationRound without_check = reassociationRound(false, false);
  const ReassociationRound occlusion_check = reassociationRound(false, true);
  EXPECT_GE(with_check.added_observations, 0);
  EXPECT_LT(with_check.added_observations, without_check.added_observations);
  EXPECT_GT(with_check.left_to_other_curves, 0);
  EXPECT_EQ(without_check.left_to_other_curves, 0);
  // A curve lifted a tenth of its depth off the plane can hide another: a few, not many.
  EXPECT_LE(occlusion_check.left_to_other_curves, without_check.added_observations / 10);
  EXPECT_GE(occlusion_check.added_observations, 0.9 * without_check.added_observations);
}

// The small orbit started at its true poses, with or without an upright cylinder at the plane's
// centre painted over every view: its silhouettes are occluding contours, image edges whose 3D
// position slides over the cylinder as the camera moves, so no 3D curve explains them from every
// view, and each view shows another stretch of the texture beside them. Returns how far the
// refined poses drift from the truth (Sim(3) ATE, m).
double driftFromTruth(bool cylinder) {
  PlanarScene scene = makePlanarScene(planarTexture(), smallOrbit());
  if (cylinder) {
    for (std::size_t i = 0; i < scene.images.size(); ++i) {
      paintOccludingCylinder(OccludingCylinder(), *scene.camera, scene.true_cam_from_world[i],
                             &scene.images[i]);
    }
  }
  PipelineOptions options;
  options.map.min_keyframe_translation = 0.0;
  options.map.min_keyframe_rotation_deg = 0.0;
  Pipeline pipeline(*scene.camera, options);
  for (std::size_t i = 0; i < scene.images.size(); ++i) {
    pipeline.addFrame({scene.timestamps[i], scene.images[i], scene.true_cam_from_world[i]});
  }
  return evaluateTrajectory(scene.true_cam_from_world, pipeline.finish().keyframe_cam_from_world)
      .position_ate_sim3;
}

// Issue 14: an occluding contour must not pull the poses. Measured when written: 0.060 mm of
// drift without the cylinder, 0.009 mm with it; the cylinder's edges did not become curves at
// all (not even its top rim), so this guards the poses, not a mechanism that keeps silhouettes
// out. The tolerance adds 0.1 % of the frame spacing, far below the 1 % noise of the real bench.
TEST(Pipeline, OccludingContoursDoNotBiasThePoses) {
  const double plain = driftFromTruth(false);
  const double with_cylinder = driftFromTruth(true);
  const double spacing = makePlanarScene(planarTexture(), smallOrbit()).meanFrameBaseline();
  RecordProperty("drift_without_cylinder_m", std::to_string(plain));
  RecordProperty("drift_with_cylinder_m", std::to_string(with_cylinder));
  EXPECT_LT(with_cylinder, 2.0 * plain + 1e-3 * spacing) << "without the cylinder " << plain;
}

}  // namespace
}  // namespace curvesfm
