#include "sim/curve_scene_input.h"

#include <utility>

#include "core/nearest_edge_field.h"

namespace curvesfm {

std::vector<std::shared_ptr<const NearestEdgeField>> buildKeyframeFields(const CurveScene& scene) {
  std::vector<std::shared_ptr<const NearestEdgeField>> fields;
  fields.reserve(scene.keyframes.size());
  for (const CurveKeyframe& keyframe : scene.keyframes) {
    fields.push_back(std::make_shared<const NearestEdgeField>(
        NearestEdgeField::build(keyframe.edges, keyframe.grad_x, keyframe.grad_y)));
  }
  return fields;
}

CurveBundleAdjustmentInput makeCurveBundleAdjustmentInput(const CurveScene& scene,
                                                          SceneStart start) {
  return makeCurveBundleAdjustmentInput(scene, buildKeyframeFields(scene), start);
}

CurveBundleAdjustmentInput makeCurveBundleAdjustmentInput(
    const CurveScene& scene, std::vector<std::shared_ptr<const NearestEdgeField>> fields,
    SceneStart start) {
  const bool truth = start == SceneStart::kTruth;
  CurveBundleAdjustmentInput input;
  input.camera = scene.camera;
  input.cam_from_world = truth ? scene.true_cam_from_world : scene.initial_cam_from_world;
  input.curves = truth ? scene.true_curves : scene.initial_curves;
  input.scale_distance = scene.trueScaleDistance();
  input.fields = std::move(fields);
  for (const CurveObservation& obs : scene.observations) {
    input.observations.push_back({obs.curve_index, obs.segment_index, obs.keyframe_index});
  }
  return input;
}

}  // namespace curvesfm
