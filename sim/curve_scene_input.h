#pragma once

#include <memory>
#include <vector>

#include "factors/curve_bundle_adjustment.h"
#include "sim/curve_scene.h"

namespace curvesfm {

/// Where a curve bundle adjustment of a synthetic scene starts.
enum class SceneStart {
  kPerturbed,  ///< The scene's initial (perturbed) poses and curves: the solver's task.
  kTruth,      ///< The true poses and curves: for costs at the optimum and for benchmarks.
};

/// One NearestEdgeField (default reach) per keyframe, from its Canny edges and Sobel gradients.
/// Building them dominates the cost of an input: build once per scene, solve many times.
std::vector<std::shared_ptr<const NearestEdgeField>> buildKeyframeFields(const CurveScene& scene);

/// The curve bundle adjustment of a synthetic scene: the scene's camera, poses and curves from
/// `start`, the keyframe fields, one SegmentObservation per scene observation (partly hidden ones
/// included: occlusion is what the solver must cope with), and the true distance between
/// keyframes 0 and 1 as the scale gauge.
CurveBundleAdjustmentInput makeCurveBundleAdjustmentInput(
    const CurveScene& scene, SceneStart start = SceneStart::kPerturbed);

/// The same with fields the caller built (one per keyframe, e.g. to time their construction).
CurveBundleAdjustmentInput makeCurveBundleAdjustmentInput(
    const CurveScene& scene, std::vector<std::shared_ptr<const NearestEdgeField>> fields,
    SceneStart start = SceneStart::kPerturbed);

}  // namespace curvesfm
