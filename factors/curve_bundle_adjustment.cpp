#include "factors/curve_bundle_adjustment.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/check.h"
#include "core/errors.h"
#include "factors/point_reprojection_factor.h"
#include "factors/pose_prior_factor.h"
#include "factors/relative_pose_factor.h"
#include "factors/segment_length_factor.h"
#include "factors/tangent_alignment_factor.h"

namespace curvesfm {
namespace {

void insertCurve(std::uint32_t c, const PolyBezier& curve, Values* values) {
  for (int i = 0; i < curve.numPoints(); ++i) {
    values->insert(curvePointKey(c, i), curve.points()[i]);
    values->insert(directionKey(c, i), curve.directions()[i]);
  }
  for (int i = 0; i < curve.numSegments(); ++i) {
    values->insert(startLengthKey(c, i), curve.lengths()[i].d1);
    values->insert(endLengthKey(c, i), curve.lengths()[i].d2);
  }
}

// `reference_lengths`: E_s1's chord per segment, or empty for the chords of `curve`.
void addRegularisers(std::uint32_t c, const PolyBezier& curve,
                     const std::vector<double>& reference_lengths,
                     const CurveBundleAdjustmentOptions& options, FactorGraph* graph) {
  const bool relative = options.length_sigma_rel > 0.0;
  for (int i = 0; i < curve.numSegments(); ++i) {
    const SegmentKeys keys = segmentKeys(c, i);
    const double length = reference_lengths.empty()
                              ? (curve.points()[i + 1] - curve.points()[i]).norm()
                              : reference_lengths[i];
    if (relative && length > 0.0) {
      graph->emplace<SegmentLengthFactor>(keys.q0, keys.q1, length,
                                          NoiseModel{options.length_sigma_rel * length, {}});
    } else if (!relative && options.lambda1 > 0.0) {
      graph->emplace<SegmentLengthFactor>(keys.q0, keys.q1, length,
                                          NoiseModel{1.0 / std::sqrt(options.lambda1), {}});
    }
    if (options.lambda2 > 0.0) {
      graph->emplace<TangentAlignmentFactor>(keys.q0, keys.q1, keys.v0, keys.v1,
                                             NoiseModel{1.0 / std::sqrt(options.lambda2), {}});
    }
  }
}

void checkFields(const CurveBundleAdjustmentInput& input) {
  CURVESFM_CHECK(input.fields.size() == input.cam_from_world.size())
      << "curve bundle adjustment: " << input.fields.size() << " edge fields for "
      << input.cam_from_world.size() << " keyframes";
  const CameraIntrinsics& intrinsics = input.camera->intrinsics();
  for (std::size_t j = 0; j < input.fields.size(); ++j) {
    CURVESFM_CHECK(input.fields[j] != nullptr) << "keyframe " << j << " has no edge field";
    CURVESFM_CHECK(input.fields[j]->width() == intrinsics.width &&
                   input.fields[j]->height() == intrinsics.height)
        << "keyframe " << j << ": edge field " << input.fields[j]->width() << "x"
        << input.fields[j]->height() << " but camera " << intrinsics.width << "x"
        << intrinsics.height;
  }
}

void addPoints(const CurveBundleAdjustmentInput& input, const CurveBundleAdjustmentOptions& options,
               CurveBundleAdjustmentProblem* problem) {
  for (std::size_t p = 0; p < input.points.size(); ++p) {
    problem->values.insert(pointKey(p), input.points[p]);
  }
  const RobustKernel kernel(options.point_kernel, options.point_kernel_width);
  const NoiseModel noise{options.point_pixel_sigma, kernel};
  const double keypoint_sigma =
      options.keypoint_pixel_sigma > 0.0 ? options.keypoint_pixel_sigma : options.point_pixel_sigma;
  const auto keypoint_noise = [&](double size) {
    const double relative = options.keypoint_reference_size > 0.0
                                ? std::max(1.0, size / options.keypoint_reference_size)
                                : 1.0;
    return NoiseModel{keypoint_sigma * relative, kernel};
  };
  const int num_keyframes = static_cast<int>(input.cam_from_world.size());
  const int num_points = static_cast<int>(input.points.size());
  for (const PointObservation& obs : input.point_observations) {
    CURVESFM_CHECK(obs.camera_index >= 0 && obs.camera_index < num_keyframes &&
                   obs.point_index >= 0 && obs.point_index < num_points)
        << "observation of point " << obs.point_index << " in keyframe " << obs.camera_index
        << " is out of range (" << num_points << " points, " << num_keyframes << " keyframes)";
    problem->graph.emplace<PointReprojectionFactor>(
        poseKey(obs.camera_index), pointKey(obs.point_index), obs.pixel, input.camera,
        obs.keypoint ? keypoint_noise(obs.keypoint_size) : noise);
  }
}

// The length unit of the priors' translation sigmas: the prior trajectory's mean step. One that
// never moves still gets a usable sigma: it pins the translations at zero.
double priorStep(const std::vector<Pose3>& prior_cam_from_world) {
  return std::max(meanCameraStep(prior_cam_from_world), 1e-12);
}

void addMotionPrior(const std::vector<Pose3>& prior_cam_from_world,
                    const CurveBundleAdjustmentOptions& options, FactorGraph* graph) {
  if (prior_cam_from_world.size() < 2) return;
  const double rotation_sigma = options.motion_prior_rotation_sigma_deg * M_PI / 180.0;
  const double translation_sigma =
      options.motion_prior_translation_sigma_rel * priorStep(prior_cam_from_world);
  for (std::size_t j = 1; j < prior_cam_from_world.size(); ++j) {
    const Pose3 cam_j_from_cam_i = prior_cam_from_world[j] * prior_cam_from_world[j - 1].inverse();
    graph->emplace<RelativePoseFactor>(poseKey(j - 1), poseKey(j), cam_j_from_cam_i, rotation_sigma,
                                       translation_sigma);
  }
}

void addStartPrior(const std::vector<Pose3>& prior_cam_from_world,
                   const CurveBundleAdjustmentOptions& options, FactorGraph* graph) {
  const double rotation_sigma = options.start_prior_rotation_sigma_deg * M_PI / 180.0;
  const double centre_sigma =
      options.start_prior_centre_sigma_rel * priorStep(prior_cam_from_world);
  for (std::size_t j = 0; j < prior_cam_from_world.size(); ++j) {
    graph->emplace<CameraPriorFactor>(poseKey(static_cast<int>(j)), prior_cam_from_world[j],
                                      rotation_sigma, centre_sigma);
  }
}

}  // namespace

void CurveBundleAdjustmentOptions::validate() const {
  const OptionCheck require("CurveBundleAdjustmentOptions");
  require(samples_per_segment >= 1 && samples_per_segment < CurveReprojectionFactor::kMaxSamples,
          "samples_per_segment", samples_per_segment,
          "must be in [1, " + std::to_string(CurveReprojectionFactor::kMaxSamples - 1) + "]");
  require(max_normal_angle_deg > 0.0 && max_normal_angle_deg <= 90.0, "max_normal_angle_deg",
          max_normal_angle_deg, "must be in (0, 90]");
  require.nonNegative("interpolate_max_line_offset_px", interpolate_max_line_offset_px);
  require.nonNegative("border_margin_px", border_margin_px);
  require(interpolate_max_normal_angle_deg >= 0.0 && interpolate_max_normal_angle_deg <= 90.0,
          "interpolate_max_normal_angle_deg", interpolate_max_normal_angle_deg,
          "must be in [0, 90]");
  require.positive("pixel_sigma", pixel_sigma);
  require.positive("kernel_width", kernel_width);
  require.nonNegative("lambda1", lambda1);
  require.nonNegative("length_sigma_rel", length_sigma_rel);
  require.nonNegative("lambda2", lambda2);
  require.positive("scale_sigma", scale_sigma);
  require.positive("motion_prior_rotation_sigma_deg", motion_prior_rotation_sigma_deg);
  require.positive("motion_prior_translation_sigma_rel", motion_prior_translation_sigma_rel);
  require.positive("start_prior_rotation_sigma_deg", start_prior_rotation_sigma_deg);
  require.positive("start_prior_centre_sigma_rel", start_prior_centre_sigma_rel);
  require.positive("point_pixel_sigma", point_pixel_sigma);
  require.nonNegative("keypoint_pixel_sigma", keypoint_pixel_sigma);
  require.nonNegative("keypoint_reference_size", keypoint_reference_size);
  require.positive("point_kernel_width", point_kernel_width);
}

CurveBundleAdjustmentProblem buildCurveBundleAdjustment(
    const CurveBundleAdjustmentInput& input, const CurveBundleAdjustmentOptions& options) {
  options.validate();
  CURVESFM_CHECK(input.camera != nullptr) << "curve bundle adjustment needs a camera";
  checkFields(input);
  CurveBundleAdjustmentProblem problem;
  const int num_keyframes = static_cast<int>(input.cam_from_world.size());
  for (int j = 0; j < num_keyframes; ++j)
    problem.values.insert(poseKey(j), input.cam_from_world[j]);
  const bool given_lengths =
      options.length_from_creation && !input.segment_reference_lengths.empty();
  CURVESFM_CHECK(!given_lengths || input.segment_reference_lengths.size() == input.curves.size())
      << "curve bundle adjustment: reference lengths for " << input.segment_reference_lengths.size()
      << " curves, " << input.curves.size() << " curves";
  for (std::size_t c = 0; c < input.curves.size(); ++c) {
    static const std::vector<double> kCurrentChords;
    const std::vector<double>& lengths =
        given_lengths ? input.segment_reference_lengths[c] : kCurrentChords;
    CURVESFM_CHECK(!given_lengths ||
                   static_cast<int>(lengths.size()) == input.curves[c].numSegments())
        << "curve bundle adjustment: curve " << c << " has " << input.curves[c].numSegments()
        << " segments and " << lengths.size() << " reference lengths";
    insertCurve(static_cast<std::uint32_t>(c), input.curves[c], &problem.values);
    addRegularisers(static_cast<std::uint32_t>(c), input.curves[c], lengths, options,
                    &problem.graph);
  }

  const EdgeBlending blending{options.interpolate_edges, options.interpolate_max_line_offset_px,
                              options.interpolate_max_normal_angle_deg};
  const auto sampling = std::make_shared<const CurveSampling>(
      options.samples_per_segment + 1, options.use_subpixel_edges, options.max_normal_angle_deg,
      blending, options.border_margin_px);
  const NoiseModel pixel_noise{options.pixel_sigma,
                               RobustKernel(options.kernel, options.kernel_width)};
  const int num_curves = static_cast<int>(input.curves.size());
  for (const SegmentObservation& obs : input.observations) {
    CURVESFM_CHECK(obs.keyframe >= 0 && obs.keyframe < num_keyframes && obs.curve >= 0 &&
                   obs.curve < num_curves && obs.segment >= 0 &&
                   obs.segment < input.curves[obs.curve].numSegments())
        << "observation of segment " << obs.segment << " of curve " << obs.curve << " in keyframe "
        << obs.keyframe << " is out of range (" << num_curves << " curves, " << num_keyframes
        << " keyframes)";
    problem.graph.emplace<CurveReprojectionFactor>(
        poseKey(obs.keyframe), segmentKeys(obs.curve, obs.segment), input.fields[obs.keyframe],
        input.camera, sampling, pixel_noise);
  }

  if (options.points) addPoints(input, options, &problem);
  if (options.fix_first_pose && num_keyframes > 0) problem.config.setConstant(poseKey(0));
  if (options.fix_scale) {
    addScaleGauge(input.cam_from_world, input.scale_distance, options.scale_sigma, &problem.graph);
  }
  const std::vector<Pose3>& prior = input.motion_prior_cam_from_world;
  if ((options.motion_prior || options.start_prior) && !prior.empty()) {
    CURVESFM_CHECK(prior.size() == input.cam_from_world.size())
        << "curve bundle adjustment: " << prior.size() << " prior poses for " << num_keyframes
        << " keyframes";
    if (options.motion_prior) addMotionPrior(prior, options, &problem.graph);
    if (options.start_prior) addStartPrior(prior, options, &problem.graph);
  }
  return problem;
}

std::vector<PolyBezier> extractCurves(const Values& values, const std::vector<PolyBezier>& layout) {
  constexpr double kMinLength = 1e-9;
  std::vector<PolyBezier> curves;
  curves.reserve(layout.size());
  for (std::size_t c = 0; c < layout.size(); ++c) {
    const auto curve = static_cast<std::uint32_t>(c);
    std::vector<Eigen::Vector3d> points;
    std::vector<Direction> directions;
    std::vector<SegmentLengths> lengths;
    for (int i = 0; i < layout[c].numPoints(); ++i) {
      points.push_back(values.at<Eigen::Vector3d>(curvePointKey(curve, i)));
      directions.push_back(values.at<Direction>(directionKey(curve, i)));
    }
    for (int i = 0; i < layout[c].numSegments(); ++i) {
      lengths.push_back({std::max(kMinLength, values.at<double>(startLengthKey(curve, i))),
                         std::max(kMinLength, values.at<double>(endLengthKey(curve, i)))});
    }
    curves.emplace_back(std::move(points), std::move(directions), std::move(lengths));
  }
  return curves;
}

CurveSampleCounts countCurveSamples(const FactorGraph& graph, const Values& values) {
  CurveSampleCounts counts;
  for (const auto& factor : graph) {
    if (const auto* curve = dynamic_cast<const CurveReprojectionFactor*>(factor.get())) {
      counts += curve->sampleCounts(values);
    }
  }
  return counts;
}

}  // namespace curvesfm
