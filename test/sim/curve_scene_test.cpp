#include "sim/curve_scene.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/angles.h"
#include "core/errors.h"
#include "core/trajectory_evaluation.h"

namespace curvesfm {
namespace {

std::string validationMessage(const CurveSceneOptions& options) {
  try {
    options.validate();
  } catch (const InvalidOptions& e) {
    return e.what();
  }
  return "valid";
}

// Small scenes keep the suite fast; the default one is shared.
CurveSceneOptions smallOptions() {
  CurveSceneOptions options;
  options.num_keyframes = 4;
  options.num_curves = 5;
  return options;
}

const CurveScene& defaultScene() {
  static const CurveScene scene = makeCurveScene(CurveSceneOptions());
  return scene;
}

// Singular values of the centred samples: (extent along the curve, across it, out of plane).
Eigen::Vector3d spread(const PolyBezier& curve) {
  const std::vector<Eigen::Vector3d> samples = curve.sample(32);
  Eigen::MatrixX3d centred(samples.size(), 3);
  for (std::size_t k = 0; k < samples.size(); ++k) centred.row(k) = samples[k].transpose();
  centred.rowwise() -= centred.colwise().mean();
  return Eigen::JacobiSVD<Eigen::MatrixX3d>(centred).singularValues() /
         std::sqrt(static_cast<double>(samples.size()));
}

double curveLength(const PolyBezier& curve) {
  const std::vector<Eigen::Vector3d> samples = curve.sample(64);
  double length = 0.0;
  for (std::size_t k = 1; k < samples.size(); ++k) length += (samples[k] - samples[k - 1]).norm();
  return length;
}

bool sameMat(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

int edgePixelCount(const CurveScene& scene) {
  int count = 0;
  for (const CurveKeyframe& keyframe : scene.keyframes) count += cv::countNonZero(keyframe.edges);
  return count;
}

TEST(CurveSceneOptions, RejectionNamesFieldValueAndConstraint) {
  EXPECT_EQ(validationMessage(CurveSceneOptions()), "valid");
  CurveSceneOptions options;
  options.num_keyframes = 1;
  EXPECT_NE(validationMessage(options).find("CurveSceneOptions.num_keyframes = 1: must be >= 2"),
            std::string::npos)
      << validationMessage(options);
  options = CurveSceneOptions();
  options.max_curve_length = 0.25;
  EXPECT_NE(validationMessage(options).find("max_curve_length = 0.25"), std::string::npos);
  options = CurveSceneOptions();
  options.volume_half_extents.y() = 0.5;
  EXPECT_NE(validationMessage(options).find("max_curve_length = 1.5: must be <= 2 * the smallest"),
            std::string::npos)
      << validationMessage(options);
  options = CurveSceneOptions();
  options.canny_high_threshold = 50.0;
  EXPECT_NE(validationMessage(options).find("canny_high_threshold = 50"), std::string::npos);
  options = CurveSceneOptions();
  options.occlusion_fraction = 1.5;
  EXPECT_NE(validationMessage(options).find("occlusion_fraction = 1.5"), std::string::npos);
  options = CurveSceneOptions();
  options.edge_blur_sigma_px = 0.0;
  EXPECT_NE(validationMessage(options).find("edge_blur_sigma_px"), std::string::npos);
  options = CurveSceneOptions();
  options.edge_return_length_px = 0.5;
  EXPECT_NE(
      validationMessage(options).find("edge_return_length_px = 0.5: must be 0 or in [1, 200]"),
      std::string::npos)
      << validationMessage(options);
  options = CurveSceneOptions();
  options.curve_point_noise = -0.1;
  EXPECT_NE(validationMessage(options).find("curve_point_noise = -0.1"), std::string::npos);
  options = CurveSceneOptions();
  options.segments_per_curve = 0;
  EXPECT_NE(validationMessage(options).find("segments_per_curve = 0"), std::string::npos);
  options = CurveSceneOptions();
  options.intrinsics.fx = -1.0;
  EXPECT_NE(validationMessage(options).find("CameraIntrinsics.fx"), std::string::npos);
}

TEST(CurveScene, NoRoomForCurvesNamesTheDistance) {
  CurveSceneOptions options = smallOptions();
  options.min_camera_distance = 10.0;
  try {
    makeCurveScene(options);
    FAIL() << "expected InvalidOptions";
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("min_camera_distance = 10"), std::string::npos)
        << e.what();
  }
}

TEST(CurveScene, SameOptionsGiveBitIdenticalScenes) {
  CurveSceneOptions options = smallOptions();
  options.pixel_noise = 3.0;
  options.num_clutter_edges = 3;
  options.occlusion_fraction = 0.5;
  const CurveScene a = makeCurveScene(options);
  const CurveScene b = makeCurveScene(options);
  ASSERT_EQ(a.true_curves.size(), b.true_curves.size());
  for (std::size_t c = 0; c < a.true_curves.size(); ++c) {
    EXPECT_EQ(a.true_curves[c].points(), b.true_curves[c].points());
    EXPECT_EQ(a.initial_curves[c].points(), b.initial_curves[c].points());
  }
  for (std::size_t k = 0; k < a.keyframes.size(); ++k) {
    EXPECT_TRUE(sameMat(a.keyframes[k].image, b.keyframes[k].image)) << "keyframe " << k;
    EXPECT_TRUE(sameMat(a.keyframes[k].edges, b.keyframes[k].edges)) << "keyframe " << k;
    EXPECT_EQ(a.initial_cam_from_world[k].translation(), b.initial_cam_from_world[k].translation());
  }
  ASSERT_EQ(a.observations.size(), b.observations.size());
  for (std::size_t i = 0; i < a.observations.size(); ++i) {
    EXPECT_EQ(a.observations[i].curve_index, b.observations[i].curve_index);
    EXPECT_EQ(a.observations[i].hidden_fraction, b.observations[i].hidden_fraction);
  }
  options.seed += 1;
  const CurveScene c = makeCurveScene(options);
  EXPECT_NE(a.true_curves[0].points(), c.true_curves[0].points());
  EXPECT_FALSE(sameMat(a.keyframes[0].image, c.keyframes[0].image));
}

TEST(CurveScene, ImagesHaveTheDocumentedTypes) {
  const CurveScene& scene = defaultScene();
  ASSERT_EQ(scene.keyframes.size(), 12u);
  for (const CurveKeyframe& keyframe : scene.keyframes) {
    EXPECT_EQ(keyframe.image.type(), CV_8UC1);
    EXPECT_EQ(keyframe.edges.type(), CV_8UC1);
    EXPECT_EQ(keyframe.grad_x.type(), CV_16SC1);
    EXPECT_EQ(keyframe.grad_y.type(), CV_16SC1);
    EXPECT_EQ(keyframe.image.cols, 640);
    EXPECT_EQ(keyframe.image.rows, 480);
    double max_edge = 0.0;
    cv::minMaxLoc(keyframe.edges, nullptr, &max_edge);
    EXPECT_EQ(max_edge, 255.0);
  }
}

TEST(CurveScene, CurvesAreInsideTheVolumeFarFromCamerasAndOfTheRequestedLength) {
  const CurveSceneOptions options;
  const CurveScene& scene = defaultScene();
  ASSERT_EQ(scene.true_curves.size(), 12u);
  for (std::size_t c = 0; c < scene.true_curves.size(); ++c) {
    const PolyBezier& curve = scene.true_curves[c];
    EXPECT_EQ(curve.numSegments(), options.segments_per_curve);
    for (const Eigen::Vector3d& point : curve.sample(32)) {
      EXPECT_LE((point.cwiseAbs() - options.volume_half_extents).maxCoeff(), 0.0) << "curve " << c;
      for (const Pose3& pose : scene.true_cam_from_world) {
        EXPECT_GE((point - pose.inverseTranslation()).norm(), options.min_camera_distance);
      }
    }
    // The fit follows the constant-speed shape, so the length is close to the drawn one.
    const double length = curveLength(curve);
    EXPECT_GT(length, 0.95 * options.min_curve_length) << "curve " << c;
    EXPECT_LT(length, 1.05 * options.max_curve_length) << "curve " << c;
  }
  // A mix of kinds.
  EXPECT_GT(std::count(scene.curve_kinds.begin(), scene.curve_kinds.end(), CurveKind::kLine), 0);
  EXPECT_GT(std::count(scene.curve_kinds.begin(), scene.curve_kinds.end(), CurveKind::kHelix), 0);
}

TEST(CurveScene, EachKindHasItsShape) {
  CurveSceneOptions options = smallOptions();
  options.curve_kind = CurveKind::kLine;
  for (const PolyBezier& curve : makeCurveScene(options).true_curves) {
    const Eigen::Vector3d s = spread(curve);
    EXPECT_LT(s[1], 1e-9 * s[0]);  // Collinear.
  }
  options.curve_kind = CurveKind::kArc;
  for (const PolyBezier& curve : makeCurveScene(options).true_curves) {
    const Eigen::Vector3d s = spread(curve);
    EXPECT_GT(s[1], 0.05 * s[0]);  // Curved...
    EXPECT_LT(s[2], 1e-9 * s[0]);  // ...in a plane.
  }
  options.curve_kind = CurveKind::kHelix;
  for (const PolyBezier& curve : makeCurveScene(options).true_curves) {
    const Eigen::Vector3d s = spread(curve);
    EXPECT_GT(s[2], 0.05 * s[0]);  // Not planar.
  }
}

TEST(CurveScene, CannyEdgesLieOnTheProjectedCurves) {
  const CurveScene& scene = defaultScene();
  for (int k = 0; k < static_cast<int>(scene.keyframes.size()); ++k) {
    const EdgeAgreement agreement = measureEdgeAgreement(scene, k);
    EXPECT_GT(agreement.num_curve_samples, 500) << "keyframe " << k;
    // About 0.2 px is the rounding to pixel centres; a 0.8 px shift of the drawing gives 0.5.
    EXPECT_LT(agreement.mean_curve_to_edge_px, 0.35) << "keyframe " << k;
    EXPECT_GT(agreement.curve_samples_on_edges, 0.9) << "keyframe " << k;
    EXPECT_GT(agreement.edge_pixels_near_curves, 0.95) << "keyframe " << k;
  }
}

TEST(CurveScene, GradientsAreNormalToTheProjectedCurves) {
  const CurveScene& scene = defaultScene();
  const Camera& camera = *scene.camera;
  int checked = 0;
  int normal = 0;
  for (const CurveObservation& observation : scene.observations) {
    const CurveKeyframe& keyframe = scene.keyframes[observation.keyframe_index];
    const Pose3& pose = scene.true_cam_from_world[observation.keyframe_index];
    const PolyBezier& curve = scene.true_curves[observation.curve_index];
    for (double t = 0.2; t < 0.85; t += 0.3) {
      const Eigen::Vector3d point = curve.evaluate(observation.segment_index, t);
      const Eigen::Vector3d step = 1e-4 * curve.derivative(observation.segment_index, t);
      Eigen::Vector2d pixel, ahead;
      if (!camera.project(pose * point, &pixel) || !camera.project(pose * (point + step), &ahead) ||
          !camera.isInImage(pixel, 2.0)) {
        continue;
      }
      const int column = static_cast<int>(std::lround(pixel.x()));
      const int row = static_cast<int>(std::lround(pixel.y()));
      const Eigen::Vector2d gradient(keyframe.grad_x.at<short>(row, column),
                                     keyframe.grad_y.at<short>(row, column));
      ++checked;
      const double cosine = std::abs(gradient.normalized().dot((ahead - pixel).normalized()));
      normal += cosine < std::sin(10.0 / kRadToDeg) ? 1 : 0;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(normal, 0.9 * checked);
}

TEST(CurveScene, ClutterAddsEdgesAwayFromCurves) {
  CurveSceneOptions options = smallOptions();
  const CurveScene clean = makeCurveScene(options);
  options.num_clutter_edges = 10;
  const CurveScene cluttered = makeCurveScene(options);
  EXPECT_GT(edgePixelCount(cluttered), edgePixelCount(clean) + 4 * 10 * 40);
  for (int k = 0; k < options.num_keyframes; ++k) {
    const EdgeAgreement before = measureEdgeAgreement(clean, k);
    const EdgeAgreement after = measureEdgeAgreement(cluttered, k);
    EXPECT_GT(before.edge_pixels_near_curves, 0.95) << "keyframe " << k;
    EXPECT_LT(after.edge_pixels_near_curves, before.edge_pixels_near_curves - 0.1)
        << "keyframe " << k;
  }
}

TEST(CurveScene, OcclusionHidesEdgesButKeepsObservations) {
  CurveSceneOptions options = smallOptions();
  const CurveScene clean = makeCurveScene(options);
  options.occlusion_fraction = 1.0;
  const CurveScene occluded = makeCurveScene(options);
  ASSERT_EQ(clean.observations.size(), occluded.observations.size());
  int partly_hidden = 0;
  for (std::size_t i = 0; i < clean.observations.size(); ++i) {
    EXPECT_EQ(clean.observations[i].curve_index, occluded.observations[i].curve_index);
    EXPECT_EQ(clean.observations[i].segment_index, occluded.observations[i].segment_index);
    EXPECT_FALSE(clean.observations[i].partlyHidden());
    partly_hidden += occluded.observations[i].partlyHidden() ? 1 : 0;
  }
  EXPECT_GT(partly_hidden, 0);
  EXPECT_LT(partly_hidden, static_cast<int>(occluded.observations.size()));

  // In the hidden parts (away from their boundary), the edges are gone.
  const Camera& camera = *clean.camera;
  int samples = 0;
  int on_edge_clean = 0;
  int on_edge_occluded = 0;
  for (std::size_t k = 0; k < occluded.keyframes.size(); ++k) {
    EXPECT_FALSE(occluded.keyframes[k].hidden_parts.empty());
    for (const HiddenCurvePart& hidden : occluded.keyframes[k].hidden_parts) {
      const PolyBezier& curve = occluded.true_curves[hidden.curve_index];
      EXPECT_GE(hidden.end - hidden.begin, 0.3 * curve.numSegments() - 1e-12);
      EXPECT_LE(hidden.end - hidden.begin, 0.5 * curve.numSegments() + 1e-12);
      for (double g = hidden.begin + 0.1; g < hidden.end - 0.1; g += 0.02) {
        const int segment = std::min(static_cast<int>(g), curve.numSegments() - 1);
        Eigen::Vector2d pixel;
        if (!camera.project(occluded.true_cam_from_world[k] * curve.evaluate(segment, g - segment),
                            &pixel) ||
            !camera.isInImage(pixel, 2.0)) {
          continue;
        }
        const int column = static_cast<int>(std::lround(pixel.x()));
        const int row = static_cast<int>(std::lround(pixel.y()));
        const cv::Rect window(column - 1, row - 1, 3, 3);
        ++samples;
        on_edge_clean += cv::countNonZero(clean.keyframes[k].edges(window)) > 0 ? 1 : 0;
        on_edge_occluded += cv::countNonZero(occluded.keyframes[k].edges(window)) > 0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(samples, 100);
  EXPECT_GT(on_edge_clean, 0.9 * samples);
  EXPECT_LT(on_edge_occluded, 0.1 * samples);
}

TEST(CurveScene, StartingGuessKeepsTheGaugeAndIsPerturbedAtTheRequestedLevel) {
  const CurveSceneOptions options;
  const CurveScene& scene = defaultScene();
  EXPECT_EQ(scene.initial_cam_from_world[0].rotation().coeffs(),
            scene.true_cam_from_world[0].rotation().coeffs());
  EXPECT_EQ(scene.initial_cam_from_world[0].translation(),
            scene.true_cam_from_world[0].translation());
  const double initial_distance = (scene.initial_cam_from_world[1].inverseTranslation() -
                                   scene.initial_cam_from_world[0].inverseTranslation())
                                      .norm();
  EXPECT_NEAR(initial_distance, scene.trueScaleDistance(), 1e-12);

  // Per-axis noise sigma: |error| averages about 1.6 sigma in 3D and 1.25 sigma in 2D.
  double centre_error = 0.0;
  for (std::size_t k = 2; k < scene.true_cam_from_world.size(); ++k) {
    centre_error += (scene.initial_cam_from_world[k].inverseTranslation() -
                     scene.true_cam_from_world[k].inverseTranslation())
                        .norm();
  }
  centre_error /= scene.true_cam_from_world.size() - 2;
  EXPECT_GT(centre_error, 0.8 * options.pose_noise_translation);
  EXPECT_LT(centre_error, 2.5 * options.pose_noise_translation);

  double point_error = 0.0, tangent_error = 0.0, length_error = 0.0;
  int points = 0, lengths = 0;
  for (std::size_t c = 0; c < scene.true_curves.size(); ++c) {
    const PolyBezier& truth = scene.true_curves[c];
    const PolyBezier& start = scene.initial_curves[c];
    ASSERT_EQ(start.numSegments(), truth.numSegments());
    for (int i = 0; i < truth.numPoints(); ++i, ++points) {
      point_error += (start.points()[i] - truth.points()[i]).norm();
      tangent_error += start.directions()[i].angleTo(truth.directions()[i]) * kRadToDeg;
    }
    for (int i = 0; i < truth.numSegments(); ++i, lengths += 2) {
      length_error += std::abs(std::log(start.lengths()[i].d1 / truth.lengths()[i].d1)) +
                      std::abs(std::log(start.lengths()[i].d2 / truth.lengths()[i].d2));
    }
  }
  EXPECT_GT(point_error / points, 0.8 * options.curve_point_noise);
  EXPECT_LT(point_error / points, 2.5 * options.curve_point_noise);
  EXPECT_GT(tangent_error / points, 0.6 * options.curve_tangent_noise_deg);
  EXPECT_LT(tangent_error / points, 2.0 * options.curve_tangent_noise_deg);
  EXPECT_GT(length_error / lengths, 0.4 * options.curve_length_noise);  // E|N(0,1)| = 0.8.
  EXPECT_LT(length_error / lengths, 1.5 * options.curve_length_noise);
}

TEST(CurveScene, EvaluateIsZeroForTheTruthAndMeasuresTheStart) {
  const CurveSceneOptions options;
  const CurveScene& scene = defaultScene();
  const CurveSceneErrors truth =
      evaluateCurveScene(scene, scene.true_cam_from_world, scene.true_curves);
  EXPECT_LT(truth.position_rmse, 1e-12);
  EXPECT_LT(truth.position_ate_sim3, 1e-9);
  EXPECT_LT(truth.rotation_mean_deg, 1e-6);
  EXPECT_EQ(truth.curve_mean_error, 0.0);
  EXPECT_EQ(truth.curve_max_error, 0.0);
  EXPECT_LT(truth.curve_mean_error_aligned, 1e-9);

  const CurveSceneErrors start =
      evaluateCurveScene(scene, scene.initial_cam_from_world, scene.initial_curves);
  EXPECT_GT(start.position_rmse, 0.8 * options.pose_noise_translation);
  EXPECT_LT(start.position_rmse, 3.0 * options.pose_noise_translation);
  EXPECT_LT(start.position_ate_sim3, start.position_rmse);
  EXPECT_GT(start.rotation_mean_deg, 0.8 * options.pose_noise_rotation_deg);
  EXPECT_LT(start.rotation_mean_deg, 2.5 * options.pose_noise_rotation_deg);
  EXPECT_GT(start.curve_mean_error, 0.5 * options.curve_point_noise);
  EXPECT_LT(start.curve_mean_error, 2.0 * options.curve_point_noise);
  EXPECT_GE(start.curve_max_error, start.curve_mean_error);
  EXPECT_GT(start.curve_mean_error_aligned, 0.3 * options.curve_point_noise);

  EXPECT_THROW(evaluateCurveScene(scene, scene.true_cam_from_world, {}), CheckError);
}

TEST(CurveScene, AlignedCurveErrorIgnoresAGlobalSimilarity) {
  const CurveScene& scene = defaultScene();
  Sim3 moved;
  moved.scale = 1.3;
  moved.rotation = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  moved.translation = Eigen::Vector3d(0.5, -0.2, 1.0);
  std::vector<Pose3> poses;
  for (const Pose3& pose : scene.true_cam_from_world) {
    const Pose3 world_from_cam = pose.inverse();
    poses.push_back(Pose3(Eigen::Matrix3d(moved.rotation * world_from_cam.rotationMatrix()),
                          moved * world_from_cam.translation())
                        .inverse());
  }
  std::vector<PolyBezier> curves;
  for (const PolyBezier& curve : scene.true_curves) {
    std::vector<Eigen::Vector3d> points;
    std::vector<Direction> directions;
    std::vector<SegmentLengths> lengths;
    for (int i = 0; i < curve.numPoints(); ++i) {
      points.push_back(moved * curve.points()[i]);
      directions.emplace_back(moved.rotation * curve.directions()[i].vector());
    }
    for (const SegmentLengths& l : curve.lengths()) {
      lengths.push_back({moved.scale * l.d1, moved.scale * l.d2});
    }
    curves.emplace_back(points, directions, lengths);
  }
  const CurveSceneErrors errors = evaluateCurveScene(scene, poses, curves);
  EXPECT_GT(errors.curve_mean_error, 0.1);
  EXPECT_LT(errors.curve_mean_error_aligned, 1e-9);
  EXPECT_LT(errors.position_ate_sim3, 1e-9);
}

TEST(TrajectoryErrors, FrameAlignmentIsDeterminedOnAStraightWalk) {
  CurveSceneOptions options = smallOptions();
  options.camera_path = CameraPath::kForwardWalk;
  const CurveScene scene = makeCurveScene(options);
  // Rotate the whole trajectory about the walk direction: the centres barely notice.
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<Pose3> rolled;
  for (const Pose3& pose : scene.true_cam_from_world) {
    const Pose3 world_from_cam = pose.inverse();
    rolled.push_back(Pose3(Eigen::Matrix3d(roll * world_from_cam.rotationMatrix()),
                           roll * world_from_cam.translation())
                         .inverse());
  }
  const Sim3 frames = alignCameraFrames(scene.true_cam_from_world, rolled, 1.0);
  EXPECT_NEAR(frames.scale, 1.0, 1e-9);
  EXPECT_LT((frames.rotation - roll.transpose()).norm(), 1e-9);
  EXPECT_THROW(alignCameraCentres(scene.true_cam_from_world, {}), CheckError);
}

TEST(CurveScene, BothCameraPathsSeeMostCurves) {
  for (const CameraPath path : {CameraPath::kOrbit, CameraPath::kForwardWalk}) {
    CurveSceneOptions options;
    options.camera_path = path;
    const CurveScene scene = makeCurveScene(options);
    const int num_segments = options.num_curves * options.segments_per_curve;
    std::vector<int> per_keyframe(options.num_keyframes, 0);
    std::vector<int> per_segment(num_segments, 0);
    for (const CurveObservation& observation : scene.observations) {
      ++per_keyframe[observation.keyframe_index];
      ++per_segment[observation.curve_index * options.segments_per_curve +
                    observation.segment_index];
    }
    for (int k = 0; k < options.num_keyframes; ++k) {
      EXPECT_GE(per_keyframe[k], 0.6 * num_segments)
          << "path " << static_cast<int>(path) << " keyframe " << k;
    }
    const int well_seen =
        static_cast<int>(std::count_if(per_segment.begin(), per_segment.end(), [&](int count) {
          return count >= options.num_keyframes / 2;
        }));
    EXPECT_GE(well_seen, 0.8 * num_segments) << "path " << static_cast<int>(path);
  }
}

TEST(CurveScene, SidewaysWalkSeesEachCurveOverAStretchOfIt) {
  CurveSceneOptions options;
  options.camera_path = CameraPath::kSidewaysWalk;
  options.num_keyframes = 60;
  options.walk_length = 30.0;  // 0.5 m between keyframes.
  options.volume_half_extents = Eigen::Vector3d(14.0, 1.5, 1.0);
  options.num_curves = 40;
  const CurveScene scene = makeCurveScene(options);
  // On the line z = -camera_distance, from x = -15 to 15, looking across it (+z).
  const Pose3& first = scene.true_cam_from_world.front();
  const Pose3& last = scene.true_cam_from_world.back();
  EXPECT_NEAR(first.inverseTranslation().x(), -15.0, 1e-9);
  EXPECT_NEAR(last.inverseTranslation().x(), 15.0, 1e-9);
  EXPECT_NEAR(first.inverseTranslation().z(), -3.0, 0.11);
  EXPECT_GT((first.rotation().conjugate() * Eigen::Vector3d::UnitZ()).z(), 0.99);
  // A 640 px image at fx 500 spans about 4 m at the curves' 2-4 m depth: nearly every curve is
  // seen (a long one at 2 m may never fit), each from a bounded stretch of the 60 keyframes,
  // and nearly every keyframe sees some (the ends of the line look past the volume's ends).
  std::vector<std::vector<int>> keyframes_of_curve(options.num_curves);
  std::vector<int> per_keyframe(options.num_keyframes, 0);
  for (const CurveObservation& observation : scene.observations) {
    keyframes_of_curve[observation.curve_index].push_back(observation.keyframe_index);
    ++per_keyframe[observation.keyframe_index];
  }
  int seen = 0;
  for (int c = 0; c < options.num_curves; ++c) {
    if (keyframes_of_curve[c].empty()) continue;
    ++seen;
    const auto [low, high] =
        std::minmax_element(keyframes_of_curve[c].begin(), keyframes_of_curve[c].end());
    EXPECT_LT(*high - *low, 20) << "curve " << c;
  }
  EXPECT_GE(seen, 0.9 * options.num_curves);
  const auto seeing =
      std::count_if(per_keyframe.begin(), per_keyframe.end(), [](int count) { return count > 0; });
  EXPECT_GE(seeing, 0.9 * options.num_keyframes);
}

TEST(CurveScene, NoiseKeepsTheEdgesOnTheCurves) {
  CurveSceneOptions options = smallOptions();
  options.pixel_noise = 4.0;
  const CurveScene scene = makeCurveScene(options);
  for (int k = 0; k < options.num_keyframes; ++k) {
    const EdgeAgreement agreement = measureEdgeAgreement(scene, k);
    EXPECT_LT(agreement.mean_curve_to_edge_px, 1.0) << "keyframe " << k;
    EXPECT_GT(agreement.edge_pixels_near_curves, 0.8) << "keyframe " << k;
  }
}

TEST(CurveSceneOptions, EnumNamesRoundTripAndUnknownNamesAreRejected) {
  for (const CameraPath path : {CameraPath::kOrbit, CameraPath::kForwardWalk}) {
    EXPECT_EQ(parseEnumName<CameraPath>(toString(path), "CurveSceneOptions", "camera_path"), path);
  }
  for (const CurveKind kind :
       {CurveKind::kLine, CurveKind::kArc, CurveKind::kHelix, CurveKind::kMixed}) {
    EXPECT_EQ(parseEnumName<CurveKind>(toString(kind), "CurveSceneOptions", "curve_kind"), kind);
  }
  try {
    parseEnumName<CurveKind>("spiral", "CurveSceneOptions", "curve_kind");
    FAIL() << "no exception";
  } catch (const InvalidOptions& e) {
    EXPECT_NE(std::string(e.what()).find("CurveSceneOptions.curve_kind"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("line, arc, helix, mixed"), std::string::npos);
  }
  EXPECT_THROW(parseEnumName<CameraPath>("orbits", "CurveSceneOptions", "camera_path"),
               InvalidOptions);
}

}  // namespace
}  // namespace curvesfm
